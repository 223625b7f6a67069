"""Triangle-mesh files read: one reader per suffix (:data:`MESH_READERS`), as the writers.

:func:`read_mesh` checks the path, picks the reader by suffix and returns the mesh in
metres as a :class:`MeshData` (vertices, faces, per-vertex fields), which is a
:class:`~latlong.geometry.surface.Surface`. Readers do not judge the mesh: shape models
check that it is closed and oriented (:func:`latlong.read_shape_model`), the sensors
take any triangles (a DEM site's open mesh too).

Formats
-------
* ``.obj .tab .plt .txt``: Wavefront OBJ (``v``/``f`` lines; polygons fanned into
  triangles; negative indices relative) and PDS plate models (``v``/``f`` lines, or the
  count format ``NV NF`` then ``index x y z`` and ``index i j k`` rows); 0- or 1-based
  indices detected and checked.
* ``.ply``: binary little-endian triangles with scalar vertex properties (as the
  craterform writers make them, ``boulder_id`` and ``height_m`` kept) read directly;
  any other PLY through VTK. A header that declares more elements than the file holds
  is refused first (VTK trusts the counts and reads past its buffers:
  :mod:`latlong.meshio.checks`).
* ``.stl .vtk .vtp .glb .gltf``: through VTK (pyvista), surfaces extracted and
  triangulated, point arrays kept.

Every failure is one line, ``cannot read {what} {path}: {reason}``.
"""

from __future__ import annotations

import re
import warnings
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from craters._shared import check_choice
from craters._shared.files import check_regular_file

from ..geometry.meshes import PlainMeshSurface
from .checks import ply_size_problem
from .writers import MeshSource, array_source

__all__ = ["MESH_READERS", "MESH_READ_SUFFIXES", "UNITS", "MeshData", "read_mesh"]

#: Length units a mesh file may be in: name -> metres.
UNITS = {"km": 1000.0, "m": 1.0}


@dataclass(frozen=True, eq=False)
class MeshData(PlainMeshSurface):
    """A triangle mesh as read from a file, in metres: a
    :class:`~latlong.geometry.surface.Surface` without catalogs."""

    vertices: np.ndarray
    """(V, 3) float64 positions, metres."""
    faces: np.ndarray
    """(F, 3) int64 0-based vertex indices, as the file orders them."""
    fields: dict = field(default_factory=dict)
    """Per-vertex arrays the file holds besides the positions (e.g. ``boulder_id``)."""
    source: str = ""
    """The path read."""

    def mesh(self) -> tuple[np.ndarray, np.ndarray]:
        """``(vertices, faces)`` of the surface: the faces of placed boulders (a
        ``boulder_id`` field >= 0, as craterform's exports write them) left out."""
        ids = self.fields.get("boulder_id")
        if ids is None:
            return self.vertices, self.faces
        return self.vertices, self.faces[np.asarray(ids)[self.faces[:, 0]] < 0]

    @property
    def metadata(self) -> dict:
        """``{"source": path, "fields": [names]}``."""
        return {"source": self.source, "fields": sorted(self.fields)}

    def mesh_source(self) -> MeshSource:
        """The mesh and its fields for the shared mesh writers."""
        return array_source(self.vertices, self.faces, "craterform mesh, metres",
                            **self.fields)


class _Unreadable(ValueError):
    """Why a file could not be read (the reason only; :func:`read_mesh` names the file)."""


# --------------------------------------------------------------------------- text
def _index(token: str) -> int:
    return int(token.split("/")[0])


