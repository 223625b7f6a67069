"""Numba kernels of cube-sphere cell sets for terrain on demand
(:mod:`latlong.ondemand.cellsets`): each output row from its own input row, so the
results do not depend on the thread count. The face arithmetic is
:mod:`craters.kernels`'s (one home with :mod:`craters.cells`)."""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from craters.kernels import cell_id, face_point, face_uv


@njit(cache=True, parallel=True)
def _cells_kernel(points, level, out):
    """Cell id of each direction at ``level``."""
    for k in prange(points.shape[0]):
        f, u, v = face_uv(points[k, 0], points[k, 1], points[k, 2])
        out[k] = cell_id(level, f, u, v)


@njit(cache=True, parallel=True)
def _neighbourhood_kernel(ids, out):
    """The 9 cells around each cell (itself and the 8 next to it, across face edges; at a
    cube corner one of them repeats): ``out`` (n, 9) uint64."""
    mask = np.uint64((1 << 27) - 1)
    for k in prange(ids.shape[0]):
        c = ids[k]
        level = int(c >> np.uint64(57))
        face = int((c >> np.uint64(54)) & np.uint64(7))
        i = int((c >> np.uint64(27)) & mask)
        j = int(c & mask)
        scale = 2.0 / (1 << level)
        t = 0
        for di in (-1, 0, 1):
            for dj in (-1, 0, 1):
                u = -1.0 + (i + 0.5 + di) * scale
                v = -1.0 + (j + 0.5 + dj) * scale
                w0, w1, w2 = face_point(face, u, v)
                f2, u2, v2 = face_uv(w0, w1, w2)
                out[k, t] = cell_id(level, f2, u2, v2)
                t += 1


@njit(cache=True, parallel=True)
def _window_kernel(c, e, n, coords, out):
    """Unit directions of the pixel centres of a gnomonic window: ``c + x e + y n``
    normalised, x = coords[col], y = -coords[row] (numpy's order of operations, for the
    same bits: :func:`latlong.ondemand.tile.tile_units`)."""
    size = coords.shape[0]
    for r in prange(size):
        y = -coords[r]
        for q in range(size):
            x = coords[q]
            v0 = c[0] + x * e[0] + y * n[0]
            v1 = c[1] + x * e[1] + y * n[1]
            v2 = c[2] + x * e[2] + y * n[2]
            norm = np.sqrt(v0 * v0 + v1 * v1 + v2 * v2)
            out[r, q, 0] = v0 / norm
            out[r, q, 1] = v1 / norm
            out[r, q, 2] = v2 / norm
