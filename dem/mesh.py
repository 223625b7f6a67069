r"""Multi-resolution triangle meshes of a layer stack (or one DEM), streamed to any mesh file.

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
The shared mesh writers (:mod:`latlong.meshio.writers`: PLY, OBJ, STL, VTP, VTK, GLB)
with a per-vertex ``layer`` (uchar); PLY and VTP are written layer by layer (memory ~ a
few arrays of one layer), STL gathers the vertices first.

Boulders
--------
A stack's boulders (:attr:`dem.Stack.boulders`, stamped by :func:`dem.enhance`) are
appended as their own closed meshes (finest level of the boulder shape, same frame),
after the terrain: their vertices carry the ``layer`` they were stamped in and a
``boulder_id`` (int32: the boulder's ``index`` in the stack catalogs; -1 on the
terrain), which the files then have as an extra vertex property / point array.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from craters.boulders import boulder_faces, catalog_shape, iter_boulder_meshes, mesh_chunk
from latlong.meshio.writers import MESH_SUFFIXES, MeshSource, write_mesh

from .core import Dem
from .frame import local_frame, pixel_affine
from .stack import Stack

__all__ = ["MESH_SUFFIXES", "as_stack", "mesh_arrays", "mesh_source", "to_mesh"]


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
            finer = self._index[k + 1]
            assert finer is not None  # made before this one (finest first)
            fine = finer[::2, ::2]
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
        assert idx is not None  # __init__ made them all
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
        idx, fine, hole = self._index[k], self._index[k + 1], self.holes[k]
        assert idx is not None and fine is not None and hole is not None  # k has a finer layer
        r0, c0, w = hole
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
            assert self.cat is not None and self.cat.dtype.names is not None  # n boulders
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
        assert self.cat is not None  # asked only when there are boulders (__bool__)
        n = len(self.cat)
        for s0 in range(0, n, self.chunk):
            k = min(self.chunk, n - s0)
            offsets = base + (s0 + np.arange(k))[:, None, None] * self.nv
            yield (faces[None] + offsets).reshape(-1, 3)


def as_stack(source) -> Stack:
    """A stack as it is; one DEM as a one-layer stack in its own local frame (origin at
    its centre pixel)."""
    if isinstance(source, Stack):
        return source
    if isinstance(source, Dem):
        return Stack([source], [], local_frame(source))
    raise TypeError(f"`source` must be a Stack or a Dem; got {type(source).__name__}")


def mesh_arrays(source) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The whole mesh in memory: vertices (n, 3) float64, faces (m, 3) int64, layer (n,).

    For tests and small stacks; :func:`to_mesh` streams instead.
    """
    lay = _Layout(as_stack(source))
    verts = np.concatenate([np.stack(lay.vertices(k), 1) for k in range(len(lay.counts))])
    faces = np.concatenate([lay.faces(k) for k in range(len(lay.counts))])
    layer = np.repeat(np.arange(len(lay.counts)), lay.counts)
    return verts, faces, layer


def mesh_source(source, *, boulders: bool = True) -> MeshSource:
    """The multi-resolution mesh of a stack (or one DEM) as a streamed mesh for the shared
    writers (:mod:`latlong.meshio.writers`): layer by layer, then the boulders."""
    stack = as_stack(source)
    lay = _Layout(stack)
    rocks = _Rocks(stack if boulders else stack.replace(boulders=[None] * len(stack)))
    if lay.n_vertices + rocks.n_vertices >= 2**31 - 1:
        raise ValueError(f"the mesh would have {lay.n_vertices} vertices; mesh indices are "
                         f"limited to 2^31 - 1 here")
    n = len(lay.counts)

    def vertex_chunks():
        for k in range(n):
            xyz = np.stack(lay.vertices(k), 1)
            values = {"layer": np.full(len(xyz), k, dtype=np.uint8)}
            if rocks:
                values["boulder_id"] = np.full(len(xyz), -1, dtype=np.int32)
            yield xyz, values
        if rocks:
            for xyz, layer, ids in rocks.vertex_chunks():
                yield xyz, {"layer": layer, "boulder_id": ids}

    def face_groups():
        terrain = (lay.faces(k) for k in range(n))
        if not rocks:
            yield None, terrain
            return
        yield "terrain", terrain
        yield "boulders", rocks.face_chunks(lay.n_vertices)

    def facet_chunks():
        verts = np.concatenate([xyz for xyz, _ in vertex_chunks()])
        for _, chunks in face_groups():
            for tri in chunks:
                yield verts[tri]

    frame = stack.frame
    title = ("craterform multi-resolution mesh; metres in a local frame: x = "
             f"(X - {frame.origin_x!r}) * {frame.scale_x!r}, y = (Y - {frame.origin_y!r}) * "
             f"{frame.scale_y!r} ({frame.kind}), z = height")
    comments = ("boulders after the terrain; boulder_id -1 = terrain",) if rocks else ()
    fields = (("layer", "u1"), *((("boulder_id", "<i4"),) if rocks else ()))
    return MeshSource(lay.n_vertices + rocks.n_vertices, lay.n_faces + rocks.n_faces,
                      vertex_chunks, face_groups, facet_chunks, fields, title, comments,
                      progress_label="mesh")


def to_mesh(source, path, *, progress: bool = False, boulders: bool = True) -> Path:
    """Write the multi-resolution mesh of a stack (or one DEM) to a mesh file chosen by
    suffix (``.ply .obj .stl .vtp .vtk .glb``, :mod:`latlong.meshio.writers`), atomically.

    See the module notes for the geometry, the frame and the formats.

    Parameters
    ----------
    source : Stack or Dem
        A DEM is meshed in its own local frame (origin at its centre pixel).
    path : str or Path
        The output file.
    progress : bool
        Show a progress bar over the faces.
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
    if path.suffix.lower() not in MESH_SUFFIXES:
        raise ValueError(f"output {str(path)!r}: unknown mesh format "
                         f"{path.suffix.lower() or '(none)'!r}; allowed: "
                         f"{' '.join(MESH_SUFFIXES)}")
    return write_mesh(mesh_source(source, boulders=boulders), path, progress=progress)
