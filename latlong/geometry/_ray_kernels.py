"""Numba kernel of ray/triangle intersection: one Möller-Trumbore for the sensors'
refinement of Embree's hits and the shape-model import's rays from the centre."""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True, inline="always")
def _moller_trumbore(ox, oy, oz, dx, dy, dz, ax, ay, az, bx, by, bz, cx, cy, cz):
    """Möller & Trumbore (1997) ray/triangle intersection in float64 (no culling, no
    bounds on u, v): (t, u, v, det). The hit is (1 - u - v) a + u b + v c at o + t d."""
    e1x, e1y, e1z = bx - ax, by - ay, bz - az
    e2x, e2y, e2z = cx - ax, cy - ay, cz - az
    px = dy * e2z - dz * e2y
    py = dz * e2x - dx * e2z
    pz = dx * e2y - dy * e2x
    det = e1x * px + e1y * py + e1z * pz
    if det == 0.0:
        return np.inf, 0.0, 0.0, 0.0
    inv = 1.0 / det
    sx, sy, sz = ox - ax, oy - ay, oz - az
    u = (sx * px + sy * py + sz * pz) * inv
    qx = sy * e1z - sz * e1y
    qy = sz * e1x - sx * e1z
    qz = sx * e1y - sy * e1x
    v = (dx * qx + dy * qy + dz * qz) * inv
    t = (e2x * qx + e2y * qy + e2z * qz) * inv
    return t, u, v, det
