"""Numba kernels of cube-sphere cell sets for terrain on demand
(:mod:`latlong.ondemand.cellsets`): each output row from its own input row, so the
results do not depend on the thread count. The face arithmetic is
:mod:`craters.kernels`'s (one home with :mod:`craters.cells`)."""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from craters.kernels import cell_id, face_point, face_uv, read_only_inputs

from ._field_kernels import C0, C1, C2, E0, N0


@read_only_inputs("out")
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


@njit(cache=True, parallel=True)
def _reach_kernel(centres, angles, level, occ, out):
    """Whether a cap (unit centre, angular radius) may touch an occupied cell (sorted ids
    ``occ`` at ``level``): a superset test. The cap's box on its centre's cube face is
    padded by its angle times the face's largest stretch over the box (sec^2 = 1 + u^2 +
    v^2 of the gnomonic face, at most 3 at its corners) and every cell of the box is
    looked up, row by row (a row of the box is one run of the sorted ids); a box leaving
    the face or taller than 4096 rows counts as touching."""
    nside = 1 << level
    for k in prange(centres.shape[0]):
        f, u, v = face_uv(centres[k, 0], centres[k, 1], centres[k, 2])
        # the stretch is sec^2 = 1 + u^2 + v^2 at most over the box padded by 3 x angle
        wide = 3.0 * angles[k]
        stretch = 1.0 + (abs(u) + wide) ** 2 + (abs(v) + wide) ** 2
        pad = min(stretch, 3.0) * angles[k] * (1.0 + 1e-9) + 1e-12
        if u - pad <= -1.0 or u + pad >= 1.0 or v - pad <= -1.0 or v + pad >= 1.0:
            out[k] = True
            continue
        i0 = int(np.floor((u - pad + 1.0) * 0.5 * nside))
        i1 = int(np.floor((u + pad + 1.0) * 0.5 * nside))
        j0 = int(np.floor((v - pad + 1.0) * 0.5 * nside))
        j1 = int(np.floor((v + pad + 1.0) * 0.5 * nside))
        if i1 - i0 > 4096:
            out[k] = True
            continue
        # each row i of the box is one run of ``occ`` (ids sort by face, i, then j)
        hit = False
        for i in range(i0, i1 + 1):
            row = (np.uint64(level) << np.uint64(57)) | (np.uint64(f) << np.uint64(54)) \
                | (np.uint64(i) << np.uint64(27))
            lo = np.searchsorted(occ, row | np.uint64(j0))
            if lo < occ.shape[0] and occ[lo] <= (row | np.uint64(j1)):
                hit = True
                break
        out[k] = hit


@njit(cache=True, parallel=True)
def _cap_blocks_kernel(fc, angles, craters, level, occ, cos_margin):
    """Pairs (block, crater): the occupied blocks (sorted cell ids ``occ`` at ``level``)
    that crater caps (centre and frame in ``fc``, angular radius ``angles``) may reach
    (:func:`_cap_blocks_one`), crater by crater in the order given. Craters in parallel,
    counted first, then written at their offsets."""
    n_cr = craters.shape[0]
    counts = np.zeros(n_cr + 1, dtype=np.int64)
    none = np.empty(0, dtype=np.int64)
    for t in prange(n_cr):
        counts[t + 1] = _cap_blocks_one(fc, angles, craters[t], level, occ, cos_margin, none,
                                        none, np.int64(0), np.bool_(False))
    offsets = np.cumsum(counts)
    out_blk = np.empty(offsets[n_cr], dtype=np.int64)
    out_crater = np.empty(offsets[n_cr], dtype=np.int64)
    for t in prange(n_cr):
        _cap_blocks_one(fc, angles, craters[t], level, occ, cos_margin, out_blk, out_crater,
                        offsets[t], np.bool_(True))
    return out_blk, out_crater


