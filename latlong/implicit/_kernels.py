"""Numba kernels of the implicit backend (:mod:`latlong.implicit`).

Grids are point lattices ``origin + (i, j, k) * h`` stored as C arrays ``[k, j, i]``
(x fastest, VTK's order). Work that adds many local items (metaballs, crater impulses,
Gabor impulses) into a grid is organised by *bins* of ``B^3`` grid points: each item
is listed in every bin its support box overlaps (``_bin_count`` / ``_bin_fill``, item
order kept), and one parallel loop runs over the bins. Every grid point belongs to one
bin and sums its items in list order, so the result does not depend on the number of
threads, and no parallel region is opened per item. The crater kernels evaluate the
LCSN formulas of :mod:`craters.lcsn` through their one compiled definition,
``craters.kernels.lcsn_height``.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from craters.kernels import lcsn_height, read_only_inputs


# --------------------------------------------------------------------------- voxelising
@njit(cache=True)
def _column_hits(verts, faces, oy, oz, h, ny, nz, counts, offsets, xs, fill):
    """Ray parity along +x: x of every triangle crossing of every (j, k) grid column."""
    for f in range(faces.shape[0]):
        a = verts[faces[f, 0]]
        b = verts[faces[f, 1]]
        c = verts[faces[f, 2]]
        area = (b[1] - a[1]) * (c[2] - a[2]) - (b[2] - a[2]) * (c[1] - a[1])
        if area == 0.0:
            continue
        y0 = min(a[1], b[1], c[1])
        y1 = max(a[1], b[1], c[1])
        z0 = min(a[2], b[2], c[2])
        z1 = max(a[2], b[2], c[2])
        j0 = max(0, int(np.ceil((y0 - oy) / h)))
        j1 = min(ny - 1, int(np.floor((y1 - oy) / h)))
        k0 = max(0, int(np.ceil((z0 - oz) / h)))
        k1 = min(nz - 1, int(np.floor((z1 - oz) / h)))
        for k in range(k0, k1 + 1):
            pz = oz + k * h
            for j in range(j0, j1 + 1):
                py = oy + j * h
                w0 = (c[1] - b[1]) * (pz - b[2]) - (c[2] - b[2]) * (py - b[1])
                w1 = (a[1] - c[1]) * (pz - c[2]) - (a[2] - c[2]) * (py - c[1])
                w2 = (b[1] - a[1]) * (pz - a[2]) - (b[2] - a[2]) * (py - a[1])
                if area > 0.0:
                    if w0 < 0.0 or w1 < 0.0 or w2 < 0.0:
                        continue
                elif w0 > 0.0 or w1 > 0.0 or w2 > 0.0:
                    continue
                col = k * ny + j
                if fill:
                    xs[offsets[col] + counts[col]] = (w0 * a[0] + w1 * b[0] + w2 * c[0]) / area
                counts[col] += 1


@njit(cache=True)
def _voxelize_kernel(verts, faces, origin, h, inside):
    """Grid points inside a closed mesh (ray parity along x), written into ``inside``.

    Returns the number of columns with an odd number of crossings (a ray grazing an
    edge or vertex); their last crossing is ignored.
    """
    nz, ny, nx = inside.shape
    ncol = ny * nz
    counts = np.zeros(ncol, np.int64)
    dummy = np.zeros(1)
    _column_hits(verts, faces, origin[1], origin[2], h, ny, nz, counts, counts, dummy,
                 np.bool_(False))
    offsets = np.zeros(ncol + 1, np.int64)
    for c in range(ncol):
        offsets[c + 1] = offsets[c] + counts[c]
    xs = np.empty(offsets[ncol])
    counts[:] = 0
    _column_hits(verts, faces, origin[1], origin[2], h, ny, nz, counts, offsets, xs,
                 np.bool_(True))
    odd = 0
    for c in range(ncol):
        n = counts[c]
        if n % 2:
            odd += 1
            n -= 1
        if n == 0:
            continue
        seg = np.sort(xs[offsets[c]:offsets[c] + counts[c]])
        k = c // ny
        j = c - k * ny
        for p in range(0, n, 2):
            i0 = max(0, int(np.ceil((seg[p] - origin[0]) / h)))
            i1 = min(nx - 1, int(np.floor((seg[p + 1] - origin[0]) / h)))
            for i in range(i0, i1 + 1):
                inside[k, j, i] = 1
    return odd


# --------------------------------------------------------------------------- packing
@njit(cache=True)
def _slab_max(free, k):
    best = -np.inf
    arg = 0
    plane = free[k]
    ny, nx = plane.shape
    for j in range(ny):
        for i in range(nx):
            if plane[j, i] > best:
                best = plane[j, i]
                arg = j * nx + i
    return best, arg


@njit(cache=True)
def _pack_kernel(free, origin, h, r_min, centers, radii):
    """Greedy non-overlapping packing: the largest free ball first, down to ``r_min``.

    ``free`` holds, for every grid point, the radius of the largest ball centred there
    that stays inside the shape and outside the balls placed so far (-inf outside the
    shape); it is updated in place. Ties go to the lowest (k, j, i). Returns the count.
    """
    nz, ny, nx = free.shape
    best = np.empty(nz)
    arg = np.empty(nz, np.int64)
    for k in range(nz):
        best[k], arg[k] = _slab_max(free, k)
    n = 0
    while n < radii.shape[0]:
        k = int(np.argmax(best))
        r = best[k]
        if r < r_min:
            break
        j = arg[k] // nx
        i = arg[k] - j * nx
        cx = origin[0] + i * h
        cy = origin[1] + j * h
        cz = origin[2] + k * h
        centers[n, 0] = cx
        centers[n, 1] = cy
        centers[n, 2] = cz
        radii[n] = r
        n += 1
        reach = int(np.ceil(2.0 * r / h)) + 1  # free <= r everywhere: no effect beyond 2r
        for kk in range(max(0, k - reach), min(nz, k + reach + 1)):
            dz = origin[2] + kk * h - cz
            for jj in range(max(0, j - reach), min(ny, j + reach + 1)):
                dy = origin[1] + jj * h - cy
                for ii in range(max(0, i - reach), min(nx, i + reach + 1)):
                    dx = origin[0] + ii * h - cx
                    d = np.sqrt(dx * dx + dy * dy + dz * dz) - r
                    if d < free[kk, jj, ii]:
                        free[kk, jj, ii] = d
            best[kk], arg[kk] = _slab_max(free, kk)
    return n


# --------------------------------------------------------------------------- bins
@njit(cache=True)
def _bin_ranges(lo, hi, bsize, nbins):
    b0 = np.empty(3, np.int64)
    b1 = np.empty(3, np.int64)
    for a in range(3):
        b0[a] = max(0, lo[a] // bsize)
        b1[a] = min(nbins[a] - 1, hi[a] // bsize)
    return b0, b1


@njit(cache=True)
def _bin_count(lo, hi, bsize, nbins, counts):
    """Count, per bin, the items whose inclusive grid-index box [lo, hi] overlaps it."""
    for t in range(lo.shape[0]):
        if hi[t, 0] < lo[t, 0] or hi[t, 1] < lo[t, 1] or hi[t, 2] < lo[t, 2]:
            continue
        b0, b1 = _bin_ranges(lo[t], hi[t], bsize, nbins)
        for bz in range(b0[2], b1[2] + 1):
            for by in range(b0[1], b1[1] + 1):
                for bx in range(b0[0], b1[0] + 1):
                    counts[(bz * nbins[1] + by) * nbins[0] + bx] += 1


@njit(cache=True)
def _bin_fill(lo, hi, bsize, nbins, offsets, items):
    """Fill the CSR item lists (items in their original order within each bin)."""
    pos = offsets[:-1].copy()
    for t in range(lo.shape[0]):
        if hi[t, 0] < lo[t, 0] or hi[t, 1] < lo[t, 1] or hi[t, 2] < lo[t, 2]:
            continue
        b0, b1 = _bin_ranges(lo[t], hi[t], bsize, nbins)
        for bz in range(b0[2], b1[2] + 1):
            for by in range(b0[1], b1[1] + 1):
                for bx in range(b0[0], b1[0] + 1):
                    b = (bz * nbins[1] + by) * nbins[0] + bx
                    items[pos[b]] = t
                    pos[b] += 1


@njit(cache=True, inline="always")
def _bin_box(b, bsize, nbins, shape):
    bx = b % nbins[0]
    rest = b // nbins[0]
    by = rest % nbins[1]
    bz = rest // nbins[1]
    i0 = bx * bsize
    j0 = by * bsize
    k0 = bz * bsize
    return (i0, min(i0 + bsize, shape[2]), j0, min(j0 + bsize, shape[1]), k0,
            min(k0 + bsize, shape[0]))


# --------------------------------------------------------------------------- metaballs
@njit(cache=True, parallel=True)
def _metaball_points_kernel(points, centers, support, out):
    """Wyvill field f = sum (1 - |p-c|^2/R^2)^3 and its gradient at points: out (n, 4)."""
    for q in prange(points.shape[0]):
        px = points[q, 0]
        py = points[q, 1]
        pz = points[q, 2]
        f = 0.0
        gx = 0.0
        gy = 0.0
        gz = 0.0
        for s in range(centers.shape[0]):
            dx = px - centers[s, 0]
            dy = py - centers[s, 1]
            dz = pz - centers[s, 2]
            inv = 1.0 / (support[s] * support[s])
            t = (dx * dx + dy * dy + dz * dz) * inv
            if t < 1.0:
                u = 1.0 - t
                f += u * u * u
                w = -6.0 * u * u * inv
                gx += w * dx
                gy += w * dy
                gz += w * dz
        out[q, 0] = f
        out[q, 1] = gx
        out[q, 2] = gy
        out[q, 3] = gz


@njit(cache=True, parallel=True)
def _metaball_grid_kernel(origin, h, active, bsize, nbins, offsets, items, centers, support,
                          iso, g_floor, dist):
    """First-order distance (f - iso) / max(|grad f|, g_floor) on the grid points of the
    active bins (``dist`` holds -iso / g_floor elsewhere, set by the caller)."""
    shape = dist.shape
    for t in prange(active.shape[0]):
        b = active[t]
        i0, i1, j0, j1, k0, k1 = _bin_box(b, bsize, nbins, shape)
        acc = np.zeros((k1 - k0, j1 - j0, i1 - i0, 4))
        for p in range(offsets[b], offsets[b + 1]):
            s = items[p]
            cx = centers[s, 0]
            cy = centers[s, 1]
            cz = centers[s, 2]
            inv = 1.0 / (support[s] * support[s])
            for k in range(k0, k1):
                dz = origin[2] + k * h - cz
                for j in range(j0, j1):
                    dy = origin[1] + j * h - cy
                    for i in range(i0, i1):
                        dx = origin[0] + i * h - cx
                        tt = (dx * dx + dy * dy + dz * dz) * inv
                        if tt < 1.0:
                            u = 1.0 - tt
                            w = -6.0 * u * u * inv
                            a = acc[k - k0, j - j0, i - i0]
                            a[0] += u * u * u
                            a[1] += w * dx
                            a[2] += w * dy
                            a[3] += w * dz
        for k in range(k0, k1):
            for j in range(j0, j1):
                for i in range(i0, i1):
                    a = acc[k - k0, j - j0, i - i0]
                    g = np.sqrt(a[1] * a[1] + a[2] * a[2] + a[3] * a[3])
                    dist[k, j, i] = (a[0] - iso) / max(g, g_floor)


# --------------------------------------------------------------------------- craters
@njit(cache=True, inline="always")
def _smooth_fall(u):
    """1 for u <= 0, 0 for u >= 1, C1 smoothstep in between."""
    if u <= 0.0:
        return 1.0
    if u >= 1.0:
        return 0.0
    return 1.0 - u * u * (3.0 - 2.0 * u)


@njit(cache=True, inline="always")
def _crater_value(px, py, pz, q, centers, normals, kinds, params, support, zhalf):
    """Tangent-frame crater kernel q at point p: kernel(r) x taper(r) x window(z)."""
    dx = px - centers[q, 0]
    dy = py - centers[q, 1]
    dz = pz - centers[q, 2]
    z = dx * normals[q, 0] + dy * normals[q, 1] + dz * normals[q, 2]
    az = abs(z)
    zh = zhalf[q]
    if az >= 2.0 * zh:
        return 0.0
    r2 = dx * dx + dy * dy + dz * dz - z * z
    if r2 < 0.0:
        r2 = 0.0
    rs = support[q]
    if r2 >= rs * rs:
        return 0.0
    u = np.sqrt(r2) / rs
    v = lcsn_height(kinds[q], r2, params[q, 0], params[q, 1], params[q, 2], params[q, 3],
                    params[q, 4])
    return v * _smooth_fall((u - 0.8) / 0.2) * _smooth_fall(az / zh - 1.0)


@njit(cache=True, parallel=True)
def _crater_grid_kernel(origin, h, active, bsize, nbins, offsets, items, lo, hi, centers,
                        normals, kinds, params, support, zhalf, base, band, out):
    """out += sum of crater kernels at grid points whose |base| < band; each crater is
    evaluated on its index box (``lo``, ``hi``: inclusive (i, j, k), holding its whole
    support) within each bin."""
    shape = out.shape
    for t in prange(active.shape[0]):
        b = active[t]
        i0, i1, j0, j1, k0, k1 = _bin_box(b, bsize, nbins, shape)
        for p in range(offsets[b], offsets[b + 1]):
            q = items[p]
            for k in range(max(k0, lo[q, 2]), min(k1, hi[q, 2] + 1)):
                pz = origin[2] + k * h
                for j in range(max(j0, lo[q, 1]), min(j1, hi[q, 1] + 1)):
                    py = origin[1] + j * h
                    for i in range(max(i0, lo[q, 0]), min(i1, hi[q, 0] + 1)):
                        if abs(base[k, j, i]) >= band:
                            continue
                        out[k, j, i] += _crater_value(origin[0] + i * h, py, pz, q, centers,
                                                      normals, kinds, params, support, zhalf)


@njit(cache=True, parallel=True)
def _crater_points_kernel(points, centers, normals, kinds, params, support, zhalf, out):
    """Reference/point version: out[p] = sum over all craters (brute force)."""
    for p in prange(points.shape[0]):
        s = 0.0
        for q in range(centers.shape[0]):
            s += _crater_value(points[p, 0], points[p, 1], points[p, 2], q, centers, normals,
                               kinds, params, support, zhalf)
        out[p] = s


# --------------------------------------------------------------------------- Gabor
@njit(cache=True, inline="always")
def _gabor_value(px, py, pz, q, pos, wave, env, amp, phase, cutoff2):
    dx = px - pos[q, 0]
    dy = py - pos[q, 1]
    dz = pz - pos[q, 2]
    r2 = dx * dx + dy * dy + dz * dz
    e = env[q]
    if r2 * e * e >= cutoff2:
        return 0.0
    arg = 2.0 * np.pi * (wave[q, 0] * dx + wave[q, 1] * dy + wave[q, 2] * dz) + phase[q]
    return amp[q] * np.exp(-np.pi * e * e * r2) * np.cos(arg)


@njit(cache=True, parallel=True)
def _gabor_grid_kernel(origin, h, active, bsize, nbins, offsets, items, lo, hi, pos, wave,
                       env, amp, phase, cutoff2, base, band, out):
    """out += Gabor sparse convolution at grid points whose |base| < band; each impulse is
    evaluated on its index box (``lo``, ``hi``: inclusive (i, j, k), its cutoff) within
    each bin."""
    shape = out.shape
    for t in prange(active.shape[0]):
        b = active[t]
        i0, i1, j0, j1, k0, k1 = _bin_box(b, bsize, nbins, shape)
        for p in range(offsets[b], offsets[b + 1]):
            q = items[p]
            for k in range(max(k0, lo[q, 2]), min(k1, hi[q, 2] + 1)):
                pz = origin[2] + k * h
                for j in range(max(j0, lo[q, 1]), min(j1, hi[q, 1] + 1)):
                    py = origin[1] + j * h
                    for i in range(max(i0, lo[q, 0]), min(i1, hi[q, 0] + 1)):
                        if abs(base[k, j, i]) >= band:
                            continue
                        out[k, j, i] += _gabor_value(origin[0] + i * h, py, pz, q, pos, wave,
                                                     env, amp, phase, cutoff2)


@njit(cache=True, parallel=True)
def _gabor_points_kernel(points, pos, wave, env, amp, phase, cutoff2, out):
    """Point version (brute force over impulses), e.g. on a plane of samples."""
    for p in prange(points.shape[0]):
        s = 0.0
        for q in range(pos.shape[0]):
            s += _gabor_value(points[p, 0], points[p, 1], points[p, 2], q, pos, wave, env, amp,
                              phase, cutoff2)
        out[p] = s


# --------------------------------------------------------------------------- distance
@read_only_inputs("out")
@njit(cache=True, parallel=True)
def _closest_distance_kernel(origin, h, nearest, seed_id, foot, normal, first_order, far2,
                            reach, out):
    """Signed distance from the tangent plane at the closest foot point.

    ``nearest`` holds, per grid point, the (k, j, i) of the nearest seed grid point
    (scipy's distance-transform indices); ``foot`` and ``normal`` the surface point and
    unit inward normal of each seed. The foot point closest to the grid point is
    searched among the seeds in the block of (2 reach + 1)^3 grid points around that
    seed (reach 2 for the thin seed layer of the metaballs); the distance is
    measured to its tangent plane (feet are about a voxel apart: the distance to the
    nearest foot itself would be off by (gap / 2)^2 / (2 depth)) -- unless the point lies
    more than two voxels along that plane from the foot (the plane's extension says
    nothing there: near a fold it reads ~0 deep inside the body); then the distance to
    the foot itself. The sign is the first-order field's. Needs at least one seed.
    Points more than ``sqrt(far2)`` voxels from their nearest seed skip the search and
    take the distance to that seed's foot (an upper bound, for where only a rough
    distance matters; ``far2 = inf`` searches everywhere).
    """
    nz, ny, nx = out.shape
    for k in prange(nz):
        pz = origin[2] + k * h
        for j in range(ny):
            py = origin[1] + j * h
            for i in range(nx):
                px = origin[0] + i * h
                k0 = nearest[0, k, j, i]
                j0 = nearest[1, k, j, i]
                i0 = nearest[2, k, j, i]
                if (k - k0) ** 2 + (j - j0) ** 2 + (i - i0) ** 2 > far2:
                    s = seed_id[k0, j0, i0]
                    d = np.sqrt((px - foot[s, 0]) ** 2 + (py - foot[s, 1]) ** 2 +
                                (pz - foot[s, 2]) ** 2)
                    out[k, j, i] = d if first_order[k, j, i] > 0 else -d
                    continue
                best = np.inf
                arg = -1
                for kk in range(max(0, k0 - reach), min(nz, k0 + reach + 1)):
                    for jj in range(max(0, j0 - reach), min(ny, j0 + reach + 1)):
                        for ii in range(max(0, i0 - reach), min(nx, i0 + reach + 1)):
                            s = seed_id[kk, jj, ii]
                            if s < 0:
                                continue
                            dx = px - foot[s, 0]
                            dy = py - foot[s, 1]
                            dz = pz - foot[s, 2]
                            d2 = dx * dx + dy * dy + dz * dz
                            if d2 < best:
                                best = d2
                                arg = s
                d = abs((px - foot[arg, 0]) * normal[arg, 0] + (py - foot[arg, 1]) *
                        normal[arg, 1] + (pz - foot[arg, 2]) * normal[arg, 2])
                if best - d * d > 4.0 * h * h:  # far along the plane: the foot itself
                    d = np.sqrt(best)
                out[k, j, i] = d if first_order[k, j, i] > 0 else -d
