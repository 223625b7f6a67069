"""Nested multi-resolution layer stacks: data object, consistency, manifest and files.

A :class:`Stack` holds layers ``0..n-1`` of a DEM around a site, each 2x finer than the
last: layer ``k`` (k >= 1) is the RMD expansion of the square *footprint*
``windows[k-1] = (row_off, col_off, width)`` of layer ``k - 1``, so it has
``2 width - 1`` pixels a side and its even pixels lie on the footprint's pixels.
**Consistency**: inside its footprint, a finer layer's even pixels equal the coarser
layer, ``layers[k].heights[::2, ::2] == layers[k-1].heights[footprint]`` exactly
(:meth:`Stack.mismatch_m`, :meth:`Stack.is_consistent`).

On disk a stack is a folder: ``layer_00.tif ...`` (GeoTIFF, :func:`dem.write`),
``craters_00.csv`` / ``craters_00.geojson ...`` (the craters stamped in each layer, local
frame metres + world coordinates), ``craters_00.scc ...`` (each layer's crater count for
crater-counting tools, :meth:`Stack.crater_count`), ``boulders_00.csv`` / ``.geojson`` (the boulders
stamped in each layer, if any) and ``manifest.json`` (format, frame, layers, files,
bounds, pixel sizes, seeds, parameters, crater counts). The folder is written as a whole
(:meth:`Stack.write`: a temporary folder renamed into place), so it is complete or absent.
"""

from __future__ import annotations

import contextlib
import json
import os
import re
import shutil
from pathlib import Path

import numpy as np

from craters import (
    make_catalog,
    read_catalog,
    validate_catalog,
    write_catalog,
    write_geojson,
    write_scc,
)
from craters._shared import (
    ParameterError,
    check_int,
    check_outside_folder,
    check_parent_folder,
    package_version,
    progress_bar,
    replace_output,
    sweep_temporaries,
    temp_folder,
)
from craters._shared.files import check_regular_file
from craters._shared.outputs import claim

from .core import Dem, crs_label
from .frame import (
    LocalFrame,
    body_axes_m,
    body_name,
    geographic_crs,
    grid_pixel_size,
    pixel_affine,
    world_to_lonlat,
)
from .io import read, write

__all__ = ["MANIFEST", "STACK_FORMAT", "Stack", "check_stack_folder", "propagate_up", "read_stack",
           "write_stack"]

STACK_FORMAT = "craterform layer stack v1"
#: File name of the manifest inside a stack folder.
MANIFEST = "manifest.json"


def _layer_file(k: int) -> str:
    return f"layer_{k:02d}.tif"


def _catalog_files(k: int) -> tuple[str, str]:
    return f"craters_{k:02d}.csv", f"craters_{k:02d}.geojson"


def _count_file(k: int) -> str:
    return f"craters_{k:02d}.scc"


def _boulder_files(k: int) -> tuple[str, str]:
    return f"boulders_{k:02d}.csv", f"boulders_{k:02d}.geojson"


def _check_catalogs(catalogs, column: str, message: str) -> None:
    for cat in catalogs:
        if cat is not None:
            validate_catalog(cat)
            if column not in cat.dtype.names:
                raise ValueError(message)


def _window(value, k: int) -> tuple[int, int, int]:
    try:
        r0, c0, w = value
    except (TypeError, ValueError):
        raise TypeError(f"`windows[{k}]` must be (row_off, col_off, width); "
                        f"got {value!r}") from None
    return (check_int(f"windows[{k}] row_off", r0, 0), check_int(f"windows[{k}] col_off", c0, 0),
            check_int(f"windows[{k}] width", w, 2))


