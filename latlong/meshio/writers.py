"""Triangle-mesh files: one writer per format, streamed, for every kind of mesh.

A :class:`MeshSource` describes a mesh as chunks (vertex positions with per-vertex
fields, faces with global 0-based indices, triangle corners), so a writer never holds
the whole mesh: a lat/long body generates a few latitude bands at a time, a DEM stack a
layer at a time, boulders a chunk of rocks at a time. :data:`MESH_WRITERS` maps each
suffix to its writer; :func:`write_mesh` picks one by suffix and writes atomically
(temporary file in the target folder, then rename). Every writer is deterministic (no
timestamps, no host names).

Formats
-------
* ``.ply``: binary little-endian; float32 ``x y z`` (float64 for a mesh far from its
  origin: :attr:`MeshSource.position_type`) plus the fields (as their numpy types),
  faces ``uchar 3`` + three ``int`` (``uint`` past 2^31 vertices) indices.
* ``.obj``: text, ``v`` with 9 significant digits (12 for float64 positions), 1-based
  ``f``; face groups ``g``.
* ``.stl``: binary, float32 facet normal and corners, 80-byte header.
* ``.vtp``: VTK XML PolyData, raw appended binary (UInt64 headers): float32 (float64) points,
  the fields, Int32 (Int64 if needed) connectivity and offsets.
* ``.vtk``: VTK legacy binary (big-endian), an UNSTRUCTURED_GRID of triangles (what
  meshio, VTK and ParaView all read; meshio has no reader for legacy POLYDATA): POINTS
  float (double), CELLS, CELL_TYPES 5, POINT_DATA fields.
* ``.glb``: glTF 2.0 binary, one node (rotated so the model's +Z is glTF's +Y, up:
  :data:`Y_UP`) and mesh: float32 POSITION (with bounds), uint32
  triangle indices (fields are not written).
"""

from __future__ import annotations

import io
import json
import struct
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from craters._shared import atomic_path, progress_bar

from .chunks import BackgroundWriter

__all__ = ["MESH_SUFFIXES", "MESH_WRITERS", "MeshSource", "array_source", "pack_faces",
           "pack_vertices", "ply_face_dtype", "ply_vertex_dtype", "write_mesh"]

#: The mesh node's rotation (glTF's x, y, z, w): -90 degrees about x, the model's +Z
#: (a body's north, a DEM's up) to glTF's +Y (up); the positions stay the model's metres.
Y_UP = [-0.7071067811865476, 0.0, 0.0, 0.7071067811865476]
_PLY_TYPES = {"f4": "float", "f8": "double", "i4": "int", "u1": "uchar", "u4": "uint",
              "i2": "short", "u2": "ushort", "i1": "char"}
_VTK_XML_TYPES = {"f4": "Float32", "f8": "Float64", "i4": "Int32", "u1": "UInt8",
                  "u4": "UInt32", "i2": "Int16", "u2": "UInt16", "i1": "Int8"}
_VTK_LEGACY_TYPES = {"f4": "float", "f8": "double", "i4": "int", "u1": "unsigned_char",
                     "u4": "unsigned_int", "i2": "short", "u2": "unsigned_short", "i1": "char"}


