"""What a build writes: the outputs of a scene (the run options of ``latlong build``) and the
one function that writes them, shared by ``latlong build`` and :func:`latlong.batch` so a
batch variant's files are the bytes a single build of the same seed writes.

:class:`Outputs` holds the file names (meshes and bodies by suffix, the crater catalog as
CSV or craterstats ``.scc``, the boulder catalog, a preview picture) and is checked
against the scene once, before any work (:meth:`Outputs.check`); :func:`write_outputs`
writes a built body, mesh surface or implicit surface, every file atomically.
"""

from __future__ import annotations

import dataclasses
import os
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path

import craters
from craters._shared import (
    ParameterError,
    ParameterTypeError,
    check_output_path,
    check_suffix,
    same_file,
)
from craters._shared.outputs import claim
from craters._shared.settings import by_key, check_declared, setting

from .body import EXPORT_SUFFIXES
from .grid import LatLongGrid
from .meshio.sizes import check_free_space, mesh_file_bytes
from .meshio.writers import MESH_SUFFIXES
from .preview import render_preview
from .scene import Scene
from .settings import ShapeBase
from .surface import band_areas

__all__ = ["OUTPUT_SETTINGS", "Outputs", "companions", "output_kind", "scene_inputs",
           "write_outputs"]


_SUFFIXES = {"latlong": (".npz", *EXPORT_SUFFIXES), "implicit": (".npz", *MESH_SUFFIXES),
             "mesh": MESH_SUFFIXES}
_EXTRA_SUFFIXES = {"catalog": (".csv", ".scc"), "boulder_catalog": (".csv",),
                   "preview": (".png",)}


def output_kind(scene: Scene) -> str:
    """``latlong``, ``implicit`` or ``mesh`` (a shape base cratered on its own mesh)."""
    mesh = isinstance(scene.base, ShapeBase) and scene.base.surface == "mesh"
    return "mesh" if mesh else scene.backend