class Stack:
    """Layers of a DEM, each the 2x expansion of a footprint of the previous one.

    Parameters
    ----------
    layers : sequence of Dem
        Coarsest first; all with the same CRS.
    windows : sequence of (row_off, col_off, width)
        ``windows[k - 1]`` is the footprint of layer ``k`` in layer ``k - 1`` (pixels);
        layer ``k`` must have ``2 width - 1`` pixels a side.
    frame : LocalFrame
        The local metric frame of the stack (:mod:`dem.frame`), origin at the site.
    catalogs : sequence of structured arrays, optional
        Per layer, the craters stamped in it (``x_m, y_m`` in ``frame``); None = none.
    info : dict, optional
        JSON-ready metadata (seed, parameters, crater counts) kept in the manifest.
    boulders : sequence of structured arrays, optional
        Per layer, the boulders stamped in it (placement in ``frame``, see
        :mod:`dem.boulders`); None = none.

    Examples
    --------
    >>> import dem
    >>> from rasterio.windows import Window
    >>> base = Dem(np.zeros((5, 5)), pixel_size_m=4.0)
    >>> fine = dem.expand(base, 1, fractal_dimension=2.2, roughness=0.1,
    ...                   region=Window(1, 1, 3, 3), rng=1)   # rows/cols 1..3
    >>> s = Stack([base, fine], [(1, 1, 3)], dem.local_frame(base))
    >>> s.shapes, s.is_consistent()
    ([(5, 5), (5, 5)], True)
    """

    __slots__ = ("_layers", "_windows", "_frame", "_catalogs", "_info", "_boulders")

    def __init__(self, layers, windows, frame: LocalFrame, catalogs=None, info=None,
                 boulders=None):
        layers = tuple(layers)
        if not layers or not all(isinstance(d, Dem) for d in layers):
            raise TypeError("`layers` must be a non-empty sequence of Dem")
        windows = tuple(_window(w, k) for k, w in enumerate(windows))
        if len(windows) != len(layers) - 1:
            raise ValueError(f"`windows` must have one footprint per finer layer "
                             f"({len(layers) - 1}); got {len(windows)}")
        if not isinstance(frame, LocalFrame):
            raise TypeError(f"`frame` must be a LocalFrame; got {type(frame).__name__}")
        for k, (r0, c0, w) in enumerate(windows, start=1):
            rows, cols = layers[k - 1].shape
            if r0 + w > rows or c0 + w > cols:
                raise ValueError(f"footprint of layer {k} (rows {r0}..{r0 + w - 1}, cols "
                                 f"{c0}..{c0 + w - 1}) is not inside layer {k - 1} "
                                 f"({rows} x {cols})")
            if layers[k].shape != (2 * w - 1, 2 * w - 1):
                raise ValueError(f"layer {k} must be {2 * w - 1} x {2 * w - 1} pixels (its "
                                 f"footprint is {w} pixels wide); got {layers[k].shape}")
            if layers[k].crs != layers[0].crs:
                raise ValueError(f"layer {k} has CRS {crs_label(layers[k].crs)}, layer 0 "
                                 f"{crs_label(layers[0].crs)}")
        if catalogs is None:
            catalogs = (None,) * len(layers)
        catalogs = tuple(catalogs)
        if len(catalogs) != len(layers):
            raise ValueError(f"`catalogs` must have one entry per layer ({len(layers)}); "
                             f"got {len(catalogs)}")
        _check_catalogs(catalogs, "x_m", "stack catalogs need local-frame positions x_m, y_m")
        boulders = (None,) * len(layers) if boulders is None else tuple(boulders)
        if len(boulders) != len(layers):
            raise ValueError(f"`boulders` must have one entry per layer ({len(layers)}); "
                             f"got {len(boulders)}")
        _check_catalogs(boulders, "centre_x_m", "stack boulder catalogs need placed "
                        "boulders (centre_x_m, ... from dem.stamp_boulders)")
        self._boulders = boulders
        self._layers = layers
        self._windows = windows
        self._frame = frame
        self._catalogs = catalogs
        self._info = dict(info or {})

    # ------------------------------------------------------------------ data
    @property
    def layers(self) -> tuple[Dem, ...]:
        """The layers, coarsest first."""
        return self._layers

    @property
    def windows(self) -> tuple[tuple[int, int, int], ...]:
        """Footprint (row_off, col_off, width) of layer k + 1 in layer k, for each k."""
        return self._windows

    @property
    def frame(self) -> LocalFrame:
        """The local metric frame (origin at the site)."""
        return self._frame

    @property
    def catalogs(self) -> tuple:
        """Per layer, the craters stamped in it (structured arrays or None)."""
        return self._catalogs

    @property
    def boulders(self) -> tuple:
        """Per layer, the boulders stamped in it (structured array) or None."""
        return self._boulders

    @property
    def info(self) -> dict:
        """Metadata (a copy): seed, parameters, crater counts."""
        return json.loads(json.dumps(self._info))

    @property
    def shapes(self) -> list[tuple[int, int]]:
        """(rows, cols) of every layer."""
        return [d.shape for d in self._layers]

    def __len__(self) -> int:
        return len(self._layers)

    def __repr__(self) -> str:
        sizes = ", ".join(f"{p:.4g}" for p in self.pixel_sizes_m())
        return f"Stack({len(self)} layers of {self._layers[0].shape}, pixel sizes m: {sizes})"

    def pixel_sizes_m(self) -> list[float]:
        """Side of each layer's pixels in the local frame, metres (the square root of the
        pixel area if the pixels are not square)."""
        return [grid_pixel_size(pixel_affine(d, self._frame), square=False)
                for d in self._layers]

    def replace(self, *, layers=None, catalogs=None, info=None, boulders=None) -> Stack:
        """A new stack with some parts replaced (same footprints and frame)."""
        return Stack(self._layers if layers is None else layers, self._windows, self._frame,
                     self._catalogs if catalogs is None else catalogs,
                     self._info if info is None else info,
                     self._boulders if boulders is None else boulders)

    # ------------------------------------------------------------------ consistency
    def mismatch_m(self) -> list[float]:
        """For k = 1..n-1: max |layer k even pixels - layer k-1 footprint| in metres.

        0.0 everywhere means the stack is consistent; NaN pixels count as equal when both
        are NaN, as infinitely different otherwise.
        """
        out = []
        for k, (r0, c0, w) in enumerate(self._windows, start=1):
            coarse = self._layers[k - 1].heights[r0:r0 + w, c0:c0 + w]
            fine = self._layers[k].heights[::2, ::2]
            both = np.isnan(coarse) & np.isnan(fine)
            d = np.where(both, 0.0, np.abs(fine - coarse))
            out.append(float(np.where(np.isnan(d), np.inf, d).max()))
        return out

    def is_consistent(self) -> bool:
        """True if every finer layer's even pixels equal the coarser layer exactly."""
        return all(m == 0.0 for m in self.mismatch_m())

    # ------------------------------------------------------------------ files
    def _geojson(self, name: str) -> str | None:
        """The GeoJSON file of a layer's catalog: written only where the CRS names a
        body (RFC 7946 positions are longitude, latitude)."""
        return name if geographic_crs(self._layers[0].crs) is not None else None

    def manifest(self) -> dict:
        """The JSON manifest describing this stack (file names relative to the folder)."""
        sizes = self.pixel_sizes_m()
        layers = []
        for k, d in enumerate(self._layers):
            b = d.bounds
            entry = {
                "index": k, "file": _layer_file(k), "shape": list(d.shape),
                "pixel_size_m": sizes[k], "dem_pixel_size_m": list(d.pixel_size_m),
                "bounds": [b.left, b.bottom, b.right, b.top],
                "transform": list(tuple(d.transform)[:6]), "level": d.level,
                "origin": list(d.origin),
                "footprint_in_parent": list(self._windows[k - 1]) if k else None,
            }
            cat = self._catalogs[k]
            if cat is not None:
                csv_name, geojson_name = _catalog_files(k)
                entry["craters"] = {"csv": csv_name, "geojson": self._geojson(geojson_name),
                                    "stamped": int(len(cat)), "scc": _count_file(k),
                                    "counted": int(len(self.crater_count(k)[0]))}
            rocks = self._boulders[k]
            if rocks is not None:
                csv_name, geojson_name = _boulder_files(k)
                entry["boulders"] = {"csv": csv_name, "geojson": self._geojson(geojson_name),
                                     "stamped": int(len(rocks))}
            layers.append(entry)
        return {
            "format": STACK_FORMAT, "generator": f"craterform {package_version()}",
            "crs": crs_label(self._layers[0].crs),
            "crs_wkt": None if self._layers[0].crs is None else self._layers[0].crs.to_wkt(),
            "frame": self._frame.to_dict(), "layers": layers, "info": self._info,
            "consistency": "inside its footprint, layer k's even pixels equal layer k-1 "
                           "exactly (layer[k][::2, ::2] == layer[k-1][footprint])",
        }

    def write(self, folder, *, force: bool = False, progress: bool = False) -> Path:
        """Write the stack into ``folder`` as a whole; return the manifest's path.

        The files go to a temporary folder next to ``folder`` that is renamed into place
        at the end, so an error leaves nothing behind. An existing ``folder`` is replaced
        only with ``force`` and only if it is empty or a stack folder (has a manifest).
        """
        return write_stack(self, check_stack_folder(folder, force=force), progress=progress)

    def world_catalog(self, k: int, *, boulders: bool = False) -> np.ndarray:
        """Layer ``k``'s crater (or boulder) catalog with ``world_x, world_y`` columns (CRS
        units) added."""
        cat = self._boulders[k] if boulders else self._catalogs[k]
        wx, wy = self._frame.to_world(cat["x_m"], cat["y_m"])
        cols = {n: cat[n] for n in cat.dtype.names if n not in ("world_x", "world_y")}
        return make_catalog(**cols, world_x=wx, world_y=wy)


    def crater_count(self, k: int, *, min_crater_px: float | None = None):
        """What a crater counter sees in layer ``k``: (catalog, area in m^2).

        Every stamped crater of the stack (the catalogs of all layers: a crater sits in
        the finest layer that holds it, and is in every coarser layer's heights too)
        whose centre lies in layer ``k`` and whose diameter spans at least
        ``min_crater_px`` of its pixels (default: the stack's own, else 2), over the
        layer's area: complete in that diameter range up to craters that reached past
        the stack or were erased on steep ground. The catalog has ``x_m, y_m`` (local
        frame), ``diameter_m, age_gyr, degradation, kind``, the ``layer`` it was stamped
        in, ``world_x, world_y`` and, where the CRS names a body, ``lat_deg, lon_deg``.
        """
        k = check_int("k", k, 0, len(self) - 1)
        if min_crater_px is None:
            min_crater_px = float((self._info.get("craters") or {}).get("min_crater_px", 2.0))
        d = self._layers[k]
        b = d.bounds
        xs, ys = self._frame.to_local([b.left, b.right], [b.bottom, b.top])
        x0, x1 = sorted(xs.tolist())
        y0, y1 = sorted(ys.tolist())
        d_min = min_crater_px * self.pixel_sizes_m()[k]
        parts = []
        for j, cat in enumerate(self._catalogs):
            if cat is None:
                continue
            inside = ((cat["x_m"] >= x0) & (cat["x_m"] <= x1) & (cat["y_m"] >= y0)
                      & (cat["y_m"] <= y1) & (cat["diameter_m"] >= d_min))
            cols = {n: cat[n][inside] for n in ("x_m", "y_m", "diameter_m", "age_gyr",
                                                "degradation", "kind")}
            parts.append(make_catalog(**cols, layer=np.full(int(inside.sum()), j)))
        cat = (np.concatenate(parts) if parts else
               make_catalog(x_m=[], y_m=[], diameter_m=[], layer=np.zeros(0, np.int64)))
        wx, wy = self._frame.to_world(cat["x_m"], cat["y_m"])
        extra = {"world_x": wx, "world_y": wy}
        lonlat = world_to_lonlat(d.crs, wx, wy)
        if lonlat is not None:
            extra.update(lat_deg=lonlat[1], lon_deg=lonlat[0])
        names = cat.dtype.names
        assert names is not None  # a catalog: a structured array
        cols = {n: cat[n] for n in names}
        return make_catalog(**cols, **extra), (x1 - x0) * (y1 - y0)