@dataclass(frozen=True)
class MeshSource:
    """A triangle mesh in chunks (module notes); positions in metres."""

    n_vertices: int
    """Number of vertices."""
    n_faces: int
    """Number of triangles."""
    vertex_chunks: Callable[[], Iterable[tuple[np.ndarray, dict[str, np.ndarray]]]]
    """Yields ``(xyz (k, 3), {field: (k,) values})`` in vertex order."""
    face_groups: Callable[[], Iterable[tuple[str | None, Iterable[np.ndarray]]]]
    """Yields ``(group name or None, chunks of (k, 3) global 0-based indices)`` in face
    order; groups name the parts of a mesh (OBJ ``g``), None for a mesh of one part."""
    facet_chunks: Callable[[], Iterable[np.ndarray]]
    """Yields ``(k, 3, 3)`` triangle corners in face order (for STL)."""
    fields: tuple[tuple[str, str], ...] = ()
    """Per-vertex fields: ``(name, numpy dtype)``, e.g. ``("height_m", "<f4")``; the first
    is the active scalar of VTK files."""
    title: str = "craterform mesh, metres"
    """What the mesh is: the first comment of every format (the STL header)."""
    comments: tuple[str, ...] = ()
    """More PLY header comments."""
    obj_title: str | None = None
    """The OBJ comment line when it differs from ``title``."""
    progress_label: str = ""
    """Label of the progress bar over the face chunks."""
    vertex_records: Callable[[np.dtype], Iterable[np.ndarray]] | None = None
    """Optional fast path of the PLY writer: yields the vertices, in order, as packed
    records of the given structured dtype (float32 ``x y z`` then the fields), the same
    values :func:`pack_vertices` makes of ``vertex_chunks``. The chunks are written on a
    background thread while the next ones are made, so a yielded array may only be
    reused two yields later (alternate two buffers)."""
    face_records: Callable[[np.dtype], Iterable[np.ndarray]] | None = None
    """Optional fast path of the PLY writer: yields the faces, in order, as records of
    the given dtype (``n`` = 3, ``v`` = the three indices), as :func:`pack_faces`
    makes of ``faces``; buffers alternate as in ``vertex_records``."""
    position_type: str = "<f4"
    """``x y z`` of PLY, VTP and VTK files: ``"<f4"``, or ``"<f8"`` for a mesh far from its
    origin (a window of the Moon in its body frame: float32 steps are 0.125 m at 1737 km;
    :func:`array_source` picks it past :data:`FLOAT64_BEYOND_M`). STL and glTF are float32;
    VTK's PLY reader reads float32 whatever the file holds (VTK keeps float64 from .vtp)."""
    own_writers: dict[str, Callable[[Path, bool], object]] = field(default_factory=dict)
    """Writers of this mesh that replace the shared one for a suffix:
    ``{suffix: writer(path, progress)}`` writing the file atomically (a lat/long body's
    ``.glb`` is its patched-strip glTF, :func:`latlong.export_glb`)."""

    def faces(self) -> Iterator[np.ndarray]:
        """Every face chunk, groups in order."""
        for _, chunks in self.face_groups():
            yield from chunks

    def arrays(self) -> tuple[np.ndarray, np.ndarray, dict[str, np.ndarray]]:
        """The whole mesh in memory: vertices (n, 3) float64 metres, faces (m, 3) int64
        and the per-vertex fields ``{name: (n,) values}``."""
        xyz: list[np.ndarray] = []
        values: dict[str, list[np.ndarray]] = {name: [] for name, _ in self.fields}
        for chunk, vals in self.vertex_chunks():
            xyz.append(np.asarray(chunk, dtype=np.float64))
            for name, parts in values.items():
                parts.append(np.asarray(vals[name]))
        faces = [np.asarray(f, dtype=np.int64) for f in self.faces()]
        return (np.concatenate(xyz) if xyz else np.zeros((0, 3)),
                np.concatenate(faces) if faces else np.zeros((0, 3), np.int64),
                {k: np.concatenate(v) for k, v in values.items()})


