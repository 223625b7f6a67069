"""Connectivity and spatial look-ups of a closed triangle mesh.

* :func:`adjacency`: vertex -> neighbouring vertices and vertex -> faces, compressed
  (CSR); on a closed, consistently oriented 2-manifold each directed edge belongs to
  exactly one face, so the neighbours of a vertex are the heads of its directed edges.
* :class:`TriangleGrid`: a uniform grid of cells listing the faces whose bounding
  boxes touch them (a spatial hash; cells of about two mean edges, bounded in number),
  for closest points (:meth:`TriangleGrid.closest`) and line casts along a normal
  (:meth:`TriangleGrid.depths`), with no O(n^2) anywhere.
* :func:`mesh_checks`: closed 2-manifold, orientation, Euler characteristic.

Face and vertex normals are :mod:`latlong.geometry.normals`'.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from ._kernels import _closest_points_kernel, _depths_kernel, _grid_kernel

__all__ = ["TriangleGrid", "adjacency", "mesh_checks"]

#: Cells of a TriangleGrid at most this many per face.
MAX_CELLS_PER_FACE = 4


def adjacency(faces: np.ndarray, n_vertices: int):
    """(voff, vnbr, foff, fids): CSR vertex -> neighbours and vertex -> faces.

    Neighbours are the heads of the directed edges leaving each vertex (each once on a
    closed, consistently oriented mesh), in face order; faces in increasing order.
    """
    f = np.ascontiguousarray(faces, dtype=np.int64)
    tail = f.ravel()
    head = f[:, [1, 2, 0]].ravel()
    order = np.argsort(tail, kind="stable")
    voff = np.zeros(n_vertices + 1, dtype=np.int64)
    np.cumsum(np.bincount(tail, minlength=n_vertices), out=voff[1:])
    vnbr = np.ascontiguousarray(head[order])
    fids = np.ascontiguousarray(order // 3)
    return voff, vnbr, voff.copy(), fids


def mesh_checks(vertices: np.ndarray, faces: np.ndarray) -> dict:
    """Closedness and topology figures: ``edges`` (undirected), ``edges_not_in_two_faces``,
    ``directed_edges_repeated`` (orientation), ``euler_characteristic`` (V - E + F; 2 for
    a closed genus-0 surface), ``components_faces`` (faces of the largest part)."""
    f = np.asarray(faces, dtype=np.int64)
    nv = len(vertices)
    e = np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]])
    directed = e[:, 0] * nv + e[:, 1]
    und = np.sort(e, axis=1)
    key = und[:, 0] * nv + und[:, 1]
    _, counts = np.unique(key, return_counts=True)
    used = np.unique(f)
    return {"vertices": int(len(used)), "faces": int(len(f)), "edges": int(len(counts)),
            "edges_not_in_two_faces": int((counts != 2).sum()),
            "directed_edges_repeated": int(len(directed) - np.unique(directed).size),
            "euler_characteristic": int(len(used) - len(counts) + len(f))}


@dataclasses.dataclass(frozen=True)
class TriangleGrid:
    """Faces listed per cell of a uniform grid (module notes); positions as given."""

    vertices: np.ndarray
    """(V, 3) positions the grid was built for, metres."""
    faces: np.ndarray
    """(F, 3) vertex indices."""
    lo: np.ndarray
    """Corner of cell (0, 0, 0), metres."""
    cell_m: float
    """Cell size, metres."""
    dims: np.ndarray
    """Cells along x, y, z."""
    offsets: np.ndarray
    """CSR offsets, one per cell plus one."""
    items: np.ndarray
    """Face ids, cell after cell."""

    @classmethod
    def build(cls, vertices, faces, cell_m: float | None = None) -> TriangleGrid:
        v = np.ascontiguousarray(vertices, dtype=np.float64)
        f = np.ascontiguousarray(faces, dtype=np.int64)
        lo, hi = v.min(axis=0), v.max(axis=0)
        span = np.maximum(hi - lo, 1e-9)
        if cell_m is None:
            e = v[f[:, 1]] - v[f[:, 0]]
            cell_m = 2.0 * float(np.sqrt((e * e).sum(axis=1)).mean())
        budget = MAX_CELLS_PER_FACE * len(f) + 1
        cell_m = max(float(cell_m), float((np.prod(span) / budget) ** (1.0 / 3.0)))
        dims = np.maximum(np.ceil(span / cell_m).astype(np.int64), 1)
        offsets = np.zeros(int(np.prod(dims)) + 1, dtype=np.int64)
        _grid_kernel(v, f, lo, cell_m, dims, offsets, np.empty(0, np.int64), False)
        np.cumsum(offsets, out=offsets)
        items = np.empty(int(offsets[-1]), dtype=np.int64)
        _grid_kernel(v, f, lo, cell_m, dims, offsets, items, True)
        return cls(v, f, lo, cell_m, dims, offsets, items)

    def closest(self, points):
        """Closest surface point of each point: (face (n,), uv (n, 2), distance (n,)),
        the point being ``a + u (b - a) + v (c - a)`` of the face's corners a, b, c."""
        p = np.ascontiguousarray(np.asarray(points, dtype=np.float64).reshape(-1, 3))
        face = np.empty(len(p), dtype=np.int64)
        uv = np.empty((len(p), 2))
        dist = np.empty(len(p))
        _closest_points_kernel(p, self.vertices, self.faces, self.lo, self.cell_m, self.dims,
                               self.offsets, self.items, face, uv, dist)
        return face, uv, dist

    def depths(self, points, normals, margin_m: float) -> np.ndarray:
        """Depth below the surface of points (k, c, 3) along their row's unit normal
        (k, 3): the nearest crossing of the line through each point on a face turned
        along the normal, searched within the row's size plus ``margin_m`` of its
        points; positive =
        below the surface, NaN = no crossing."""
        pts = np.ascontiguousarray(points, dtype=np.float64)
        nrm = np.ascontiguousarray(normals, dtype=np.float64)
        out = np.empty(pts.shape[:2])
        _depths_kernel(pts, nrm, float(margin_m), self.vertices, self.faces, self.lo,
                       self.cell_m, self.dims, self.offsets, self.items, out)
        return out