@njit(cache=True)
def _cap_blocks_one(fc, angles, k, level, occ, cos_margin, out_blk, out_crater, at, write):
    """The occupied blocks crater k's cap may reach, written from ``at`` when ``write``;
    returns how many. A cap narrower than 0.3 rad is projected on each face it can touch
    and the blocks of its bounding box are looked up; a wider one is tested against every
    occupied block (its centre within the cap widened by ``cos_margin``, the blocks'
    angular radius)."""
    n = 0
    nside = 1 << level
    n_samples = 64
    bp = np.empty((n_samples + 1, 3))
    # the angle itself: its cosine rounds to 1 below ~1e-8 rad (2 cm on the Moon), which
    # listed a centimetre crater in its centre's block only (steps along block edges)
    ang = angles[k]
    cosf = np.cos(ang)
    c = np.array([fc[k, C0], fc[k, C1], fc[k, C2]])
    if ang >= 0.3:
        # angle(c, block) <= ang + margin
        cos_tot = np.cos(min(np.pi, ang + np.arccos(cos_margin)))
        for b in range(occ.shape[0]):
            cell = occ[b]
            lv = int(cell >> np.uint64(57))
            face = int((cell >> np.uint64(54)) & np.uint64(7))
            i = int((cell >> np.uint64(27)) & np.uint64((1 << 27) - 1))
            j = int(cell & np.uint64((1 << 27) - 1))
            sc = 2.0 / (1 << lv)
            w = face_point(face, -1.0 + (i + 0.5) * sc, -1.0 + (j + 0.5) * sc)
            nw = np.sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2])
            if (w[0] * c[0] + w[1] * c[1] + w[2] * c[2]) / nw >= cos_tot:
                if write:
                    out_blk[at + n] = b
                    out_crater[at + n] = k
                n += 1
        return n
    sa = np.sin(ang)
    for s in range(n_samples):
        phi = 2.0 * np.pi * s / n_samples
        for d in range(3):
            bp[s, d] = cosf * c[d] + sa * (np.cos(phi) * fc[k, E0 + d]
                                           + np.sin(phi) * fc[k, N0 + d])
    for d in range(3):
        bp[n_samples, d] = c[d]
    for face in range(6):
        a = face // 2
        sgn = 1.0 if face % 2 == 0 else -1.0
        ok = True
        umin = 1e300
        umax = -1e300
        vmin = 1e300
        vmax = -1e300
        for s in range(n_samples + 1):
            m = sgn * bp[s, a]
            if m <= 0.0:
                ok = False
                break
            u = bp[s, (a + 1) % 3] / m
            v = bp[s, (a + 2) % 3] / m
            umin = min(umin, u)
            umax = max(umax, u)
            vmin = min(vmin, v)
            vmax = max(vmax, v)
        if not ok:
            continue
        big = max(max(abs(umin), abs(umax)), max(abs(vmin), abs(vmax)))
        pad = 0.02 * ang * (1.0 + 2.0 * big * big) + 1e-12
        umin -= pad
        umax += pad
        vmin -= pad
        vmax += pad
        if umin > 1.0 or umax < -1.0 or vmin > 1.0 or vmax < -1.0:
            continue
        i0 = max(int(np.floor((max(umin, -1.0) + 1.0) * 0.5 * nside)), 0)
        i1 = min(int(np.floor((min(umax, 1.0) + 1.0) * 0.5 * nside)), nside - 1)
        j0 = max(int(np.floor((max(vmin, -1.0) + 1.0) * 0.5 * nside)), 0)
        j1 = min(int(np.floor((min(vmax, 1.0) + 1.0) * 0.5 * nside)), nside - 1)
        if (i1 - i0 + 1) * (j1 - j0 + 1) > occ.shape[0]:
            # fewer occupied blocks than cells in the box: test those
            for pos in range(occ.shape[0]):
                cell = occ[pos]
                if int((cell >> np.uint64(54)) & np.uint64(7)) != face:
                    continue
                i = int((cell >> np.uint64(27)) & np.uint64((1 << 27) - 1))
                j = int(cell & np.uint64((1 << 27) - 1))
                if i0 <= i <= i1 and j0 <= j <= j1:
                    if write:
                        out_blk[at + n] = pos
                        out_crater[at + n] = k
                    n += 1
            continue
        for i in range(i0, i1 + 1):
            for j in range(j0, j1 + 1):
                cell = (np.uint64(level) << np.uint64(57)) \
                    | (np.uint64(face) << np.uint64(54)) \
                    | (np.uint64(i) << np.uint64(27)) | np.uint64(j)
                pos = np.searchsorted(occ, cell)
                if pos < occ.shape[0] and occ[pos] == cell:
                    if write:
                        out_blk[at + n] = pos
                        out_crater[at + n] = k
                    n += 1
    return n
