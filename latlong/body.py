"""The body: a lat/long grid with one radius per vertex, saved losslessly as .npz.

A :class:`Body` is a :class:`~latlong.geometry.surface.Surface` (its triangle mesh, vertex
normals, local frames, mesh export) and :class:`~latlong.geometry.surface.Resamplable`
(onto a coarser grid)."""

from __future__ import annotations

import json
import zipfile
from pathlib import Path

import numpy as np

from craters import validate_catalog
from craters._shared import (
    ParameterError,
    ParameterTypeError,
    atomic_path,
    check_int,
    check_positive,
)
from craters._shared.files import check_regular_file
from craters.exact import dot

from .export import EXPORT_SUFFIXES, body_mesh_source, export_body
from .geometry.meshes import polydata
from .geometry.normals import lat_long_vertex_normals, tangent_frames, unit_rows, vertex_normals
from .grid import LatLongGrid
from .scratch import drop_pages

__all__ = ["Body", "EXPORT_SUFFIXES", "load"]

FORMAT = "craterform.body/1"
#: The arrays every saved body holds (craters and boulders are optional).
_SAVED = ("format", "magnitude", "radius_m", "stretch", "radii_m", "metadata_json")
# a fixed zip timestamp so that the same body always gives the same bytes
_ZIP_DATE = (1980, 1, 1, 0, 0, 0)


