r"""Multi-resolution triangle meshes of a layer stack (or one DEM): PLY and VTP, streamed.

Geometry
--------
Vertices are pixel centres in the stack's local metric frame (:mod:`dem.frame`: x east,
y north, metres from the target pixel; equirectangular at the target for a geographic
CRS), z = height in metres; float32 is enough because the frame is centred on the site
(1 mm at 10 km). Each layer is triangulated cell by cell (two triangles per square of
four pixel centres), except where the next finer layer sits: the cells inside its
footprint are left out (a hole) and the footprint's border pixels are *the same
vertices* as the finer layer's even border pixels (equal heights by the stack's
consistency). The finer layer has a vertex between each two of them (its odd border
pixels), so the ring of coarse cells around the hole is triangulated as a fan from that
vertex (three triangles per cell): no T-junction, no crack. The result is one
connected, consistently oriented surface (normals up) whose only boundary is layer 0's
outline. Needs footprints one pixel clear of their layer's border (what
:func:`dem.enhance` makes).

Formats
-------
* PLY: ``binary_little_endian``; vertex ``x, y, z`` (float32) and ``layer`` (uchar);
  faces as ``uchar 3`` + three int32 indices.
* VTP (VTK XML PolyData): raw appended binary (UInt64 headers), float32 points, a
  UInt8 point array ``layer``, int32 (int64 if needed) connectivity and offsets.

Both are written layer by layer (memory ~ a few arrays of one layer) to a temporary
file renamed into place at the end.

Boulders
--------
A stack's boulders (:attr:`dem.Stack.boulders`, stamped by :func:`dem.enhance`) are
appended as their own closed meshes (finest level of the boulder shape, same frame),
after the terrain: their vertices carry the ``layer`` they were stamped in and a
``boulder_id`` (int32: the boulder's ``index`` in the stack catalogs; -1 on the
terrain), which the files then have as an extra vertex property / point array.
"""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np

from craters._shared import atomic_path, progress_bar
from craters.boulders import boulder_faces, catalog_shape, iter_boulder_meshes, mesh_chunk

from .core import Dem
from .frame import local_frame, pixel_affine
from .stack import Stack

__all__ = ["MESH_SUFFIXES", "mesh_arrays", "to_mesh"]

#: Suffixes :func:`to_mesh` writes.
MESH_SUFFIXES = (".ply", ".vtp")