def array_source(vertices, faces, title: str, **fields) -> MeshSource:
    """A mesh held in memory: ``vertices`` (n, 3) metres, ``faces`` (m, 3) 0-based, and
    per-vertex ``fields`` (name=array; written with the arrays' dtypes).

    Examples
    --------
    >>> src = array_source(np.eye(3), [[0, 1, 2]], "one triangle")
    >>> src.n_vertices, src.n_faces, next(iter(src.faces())).tolist()
    (3, 1, [[0, 1, 2]])
    """
    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces, dtype=np.int64)
    if v.ndim != 2 or v.shape[1:] != (3,) or f.ndim != 2 or f.shape[1:] != (3,):
        raise ValueError(f"`vertices` and `faces` must be (n, 3) and (m, 3); got {v.shape} "
                         f"and {f.shape}")
    values = {k: np.asarray(a) for k, a in fields.items()}
    far = len(v) > 0 and float(np.abs(v).max()) > FLOAT64_BEYOND_M
    return MeshSource(len(v), len(f), lambda: [(v, values)], lambda: [(None, [f])],
                      lambda: [v[f]], tuple((k, a.dtype.str) for k, a in values.items()),
                      title, position_type="<f8" if far else "<f4")


#: :func:`array_source` writes float64 positions past this distance from the origin
#: (float32 steps are 7.8 mm at 100 km, 0.125 m at the Moon's radius).
FLOAT64_BEYOND_M = 1e5


def _dtype(code: str) -> np.dtype:
    return np.dtype(code).newbyteorder("<")


def _index_type(n_vertices: int) -> tuple[str, str]:
    return ("int", "<i4") if n_vertices < 2**31 else ("uint", "<u4")


def ply_vertex_dtype(src: MeshSource) -> np.dtype:
    """The packed PLY vertex record of ``src``: ``x y z`` then its fields."""
    pt = src.position_type
    return np.dtype([("x", pt), ("y", pt), ("z", pt),
                     *((n, _dtype(t)) for n, t in src.fields)])


def ply_face_dtype(n_vertices: int) -> np.dtype:
    """The packed PLY face record: uchar count, three int (uint past 2^31) indices."""
    return np.dtype([("n", "u1"), ("v", _index_type(n_vertices)[1], (3,))])


def pack_vertices(xyz, values: dict, dtype: np.dtype, out: np.ndarray | None = None):
    """Vertex records of ``dtype`` (:func:`ply_vertex_dtype`) from positions and fields."""
    rec = np.empty(len(xyz), dtype=dtype) if out is None else out[:len(xyz)]
    rec["x"], rec["y"], rec["z"] = xyz[:, 0], xyz[:, 1], xyz[:, 2]
    assert dtype.names is not None  # x, y, z were set: a structured dtype
    for name in dtype.names[3:]:
        rec[name] = values[name]
    return rec


def pack_faces(tri, dtype: np.dtype, out: np.ndarray | None = None):
    """Face records of ``dtype`` (:func:`ply_face_dtype`) from (k, 3) indices."""
    rec = np.empty(len(tri), dtype=dtype) if out is None else out[:len(tri)]
    rec["n"] = 3
    rec["v"] = tri
    return rec


def _bytes_of(rec: np.ndarray) -> np.ndarray:
    return rec.reshape(-1).view(np.uint8)


def write_ply(src: MeshSource, fh, progress: bool = False) -> None:
    """Binary little-endian PLY (module notes)."""
    idx = _index_type(src.n_vertices)[0]
    header = ["ply", "format binary_little_endian 1.0", f"comment {src.title}",
              *(f"comment {c}" for c in src.comments), f"element vertex {src.n_vertices}",
              *(f"property {_PLY_TYPES[src.position_type[1:]]} {c}" for c in "xyz"),
              *(f"property {_PLY_TYPES[_dtype(t).str[1:]]} {n}" for n, t in src.fields),
              f"element face {src.n_faces}", f"property list uchar {idx} vertex_indices",
              "end_header"]
    fh.write(("\n".join(header) + "\n").encode("ascii"))
    vdt, fdt = ply_vertex_dtype(src), ply_face_dtype(src.n_vertices)
    vertices = (src.vertex_records(vdt) if src.vertex_records is not None
                else (pack_vertices(xyz, values, vdt) for xyz, values in src.vertex_chunks()))
    faces = (src.face_records(fdt) if src.face_records is not None
             else (pack_faces(tri, fdt) for tri in src.faces()))
    with BackgroundWriter(fh) as out:
        for rec in vertices:
            out.write(_bytes_of(rec))
        for rec in progress_bar(faces, enabled=progress, desc=src.progress_label or "PLY"):
            out.write(_bytes_of(rec))