def _text_rows(path: Path):
    """OBJ or PDS plate text: (vertices, faces as in the file, "vf" or "counts")."""
    with open(path, encoding="ascii", errors="replace") as fh:
        lines = [ln.split("#", 1)[0].strip() for ln in fh]
    lines = [ln for ln in lines if ln]
    if not lines:
        raise _Unreadable("it is empty")
    verts, faces = [], []
    if lines[0].split()[0].lower() in ("v", "vn", "vt", "f", "o", "g", "s", "mtllib",
                                       "usemtl"):
        for ln in lines:
            parts = ln.split()
            key = parts[0].lower()
            if key == "v":
                verts.append([float(x) for x in parts[1:4]])
            elif key == "f":
                idx = [_index(p) for p in parts[1:]]
                for k in range(1, len(idx) - 1):  # fan polygons into triangles
                    faces.append([idx[0], idx[k], idx[k + 1]])
        return np.array(verts, dtype=np.float64), np.array(faces, dtype=np.int64), "vf"
    # PDS count format: "NV NF" (or "NV" then later "NF"), indexed rows
    head = [int(float(x)) for x in re.split(r"[\s,]+", lines[0]) if x]
    nv = head[0]
    rows = [re.split(r"[\s,]+", ln) for ln in lines[1:]]
    vrows, rest = rows[:nv], rows[nv:]
    if rest and len(rest[0]) == 1:  # a separate facet-count line
        nf = int(float(rest[0][0]))
        rest = rest[1:]
    else:
        nf = head[1] if len(head) > 1 else len(rest)
    frows = rest[:nf]
    if len(vrows) != nv or len(frows) != nf:
        raise _Unreadable(f"header says {nv} vertices and {nf} facets; found {len(vrows)} "
                          f"and {len(frows)}")
    verts = [[float(x) for x in r[-3:]] for r in vrows]
    faces = [[int(float(x)) for x in r[-3:]] for r in frows]
    return np.array(verts, dtype=np.float64), np.array(faces, dtype=np.int64), "counts"


def _zero_based(faces: np.ndarray, n_verts: int, fmt: str, obj: bool) -> np.ndarray:
    """Detect 0- or 1-based (or negative, OBJ-relative) indices and check them."""
    if faces.size == 0:
        return faces
    if (faces < 0).any():
        if fmt != "vf" or (faces > 0).any():
            raise _Unreadable("negative and positive facet indices mixed")
        faces = faces + n_verts  # OBJ relative indices (all of them negative)
    else:
        lo, hi = faces.min(), faces.max()
        if fmt == "vf" and lo >= 1 and obj:
            faces = faces - 1  # OBJ is 1-based by definition
        elif lo == 0 and hi <= n_verts - 1:
            pass
        elif lo >= 1 and hi == n_verts:
            faces = faces - 1
        elif lo == 0 and hi == n_verts:
            raise _Unreadable(f"facet indices run from 0 to {hi} for {n_verts} vertices: "
                              "neither 0- nor 1-based")
    return faces


def read_text_mesh(path: Path):
    """OBJ or PDS plate model (module notes): (vertices, 0-based faces, {})."""
    try:
        verts, faces, fmt = _text_rows(path)
    except (ValueError, IndexError) as exc:
        raise _Unreadable(f"cannot parse it: {exc}") from None
    except OverflowError:
        raise _Unreadable("a count or facet index is not a finite integer below 2**63") \
            from None
    if verts.ndim != 2 or (len(verts) and verts.shape[1] != 3):
        raise _Unreadable("vertices need three coordinates")
    return verts, _zero_based(faces, len(verts), fmt, path.suffix.lower() == ".obj"), {}


# --------------------------------------------------------------------------- PLY
_PLY_TYPES = {"float": "<f4", "float32": "<f4", "double": "<f8", "float64": "<f8",
              "int": "<i4", "int32": "<i4", "uint": "<u4", "uint32": "<u4", "short": "<i2",
              "int16": "<i2", "ushort": "<u2", "uint16": "<u2", "char": "i1", "int8": "i1",
              "uchar": "u1", "uint8": "u1"}


