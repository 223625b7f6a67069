"""Numba kernel for gravity: the local linear fit that carries a field evaluated at some
vertices of a mesh to all of them."""

from __future__ import annotations

import numpy as np
from numba import njit, prange


@njit(cache=True, parallel=True)
def _local_linear_kernel(points, normals, src, vals, nb, out):
    """``out[i]``: the value at ``points[i]`` of the weighted least-squares plane
    ``a + b u + c v`` through ``vals`` (S, k) at the neighbours ``src[nb[i]]``, in the
    tangent frame of ``normals[i]`` (u, v: offsets along two tangents), weights
    ``1 / (d^2 + h^2)`` (d: distance, h: the farthest neighbour's). Exact for fields
    linear along the surface; the weighted mean where the neighbours are collinear."""
    n = points.shape[0]
    k = vals.shape[1]
    for i in prange(n):
        nx, ny, nz = normals[i, 0], normals[i, 1], normals[i, 2]
        # a tangent: the axis least aligned with the normal, made orthogonal
        if abs(nx) <= abs(ny) and abs(nx) <= abs(nz):
            ax, ay, az = 1.0, 0.0, 0.0
        elif abs(ny) <= abs(nz):
            ax, ay, az = 0.0, 1.0, 0.0
        else:
            ax, ay, az = 0.0, 0.0, 1.0
        d = ax * nx + ay * ny + az * nz
        tx, ty, tz = ax - d * nx, ay - d * ny, az - d * nz
        tn = np.sqrt(tx * tx + ty * ty + tz * tz)
        tx, ty, tz = tx / tn, ty / tn, tz / tn
        sx, sy, sz = ny * tz - nz * ty, nz * tx - nx * tz, nx * ty - ny * tx
        m = nb.shape[1]
        h2 = 0.0
        for q in range(m):
            j = nb[i, q]
            ex = src[j, 0] - points[i, 0]
            ey = src[j, 1] - points[i, 1]
            ez = src[j, 2] - points[i, 2]
            h2 = max(h2, ex * ex + ey * ey + ez * ez)
        a = np.zeros((3, 3))
        rhs = np.zeros((3, k))
        for q in range(m):
            j = nb[i, q]
            ex = src[j, 0] - points[i, 0]
            ey = src[j, 1] - points[i, 1]
            ez = src[j, 2] - points[i, 2]
            w = 1.0 / (ex * ex + ey * ey + ez * ez + h2 + 1e-300)
            basis = (1.0, ex * tx + ey * ty + ez * tz, ex * sx + ey * sy + ez * sz)
            for r in range(3):
                for c in range(3):
                    a[r, c] += w * basis[r] * basis[c]
                for c in range(k):
                    rhs[r, c] += w * basis[r] * vals[j, c]
        det = np.linalg.det(a)
        if abs(det) > 1e-12 * a[0, 0] * a[1, 1] * a[2, 2] and a[1, 1] > 0 and a[2, 2] > 0:
            sol = np.linalg.solve(a, rhs)
            for c in range(k):
                out[i, c] = sol[0, c]
        else:
            for c in range(k):
                out[i, c] = rhs[0, c] / a[0, 0]
