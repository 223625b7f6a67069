"""A surface from a file: :func:`load_surface` turns a path into a surface
(:class:`latlong.geometry.surface.Surface`), what the sensors, the writers and the slopes
take: a body ``.npz`` becomes a :class:`latlong.Body`, a mesh file (PLY, OBJ, STL, VTP,
VTK, GLB/glTF: exported bodies and mesh surfaces, ``dem mesh`` outputs, shape models) a
:class:`MeshFile`.

A mesh file keeps its per-vertex fields, ``boulder_id`` among them (the exports write
placed boulders after the surface with their catalog row, -1 on the surface), so the
sensors label the boulders of a mesh written by craterform. craterform's own binary PLY
files are read directly (VTK's reader drops their extra vertex properties); anything else
through pyvista. (A DEM or a layer stack is a surface of ``dem``: ``dem.DemSurface``.)
"""

from __future__ import annotations

import dataclasses
import warnings
from pathlib import Path

import numpy as np

from craters._shared import ParameterError, check_choice
from craters._shared.files import check_regular_file

from .body import load
from .meshio.writers import MeshSource, array_source, write_mesh

__all__ = ["MESH_SUFFIXES", "MeshFile", "load_surface", "read_mesh_file"]

#: Mesh files read through pyvista (or directly: craterform's PLY).
MESH_SUFFIXES = (".ply", ".obj", ".stl", ".vtp", ".vtk", ".glb", ".gltf")
_UNITS = {"m": 1.0, "km": 1000.0}


def load_surface(path, *, units: str = "m"):
    """The surface stored in ``path``: a :class:`latlong.Body` from a ``.npz``, a
    :class:`MeshFile` from a mesh file (``MESH_SUFFIXES``) whose coordinates are in
    ``units`` ("m" or "km"; bodies are in metres). One-line ValueError for a file that
    cannot be read.
    """
    check_choice("units", units, tuple(_UNITS))
    path = Path(path)
    check_regular_file(path, "model file")
    suffix = path.suffix.lower()
    if suffix == ".npz":
        return load(path)
    if suffix in MESH_SUFFIXES:
        return read_mesh_file(path, units=units)
    raise ParameterError("model", f"must be a body .npz or a mesh file "
                         f"({' '.join(MESH_SUFFIXES)}; a DEM or a layer stack is a "
                         f"dem.DemSurface: dem camera, dem lidar); got {str(path)!r}")


@dataclasses.dataclass(frozen=True, eq=False)
class MeshFile:
    """A triangle mesh read from a file, with its per-vertex fields: a surface
    (:class:`latlong.geometry.surface.Surface`) with no catalogs."""

    vertices: np.ndarray
    """(V, 3) float64 positions, metres."""
    faces: np.ndarray
    """(F, 3) int64 vertex indices as in the file."""
    fields: dict = dataclasses.field(default_factory=dict)
    """Per-vertex fields of the file, name -> (V,) array (``boulder_id``: boulder catalog
    row of the boulders' vertices, -1 on the surface)."""
    metadata: dict = dataclasses.field(default_factory=dict)
    """``source`` (the file) and ``units``."""
    craters: np.ndarray | None = None
    """No catalog comes with a mesh file (give one to the sensors)."""
    boulders: np.ndarray | None = None
    """No catalog comes with a mesh file."""

    def mesh(self) -> tuple[np.ndarray, np.ndarray]:
        """``(vertices, faces)`` of the surface: the faces of the boulders left out."""
        ids = self.fields.get("boulder_id")
        if ids is None:
            return self.vertices, self.faces
        return self.vertices, self.faces[np.asarray(ids)[self.faces[:, 0]] < 0]

    def vertex_normals(self, weighting: str = "area") -> np.ndarray:
        """(V, 3) unit area-weighted vertex normals of :meth:`mesh` (0 where unused)."""
        from .mesh.topology import vertex_normals

        check_choice("weighting", weighting, ("area",))
        return vertex_normals(*self.mesh())

    def local_frames(self, points) -> np.ndarray:
        """(n, 3, 3) frames at ``points``, rows east, north, up: up the vertex normal of
        the nearest vertex, east along ``z x up`` (x where up is along z)."""
        from scipy.spatial import cKDTree

        verts, faces = self.mesh()
        used = np.unique(faces)
        _, near = cKDTree(verts[used]).query(np.asarray(points, dtype=np.float64)
                                             .reshape(-1, 3))
        up = self.vertex_normals()[used[near]]
        east = np.cross([0.0, 0.0, 1.0], up)
        flat = np.linalg.norm(east, axis=1) < 1e-12
        east[flat] = [1.0, 0.0, 0.0]
        east /= np.linalg.norm(east, axis=1, keepdims=True)
        return np.stack([east, np.cross(up, east), up], axis=1)

    def mesh_source(self) -> MeshSource:
        """The mesh and its fields for the mesh writers."""
        return array_source(self.vertices, self.faces,
                            f"craterform mesh read from {self.metadata.get('source', '')}",
                            **self.fields)

    def save(self, path, *, progress: bool = False) -> Path:
        """Write the mesh to a file chosen by suffix, atomically."""
        return write_mesh(self.mesh_source(), path, progress=progress)