def propagate_up(arrays: list[np.ndarray], windows, k: int) -> None:
    """Make layers k-1 .. 0 agree with layer k in place: each coarser footprint takes the
    finer layer's even pixels (``arrays[j][footprint] = arrays[j + 1][::2, ::2]``)."""
    for j in range(k - 1, -1, -1):
        r0, c0, w = windows[j]
        arrays[j][r0:r0 + w, c0:c0 + w] = arrays[j + 1][::2, ::2]


#: The names of the files a stack writes (:func:`write_stack`): only a folder holding
#: nothing else is replaced.
STACK_FILE = re.compile(r"^(manifest\.json|layer_\d{2,}\.tif|(craters|boulders)_\d{2,}"
                        r"\.(csv|geojson|prj)|craters_\d{2,}\.scc)$")


def check_stack_folder(folder, *, force: bool, inputs=()) -> Path:
    """Validate an output stack folder before any work (see :meth:`Stack.write`): a
    folder replaced with ``force`` must be a stack folder holding only the files a stack
    writes, and none of ``inputs`` (pairs of (what, path)) may lie inside it."""
    folder = Path(folder)
    check_parent_folder(folder)
    check_outside_folder(folder, inputs, flag="output")
    if folder.exists():
        if not folder.is_dir():
            raise ValueError(f"output {str(folder)!r} exists and is not a folder")
        if any(folder.iterdir()):
            if not force:
                raise ParameterError("force", f"is needed: output {str(folder)!r} exists")
            if not (folder / MANIFEST).is_file():
                raise ValueError(f"output {str(folder)!r} is not a stack folder (no {MANIFEST}); "
                                 f"refusing to replace it")
            foreign = sorted(p.name for p in folder.iterdir()
                             if not (STACK_FILE.match(p.name) and p.is_file()
                                     and not p.is_symlink()))
            if foreign:
                more = f" and {len(foreign) - 1} more" if len(foreign) > 1 else ""
                raise ValueError(f"output {str(folder)!r} holds {foreign[0]!r}{more}, which a "
                                 f"stack does not write; refusing to replace it")
    sweep_temporaries(folder.parent if str(folder.parent) else Path("."))
    claim(folder, force=force)
    return folder