def _triangle_ply(path: Path):
    """A binary little-endian PLY of triangles with scalar vertex properties (as the
    craterform writers make them): ``(xyz, faces, {property: values})``, or None for any
    other PLY (then VTK reads it; VTK's reader drops the extra properties such as
    ``boulder_id``)."""
    with open(path, "rb") as fh:
        if fh.readline().strip() != b"ply":
            return None
        elements: list[tuple[str, int, list[list[str]]]] = []
        fmt = None
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
                break
        names = [e[0] for e in elements]
        if fmt not in _PLY_FORMATS or names != ["vertex", "face"]:
            return None
        (_, nv, vprops), (_, nf, fprops) = elements
        if any(len(p) != 2 or p[0] not in _PLY_TYPES for p in vprops) or len(fprops) != 1 \
                or fprops[0][0] != "list" or fprops[0][1] not in _PLY_TYPES \
                or fprops[0][2] not in _PLY_TYPES:
            return None
        order = _PLY_FORMATS[fmt]
        vdt = np.dtype([(p[1], _PLY_TYPES[p[0]].replace("<", order)) for p in vprops])
        assert vdt.names is not None  # made from a list of fields
        if fmt == "ascii":  # VTK's reader crashes on an index past the vertices: read here
            verts, faces = _ascii_body(fh, vdt, nv, nf)
            nf = len(faces)  # polygons fanned
        else:
            fdt = np.dtype([("n", _PLY_TYPES[fprops[0][1]].replace("<", order)),
                            ("i", _PLY_TYPES[fprops[0][2]].replace("<", order), 3)])
            verts = np.fromfile(fh, dtype=vdt, count=nv)
            faces = np.fromfile(fh, dtype=fdt, count=nf)
    if len(verts) != nv or len(faces) != nf or not {"x", "y", "z"} <= set(vdt.names) \
            or (faces["n"] != 3).any():
        return None
    xyz = np.stack([verts["x"], verts["y"], verts["z"]], 1).astype(np.float64)
    fields = {k: verts[k] for k in vdt.names if k not in ("x", "y", "z")}
    return xyz, faces["i"].astype(np.int64), fields


#: PLY formats read here -> their byte order (ascii: parsed as text).
_PLY_FORMATS = {"binary_little_endian": "<", "binary_big_endian": ">", "ascii": "<"}


def _ascii_body(fh, vdt: np.dtype, nv: int, nf: int):
    """The vertex and face elements of an ASCII PLY (polygons fanned into triangles)."""
    assert vdt.names is not None
    rows = [fh.readline().split() for _ in range(nv)]
    if any(len(r) != len(vdt.names) for r in rows):
        raise _Unreadable(f"an ASCII vertex line does not hold its {len(vdt.names)} properties")
    try:
        verts = np.array([tuple(r) for r in rows], dtype=vdt) if nv else np.zeros(0, vdt)
    except ValueError:
        raise _Unreadable("an ASCII vertex line holds a value that is not a number") from None
    tris = []
    for _ in range(nf):
        try:
            idx = [int(w) for w in fh.readline().split()]
        except ValueError:
            raise _Unreadable("an ASCII face line holds a value that is not an integer") from None
        if not idx or idx[0] < 3 or len(idx) != idx[0] + 1:
            raise _Unreadable("an ASCII face line does not hold its vertex count and indices")
        tris += [(3, idx[1], idx[k], idx[k + 1]) for k in range(2, len(idx) - 1)]
    faces = np.zeros(len(tris), dtype=[("n", "i4"), ("i", "i8", 3)])
    if tris:
        t = np.array(tris, dtype=np.int64)
        faces["n"], faces["i"] = t[:, 0], t[:, 1:]
    return verts, faces


def read_ply(path: Path):
    """PLY (module notes): (vertices, faces, fields)."""
    problem = ply_size_problem(path)
    if problem:
        raise _Unreadable(problem)
    try:
        ply = _triangle_ply(path)
    except _Unreadable:
        raise
    except (OSError, ValueError):
        ply = None
    return ply if ply is not None else read_vtk_mesh(path)