@dataclass(frozen=True, slots=True)
class Outputs:
    """The files of one build (None or empty: not written)."""

    output: tuple[str, ...] = setting(
        (), "output file, format by suffix: " + " ".join((".npz", *EXPORT_SUFFIXES)) + " "
        "(repeatable; .glb is the patched strip export with its .json manifest, full "
        "resolution only - `latlong export` adds levels of detail)", flag="-o/--output",
        many="append")
    """Bodies and meshes, format by suffix (.npz and the :data:`~latlong.EXPORT_SUFFIXES`)."""
    catalog: str | None = setting(
        None, "write the ground-truth crater catalog as stamped: .csv, or .scc (craterstats "
        "spatial crater count: the body's area in km^2, diameters in km, lon/lat)")
    """The crater catalog as stamped: .csv or .scc (craterstats)."""
    boulder_catalog: str | None = setting(None, "write the boulder catalog as placed (CSV)")
    """The boulder catalog as placed (.csv)."""
    preview: str | None = setting(None, "write a preview picture (PNG)")
    """A preview picture (.png)."""
    catalog_columns: str = setting(
        "craterform", "column names of a CSV catalog: craterform (units in the names) or "
        "robbins (LAT_CIRC_IMG, LON_CIRC_IMG, DIAM_CIRC_IMG in km, as the Robbins 2019 lunar "
        "crater database)", choices=craters.CATALOG_COLUMNS)
    """Column names of a CSV catalog (:data:`craters.CATALOG_COLUMNS`)."""

    def __post_init__(self):
        check_declared(self)
        out = self.output
        if isinstance(out, str | Path):
            out = (out,)
        if not isinstance(out, list | tuple) or not all(isinstance(o, str | Path) for o in out):
            raise ParameterTypeError("output", f"must be a file name or a list of them; got "
                                     f"{self.output!r}")
        object.__setattr__(self, "output", tuple(str(o) for o in out))
        for key in ("catalog", "boulder_catalog", "preview"):
            value = getattr(self, key)
            if value is not None and not isinstance(value, str | Path):
                raise ParameterTypeError(key, f"must be a file name; got {value!r}")
            object.__setattr__(self, key, None if value is None else str(value))
        if self.catalog_columns != "craterform" and not str(self.catalog or "").lower(
                ).endswith(".csv"):
            raise ParameterError("catalog_columns", "applies to a CSV {}", see=("catalog",))

    @classmethod
    def from_settings(cls, settings: Mapping) -> Outputs:
        """From the output keys of a scene file (:data:`OUTPUT_SETTINGS`; None: not given)."""
        return cls(**{k: v for k, v in settings.items() if v is not None})

    def files(self) -> list[str]:
        """Every file named, in writing order (a .glb also writes its .json manifest)."""
        return [*self.output, *(f for f in (self.catalog, self.boulder_catalog, self.preview)
                                if f)]

    def renamed(self, rename: Callable[[str], str]) -> Outputs:
        """The same outputs with every file name passed through ``rename``."""
        return dataclasses.replace(
            self, output=tuple(map(rename, self.output)),
            **{k: rename(getattr(self, k)) for k in ("catalog", "boulder_catalog", "preview")
               if getattr(self, k)})

    def check(self, scene: Scene, *, force: bool = False, paths: bool = True,
              inputs=()) -> None:
        """Raise before any work if the scene cannot write these outputs: known suffixes for
        its kind, catalogs only of layers it has, no file twice, no output that is an input
        (the scene's shape files and ``inputs``, pairs of (what, path)) and (``paths``)
        folders that exist, nothing overwritten without ``force`` - a .glb's manifest
        ``.json`` and external ``.lod0.bin`` included."""
        kind = output_kind(scene)
        if scene.backend == "implicit" and self.boulder_catalog:
            raise ParameterError("boulder_catalog", "does not apply to {} implicit",
                                 see=("backend",))
        if kind == "mesh" and any(o.lower().endswith(".npz") for o in self.output):
            raise ParameterError("output", ": {} mesh writes meshes (" + " ".join(MESH_SUFFIXES)
                                 + "), not .npz (a lat/long body)", see=("surface",))
        if scene.backend == "latlong":
            if self.catalog and not scene.craters.layers:
                raise ParameterError("catalog", "needs crater layers ({} or a cratered {})",
                                     see=("craters", "preset"))
            if self.boulder_catalog and not scene.boulders.layers:
                raise ParameterError("boulder_catalog", "needs boulder layers ({})",
                                     see=("boulders",))
        seen = set()
        for x in self.files():
            resolved = Path(x).resolve()
            if resolved in seen:
                raise ValueError(f"output {x!r} is given twice")
            seen.add(resolved)
        named = [("output", o, _SUFFIXES[kind]) for o in self.output]
        named += [(k, getattr(self, k), s) for k, s in _EXTRA_SUFFIXES.items()
                  if getattr(self, k)]
        inputs = [*scene_inputs(scene), *inputs]
        for key, path, suffixes in named:
            if paths:
                check_output_path(path, force=force, suffixes=suffixes)
            else:
                check_suffix(path, suffixes)
            for out in (path, *companions(path)):
                for what, inp in inputs:
                    if same_file(out, inp):
                        raise ParameterError(key, f"{str(path)!r} would overwrite the "
                                             f"input {what} {str(inp)!r}; inputs are never "
                                             f"modified")
            for extra in companions(path) if paths else ():
                if extra.is_dir() or (os.path.lexists(extra) and not force):
                    raise ParameterError(key, f"{str(path)!r} also writes {str(extra)!r}, "
                                         f"which exists; use --force to overwrite")
                claim(extra, force=force)
        if paths and kind == "latlong":  # a lat/long body's size is known from M
            n = LatLongGrid(scene.body.magnitude).n_vertices
            check_free_space([(o, mesh_file_bytes(o, n)) for o in self.output],
                             hint="give a smaller --magnitude, fewer or binary outputs, or "
                             "another folder")