def write_stack(stack: Stack, folder: Path, *, progress: bool = False,
                layer_files=None) -> Path:
    """Write ``stack`` into ``folder``, already checked by :func:`check_stack_folder`
    (:meth:`Stack.write` does both; the command line checks before the work); return the
    manifest's path. The files go to a temporary folder next to ``folder`` that is renamed
    into place at the end, so an error leaves nothing behind. ``layer_files``: the layers'
    GeoTIFFs made already (on the same file system; moved in instead of written)."""
    n = len(stack)
    with _atomic_folder(Path(folder)) as tmp:
        steps = [("layer", k) for k in range(n)]
        steps += [("craters", k) for k in range(n) if stack.catalogs[k] is not None]
        steps += [("boulders", k) for k in range(n) if stack.boulders[k] is not None]
        for what, k in progress_bar(steps, enabled=progress, desc="write"):
            if what == "layer" and layer_files is not None:
                os.replace(layer_files[k], tmp / _layer_file(k))
            elif what == "layer":
                write(stack.layers[k], tmp / _layer_file(k))
            else:
                _write_catalog(stack, k, tmp, boulders=what == "boulders")
        text = json.dumps(stack.manifest(), indent=1, sort_keys=True, allow_nan=False)
        (tmp / MANIFEST).write_text(text + "\n", encoding="utf-8")
    return Path(folder) / MANIFEST