def _text_blocks(rows: np.ndarray, fmt: str, step: int = 1 << 18):
    for s in range(0, len(rows), step):
        block = rows[s:s + step]
        yield (fmt * len(block)) % tuple(block.ravel().tolist())


def write_obj(src: MeshSource, fh, progress: bool = False) -> None:
    """Wavefront OBJ text (module notes)."""
    out = io.TextIOWrapper(fh, encoding="ascii", newline="\n")
    out.write(f"# {src.obj_title or src.title}\n")
    digits = 12 if src.position_type == "<f8" else 9
    for xyz, _ in src.vertex_chunks():
        for text in _text_blocks(np.asarray(xyz), f"v %.{digits}g %.{digits}g %.{digits}g\n"):
            out.write(text)
    bar = progress_bar(total=None, enabled=progress, desc=src.progress_label or "OBJ")
    for group, chunks in src.face_groups():
        if group is not None:
            out.write(f"g {group}\n")
        for tri in chunks:
            for text in _text_blocks(np.asarray(tri) + 1, "f %d %d %d\n"):
                out.write(text)
            bar.update()
    bar.close()
    out.flush()
    out.detach()


def write_stl(src: MeshSource, fh, progress: bool = False) -> None:
    """Binary STL (module notes)."""
    tdt = np.dtype([("n", "<f4", (3,)), ("v", "<f4", (3, 3)), ("a", "<u2")])
    fh.write(src.title.encode("ascii")[:80].ljust(80, b" "))
    fh.write(np.uint32(src.n_faces).tobytes())
    for corners in progress_bar(src.facet_chunks(), enabled=progress,
                                desc=src.progress_label or "STL"):
        normal = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
        norm = np.linalg.norm(normal, axis=1, keepdims=True)
        normal = np.divide(normal, norm, out=np.zeros_like(normal), where=norm > 0)
        rec = np.zeros(len(corners), dtype=tdt)
        rec["n"] = normal
        rec["v"] = corners
        fh.write(rec.tobytes())


