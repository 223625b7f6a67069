"""Numba kernels of the mesh surface: n-section refinement, geodesic gathering, a uniform
grid of triangles, closest points and line casts.

No validation here: :mod:`latlong.mesh.topology` and :mod:`latlong.mesh.refine` check
and allocate. Every loop that writes shared arrays is serial or writes disjoint rows, so
results never depend on the thread count.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from craters.kernels import read_only_inputs

from ..geometry._normal_kernels import _triangle_edges


# --------------------------------------------------------------------------- refinement
@njit(cache=True)
def _nsection_kernel(pos, faces, face_edges, edge_v, n, out_pos, out_faces):
    """Split every triangle into n^2 by cutting each edge into n equal parts.

    ``face_edges[f]`` are the edge ids of (v0 v1, v1 v2, v2 v0), ``edge_v[e]`` the edge's
    vertices, lower id first. Output vertices: the input ones, then n - 1 per edge (from
    its lower vertex), then (n - 1)(n - 2) / 2 inside each face. Orientation is kept.
    """
    nv = pos.shape[0]
    ne = edge_v.shape[0]
    for i in range(nv):
        for k in range(3):
            out_pos[i, k] = pos[i, k]
    for e in prange(ne):
        a = edge_v[e, 0]
        b = edge_v[e, 1]
        for s in range(1, n):
            t = s / n
            row = nv + e * (n - 1) + s - 1
            for k in range(3):
                out_pos[row, k] = pos[a, k] + t * (pos[b, k] - pos[a, k])
    m = (n - 1) * (n - 2) // 2
    base = nv + ne * (n - 1)
    local = np.empty((n + 1, n + 1), np.int64)
    for f in range(faces.shape[0]):
        a = faces[f, 0]
        b = faces[f, 1]
        c = faces[f, 2]
        local[0, 0] = a
        local[n, 0] = b
        local[0, n] = c
        e0 = face_edges[f, 0]
        e1 = face_edges[f, 1]
        e2 = face_edges[f, 2]
        for s in range(1, n):
            k = s if edge_v[e0, 0] == a else n - s  # a -> b
            local[s, 0] = nv + e0 * (n - 1) + k - 1
            k = s if edge_v[e1, 0] == b else n - s  # b -> c
            local[n - s, s] = nv + e1 * (n - 1) + k - 1
            k = s if edge_v[e2, 0] == a else n - s  # a -> c
            local[0, s] = nv + e2 * (n - 1) + k - 1
        q = 0
        for i in range(1, n - 1):
            for j in range(1, n - i):
                row = base + f * m + q
                local[i, j] = row
                for k in range(3):
                    out_pos[row, k] = (pos[a, k] + (i / n) * (pos[b, k] - pos[a, k])
                                       + (j / n) * (pos[c, k] - pos[a, k]))
                q += 1
        t = f * n * n
        for i in range(n):
            for j in range(n - i):
                out_faces[t, 0] = local[i, j]
                out_faces[t, 1] = local[i + 1, j]
                out_faces[t, 2] = local[i, j + 1]
                t += 1
                if i + j <= n - 2:
                    out_faces[t, 0] = local[i + 1, j]
                    out_faces[t, 1] = local[i + 1, j + 1]
                    out_faces[t, 2] = local[i, j + 1]
                    t += 1


# --------------------------------------------------------------------------- geodesic gather
@njit(cache=True)
def _dist3(pos, i, j):
    d0 = pos[i, 0] - pos[j, 0]
    d1 = pos[i, 1] - pos[j, 1]
    d2 = pos[i, 2] - pos[j, 2]
    return np.sqrt(d0 * d0 + d1 * d1 + d2 * d2)


@njit(cache=True, inline="always")
def _heap_push(hk, hv, size, key, value):
    """Push (key, value) on the binary min-heap of keys ``hk`` and values ``hv`` holding
    ``size`` entries (doubled when full; sift up); returns (hk, hv, size)."""
    if size == hk.shape[0]:
        hk = np.concatenate((hk, np.empty(size)))
        hv = np.concatenate((hv, np.empty(size, np.int64)))
    k = size
    size += 1
    while k > 0:
        p = (k - 1) // 2
        if hk[p] <= key:
            break
        hk[k] = hk[p]
        hv[k] = hv[p]
        k = p
    hk[k] = key
    hv[k] = value
    return hk, hv, size


@njit(cache=True)
def _geodesic_gather(pos, voff, vnbr, seed_v, seed_d, limit, mark, gdist, epoch):
    """Vertices within graph distance ``limit`` of the seeds (Dijkstra over the edges at
    their current lengths, seeds starting at ``seed_d``). Returns (vertices, distances)
    in the order they were settled. ``mark`` / ``gdist`` are whole-mesh work arrays:
    ``mark == 2 epoch`` seen, ``2 epoch + 1`` settled (``epoch`` grows per call, so they
    are never cleared)."""
    seen = 2 * epoch
    done = 2 * epoch + 1
    cap = 256
    hk = np.empty(cap)
    hv = np.empty(cap, np.int64)
    size = 0
    out = np.empty(cap, np.int64)
    od = np.empty(cap)
    n_out = 0
    for s in range(seed_v.shape[0]):
        v = seed_v[s]
        d = seed_d[s]
        if mark[v] == seen and gdist[v] <= d:
            continue
        mark[v] = seen
        gdist[v] = d
        hk, hv, size = _heap_push(hk, hv, size, d, v)
    while size > 0:
        d = hk[0]
        v = hv[0]
        size -= 1  # pop: move the last to the root and sift down
        lk = hk[size]
        lv = hv[size]
        k = 0
        while True:
            c = 2 * k + 1
            if c >= size:
                break
            if c + 1 < size and hk[c + 1] < hk[c]:
                c += 1
            if hk[c] >= lk:
                break
            hk[k] = hk[c]
            hv[k] = hv[c]
            k = c
        if size > 0:
            hk[k] = lk
            hv[k] = lv
        if mark[v] == done or d > gdist[v]:
            continue  # stale entry
        mark[v] = done
        if n_out == out.shape[0]:
            out = np.concatenate((out, np.empty(n_out, np.int64)))
            od = np.concatenate((od, np.empty(n_out)))
        out[n_out] = v
        od[n_out] = d
        n_out += 1
        for q in range(voff[v], voff[v + 1]):
            w = vnbr[q]
            if mark[w] == done:
                continue
            nd = d + _dist3(pos, v, w)
            if nd > limit or (mark[w] == seen and nd >= gdist[w]):
                continue
            mark[w] = seen
            gdist[w] = nd
            hk, hv, size = _heap_push(hk, hv, size, nd, w)
    return out[:n_out], od[:n_out]


# --------------------------------------------------------------------------- triangle grid
@njit(cache=True)
def _cell_range(lo, h, dims, x0, x1, y0, y1, z0, z1):
    """Cell index ranges (inclusive) covering a box, clipped to the grid."""
    i0 = min(max(int(np.floor((x0 - lo[0]) / h)), 0), dims[0] - 1)
    i1 = min(max(int(np.floor((x1 - lo[0]) / h)), 0), dims[0] - 1)
    j0 = min(max(int(np.floor((y0 - lo[1]) / h)), 0), dims[1] - 1)
    j1 = min(max(int(np.floor((y1 - lo[1]) / h)), 0), dims[1] - 1)
    k0 = min(max(int(np.floor((z0 - lo[2]) / h)), 0), dims[2] - 1)
    k1 = min(max(int(np.floor((z1 - lo[2]) / h)), 0), dims[2] - 1)
    return i0, i1, j0, j1, k0, k1


@njit(cache=True)
def _face_box(pos, faces, f):
    a = faces[f, 0]
    b = faces[f, 1]
    c = faces[f, 2]
    return (min(pos[a, 0], min(pos[b, 0], pos[c, 0])), max(pos[a, 0], max(pos[b, 0], pos[c, 0])),
            min(pos[a, 1], min(pos[b, 1], pos[c, 1])), max(pos[a, 1], max(pos[b, 1], pos[c, 1])),
            min(pos[a, 2], min(pos[b, 2], pos[c, 2])), max(pos[a, 2], max(pos[b, 2], pos[c, 2])))


@read_only_inputs("offsets", "items")
@njit(cache=True)
def _grid_kernel(pos, faces, lo, h, dims, offsets, items, fill):
    """Count (``fill`` False: cells' counts into ``offsets[1:]``) or list (``fill`` True:
    face ids into ``items`` at ``offsets``) the faces whose boxes touch each cell."""
    ny = dims[1]
    nz = dims[2]
    cursor = offsets[:-1].copy() if fill else offsets[:1].copy()
    for f in range(faces.shape[0]):
        x0, x1, y0, y1, z0, z1 = _face_box(pos, faces, f)
        i0, i1, j0, j1, k0, k1 = _cell_range(lo, h, dims, x0, x1, y0, y1, z0, z1)
        for i in range(i0, i1 + 1):
            for j in range(j0, j1 + 1):
                for k in range(k0, k1 + 1):
                    cell = (i * ny + j) * nz + k
                    if fill:
                        items[cursor[cell]] = f
                        cursor[cell] += 1
                    else:
                        offsets[cell + 1] += 1


@njit(cache=True)
def _closest_on_triangle(px, py, pz, pos, faces, f):
    """Closest point of face f to p (Ericson 2005, 5.1.5): (squared distance, u, v) with
    the point a + u (b - a) + v (c - a)."""
    a = faces[f, 0]
    b = faces[f, 1]
    c = faces[f, 2]
    ab0, ab1, ab2, ac0, ac1, ac2 = _triangle_edges(pos, a, b, c)
    ap0 = px - pos[a, 0]
    ap1 = py - pos[a, 1]
    ap2 = pz - pos[a, 2]
    d1 = ab0 * ap0 + ab1 * ap1 + ab2 * ap2
    d2 = ac0 * ap0 + ac1 * ap1 + ac2 * ap2
    if d1 <= 0.0 and d2 <= 0.0:
        u, v = 0.0, 0.0
    else:
        bp0 = px - pos[b, 0]
        bp1 = py - pos[b, 1]
        bp2 = pz - pos[b, 2]
        d3 = ab0 * bp0 + ab1 * bp1 + ab2 * bp2
        d4 = ac0 * bp0 + ac1 * bp1 + ac2 * bp2
        cp0 = px - pos[c, 0]
        cp1 = py - pos[c, 1]
        cp2 = pz - pos[c, 2]
        d5 = ab0 * cp0 + ab1 * cp1 + ab2 * cp2
        d6 = ac0 * cp0 + ac1 * cp1 + ac2 * cp2
        vc = d1 * d4 - d3 * d2
        vb = d5 * d2 - d1 * d6
        va = d3 * d6 - d5 * d4
        if d3 >= 0.0 and d4 <= d3:
            u, v = 1.0, 0.0
        elif d6 >= 0.0 and d5 <= d6:
            u, v = 0.0, 1.0
        elif vc <= 0.0 and d1 >= 0.0 and d3 <= 0.0:
            u, v = d1 / (d1 - d3), 0.0
        elif vb <= 0.0 and d2 >= 0.0 and d6 <= 0.0:
            u, v = 0.0, d2 / (d2 - d6)
        elif va <= 0.0 and (d4 - d3) >= 0.0 and (d5 - d6) >= 0.0:
            w = (d4 - d3) / ((d4 - d3) + (d5 - d6))
            u, v = 1.0 - w, w
        else:
            den = 1.0 / (va + vb + vc)
            u, v = vb * den, vc * den
    q0 = ap0 - u * ab0 - v * ac0
    q1 = ap1 - u * ab1 - v * ac1
    q2 = ap2 - u * ab2 - v * ac2
    return q0 * q0 + q1 * q1 + q2 * q2, u, v


@read_only_inputs("out_face", "out_uv", "out_dist")
@njit(cache=True, parallel=True)
def _closest_points_kernel(points, pos, faces, lo, h, dims, offsets, items, out_face,
                           out_uv, out_dist):
    """Closest surface point of every point: its face, (u, v) and distance. Boxes of
    growing size around the point are searched until the best distance fits inside."""
    ny = dims[1]
    nz = dims[2]
    for p in prange(points.shape[0]):
        px = points[p, 0]
        py = points[p, 1]
        pz = points[p, 2]
        r = h
        best = np.inf
        bf = -1
        bu = 0.0
        bv = 0.0
        while True:
            i0, i1, j0, j1, k0, k1 = _cell_range(lo, h, dims, px - r, px + r, py - r, py + r,
                                                 pz - r, pz + r)
            for i in range(i0, i1 + 1):
                for j in range(j0, j1 + 1):
                    for k in range(k0, k1 + 1):
                        cell = (i * ny + j) * nz + k
                        for q in range(offsets[cell], offsets[cell + 1]):
                            f = items[q]
                            d2, u, v = _closest_on_triangle(px, py, pz, pos, faces, f)
                            if d2 < best or (d2 == best and f < bf):
                                best = d2
                                bf = f
                                bu = u
                                bv = v
            if bf >= 0 and np.sqrt(best) <= r:
                break
            covers = (i0 == 0 and j0 == 0 and k0 == 0 and i1 == dims[0] - 1
                      and j1 == dims[1] - 1 and k1 == dims[2] - 1)
            if covers:
                break
            r = 2.0 * r if bf < 0 else max(np.sqrt(best), 1.001 * r)
        out_face[p] = bf
        out_uv[p, 0] = bu
        out_uv[p, 1] = bv
        out_dist[p] = np.sqrt(best)


@njit(cache=True)
def _line_hit(px, py, pz, n0, n1, n2, pos, faces, f):
    """t with p + t n on face f (the line through p along n, both ways), or NaN."""
    a = faces[f, 0]
    e10, e11, e12, e20, e21, e22 = _triangle_edges(pos, a, faces[f, 1], faces[f, 2])
    h0 = n1 * e22 - n2 * e21
    h1 = n2 * e20 - n0 * e22
    h2 = n0 * e21 - n1 * e20
    det = e10 * h0 + e11 * h1 + e12 * h2
    if abs(det) < 1e-300:
        return np.nan
    inv = 1.0 / det
    s0 = px - pos[a, 0]
    s1 = py - pos[a, 1]
    s2 = pz - pos[a, 2]
    u = (s0 * h0 + s1 * h1 + s2 * h2) * inv
    if u < -1e-12 or u > 1.0 + 1e-12:
        return np.nan
    q0 = s1 * e12 - s2 * e11
    q1 = s2 * e10 - s0 * e12
    q2 = s0 * e11 - s1 * e10
    v = (n0 * q0 + n1 * q1 + n2 * q2) * inv
    if v < -1e-12 or u + v > 1.0 + 1e-12:
        return np.nan
    return (e20 * q0 + e21 * q1 + e22 * q2) * inv


@read_only_inputs("out")
@njit(cache=True, parallel=True)
def _depths_kernel(points, normals, margin, pos, faces, lo, h, dims, offsets, items, out):
    """Depth of each point below the surface along its row's normal (the nearest
    crossing of the line through it, on faces that face along the normal; positive =
    below): ``points`` (k, c, 3), ``normals`` (k, 3); faces searched within the row's
    bounding box grown by its size plus ``margin``; NaN where the line misses."""
    ny = dims[1]
    nz = dims[2]
    for r in prange(points.shape[0]):
        n0 = normals[r, 0]
        n1 = normals[r, 1]
        n2 = normals[r, 2]
        x0, y0, z0 = np.inf, np.inf, np.inf
        x1, y1, z1 = -np.inf, -np.inf, -np.inf
        for q in range(points.shape[1]):
            x0 = min(x0, points[r, q, 0])
            x1 = max(x1, points[r, q, 0])
            y0 = min(y0, points[r, q, 1])
            y1 = max(y1, points[r, q, 1])
            z0 = min(z0, points[r, q, 2])
            z1 = max(z1, points[r, q, 2])
        m = margin + max(x1 - x0, max(y1 - y0, z1 - z0))  # the row's size plus margin
        i0, i1, j0, j1, k0, k1 = _cell_range(lo, h, dims, x0 - m, x1 + m, y0 - m, y1 + m,
                                             z0 - m, z1 + m)
        cand = np.empty(64, np.int64)
        nc = 0
        for i in range(i0, i1 + 1):
            for j in range(j0, j1 + 1):
                for k in range(k0, k1 + 1):
                    cell = (i * ny + j) * nz + k
                    for q in range(offsets[cell], offsets[cell + 1]):
                        f = items[q]
                        a = faces[f, 0]
                        b = faces[f, 1]
                        c = faces[f, 2]
                        fn0 = ((pos[b, 1] - pos[a, 1]) * (pos[c, 2] - pos[a, 2])
                               - (pos[b, 2] - pos[a, 2]) * (pos[c, 1] - pos[a, 1]))
                        fn1 = ((pos[b, 2] - pos[a, 2]) * (pos[c, 0] - pos[a, 0])
                               - (pos[b, 0] - pos[a, 0]) * (pos[c, 2] - pos[a, 2]))
                        fn2 = ((pos[b, 0] - pos[a, 0]) * (pos[c, 1] - pos[a, 1])
                               - (pos[b, 1] - pos[a, 1]) * (pos[c, 0] - pos[a, 0]))
                        if fn0 * n0 + fn1 * n1 + fn2 * n2 <= 0.0:
                            continue  # faces turned away: the other side of the body
                        if nc == cand.shape[0]:
                            cand = np.concatenate((cand, np.empty(nc, np.int64)))
                        cand[nc] = f
                        nc += 1
        cand = np.unique(cand[:nc])  # a face listed in several cells counts once
        for q in range(points.shape[1]):
            px = points[r, q, 0]
            py = points[r, q, 1]
            pz = points[r, q, 2]
            best = np.nan
            for s in range(cand.shape[0]):
                t = _line_hit(px, py, pz, n0, n1, n2, pos, faces, cand[s])
                if not np.isnan(t) and (np.isnan(best) or abs(t) < abs(best)):
                    best = t
            out[r, q] = best