def read_mesh_file(path, *, units: str = "m") -> MeshFile:
    """A mesh file (``MESH_SUFFIXES``) as a :class:`MeshFile`, coordinates in ``units``
    (one-line ValueError if it cannot be read or has no triangles)."""
    path = Path(path)
    scale = _UNITS[check_choice("units", units, tuple(_UNITS))]
    ply = None
    if path.suffix.lower() == ".ply":
        try:
            ply = _read_triangle_ply(path)
        except (OSError, ValueError):
            ply = None
    if ply is not None:
        verts, faces, fields = ply
        if len(faces) and (faces.min() < 0 or faces.max() >= len(verts)):
            raise ValueError(f"cannot read mesh {str(path)!r}: face indices out of range")
    else:
        verts, faces, fields = _read_with_pyvista(path)
    if not len(faces):
        raise ValueError(f"cannot read mesh {str(path)!r}: no triangles in it")
    verts = verts * scale
    if not np.isfinite(verts).all():
        raise ValueError(f"mesh {str(path)!r} has non-finite vertices")
    fields = {k: v for k, v in fields.items()
              if k not in ("x", "y", "z") and np.ndim(v) == 1 and len(v) == len(verts)}
    return MeshFile(verts, faces, fields, {"source": str(path), "units": units})


_PLY_TYPES = {"float": "<f4", "float32": "<f4", "double": "<f8", "float64": "<f8",
              "int": "<i4", "int32": "<i4", "uint": "<u4", "uint32": "<u4", "short": "<i2",
              "int16": "<i2", "ushort": "<u2", "uint16": "<u2", "char": "i1", "int8": "i1",
              "uchar": "u1", "uint8": "u1"}


def _ply_header(fh):
    """(format, [(element, count, [property words])]) of a PLY header, or None."""
    if fh.readline().strip() != b"ply":
        return None
    elements, fmt = [], None
    while True:
        line = fh.readline()
        if not line:
            return None
        words = line.decode("ascii", "replace").split()
        if not words or words[0] in ("comment", "obj_info"):
            continue
        if words[0] == "format":
            fmt = words[1]
        elif words[0] == "element":
            elements.append((words[1], int(words[2]), []))
        elif words[0] == "property" and elements:
            elements[-1][2].append(words[1:])
        elif words[0] == "end_header":
            return fmt, elements


def _read_triangle_ply(path: Path):
    """A binary little-endian PLY of triangles with scalar vertex properties (as the
    craterform writers make them): ``(xyz, faces, {property: values})``, or None for any
    other PLY (then pyvista reads it; VTK's reader drops the extra properties such as
    ``boulder_id``)."""
    with open(path, "rb") as fh:
        header = _ply_header(fh)
        if header is None:
            return None
        fmt, elements = header
        if fmt != "binary_little_endian" or [e[0] for e in elements] != ["vertex", "face"]:
            return None
        (_, nv, vprops), (_, nf, fprops) = elements
        if any(len(p) != 2 or p[0] not in _PLY_TYPES for p in vprops) or len(fprops) != 1 \
                or fprops[0][0] != "list" or fprops[0][1] not in _PLY_TYPES \
                or fprops[0][2] not in _PLY_TYPES:
            return None
        vdt = np.dtype([(p[1], _PLY_TYPES[p[0]]) for p in vprops])
        fdt = np.dtype([("n", _PLY_TYPES[fprops[0][1]]), ("i", _PLY_TYPES[fprops[0][2]], 3)])
        verts = np.fromfile(fh, dtype=vdt, count=nv)
        faces = np.fromfile(fh, dtype=fdt, count=nf)
    if len(verts) != nv or len(faces) != nf or not {"x", "y", "z"} <= set(vdt.names) \
            or (faces["n"] != 3).any():
        return None
    xyz = np.stack([verts["x"], verts["y"], verts["z"]], 1).astype(np.float64)
    return xyz, faces["i"].astype(np.int64), {k: verts[k] for k in vdt.names}


def _read_with_pyvista(path: Path):
    """``(xyz, faces, {point array: values})`` of any mesh file pyvista reads."""
    import pyvista as pv
    from vtkmodules.vtkCommonCore import vtkObject

    shown = vtkObject.GetGlobalWarningDisplay()
    vtkObject.GlobalWarningDisplayOff()  # a bad file: one line from us, not VTK's report
    try:
        with pv.vtk_verbosity("off"), warnings.catch_warnings():
            warnings.simplefilter("error")
            mesh = pv.read(path)
    except Exception as exc:  # noqa: BLE001 - any reader failure is an unreadable mesh
        raise ValueError(f"cannot read mesh {str(path)!r}: {exc}".splitlines()[0]) from None
    finally:
        vtkObject.SetGlobalWarningDisplay(shown)
    if isinstance(mesh, pv.MultiBlock):
        mesh = mesh.combine(merge_points=False)
    if not isinstance(mesh, pv.PolyData):
        mesh = mesh.extract_surface()
    mesh = mesh.triangulate()
    faces = np.asarray(mesh.faces).reshape(-1, 4)[:, 1:].astype(np.int64) if mesh.n_cells \
        else np.zeros((0, 3), np.int64)
    return (np.asarray(mesh.points, dtype=np.float64), faces,
            {k: np.asarray(mesh.point_data[k]) for k in mesh.point_data.keys()})