def write_vtp(src: MeshSource, fh, progress: bool = False) -> None:
    """VTK XML PolyData, raw appended (module notes). Data order: points, the first
    field, connectivity, offsets, the other fields."""
    n_v, n_f = src.n_vertices, src.n_faces
    itype, idt = ("Int32", "<i4") if 3 * n_f < 2**31 - 1 else ("Int64", "<i8")
    isize = np.dtype(idt).itemsize
    fields = [(n, _dtype(t)) for n, t in src.fields]
    pt = np.dtype(src.position_type)
    sizes = [3 * pt.itemsize * n_v, *([n_v * fields[0][1].itemsize] if fields else []),
             3 * n_f * isize, n_f * isize, *(n_v * t.itemsize for _, t in fields[1:])]
    offs = np.concatenate([[0], np.cumsum([8 + s for s in sizes])])
    first = 1 if fields else 0  # blocks: points, [field 0], connectivity, offsets, fields...
    arrays = []
    for k, (name, t) in enumerate(fields):
        block = 1 if k == 0 else 3 + k
        arrays.append(f'<DataArray type="{_VTK_XML_TYPES[t.str[1:]]}" Name="{name}" '
                      f'format="appended" offset="{offs[block]}"/>\n')
    scalars = f' Scalars="{fields[0][0]}"' if fields else ""
    xml = (
        '<?xml version="1.0"?>\n'
        '<VTKFile type="PolyData" version="1.0" byte_order="LittleEndian" '
        'header_type="UInt64">\n'
        f"<!-- {src.title} -->\n"
        "<PolyData>\n"
        f'<Piece NumberOfPoints="{n_v}" NumberOfVerts="0" NumberOfLines="0" '
        f'NumberOfStrips="0" NumberOfPolys="{n_f}">\n'
        f"<PointData{scalars}>\n" + "".join(arrays) + "</PointData>\n<Points>\n"
        f'<DataArray type="{_VTK_XML_TYPES[pt.str[1:]]}" Name="Points" NumberOfComponents="3" '
        f'format="appended" offset="{offs[0]}"/>\n'
        "</Points>\n<Polys>\n"
        f'<DataArray type="{itype}" Name="connectivity" format="appended" '
        f'offset="{offs[first + 1]}"/>\n'
        f'<DataArray type="{itype}" Name="offsets" format="appended" '
        f'offset="{offs[first + 2]}"/>\n'
        "</Polys>\n</Piece>\n</PolyData>\n"
        '<AppendedData encoding="raw">\n_')
    fh.write(xml.encode("ascii"))
    bar = progress_bar(total=None, enabled=progress, desc=src.progress_label or "VTP")

    def field_block(k: int) -> None:
        name, t = fields[k]
        fh.write(np.uint64(n_v * t.itemsize).tobytes())
        for _, values in src.vertex_chunks():
            fh.write(np.asarray(values[name]).astype(t).tobytes())

    fh.write(np.uint64(sizes[0]).tobytes())
    for xyz, _ in src.vertex_chunks():
        fh.write(np.asarray(xyz).astype(pt).tobytes())
    if fields:
        field_block(0)
    fh.write(np.uint64(3 * n_f * isize).tobytes())
    for tri in src.faces():
        fh.write(np.asarray(tri).astype(idt).tobytes())
        bar.update()
    fh.write(np.uint64(n_f * isize).tobytes())
    done = 0
    for tri in src.faces():
        m = len(tri)
        fh.write((3 * np.arange(done + 1, done + m + 1, dtype=np.int64)).astype(idt).tobytes())
        done += m
    for k in range(1, len(fields)):
        field_block(k)
    bar.close()
    fh.write(b"\n</AppendedData>\n</VTKFile>\n")


def write_vtk(src: MeshSource, fh, progress: bool = False) -> None:
    """VTK legacy binary unstructured grid of triangles, big-endian (module notes)."""
    fh.write(f"# vtk DataFile Version 4.2\n{src.title[:255]}\nBINARY\n"
             f"DATASET UNSTRUCTURED_GRID\n"
             f"POINTS {src.n_vertices} {_VTK_LEGACY_TYPES[src.position_type[1:]]}\n"
             .encode("ascii"))
    for xyz, _ in src.vertex_chunks():
        fh.write(np.asarray(xyz).astype(">" + src.position_type[1:]).tobytes())
    fh.write(f"\nCELLS {src.n_faces} {4 * src.n_faces}\n".encode("ascii"))
    for tri in progress_bar(src.faces(), enabled=progress, desc=src.progress_label or "VTK"):
        rec = np.empty((len(tri), 4), dtype=">i4")
        rec[:, 0] = 3
        rec[:, 1:] = tri
        fh.write(rec.tobytes())
    fh.write(f"\nCELL_TYPES {src.n_faces}\n".encode("ascii"))
    triangle = np.full(1 << 16, 5, dtype=">i4").tobytes()  # VTK_TRIANGLE
    for start in range(0, src.n_faces, 1 << 16):
        fh.write(triangle[:4 * min(1 << 16, src.n_faces - start)])
    if src.fields:
        fh.write(f"\nPOINT_DATA {src.n_vertices}\n".encode("ascii"))
    for name, t in src.fields:
        dt = _dtype(t)
        fh.write(f"SCALARS {name} {_VTK_LEGACY_TYPES[dt.str[1:]]} 1\nLOOKUP_TABLE default\n"
                 .encode("ascii"))
        for _, values in src.vertex_chunks():
            fh.write(np.asarray(values[name]).astype(dt.newbyteorder(">")).tobytes())
        fh.write(b"\n")