#: The keys of a scene file that say what to write (not what to make).
OUTPUT_SETTINGS = tuple(by_key(Outputs))


def companions(path) -> list[Path]:
    """The files a body export writes next to ``path`` besides it: a .glb's manifest
    ``<stem>.json`` and, past 4 GiB, its external buffer ``<stem>.lod0.bin``."""
    path = Path(path)
    if path.suffix.lower() != ".glb":
        return []
    return [path.with_suffix(".json"), path.with_name(f"{path.stem}.lod0.bin")]


def scene_inputs(scene: Scene) -> list[tuple[str, str]]:
    """The files a scene reads (its shape models), as (what, path) pairs."""
    found = []
    if isinstance(scene.base, ShapeBase):
        found.append(("shape model", getattr(scene.base.model, "source", scene.base.model)))
    if scene.implicit is not None:
        found.append(("shape model", getattr(scene.implicit.shape, "source",
                                             scene.implicit.shape)))
    return [(what, str(p)) for what, p in found if p and not str(p).startswith("latlong/data/")]


def write_outputs(made, scene: Scene, outputs: Outputs, *, progress: bool = False,
                  done: Callable[[], None] | None = None) -> list[str]:
    """Write what :func:`latlong.build` made of ``scene`` (a Body, a mesh surface or an
    implicit surface) to ``outputs``, each file atomically; ``done()`` after each file.
    Returns the files named (a .glb's .json manifest is written next to it)."""
    done = done or (lambda: None)
    kind = output_kind(scene)
    if kind == "implicit":
        body = None
        if any(o.lower().endswith(".npz") for o in outputs.output):  # before any write
            try:
                assert scene.implicit is not None  # the implicit backend
                body = made.to_body(scene.body.magnitude, crossings=scene.implicit.crossings)
            except ValueError as exc:
                if not (isinstance(exc, ParameterError) and exc.name == "crossings"):
                    raise ValueError(f".npz output (lat/long projection): {exc}") from None
                # the scene's name; the advice of a shape base (another centre, --surface
                # mesh) does not apply: the implicit surface is cast from its origin
                why = exc.rule.partition(": ")[2].partition("; crater it")[0]
                raise ParameterError("shape_crossings", "must be outermost or innermost for "
                                     f"a .npz output (the surface cast onto the lat/long "
                                     f"grid from its origin): {why}; or write only meshes "
                                     "(.ply .obj .stl .vtp .vtk .glb)") from None
        for out in outputs.output:
            if out.lower().endswith(".npz"):
                assert body is not None  # made above for the .npz outputs
                body.save(out)
            else:
                made.save(out)
            done()
        catalog, area, axes = made.catalog, made.area_m2, None
    else:
        for out in outputs.output:
            if kind == "mesh":
                made.save(out, progress=progress)
            elif out.lower().endswith(".npz"):
                made.save(out)
            else:
                made.export(out, progress=progress)
            done()
        catalog = made.craters
        if kind == "mesh":
            area, axes = made.area_m2, None
        else:
            scc = str(outputs.catalog or "").lower().endswith(".scc")
            area = float(band_areas(made).sum()) if scc else 0.0
            axes = made.radius_m * made.stretch
    if outputs.catalog:
        if outputs.catalog.lower().endswith(".scc"):
            craters.write_scc(catalog, outputs.catalog, area_m2=area, axes_m=axes,
                              note="latlong build: the craters as stamped on the whole body")
        else:
            craters.write_catalog(catalog, outputs.catalog, columns=outputs.catalog_columns)
        done()
    if outputs.boulder_catalog:
        craters.write_catalog(made.boulders, outputs.boulder_catalog)
        done()
    if outputs.preview:
        view = made if kind == "latlong" else made.to_pyvista()
        render_preview(view, outputs.preview, scene.preview)
        done()
    return outputs.files()