# --------------------------------------------------------------------------- VTK
def read_vtk_mesh(path: Path):
    """Any surface VTK reads (module notes): (vertices, faces, point arrays)."""
    import pyvista as pv
    from vtkmodules.vtkCommonCore import vtkObject

    shown = vtkObject.GetGlobalWarningDisplay()
    vtkObject.GlobalWarningDisplayOff()  # a bad file: one line from us, not VTK's report
    try:
        with pv.vtk_verbosity("off"), warnings.catch_warnings():
            warnings.simplefilter("error")
            mesh = pv.read(path)
    except Exception as exc:  # noqa: BLE001 - any reader failure is an unreadable mesh
        raise _Unreadable(str(exc).splitlines()[0] if str(exc) else type(exc).__name__) \
            from None
    finally:
        vtkObject.SetGlobalWarningDisplay(shown)
    if isinstance(mesh, pv.MultiBlock):
        mesh = mesh.combine(merge_points=False)
    triangles = isinstance(mesh, pv.UnstructuredGrid) and mesh.n_cells \
        and (np.asarray(mesh.celltypes) == pv.CellType.TRIANGLE).all()
    if triangles:  # as written (craterform's .vtk): vertices and faces in the file's order
        faces = np.asarray(mesh.cells).reshape(-1, 4)[:, 1:].astype(np.int64)
    else:
        if not isinstance(mesh, pv.PolyData):
            mesh = mesh.extract_surface(algorithm="dataset_surface")
        mesh = mesh.triangulate()
        faces = np.asarray(mesh.faces).reshape(-1, 4)[:, 1:].astype(np.int64) \
            if mesh.n_cells else np.zeros((0, 3), np.int64)
    return (np.asarray(mesh.points, dtype=np.float64), faces,
            {k: np.asarray(mesh.point_data[k]) for k in mesh.point_data.keys()})


#: Suffix -> reader(path) -> (vertices in the file's units, 0-based faces, fields).
MESH_READERS: dict[str, Callable] = {
    ".obj": read_text_mesh, ".tab": read_text_mesh, ".plt": read_text_mesh,
    ".txt": read_text_mesh, ".ply": read_ply, ".stl": read_vtk_mesh, ".vtk": read_vtk_mesh,
    ".vtp": read_vtk_mesh, ".glb": read_vtk_mesh, ".gltf": read_vtk_mesh}
MESH_READ_SUFFIXES = tuple(MESH_READERS)


def read_mesh(path, *, units: str, what: str = "mesh") -> MeshData:
    """Read a triangle mesh file chosen by suffix (:data:`MESH_READERS`), in metres.

    Parameters
    ----------
    path : str or Path
    units : {"km", "m"}
        Length unit of the file's coordinates (explicit: shape models come in both).
    what : str
        What the file is, for messages (``"shape model"``, ``"model file"``).

    Returns
    -------
    MeshData with float64 vertices in metres, int64 0-based faces (checked to index the
    vertices) and the file's per-vertex fields. ``ValueError`` (one line) for a file
    that cannot be read; ``FileNotFoundError`` for a missing one.

    Examples
    --------
    >>> m = read_mesh("tests/data/itokawa_8.obj", units="km")
    >>> m.vertices.shape, m.faces.shape
    ((386, 3), (768, 3))
    """
    units = check_choice("units", units, tuple(UNITS))
    path = Path(path)
    check_regular_file(path, what)
    suffix = path.suffix.lower()
    reader = MESH_READERS.get(suffix)
    if reader is None:
        raise ValueError(f"{what} {str(path)!r}: unknown format {suffix!r}; allowed: "
                         f"{' '.join(MESH_READ_SUFFIXES)}")
    try:
        verts, faces, fields = reader(path)
        if faces.size and (faces.min() < 0 or faces.max() >= len(verts)):
            raise _Unreadable(f"facet indices out of range [{faces.min()}, {faces.max()}] "
                              f"for {len(verts)} vertices")
        if not len(faces):
            raise _Unreadable("no triangles in it")
        if not np.isfinite(verts).all():
            raise _Unreadable("it has non-finite vertices")
    except _Unreadable as exc:
        raise ValueError(f"cannot read {what} {str(path)!r}: {exc}") from None
    return MeshData(verts * UNITS[units], faces, fields, str(path))