class Body:
    """A lat/long grid plus one radius per vertex (metres) and an optional axis stretch.

    Vertex ``i`` sits at ``stretch * radii_m[i] * u_i`` with ``u_i`` the grid's unit
    vector. ``radius_m`` is the reference radius (heights are ``radii_m - radius_m``).
    Bodies are immutable: operations return new bodies.

    Parameters
    ----------
    grid : LatLongGrid
    radii_m : (N,) array_like
        Radius of every vertex in metres, finite and > 0.
    radius_m : float, optional
        Reference radius in metres (default: the area-weighted mean of ``radii_m``).
    stretch : (3,) array_like, optional
        Scale factors along x, y, z (default 1, 1, 1).
    metadata : dict, optional
        JSON-serialisable description (seed, parameters, version, ...).
    craters : structured array, optional
        The crater catalog that made the body (see :mod:`craters.catalog`), as stamped.
    boulders : structured array, optional
        The boulders placed on the body (see :mod:`latlong.boulders`).
    copy : bool
        False: take ``radii_m`` over without a copy when it is a C-contiguous float64
        array already (for very large bodies: no second array); it becomes read-only and
        must not be written to afterwards by other means.

    Examples
    --------
    >>> b = Body.sphere(LatLongGrid(4), 10.0)
    >>> b.n_vertices, float(b.radii_m.max())
    (98, 10.0)
    """

    __slots__ = ("_grid", "_radii", "_radius_m", "_stretch", "_metadata", "_craters",
                 "_boulders")

    def __init__(self, grid: LatLongGrid, radii_m, *, radius_m: float | None = None,
                 stretch=(1.0, 1.0, 1.0), metadata: dict | None = None, craters=None,
                 boulders=None, copy: bool = True):
        if not isinstance(grid, LatLongGrid):
            raise TypeError(f"`grid` must be a LatLongGrid; got {type(grid).__name__}")
        if np.iscomplexobj(radii_m):
            raise ParameterTypeError("radii_m", "must be real numbers; got complex values")
        if copy:
            radii = np.array(radii_m, dtype=np.float64, copy=True)
        else:
            radii = np.ascontiguousarray(radii_m, dtype=np.float64)
        if radii.shape != (grid.n_vertices,):
            raise ValueError(f"`radii_m` must have shape ({grid.n_vertices},); got {radii.shape}")
        self._setup(grid, radii, radius_m, stretch, metadata, craters, boulders)

    def _setup(self, grid, radii, radius_m, stretch, metadata, craters, boulders, *,
               checked: bool = False):
        """Validate and store (``radii``: this body's own float64 array, made read-only;
        ``checked``: known finite and > 0 already)."""
        if not checked:
            _check_radii(radii)
        radii.setflags(write=False)
        stretch = np.array(stretch, dtype=np.float64).reshape(-1)
        if stretch.shape != (3,) or not np.isfinite(stretch).all() or (stretch <= 0).any():
            raise ValueError(f"`stretch` must be three finite factors > 0; got {stretch.tolist()}")
        stretch.setflags(write=False)
        if radius_m is None:
            radius_m = _area_mean(grid, radii)
        self._grid = grid
        self._radii = radii
        self._radius_m = check_positive("radius_m", radius_m)
        self._stretch = stretch
        meta = {} if metadata is None else dict(metadata)
        try:
            json.dumps(meta)
        except TypeError as exc:
            raise TypeError(f"`metadata` must be JSON-serialisable: {exc}") from None
        self._metadata = meta
        if craters is not None:
            craters = np.array(validate_catalog(craters), copy=True)
            craters.setflags(write=False)
        self._craters = craters
        if boulders is not None:
            boulders = np.array(validate_catalog(boulders), copy=True)
            missing = [c for c in ("centre_x_m", "quat_w", "seed", "shape_flatten")
                       if c not in boulders.dtype.names]
            if missing:
                raise ValueError(f"`boulders` must be a placed catalog "
                                 f"(latlong.place_boulders); it has no {missing[0]!r} column")
            boulders.setflags(write=False)
        self._boulders = boulders

    # ------------------------------------------------------------------ constructors
    @classmethod
    def sphere(cls, grid: LatLongGrid, radius_m: float, **kwargs) -> Body:
        """A sphere of ``radius_m`` metres."""
        radius_m = check_positive("radius_m", radius_m)
        return cls(grid, np.full(grid.n_vertices, radius_m), radius_m=radius_m, copy=False,
                   **kwargs)

    @classmethod
    def from_heights(cls, grid: LatLongGrid, radius_m: float, heights_m, **kwargs) -> Body:
        """A body whose radii are ``radius_m + heights_m``."""
        radius_m = check_positive("radius_m", radius_m)
        return cls(grid, radius_m + np.asarray(heights_m, dtype=np.float64),
                   radius_m=radius_m, copy=False, **kwargs)

    def replace(self, *, copy: bool = True, **changes) -> Body:
        """A new body with some of ``radii_m, radius_m, stretch, metadata, craters,
        boulders`` replaced. Pure: nothing is recomputed. A body with boulders whose
        surface changes (``radii_m`` or ``stretch``) must be given its boulders again,
        placed on the new surface (``boulders=latlong.place_boulders(new, old.boulders)``
        or ``boulders=None``): boulders are never left floating or buried silently.

        Unchanged radii are shared with this body (read-only), not copied; new
        ``radii_m`` are copied unless ``copy=False`` (see :class:`Body`)."""
        kw = {"radii_m": self._radii, "radius_m": self._radius_m,
              "stretch": self._stretch, "metadata": self._metadata,
              "craters": self._craters, "boulders": self._boulders}
        unknown = set(changes) - set(kw)
        if unknown:
            raise TypeError(f"unknown Body fields: {', '.join(sorted(unknown))}")
        moved = {"radii_m", "stretch"} & set(changes)
        if moved and "boulders" not in changes and self._boulders is not None \
                and len(self._boulders):
            raise ValueError(
                f"the body's surface changes ({', '.join(sorted(moved))}) but it has "
                f"{len(self._boulders)} placed boulders: pass `boulders` too (None, or the "
                "catalog placed again with latlong.place_boulders on the new body)")
        kw.update(changes)
        radii = kw.pop("radii_m")
        if "radii_m" not in changes:  # read-only and checked already: shared
            new = Body.__new__(Body)
            new._setup(self._grid, radii, checked=True, **kw)
            return new
        return Body(self._grid, radii, copy=copy, **kw)

    # ------------------------------------------------------------------ data
    @property
    def grid(self) -> LatLongGrid:
        return self._grid

    @property
    def magnitude(self) -> int:
        return self._grid.magnitude

    @property
    def n_vertices(self) -> int:
        return self._grid.n_vertices

    @property
    def radii_m(self) -> np.ndarray:
        """Radius of every vertex in metres (before the stretch), read-only."""
        return self._radii

    @property
    def radius_m(self) -> float:
        """Reference radius in metres."""
        return self._radius_m

    @property
    def stretch(self) -> np.ndarray:
        """Scale factors along x, y, z, read-only."""
        return self._stretch

    @property
    def metadata(self) -> dict:
        """A copy of the metadata dictionary."""
        return json.loads(json.dumps(self._metadata))

    @property
    def craters(self) -> np.ndarray | None:
        """The crater catalog as stamped (read-only structured array) or None."""
        return self._craters

    @property
    def boulders(self) -> np.ndarray | None:
        """The boulders placed on the body (read-only structured array) or None."""
        return self._boulders

    @property
    def heights_m(self) -> np.ndarray:
        """``radii_m - radius_m`` in metres."""
        return self._radii - self._radius_m

    def lod(self, level: int) -> Body:
        """The nested coarser body of magnitude M / 2^level: exactly this body's vertices
        on the even rings / even positions, ``level`` times (no resampling)."""
        level = check_int("level", level, 0, 30)
        factor = 2**level
        if self.magnitude % factor:
            raise ValueError(f"`level` {level} needs a magnitude divisible by {factor}; "
                             f"this body has M = {self.magnitude}")
        if level == 0:
            return self
        coarse = LatLongGrid(self.magnitude // factor)
        idx = self._grid.nested_indices(coarse)
        meta = {**self._metadata, "lod_level": level, "lod_of_magnitude": self.magnitude}
        return Body(coarse, self._radii[idx], radius_m=self._radius_m, stretch=self._stretch,
                    metadata=meta, copy=False)

    def vertices(self, lo: int = 0, hi: int | None = None) -> np.ndarray:
        """Vertex positions in metres, (N, 3) float64 (or the rows ``lo:hi``)."""
        u = self._grid.unit_vectors_range(lo, hi)
        return u * (self._radii[lo:hi, None] * self._stretch)

    def mesh(self) -> tuple[np.ndarray, np.ndarray]:
        """``(vertices, faces)``: (N, 3) float64 positions in metres and the grid's
        (2N - 4, 3) triangles (boulders not included)."""
        return self.vertices(), self._grid.triangles()

    def vertex_normals(self, weighting: str = "area") -> np.ndarray:
        """Unit vertex normals of the body's triangle mesh with a named weighting
        (:data:`latlong.geometry.normals.WEIGHTINGS`): ``"area"`` float32 (N, 3), streamed
        band by band (:func:`~latlong.geometry.normals.lat_long_vertex_normals`); the
        others float64 from :meth:`mesh`."""
        if weighting == "area":
            return lat_long_vertex_normals(self._grid, self._radii, self._stretch)
        return vertex_normals(*self.mesh(), weighting)

    def local_frames(self, points) -> np.ndarray:
        """(n, 3, 3) frames, rows east, north, up, at the surface under ``points`` (n, 3)
        seen from the centre: up is the area-weighted vertex normals interpolated at the
        points' grid directions (as boulders stand), east = z x up
        (:func:`~latlong.geometry.normals.tangent_frames`)."""
        q = np.asarray(points, dtype=np.float64).reshape(-1, 3) / self._stretch
        r = np.linalg.norm(q, axis=1)
        colat = np.arccos(np.clip(q[:, 2] / np.where(r > 0, r, 1.0), -1.0, 1.0))
        lon = np.arctan2(q[:, 1], q[:, 0])
        normals = self.vertex_normals("area").astype(np.float64)
        up = np.stack([self._grid.interpolate(normals[:, c], colat, lon) for c in range(3)], 1)
        return tangent_frames(unit_rows(up))

    def mesh_source(self):
        """The body and its placed boulders as a streamed
        :class:`~latlong.meshio.writers.MeshSource` for the mesh writers
        (:func:`latlong.export.body_mesh_source`)."""
        return body_mesh_source(self)

    def resampled(self, max_vertices: int) -> Body:
        """This body on the largest grid of at most ``max_vertices`` vertices (itself when
        it has no more): radii interpolated at the coarse grid's directions
        (:meth:`LatLongGrid.interpolate`), reference radius, stretch and boulders kept."""
        max_vertices = check_int("max_vertices", max_vertices, 8, 2**62)
        if self.n_vertices <= max_vertices:
            return self
        small = LatLongGrid(int(np.sqrt((max_vertices - 2) / 6.0)))
        radii = self._grid.interpolate(self._radii, (np.pi / 2) - small.latitudes(),
                                       small.longitudes())
        return Body(small, radii, radius_m=self._radius_m, stretch=self._stretch,
                    boulders=self._boulders)

    def __repr__(self) -> str:
        return (f"Body(magnitude={self.magnitude}, n_vertices={self.n_vertices}, "
                f"radius_m={self._radius_m:g}, stretch={self._stretch.tolist()})")

    # ------------------------------------------------------------------ I/O
    def save(self, path, *, progress: bool = False) -> Path:
        """Write the body to ``path``, atomically: losslessly as ``.npz`` (no pickles;
        the bytes depend only on the body: fixed zip timestamps, so the same seed and
        parameters give identical files), or as a mesh file chosen by its suffix
        (:meth:`export`)."""
        path = Path(path)
        if path.suffix.lower() != ".npz":
            return self.export(path, progress=progress)
        arrays = {
            "format": np.array(FORMAT),
            "magnitude": np.array(self.magnitude, dtype=np.int64),
            "radius_m": np.array(self._radius_m, dtype=np.float64),
            "stretch": np.asarray(self._stretch, dtype=np.float64),
            "radii_m": np.asarray(self._radii, dtype=np.float64),
            "metadata_json": np.array(json.dumps(self._metadata, sort_keys=True)),
        }
        if self._craters is not None:
            arrays["craters"] = np.asarray(self._craters)
        if self._boulders is not None:
            arrays["boulders"] = np.asarray(self._boulders)
        with atomic_path(path) as tmp:
            with zipfile.ZipFile(tmp, "w", compression=zipfile.ZIP_STORED,
                                 allowZip64=True) as zf:
                for name, arr in arrays.items():
                    info = zipfile.ZipInfo(name + ".npy", date_time=_ZIP_DATE)
                    info.external_attr = 0o644 << 16
                    with zf.open(info, "w", force_zip64=True) as fh:
                        np.lib.format.write_array(fh, np.asarray(arr),
                                                  allow_pickle=False)
        return path

    def export(self, path, *, progress: bool = False) -> Path:
        """Write a mesh file chosen by suffix (.ply .obj .stl .vtp .vtk .glb), atomically.

        Streamed band by band through the shared mesh writers (float32 positions and
        ``height_m`` per vertex, boulders merged with ``boulder_id``);
        ``.glb`` is the patched-strip renderer export (:func:`latlong.export_glb`). See
        :mod:`latlong.export`.
        """
        return export_body(self, path, progress=progress)

    def to_pyvista(self):
        """A ``pyvista.PolyData`` with point array ``height_m`` (radius minus reference)."""
        mesh = polydata(*self.mesh())
        mesh.point_data["height_m"] = self.heights_m
        return mesh


_CHECK_CHUNK = 1 << 20  # vertices per block of the checks below (bounded temporaries)


def _check_radii(radii: np.ndarray) -> None:
    """Finite and > 0 everywhere, checked block by block (no whole-grid temporaries)."""
    n = radii.shape[0]
    bad = 0
    for s in range(0, n, _CHECK_CHUNK):
        block = radii[s:s + _CHECK_CHUNK]
        if not np.isfinite(block).all():
            raise ParameterError("radii_m", "must be finite")
        bad += int(np.count_nonzero(block <= 0))
        drop_pages(radii, s, s + len(block))  # radii on disk: what was read leaves memory
    if bad:
        raise ParameterError(
            "radii_m", f"must be > 0 everywhere; {bad} vertices have radius <= 0 "
            f"(min {radii.min():.6g} m)")


#: Vertices per block of the area-weighted mean: numpy's dot (OpenBLAS ddot) runs on one
#: thread up to 10 000 elements and splits longer vectors between the BLAS threads, which
#: changes its rounding with the thread count (measured: OpenBLAS 0.3.31, 1 vs 2 threads).
_DOT_BLOCK = 10_000


def _area_mean(grid: LatLongGrid, radii: np.ndarray) -> float:
    """The area-weighted mean radius, ``dot(vertex_areas, radii) / sum(vertex_areas)``,
    in blocks of :data:`_DOT_BLOCK` vertices summed in order.

    The per-vertex areas of a block are made from the grid's :meth:`ring_areas` (no
    whole-grid array). A grid of at most one block (M <= 40) gets the very bits of the
    single ``np.dot`` used before; a larger one a result that no longer depends on the
    BLAS thread count (the single dot's did). Each block's dot is :func:`craters.exact.dot`
    (in index order): OpenBLAS's ``ddot`` kernel, and so its last bits, depend on the CPU.
    """
    areas, offs = grid.ring_areas(), grid.ring_offsets()
    num = den = 0.0
    for s in range(0, grid.n_vertices, _DOT_BLOCK):
        e = min(s + _DOT_BLOCK, grid.n_vertices)
        r0 = int(np.searchsorted(offs, s, side="right")) - 1
        r1 = int(np.searchsorted(offs, e - 1, side="right")) - 1
        w = np.repeat(areas[r0:r1 + 1], np.diff(np.clip(offs[r0:r1 + 2], s, e)))
        num += dot(w, radii[s:e])
        den += float(w.sum())
    return num / den


def load(path) -> Body:
    """Read a body written by :meth:`Body.save`."""
    path = Path(path)
    check_regular_file(path, "model file")
    need = (f"{str(path)!r} is not a body .npz (as Body.save and `latlong build -o NAME.npz` "
            "write)")
    if not zipfile.is_zipfile(path):  # a mesh (.ply ...), a single .npy, anything else
        mesh = path.suffix.lower() in (*EXPORT_SUFFIXES, ".tab", ".plt", ".gltf")
        raise ValueError(need + (f": a {path.suffix} file is a mesh, which holds no lat/long "
                                 "body" if mesh else ": it is not a .npz (zip) archive"))
    try:
        with np.load(path, allow_pickle=False) as z:
            fields = {k: z[k] for k in z.files}
    except ValueError as exc:
        if "allow_pickle" in str(exc):  # numpy's words for Python objects in the archive
            raise ValueError(need + ": it holds Python objects (pickles), which a body "
                             "never does, and they are not read") from None
        raise ValueError(f"cannot read body {str(path)!r}: {exc}") from None
    except (zipfile.BadZipFile, OSError, EOFError) as exc:
        raise ValueError(f"cannot read body {str(path)!r}: {exc}") from None
    fmt = str(fields["format"]) if "format" in fields else ""
    if fmt != FORMAT:
        raise ValueError(f"{str(path)!r} is not a craterform body (format {fmt!r})")
    missing = [k for k in _SAVED if k not in fields]
    if missing:
        raise ValueError(f"body {str(path)!r} is incomplete: no {', '.join(missing)}")
    for key in ("magnitude", "radius_m", "stretch", "radii_m"):
        if fields[key].dtype.kind not in "iuf":
            raise ValueError(f"body {str(path)!r}: {key} must hold real numbers; got dtype "
                             f"{fields[key].dtype}")
    if fields["magnitude"].shape != () or fields["radius_m"].shape != ():
        raise ValueError(f"body {str(path)!r}: magnitude and radius_m must be single numbers")
    try:  # the file's values, not the caller's arguments: no parameter names in errors
        return Body(LatLongGrid(int(fields["magnitude"])), fields["radii_m"],
                    radius_m=float(fields["radius_m"]), stretch=fields["stretch"],
                    metadata=json.loads(str(fields["metadata_json"])),
                    craters=fields.get("craters"), boulders=fields.get("boulders"),
                    copy=False)
    except (ValueError, TypeError, OverflowError) as exc:
        raise ValueError(f"body {str(path)!r} is invalid: {exc}") from None