def _write_catalog(stack: Stack, k: int, folder: Path, *, boulders: bool = False) -> None:
    csv_name, geojson_name = (_boulder_files if boulders else _catalog_files)(k)
    cat = stack.world_catalog(k, boulders=boulders)
    write_catalog(cat, folder / csv_name)
    crs = stack.layers[0].crs
    geo = geographic_crs(crs)
    if geo is not None:  # RFC 7946 GeoJSON is longitude, latitude: only on a known body
        write_geojson(cat, folder / geojson_name, body=body_name(geo), crs=crs_label(geo),
                      lonlat=lambda x, y: world_to_lonlat(crs, *stack.frame.to_world(x, y)),
                      prj=geo.to_wkt(version="WKT1_ESRI"))
    if not boulders:
        _write_count(stack, k, folder)


def _write_count(stack: Stack, k: int, folder: Path) -> None:
    """Layer ``k``'s crater count as a craterstats ``.scc`` (:meth:`Stack.crater_count`)."""
    count, area = stack.crater_count(k)
    d = stack.layers[k]
    b = d.bounds
    corners = world_to_lonlat(d.crs, [b.left, b.right, b.right, b.left],
                              [b.bottom, b.bottom, b.top, b.top])
    crs = d.crs
    write_scc(count, folder / _count_file(k), area_m2=area,
              axes_m=body_axes_m(crs, d.body_radius_m),
              coordinate_system=None if crs is None else crs_label(crs),
              boundary_lonlat_deg=None if corners is None else np.column_stack(corners),
              note=f"dem enhance layer {k}: the stack's craters centred in this layer and "
                   f"resolved by it (dem.Stack.crater_count)")


