"""Mesh export of a body: the body as a streamed :class:`~latlong.meshio.writers.MeshSource`
for the shared writers (PLY, OBJ, STL, VTP, VTK), and the patched-strip glTF for ``.glb``.

Nothing holds the whole triangle array: triangles are generated a few latitude bands at a
time (``LatLongGrid.band_triangles``), so a 24 M-vertex body exports in a few hundred MB
beyond the body itself. PLY takes a fast path (``MeshSource.vertex_records`` /
``face_records``): numba kernels write the packed records of 1 M vertices or triangles
straight into buffers, several chunks at once on worker threads, while the chunks before
are written on a background thread (the longitudes' cosines and sines, 8 B a vertex,
are found once per pair of mirror rings); the bytes are those of the generic packing.
Every vertex has ``height_m`` (radius minus the reference radius). Placed boulders
(``body.boulders``) are merged in at their finest level after the body's vertices and
triangles, with a per-vertex ``boulder_id`` (-1 on the body, else the boulder's row in
the catalog: ground truth for hazard detection) and, in OBJ, the face groups ``body`` and
``boulders``. ``.glb`` is the renderer export of :func:`latlong.export_glb` (patched
triangle strips, manifest).
"""

from __future__ import annotations

import functools
from pathlib import Path

import numpy as np

from .gltf import export_glb
from .meshio.boulders import BoulderMeshes, mesh_fields
from .meshio.chunks import ordered_chunks
from .meshio.writers import (
    MESH_SUFFIXES,
    MeshSource,
    pack_faces,
    pack_vertices,
    write_mesh,
)

__all__ = ["EXPORT_SUFFIXES", "body_mesh_source", "export_body"]

#: Suffixes :meth:`latlong.Body.export` writes.
EXPORT_SUFFIXES = MESH_SUFFIXES
# triangles (and vertices) per streamed chunk
_CHUNK = 1 << 20
_TABLE_BYTES = 1 << 29  # largest longitude table the PLY writer makes (M ~ 4600)


def _band_chunks(grid):
    """(band_lo, band_hi) ranges holding about _CHUNK triangles."""
    bo = grid.band_offsets()
    n_bands = len(bo) - 1
    lo = 0
    while lo < n_bands:
        hi = int(np.searchsorted(bo, bo[lo] + _CHUNK, side="right")) - 1
        hi = min(max(hi, lo + 1), n_bands)
        yield lo, hi
        lo = hi


def body_mesh_source(body) -> MeshSource:
    """The body (and its placed boulders) as a streamed mesh for the shared writers."""
    grid = body.grid
    n = grid.n_vertices
    rocks = BoulderMeshes.of(body.boulders, n)
    stretch = np.array(body.stretch, dtype=np.float64)

    def rock_heights(_, world):  # above the reference radius, as the body's vertices
        return np.linalg.norm(world.reshape(-1, 3) / stretch, axis=-1) - body.radius_m

    def vertex_chunks():
        heights = body.heights_m
        for s in range(0, n, _CHUNK):
            e = min(s + _CHUNK, n)
            values = {"height_m": heights[s:e]}
            if rocks is not None:
                values["boulder_id"] = np.full(e - s, -1, dtype=np.int32)
            yield body.vertices(s, e), values
        if rocks is not None:
            yield from rocks.vertex_chunks(rock_heights)

    def body_faces():
        for lo, hi in _band_chunks(grid):
            yield grid.band_triangles(lo, hi)

    def face_groups():
        if rocks is None:
            yield None, body_faces()
        else:
            yield "body", body_faces()
            yield "boulders", rocks.face_chunks()

    def facet_chunks():
        for tri in body_faces():
            vlo, vhi = int(tri.min()), int(tri.max()) + 1
            yield body.vertices(vlo, vhi)[tri - vlo]
        if rocks is not None:
            yield from rocks.facet_chunks()

    comments = (f"magnitude {grid.magnitude}",) + (
        (rocks.comment("the body"),) if rocks is not None else ())
    extra_v, extra_f = (0, 0) if rocks is None else (rocks.n_vertices, rocks.n_faces)
    return MeshSource(n + extra_v, grid.n_triangles + extra_f, vertex_chunks,
                      face_groups, facet_chunks, mesh_fields(rocks),
                      "craterform lat/long body, metres", comments,
                      f"craterform lat/long body, magnitude {grid.magnitude}, metres",
                      vertex_records=functools.partial(_vertex_records, body, rocks,
                                                       rock_heights),
                      face_records=functools.partial(_face_records, grid, rocks),
                      own_writers={".glb": functools.partial(_write_glb, body)})


def _write_glb(body, path, progress: bool) -> None:
    """A body's ``.glb``: the patched-strip renderer export (:func:`latlong.export_glb`)."""
    export_glb(body, path, progress=progress)


def _vertex_records(body, rocks, rock_heights, dtype):
    """The PLY writer's fast path (:attr:`MeshSource.vertex_records`): the body's records
    straight from a kernel, chunks made on worker threads, then the boulders'."""
    from ._export_kernels import _ply_vertex_kernel  # numba loads here
    from ._grid_kernels import lon_table

    grid = body.grid
    n = grid.n_vertices
    radii = np.ascontiguousarray(body.radii_m, dtype=np.float64)
    stretch = np.array(body.stretch, dtype=np.float64)
    # the longitude table (8 B a vertex) up to _TABLE_BYTES; past it the kernel
    # computes the same cosines and sines itself (3.2 GB saved at M = 8192)
    table = lon_table(grid.magnitude, grid.ring_offsets()) \
        if 8 * n <= _TABLE_BYTES else np.empty((0, 2))

    def make(s, buf):
        e = min(s + _CHUNK, n)
        _ply_vertex_kernel(grid.magnitude, grid.ring_offsets(), radii, body.radius_m,
                           stretch, table, s, e, buf.view(np.float32).reshape(len(buf), -1))
        rec = buf[:e - s]
        if rocks is not None:
            rec["boulder_id"] = -1
        return rec

    yield from ordered_chunks(make, range(0, n, _CHUNK),
                              lambda: np.empty(min(n, _CHUNK), dtype=dtype))
    if rocks is not None:
        for v, values in rocks.vertex_chunks(rock_heights):
            yield pack_vertices(v, values, dtype)


def _face_records(grid, rocks, dtype):
    """The PLY writer's fast path (:attr:`MeshSource.face_records`): the body's triangles
    packed by a kernel on worker threads, then the boulders'."""
    from ._export_kernels import _ply_face_kernel  # numba loads here
    ro, bo = grid.ring_offsets(), grid.band_offsets()
    chunks = list(_band_chunks(grid))
    size = max((int(bo[hi] - bo[lo]) for lo, hi in chunks), default=0)

    def make(chunk, buf):
        lo, hi = chunk
        rec = buf[:int(bo[hi] - bo[lo])]
        _ply_face_kernel(grid.magnitude, lo, hi, ro, bo, rec.view(np.uint8))
        return rec

    yield from ordered_chunks(make, chunks, lambda: np.empty(size, dtype=dtype))
    if rocks is not None:
        for tri in rocks.face_chunks():
            yield pack_faces(tri, dtype)


def export_body(body, path, *, progress: bool = False) -> Path:
    """Write ``body`` to a mesh file chosen by suffix (module notes), atomically."""
    return write_mesh(body_mesh_source(body), path, progress=progress)
