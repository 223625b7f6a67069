"""Numba kernels of :mod:`latlong.implicit.distance`: the exact signed distance to a
closed triangle mesh in a band of grid points around it.

Grids are point lattices ``origin + (i, j, k) * h`` stored as C arrays ``[k, j, i]``.
The triangles are listed in the bins of ``B^3`` grid points that their bounding box
(grown by the band) overlaps, in triangle order; one parallel loop runs over the bins,
each grid point belongs to one bin and keeps the first closest triangle in list order,
so the result does not depend on the number of threads.

Closest point on a triangle: Ericson, *Real-Time Collision Detection* (2005), 5.1.5
(Voronoi regions of the vertices, edges and face). Sign: the angle-weighted
pseudo-normal of the feature (face, edge or vertex) holding the closest point
(Baerentzen & Aanaes, IEEE TVCG 11(3), 2005): ``(p - q) . n < 0`` inside, exactly, for
a closed, consistently oriented 2-manifold.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from craters.kernels import read_only_inputs

# feature codes of _closest_on_triangle: 0 face, 1..3 vertex a, b, c; 4..6 edge ab, bc, ca
_FACE, _EDGE_AB = 0, 4


@njit(cache=True, inline="always")
def _closest_on_triangle(px, py, pz, a, b, c):
    """Closest point q of triangle abc to p and the feature holding it (Ericson 5.1.5):
    returns (qx, qy, qz, feature)."""
    abx, aby, abz = b[0] - a[0], b[1] - a[1], b[2] - a[2]
    acx, acy, acz = c[0] - a[0], c[1] - a[1], c[2] - a[2]
    apx, apy, apz = px - a[0], py - a[1], pz - a[2]
    d1 = abx * apx + aby * apy + abz * apz
    d2 = acx * apx + acy * apy + acz * apz
    if d1 <= 0.0 and d2 <= 0.0:
        return a[0], a[1], a[2], 1
    bpx, bpy, bpz = px - b[0], py - b[1], pz - b[2]
    d3 = abx * bpx + aby * bpy + abz * bpz
    d4 = acx * bpx + acy * bpy + acz * bpz
    if d3 >= 0.0 and d4 <= d3:
        return b[0], b[1], b[2], 2
    vc = d1 * d4 - d3 * d2
    if vc <= 0.0 and d1 >= 0.0 and d3 <= 0.0:
        v = d1 / (d1 - d3)
        return a[0] + v * abx, a[1] + v * aby, a[2] + v * abz, 4
    cpx, cpy, cpz = px - c[0], py - c[1], pz - c[2]
    d5 = abx * cpx + aby * cpy + abz * cpz
    d6 = acx * cpx + acy * cpy + acz * cpz
    if d6 >= 0.0 and d5 <= d6:
        return c[0], c[1], c[2], 3
    vb = d5 * d2 - d1 * d6
    if vb <= 0.0 and d2 >= 0.0 and d6 <= 0.0:
        w = d2 / (d2 - d6)
        return a[0] + w * acx, a[1] + w * acy, a[2] + w * acz, 6
    va = d3 * d6 - d5 * d4
    if va <= 0.0 and (d4 - d3) >= 0.0 and (d5 - d6) >= 0.0:
        w = (d4 - d3) / ((d4 - d3) + (d5 - d6))
        return (b[0] + w * (c[0] - b[0]), b[1] + w * (c[1] - b[1]), b[2] + w * (c[2] - b[2]),
                5)
    denom = 1.0 / (va + vb + vc)
    v = vb * denom
    w = vc * denom
    return (a[0] + abx * v + acx * w, a[1] + aby * v + acy * w, a[2] + abz * v + acz * w,
            0)


@njit(cache=True, inline="always")
def _pseudo_normal(f, feature, faces, face_n, edge_n, vert_n, out):
    """The pseudo-normal of a feature of face f into out (3,)."""
    if feature == _FACE:
        src = face_n[f]
    elif feature < _EDGE_AB:
        src = vert_n[faces[f, feature - 1]]
    else:
        src = edge_n[f, feature - _EDGE_AB]
    out[0] = src[0]
    out[1] = src[1]
    out[2] = src[2]


@njit(cache=True, parallel=True)
def _band_distance_kernel(origin, h, active, bsize, nbins, offsets, items, lo, hi, verts,
                          faces, face_n, edge_n, vert_n, band, dist, face_id):
    """Signed distance (> 0 inside) to the mesh at every grid point closer than ``band``
    to it, and the index of the closest face (the first in list order on ties); other
    points are left as they are. ``lo``, ``hi``: inclusive (i, j, k) index box of each
    face grown by the band."""
    nz, ny, nx = dist.shape
    band2 = band * band
    for t in prange(active.shape[0]):
        b = active[t]
        bx = b % nbins[0]
        rest = b // nbins[0]
        by = rest % nbins[1]
        bz = rest // nbins[1]
        i0, j0, k0 = bx * bsize, by * bsize, bz * bsize
        i1, j1, k1 = min(i0 + bsize, nx), min(j0 + bsize, ny), min(k0 + bsize, nz)
        best = np.full((k1 - k0, j1 - j0, i1 - i0), band2)
        arg = np.full((k1 - k0, j1 - j0, i1 - i0), -1, np.int64)
        feat = np.zeros((k1 - k0, j1 - j0, i1 - i0), np.int64)
        for p in range(offsets[b], offsets[b + 1]):
            f = items[p]
            a = verts[faces[f, 0]]
            bb = verts[faces[f, 1]]
            c = verts[faces[f, 2]]
            for k in range(max(k0, lo[f, 2]), min(k1, hi[f, 2] + 1)):
                pz = origin[2] + k * h
                for j in range(max(j0, lo[f, 1]), min(j1, hi[f, 1] + 1)):
                    py = origin[1] + j * h
                    for i in range(max(i0, lo[f, 0]), min(i1, hi[f, 0] + 1)):
                        px = origin[0] + i * h
                        qx, qy, qz, ft = _closest_on_triangle(px, py, pz, a, bb, c)
                        d2 = (px - qx) ** 2 + (py - qy) ** 2 + (pz - qz) ** 2
                        if d2 < best[k - k0, j - j0, i - i0]:
                            best[k - k0, j - j0, i - i0] = d2
                            arg[k - k0, j - j0, i - i0] = f
                            feat[k - k0, j - j0, i - i0] = ft
        n = np.empty(3)
        for k in range(k0, k1):
            pz = origin[2] + k * h
            for j in range(j0, j1):
                py = origin[1] + j * h
                for i in range(i0, i1):
                    f = arg[k - k0, j - j0, i - i0]
                    if f < 0:
                        continue
                    px = origin[0] + i * h
                    a = verts[faces[f, 0]]
                    qx, qy, qz, ft = _closest_on_triangle(px, py, pz, a, verts[faces[f, 1]],
                                                          verts[faces[f, 2]])
                    _pseudo_normal(f, feat[k - k0, j - j0, i - i0], faces, face_n, edge_n,
                                   vert_n, n)
                    d = np.sqrt(best[k - k0, j - j0, i - i0])
                    s = (px - qx) * n[0] + (py - qy) * n[1] + (pz - qz) * n[2]
                    dist[k, j, i] = -d if s > 0.0 else d
                    face_id[k, j, i] = f


@read_only_inputs("foot", "normal")
@njit(cache=True, parallel=True)
def _feet_kernel(points, fids, verts, faces, face_n, foot, normal):
    """Closest point on face fids[s] of every point, and the unit normal of the tangent
    plane there: along p - foot, or the face normal when p lies on the face."""
    for s in prange(points.shape[0]):
        f = fids[s]
        px, py, pz = points[s, 0], points[s, 1], points[s, 2]
        qx, qy, qz, _ = _closest_on_triangle(px, py, pz, verts[faces[f, 0]],
                                             verts[faces[f, 1]], verts[faces[f, 2]])
        foot[s, 0], foot[s, 1], foot[s, 2] = qx, qy, qz
        dx, dy, dz = px - qx, py - qy, pz - qz
        d = np.sqrt(dx * dx + dy * dy + dz * dz)
        if d > 1e-9 * (abs(qx) + abs(qy) + abs(qz) + 1.0):
            normal[s, 0], normal[s, 1], normal[s, 2] = dx / d, dy / d, dz / d
        else:
            normal[s, 0], normal[s, 1], normal[s, 2] = face_n[f, 0], face_n[f, 1], face_n[f, 2]


@njit(cache=True, parallel=True)
def _nearest_sign_kernel(nearest, values, out):
    """``out`` = 1 where ``values`` at the grid point's nearest seed (``nearest``: its
    (k, j, i), scipy's distance-transform indices) is > 0, else -1: the gather
    ``values[nearest[0], nearest[1], nearest[2]]`` without its index arrays."""
    nz, ny, nx = out.shape
    for k in prange(nz):
        for j in range(ny):
            for i in range(nx):
                v = values[nearest[0, k, j, i], nearest[1, k, j, i], nearest[2, k, j, i]]
                out[k, j, i] = 1 if v > 0.0 else -1