class _Layout:
    """Vertex numbering of every layer (own vertices: pixels outside the finer footprint)."""

    def __init__(self, stack: Stack):
        self.stack = stack
        layers = stack.layers
        n = len(layers)
        self.holes = list(stack.windows) + [None]
        counts = []
        for k, d in enumerate(layers):
            if not np.isfinite(d.heights).all():
                raise ValueError(f"layer {k} has unknown (NaN) pixels; fill them before meshing")
            rows, cols = d.shape
            hole = self.holes[k]
            if hole is not None:
                r0, c0, w = hole
                if r0 < 1 or c0 < 1 or r0 + w > rows - 1 or c0 + w > cols - 1:
                    raise ValueError(f"the footprint of layer {k + 1} touches the border of "
                                     f"layer {k}; the mesh needs it one pixel clear")
                counts.append(rows * cols - w * w)
            else:
                counts.append(rows * cols)
        self.counts = counts
        self.offsets = np.concatenate([[0], np.cumsum(counts)]).astype(np.int64)
        self.n_vertices = int(self.offsets[-1])
        self.face_counts = []
        for k, d in enumerate(layers):
            rows, cols = d.shape
            cells = (rows - 1) * (cols - 1)
            hole = self.holes[k]
            if hole is None:
                self.face_counts.append(2 * cells)
            else:
                w = hole[2]
                seam = 4 * (w - 1)
                self.face_counts.append(2 * (cells - (w - 1) ** 2 - seam) + 3 * seam)
        self.n_faces = int(sum(self.face_counts))
        # vertex index arrays, finest first (a coarse footprint border refers to the finer)
        self._index: list[np.ndarray | None] = [None] * n
        for k in range(n - 1, -1, -1):
            self._index[k] = self._make_index(k)

    def own_mask(self, k: int) -> np.ndarray:
        mask = np.ones(self.stack.layers[k].shape, dtype=bool)
        hole = self.holes[k]
        if hole is not None:
            r0, c0, w = hole
            mask[r0:r0 + w, c0:c0 + w] = False
        return mask

    def _make_index(self, k: int) -> np.ndarray:
        idx = np.full(self.stack.layers[k].shape, -1, dtype=np.int64)
        mask = self.own_mask(k)
        idx[mask] = self.offsets[k] + np.arange(self.counts[k], dtype=np.int64)
        hole = self.holes[k]
        if hole is not None:
            r0, c0, w = hole
            fine = self._index[k + 1][::2, ::2]
            for sl_c, sl_f in (((r0, slice(c0, c0 + w)), (0, slice(None))),
                               ((r0 + w - 1, slice(c0, c0 + w)), (w - 1, slice(None))),
                               ((slice(r0, r0 + w), c0), (slice(None), 0)),
                               ((slice(r0, r0 + w), c0 + w - 1), (slice(None), w - 1))):
                idx[sl_c] = fine[sl_f]
        return idx

    def vertices(self, k: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """x, y, z (float64) of layer k's own vertices, in index order."""
        d = self.stack.layers[k]
        rows, cols = np.nonzero(self.own_mask(k))
        a = pixel_affine(d, self.stack.frame)
        x = a.a * cols + a.b * rows + a.c
        y = a.d * cols + a.e * rows + a.f
        return x, y, d.heights[rows, cols]

    def faces(self, k: int) -> np.ndarray:
        """(m, 3) vertex indices of layer k's triangles, counter-clockwise seen from +z."""
        idx = self._index[k]
        rows, cols = idx.shape
        cell = np.ones((rows - 1, cols - 1), dtype=bool)
        hole = self.holes[k]
        parts = []
        if hole is not None:
            r0, c0, w = hole
            cell[r0:r0 + w - 1, c0:c0 + w - 1] = False  # covered by the finer layer
            cell[r0 - 1, c0:c0 + w - 1] = False  # the four seam strips
            cell[r0 + w - 1, c0:c0 + w - 1] = False
            cell[r0:r0 + w - 1, c0 - 1] = False
            cell[r0:r0 + w - 1, c0 + w - 1] = False
        i, j = np.nonzero(cell)
        a, b, c, d = idx[i, j], idx[i, j + 1], idx[i + 1, j], idx[i + 1, j + 1]
        parts.append(np.stack([np.stack([a, c, d], 1), np.stack([a, d, b], 1)], 1)
                     .reshape(-1, 3))
        if hole is not None:
            parts.append(self._seam(k))
        tri = np.concatenate(parts)
        # the cycle a -> c -> d -> b is clockwise in (col, row); flip if the frame keeps it
        if pixel_affine(self.stack.layers[k], self.stack.frame).determinant > 0:
            tri = tri[:, [0, 2, 1]]
        return tri

    def _seam(self, k: int) -> np.ndarray:
        """Fans from the finer layer's odd border vertices over the ring of coarse cells."""
        idx = self._index[k]
        fine = self._index[k + 1]
        r0, c0, w = self.holes[k]
        s = np.arange(w - 1)
        odd = 2 * s + 1
        last = 2 * (w - 1)
        # cell corners a (i, j), b (i, j+1), c (i+1, j), d (i+1, j+1): the cycle a c d b
        # with the finer layer's odd border vertex m inserted on the hole edge, rotated to
        # start at m; fanned from m it gives three triangles of the cycle's orientation
        fans = []
        i, j = np.full(w - 1, r0 - 1), c0 + s  # above the hole: edge c-d
        fans.append([fine[0, odd], idx[i + 1, j + 1], idx[i, j + 1], idx[i, j], idx[i + 1, j]])
        i, j = np.full(w - 1, r0 + w - 1), c0 + s  # below: edge b-a
        fans.append([fine[last, odd], idx[i, j], idx[i + 1, j], idx[i + 1, j + 1],
                     idx[i, j + 1]])
        i, j = r0 + s, np.full(w - 1, c0 - 1)  # left: edge d-b
        fans.append([fine[odd, 0], idx[i, j + 1], idx[i, j], idx[i + 1, j], idx[i + 1, j + 1]])
        i, j = r0 + s, np.full(w - 1, c0 + w - 1)  # right: edge a-c
        fans.append([fine[odd, last], idx[i + 1, j], idx[i + 1, j + 1], idx[i, j + 1],
                     idx[i, j]])
        return np.concatenate([np.stack([f[0], f[q], f[q + 1]], 1)
                               for f in fans for q in (1, 2, 3)])


class _Rocks:
    """The boulders of a stack, meshed a chunk at a time after the terrain."""

    def __init__(self, stack: Stack):
        parts, layers = [], []
        for k, cat in enumerate(stack.boulders):
            if cat is not None and len(cat):
                parts.append(cat)
                layers.append(np.full(len(cat), k, dtype=np.uint8))
        self.cat = np.concatenate(parts) if parts else None
        self.layer = np.concatenate(layers) if layers else np.zeros(0, np.uint8)
        n = 0 if self.cat is None else len(self.cat)
        if n:
            self.shape = catalog_shape(self.cat)
            self.level, self.chunk = self.shape.levels[-1], mesh_chunk(self.shape)
            self.ids = (self.cat["index"].astype(np.int32) if "index" in self.cat.dtype.names
                        else np.arange(n, dtype=np.int32))
        else:
            self.level, self.chunk = 0, 1
        self.nv = 10 * 4**self.level + 2
        self.n_vertices = n * self.nv
        self.n_faces = n * 20 * 4**self.level

    def __bool__(self) -> bool:
        return self.n_vertices > 0

    def vertex_chunks(self):
        """(xyz (m, 3), layer (m,), boulder_id (m,)) per chunk."""
        for s0, world, _ in iter_boulder_meshes(self.cat, self.level, chunk=self.chunk):
            k = len(world)
            yield (world.reshape(-1, 3), np.repeat(self.layer[s0:s0 + k], self.nv),
                   np.repeat(self.ids[s0:s0 + k], self.nv))

    def face_chunks(self, base: int):
        faces = boulder_faces(self.level)
        n = len(self.cat)
        for s0 in range(0, n, self.chunk):
            k = min(self.chunk, n - s0)
            offsets = base + (s0 + np.arange(k))[:, None, None] * self.nv
            yield (faces[None] + offsets).reshape(-1, 3)


def _as_stack(source) -> Stack:
    if isinstance(source, Stack):
        return source
    if isinstance(source, Dem):
        return Stack([source], [], local_frame(source))
    raise TypeError(f"`source` must be a Stack or a Dem; got {type(source).__name__}")


def mesh_arrays(source) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The whole mesh in memory: vertices (n, 3) float64, faces (m, 3) int64, layer (n,).

    For tests and small stacks; :func:`to_mesh` streams instead.
    """
    lay = _Layout(_as_stack(source))
    verts = np.concatenate([np.stack(lay.vertices(k), 1) for k in range(len(lay.counts))])
    faces = np.concatenate([lay.faces(k) for k in range(len(lay.counts))])
    layer = np.repeat(np.arange(len(lay.counts)), lay.counts)
    return verts, faces, layer


def to_mesh(source, path, *, progress: bool = False, boulders: bool = True) -> Path:
    """Write the multi-resolution mesh of a stack (or one DEM) as PLY or VTP.

    See the module notes for the geometry, the frame and the formats.

    Parameters
    ----------
    source : Stack or Dem
        A DEM is meshed in its own local frame (origin at its centre pixel).
    path : str or Path
        ``.ply`` or ``.vtp``; written atomically.
    progress : bool
        Show a progress bar over the layers.
    boulders : bool
        Append the stack's boulders (if it has any) as their own meshes.

    Returns
    -------
    Path

    Examples
    --------
    >>> import tempfile, pyvista
    >>> d = Dem(np.zeros((3, 4)), pixel_size_m=2.0)
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     m = pyvista.read(to_mesh(d, f"{tmp}/d.ply"))
    >>> m.n_points, m.n_cells, m.bounds[:4]
    (12, 12, (-4.0, 2.0, -2.0, 2.0))
    """
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in MESH_SUFFIXES:
        raise ValueError(f"output {str(path)!r}: unknown mesh format {suffix or '(none)'!r}; "
                         f"allowed: {' '.join(MESH_SUFFIXES)}")
    stack = _as_stack(source)
    lay = _Layout(stack)
    lay.rocks = _Rocks(stack) if boulders else _Rocks(stack.replace(
        boulders=[None] * len(stack)))
    if lay.n_vertices + lay.rocks.n_vertices >= 2**31 - 1:
        raise ValueError(f"the mesh would have {lay.n_vertices} vertices; PLY/VTP indices are "
                         f"limited to 2^31 - 1 here")
    with atomic_path(path) as tmp, open(tmp, "wb") as fh:
        out = io.BufferedWriter(fh, buffer_size=1 << 22)
        (_write_ply if suffix == ".ply" else _write_vtp)(lay, out, progress)
        out.flush()
        out.detach()
    return path


_PLY_VERTEX = np.dtype([("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("layer", "u1")])
_PLY_FACE = np.dtype([("n", "u1"), ("v", "<i4", (3,))])


_PLY_VERTEX_ROCKS = np.dtype([("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("layer", "u1"),
                              ("boulder_id", "<i4")])


def _write_ply(lay: _Layout, fh, progress: bool) -> None:
    frame = lay.stack.frame
    rocks = lay.rocks
    header = ("ply\nformat binary_little_endian 1.0\n"
              "comment craterform multi-resolution mesh; metres in a local frame: x = "
              f"(X - {frame.origin_x!r}) * {frame.scale_x!r}, y = (Y - {frame.origin_y!r}) * "
              f"{frame.scale_y!r} ({frame.kind}), z = height\n"
              + ("comment boulders after the terrain; boulder_id -1 = terrain\n"
                 if rocks else "")
              + f"element vertex {lay.n_vertices + rocks.n_vertices}\nproperty float x\n"
              "property float y\nproperty float z\nproperty uchar layer\n"
              + ("property int boulder_id\n" if rocks else "")
              + f"element face {lay.n_faces + rocks.n_faces}\n"
              "property list uchar int vertex_indices\nend_header\n")
    fh.write(header.encode("ascii"))
    vdt = _PLY_VERTEX_ROCKS if rocks else _PLY_VERTEX
    n = len(lay.counts)
    for k in progress_bar(range(n), enabled=progress, desc="mesh vertices"):
        x, y, z = lay.vertices(k)
        rec = np.empty(x.size, dtype=vdt)
        rec["x"], rec["y"], rec["z"], rec["layer"] = x, y, z, k
        if rocks:
            rec["boulder_id"] = -1
        fh.write(rec.tobytes())
    if rocks:
        for xyz, layer, ids in rocks.vertex_chunks():
            rec = np.empty(len(xyz), dtype=vdt)
            rec["x"], rec["y"], rec["z"] = xyz[:, 0], xyz[:, 1], xyz[:, 2]
            rec["layer"], rec["boulder_id"] = layer, ids
            fh.write(rec.tobytes())
    for k in progress_bar(range(n), enabled=progress, desc="mesh faces"):
        tri = lay.faces(k)
        rec = np.empty(len(tri), dtype=_PLY_FACE)
        rec["n"] = 3
        rec["v"] = tri
        fh.write(rec.tobytes())
    if rocks:
        for tri in rocks.face_chunks(lay.n_vertices):
            rec = np.empty(len(tri), dtype=_PLY_FACE)
            rec["n"] = 3
            rec["v"] = tri
            fh.write(rec.tobytes())


def _write_vtp(lay: _Layout, fh, progress: bool) -> None:
    rocks = lay.rocks
    n_v, n_f = lay.n_vertices + rocks.n_vertices, lay.n_faces + rocks.n_faces
    itype, idt = ("Int32", "<i4") if 3 * n_f < 2**31 - 1 else ("Int64", "<i8")
    isize = np.dtype(idt).itemsize
    sizes = [12 * n_v, n_v, 3 * n_f * isize, n_f * isize] + ([4 * n_v] if rocks else [])
    offs = np.concatenate([[0], np.cumsum([8 + s for s in sizes])])
    frame = lay.stack.frame
    rock_array = (f'<DataArray type="Int32" Name="boulder_id" format="appended" '
                  f'offset="{offs[4]}"/>\n' if rocks else "")
    xml = (
        '<?xml version="1.0"?>\n'
        '<VTKFile type="PolyData" version="1.0" byte_order="LittleEndian" '
        'header_type="UInt64">\n'
        f"<!-- craterform multi-resolution mesh; metres in a local frame: x = "
        f"(X - {frame.origin_x!r}) * {frame.scale_x!r}, y = (Y - {frame.origin_y!r}) * "
        f"{frame.scale_y!r} ({frame.kind}), z = height -->\n"
        "<PolyData>\n"
        f'<Piece NumberOfPoints="{n_v}" NumberOfVerts="0" NumberOfLines="0" '
        f'NumberOfStrips="0" NumberOfPolys="{n_f}">\n'
        '<PointData Scalars="layer">\n'
        f'<DataArray type="UInt8" Name="layer" format="appended" offset="{offs[1]}"/>\n'
        + rock_array +
        "</PointData>\n<Points>\n"
        f'<DataArray type="Float32" Name="Points" NumberOfComponents="3" format="appended" '
        f'offset="{offs[0]}"/>\n'
        "</Points>\n<Polys>\n"
        f'<DataArray type="{itype}" Name="connectivity" format="appended" '
        f'offset="{offs[2]}"/>\n'
        f'<DataArray type="{itype}" Name="offsets" format="appended" offset="{offs[3]}"/>\n'
        "</Polys>\n</Piece>\n</PolyData>\n"
        '<AppendedData encoding="raw">\n_')
    fh.write(xml.encode("ascii"))
    n = len(lay.counts)
    bar = progress_bar(total=3 * n, enabled=progress, desc="mesh")
    fh.write(np.uint64(sizes[0]).tobytes())
    for k in range(n):
        fh.write(np.stack(lay.vertices(k), 1).astype("<f4").tobytes())
        bar.update()
    if rocks:
        for xyz, _, _ in rocks.vertex_chunks():
            fh.write(xyz.astype("<f4").tobytes())
    fh.write(np.uint64(sizes[1]).tobytes())
    for k in range(n):
        fh.write(np.full(lay.counts[k], k, dtype="u1").tobytes())
    if rocks:
        fh.write(np.repeat(rocks.layer, rocks.nv).tobytes())
    fh.write(np.uint64(sizes[2]).tobytes())
    for k in range(n):
        fh.write(lay.faces(k).astype(idt).tobytes())
        bar.update()
    if rocks:
        for tri in rocks.face_chunks(lay.n_vertices):
            fh.write(tri.astype(idt).tobytes())
    fh.write(np.uint64(sizes[3]).tobytes())
    done = 0
    for k in range(n):
        m = lay.face_counts[k]
        fh.write((3 * np.arange(done + 1, done + m + 1, dtype=np.int64)).astype(idt).tobytes())
        done += m
        bar.update()
    if rocks:
        fh.write((3 * np.arange(done + 1, done + rocks.n_faces + 1, dtype=np.int64))
                 .astype(idt).tobytes())
    if rocks:
        fh.write(np.uint64(sizes[4]).tobytes())
        fh.write(np.full(lay.n_vertices, -1, dtype="<i4").tobytes())
        fh.write(np.repeat(rocks.ids, rocks.nv).astype("<i4").tobytes())
    bar.close()
    fh.write(b"\n</AppendedData>\n</VTKFile>\n")