@contextlib.contextmanager
def _atomic_folder(folder: Path):
    """Yield a temporary folder next to ``folder``; swap it into place on success."""
    tmp = temp_folder(folder)
    try:
        yield tmp
        replace_output(tmp, folder)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise


def read_stack(path, *, progress: bool = False) -> Stack:
    """Read a stack written by :meth:`Stack.write` (its manifest, or the folder)."""
    path = Path(path)
    manifest = path / MANIFEST if path.is_dir() else path
    check_regular_file(manifest, "stack manifest")
    try:
        doc = json.loads(manifest.read_text(encoding="utf-8"))
    except (UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise ValueError(f"{str(manifest)!r} is not a JSON manifest: {exc}") from None
    if not isinstance(doc, dict) or doc.get("format") != STACK_FORMAT:
        raise ValueError(f"{str(manifest)!r} is not a craterform stack manifest (format "
                         f"{STACK_FORMAT!r})")
    folder = manifest.parent
    try:
        frame = LocalFrame.from_dict(doc["frame"])
        entries = doc["layers"]
        layers, windows, catalogs, rocks = [], [], [], []
        for e in progress_bar(entries, enabled=progress, desc="read"):
            layers.append(read(folder / e["file"]))
            if e["index"] > 0:
                windows.append(tuple(e["footprint_in_parent"]))
            cat = e.get("craters")
            catalogs.append(read_catalog(folder / cat["csv"]) if cat else None)
            b = e.get("boulders")
            rocks.append(read_catalog(folder / b["csv"]) if b else None)
        return Stack(layers, windows, frame, catalogs, doc.get("info"), rocks)
    except (KeyError, TypeError) as exc:
        raise ValueError(f"stack manifest {str(manifest)!r} is incomplete: {exc!r}") from None