def write_glb(src: MeshSource, fh, progress: bool = False) -> None:
    """glTF 2.0 binary with one triangle mesh (module notes); below 4 GiB."""
    n_v, n_f = src.n_vertices, src.n_faces
    pos_bytes, idx_bytes = 12 * n_v, 12 * n_f
    if pos_bytes + idx_bytes > 2**32 - 4096:
        raise ValueError(f"the mesh ({n_v} vertices, {n_f} triangles) is beyond a GLB's 4 GiB")
    lo, hi = np.full(3, np.inf), np.full(3, -np.inf)
    for xyz, _ in src.vertex_chunks():
        p = np.asarray(xyz).astype(np.float32)
        lo, hi = np.minimum(lo, p.min(axis=0)), np.maximum(hi, p.max(axis=0))
    gl = {"asset": {"version": "2.0", "generator": "craterform"},
          "extras": {"title": src.title}, "scene": 0, "scenes": [{"nodes": [0]}],
          "nodes": [{"mesh": 0, "rotation": Y_UP}],
          "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1,
                                      "mode": 4}]}],
          "buffers": [{"byteLength": pos_bytes + idx_bytes}],
          "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": pos_bytes,
                           "target": 34962},
                          {"buffer": 0, "byteOffset": pos_bytes, "byteLength": idx_bytes,
                           "target": 34963}],
          "accessors": [{"bufferView": 0, "componentType": 5126, "count": n_v,
                         "type": "VEC3", "min": [float(v) for v in lo],
                         "max": [float(v) for v in hi]},
                        {"bufferView": 1, "componentType": 5125, "count": 3 * n_f,
                         "type": "SCALAR"}]}
    text = json.dumps(gl, separators=(",", ":")).encode("utf-8")
    text += b" " * ((4 - len(text) % 4) % 4)
    total = 12 + 8 + len(text) + 8 + pos_bytes + idx_bytes
    fh.write(struct.pack("<4sII", b"glTF", 2, total))
    fh.write(struct.pack("<I4s", len(text), b"JSON") + text)
    fh.write(struct.pack("<I4s", pos_bytes + idx_bytes, b"BIN\x00"))
    for xyz, _ in src.vertex_chunks():
        fh.write(np.asarray(xyz).astype("<f4").tobytes())
    for tri in progress_bar(src.faces(), enabled=progress, desc=src.progress_label or "GLB"):
        fh.write(np.asarray(tri).astype("<u4").tobytes())


#: Suffix -> writer(source, binary file, progress).
MESH_WRITERS: dict[str, Callable] = {".ply": write_ply, ".obj": write_obj, ".stl": write_stl,
                                     ".vtp": write_vtp, ".vtk": write_vtk, ".glb": write_glb}
MESH_SUFFIXES = tuple(MESH_WRITERS)


def write_mesh(src: MeshSource, path, *, progress: bool = False) -> Path:
    """Write ``src`` to ``path`` in the format of its suffix (:data:`MESH_WRITERS`, or the
    source's own writer for it: :attr:`MeshSource.own_writers`), atomically; returns the
    path."""
    path = Path(path)
    own = src.own_writers.get(path.suffix.lower())
    if own is not None:
        own(path, progress)
        return path
    writer = MESH_WRITERS.get(path.suffix.lower())
    if writer is None:
        raise ValueError(f"`path` {str(path)!r}: unknown mesh format {path.suffix or '(none)'!r}; "
                         f"allowed: {' '.join(MESH_SUFFIXES)}")
    with atomic_path(path) as tmp, open(tmp, "wb") as raw:
        fh = io.BufferedWriter(raw, buffer_size=1 << 22)
        writer(src, fh, progress)
        fh.flush()
        fh.detach()
    return path
