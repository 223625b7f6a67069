"""A surface from a file: :func:`load_surface` turns a path into a surface
(:class:`latlong.geometry.surface.Surface`), what the sensors, the writers and the slopes
take: a body ``.npz`` becomes a :class:`latlong.Body`, a mesh file (PLY, OBJ, STL, VTP,
VTK, GLB/glTF: exported bodies and mesh surfaces, ``dem mesh`` outputs, shape models) a
:class:`~latlong.meshio.readers.MeshData`.

A mesh file is read by the mesh-reader registry (:func:`latlong.meshio.readers.read_mesh`)
and keeps its per-vertex fields, ``boulder_id`` among them (the exports write placed
boulders after the surface with their catalog row, -1 on the surface), so the sensors
label the boulders of a mesh written by craterform. (A DEM or a layer stack is a surface
of ``dem``: ``dem.DemSurface``.)
"""

from __future__ import annotations

from pathlib import Path

from craters._shared import ParameterError, check_choice
from craters._shared.files import check_regular_file

from .body import load
from .meshio.readers import MESH_READ_SUFFIXES, UNITS, read_mesh

__all__ = ["load_surface"]


def load_surface(path, *, units: str = "m"):
    """The surface stored in ``path``: a :class:`latlong.Body` from a ``.npz``, a
    :class:`~latlong.meshio.readers.MeshData` from a mesh file
    (:data:`~latlong.meshio.readers.MESH_READ_SUFFIXES`) whose coordinates are in
    ``units`` ("m" or "km"; bodies are in metres). One-line ValueError for a file that
    cannot be read.
    """
    check_choice("units", units, tuple(UNITS))
    path = Path(path)
    check_regular_file(path, "model file")
    suffix = path.suffix.lower()
    if suffix == ".npz":
        return load(path)
    if suffix in MESH_READ_SUFFIXES:
        return read_mesh(path, units=units, what="model file")
    raise ParameterError("model", f"must be a body .npz or a mesh file "
                         f"({' '.join(MESH_READ_SUFFIXES)}; a DEM or a layer stack is a "
                         f"dem.DemSurface: dem camera, dem lidar); got {str(path)!r}")
