"""Numba kernels of the mesh exports: packed PLY records and glTF patch data.

Every value is computed as the numpy code it replaces computed it (same operations in
the same order, float64 rounded once to float32), so the files keep their bytes; the
kernels only skip the intermediate arrays and the per-patch Python work. The chunk
kernels run on one thread without the GIL: the exports make several chunks at once on
worker threads (``latlong.meshio.chunks.ordered_chunks``).
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from ._grid_kernels import (
    _band_strip_kernel,
    _band_triangles_kernel,
    _lon_row,
    _ring_part,
    _ring_size,
    _rings_of_range,
)


@njit(cache=True, nogil=True)
def _ply_vertex_kernel(m, ring_offsets, radii, radius_m, stretch, lon_table, lo, hi, out):
    """PLY vertex records of vertices ``lo .. hi - 1`` into ``out`` ((hi - lo, w) float32
    view of the records): x y z = float32(u * (radius * stretch)) (``Body.vertices``)
    and height = float32(radius - radius_m); columns past 3 are left alone. The
    latitude's cosine and sine once per ring and the longitudes' from ``lon_table``
    (``_unit_of``'s values), or computed as the table's are when it is empty."""
    r_first, r_last = _rings_of_range(ring_offsets, lo, hi)
    for r in range(r_first, r_last + 1):
        o, n, j0, j1 = _ring_part(ring_offsets, lo, hi, r)
        lat = 0.5 * np.pi - r * (np.pi / (2 * m))
        c = np.cos(lat)
        sz = np.sin(lat)
        t0 = _lon_row(m, r, ring_offsets)
        for j in range(j0, j1):
            q = o + j - lo
            rad = radii[o + j]
            if r == 0 or r == 2 * m:
                x, y, z = 0.0, 0.0, 1.0 if r == 0 else -1.0
            elif lon_table.shape[0] == 0:
                lon = 2.0 * np.pi * j / n
                x, y, z = c * np.cos(lon), c * np.sin(lon), sz
            else:
                x, y, z = c * lon_table[t0 + j, 0], c * lon_table[t0 + j, 1], sz
            out[q, 0] = np.float32(x * (rad * stretch[0]))
            out[q, 1] = np.float32(y * (rad * stretch[1]))
            out[q, 2] = np.float32(z * (rad * stretch[2]))
            out[q, 3] = np.float32(rad - radius_m)


@njit(cache=True, nogil=True)
def _ply_face_kernel(m, band_lo, band_hi, ring_offsets, band_offsets, out):
    """PLY face records (uchar 3, three little-endian 32-bit indices: 13 bytes) of the
    bands ``band_lo .. band_hi - 1`` into the bytes ``out``, each band triangulated by
    :func:`_band_triangles_kernel` into a small buffer first."""
    base = band_offsets[band_lo]
    most = 0
    for band in range(band_lo, band_hi):
        most = max(most, band_offsets[band + 1] - band_offsets[band])
    tri = np.empty((most, 3), dtype=np.int64)
    for band in range(band_lo, band_hi):
        t0 = band_offsets[band]
        nt = band_offsets[band + 1] - t0
        if band < m:
            ra, rb, south = band, band + 1, False
        else:
            ra, rb, south = band + 1, band, True
        _band_triangles_kernel(ring_offsets[ra], _ring_size(ra, m), ring_offsets[rb],
                               _ring_size(rb, m), south, tri, np.int64(0))
        p = (t0 - base) * 13
        for t in range(nt):
            out[p] = 3
            for c in range(3):
                v = tri[t, c]
                q = p + 1 + 4 * c
                out[q] = v & 0xFF
                out[q + 1] = (v >> 8) & 0xFF
                out[q + 2] = (v >> 16) & 0xFF
                out[q + 3] = (v >> 24) & 0xFF
            p += 13


@njit(cache=True, nogil=True, parallel=True)
def _glb_positions_kernel(m, ring_offsets, radii, stretch, lon_table, out):
    """float32(u * radius * stretch) of every vertex into ``out`` (N, 3): the glTF
    export's positions (``(u * r) * s``, its order of operations), rings in parallel,
    the longitudes' cosines and sines from ``lon_table``."""
    for r in prange(2 * m + 1):
        o = ring_offsets[r]
        n = ring_offsets[r + 1] - o
        lat = 0.5 * np.pi - r * (np.pi / (2 * m))
        c = np.cos(lat)
        sz = np.sin(lat)
        t0 = _lon_row(m, r, ring_offsets)
        for j in range(n):
            rad = radii[o + j]
            if r == 0 or r == 2 * m:
                x, y, z = 0.0, 0.0, 1.0 if r == 0 else -1.0
            else:
                x, y, z = c * lon_table[t0 + j, 0], c * lon_table[t0 + j, 1], sz
            out[o + j, 0] = np.float32(x * rad * stretch[0])
            out[o + j, 1] = np.float32(y * rad * stretch[1])
            out[o + j, 2] = np.float32(z * rad * stretch[2])


@njit(cache=True, nogil=True)
def _patch_strip(m, ring_offsets, band_lo, n_bands, rng_lo, rng_hi, out):
    """A patch's joined strip (``join_strips`` of its band strips) into ``out``;
    returns its length. Band ``band_lo + e`` contributes triangles
    ``rng_lo[e] .. rng_hi[e] - 1``; strips are stitched with degenerate triangles,
    [last, first] after an even length, [last, last, first] after an odd one."""
    k = 0
    for e in range(n_bands):
        lo = rng_lo[e]
        hi = rng_hi[e]
        if hi <= lo:
            continue
        band = band_lo + e
        if band < m:
            ra, rb, south = band, band + 1, False
        else:
            ra, rb, south = band + 1, band, True
        bridge = 0 if k == 0 else (2 if k % 2 == 0 else 3)
        n = _band_strip_kernel(ring_offsets[ra], _ring_size(ra, m), ring_offsets[rb],
                               _ring_size(rb, m), south, lo, hi, out[k + bridge:])
        if bridge:
            last = out[k - 1]
            out[k] = last
            if bridge == 3:
                out[k + 1] = last
            out[k + bridge - 1] = out[k + bridge]
        k += bridge + n
    return k


@njit(cache=True, nogil=True)
def _patch_local(ring_offsets, strip, length, r_lo, r_hi, vertices, local):
    """``np.unique(strip[:length], return_inverse=True)`` for a strip on the rings
    ``r_lo .. r_hi``: the sorted vertices into ``vertices`` and each entry's index among
    them into ``local``; returns their count. Ring by ring over the span of positions
    each ring uses (no sort)."""
    nr = r_hi - r_lo + 1
    pmin = np.full(nr, np.iinfo(np.int64).max, dtype=np.int64)
    pmax = np.full(nr, -1, dtype=np.int64)
    ring = np.empty(length, dtype=np.int64)
    r = r_lo
    for k in range(length):
        g = strip[k]
        # the ring of g: a strip moves between neighbouring rings, so walk from the last
        while g < ring_offsets[r]:
            r -= 1
        while g >= ring_offsets[r + 1]:
            r += 1
        ring[k] = r - r_lo
        p = g - ring_offsets[r]
        pmin[r - r_lo] = min(pmin[r - r_lo], p)
        pmax[r - r_lo] = max(pmax[r - r_lo], p)
    base = np.zeros(nr + 1, dtype=np.int64)
    for i in range(nr):
        base[i + 1] = base[i] + (pmax[i] - pmin[i] + 1 if pmax[i] >= 0 else 0)
    rank = np.full(base[nr], -1, dtype=np.int64)
    for k in range(length):
        i = ring[k]
        rank[base[i] + strip[k] - ring_offsets[r_lo + i] - pmin[i]] = 0
    count = 0
    for i in range(nr):
        for q in range(base[i], base[i + 1]):
            if rank[q] == 0:
                rank[q] = count
                vertices[count] = ring_offsets[r_lo + i] + pmin[i] + q - base[i]
                count += 1
    for k in range(length):
        i = ring[k]
        local[k] = rank[base[i] + strip[k] - ring_offsets[r_lo + i] - pmin[i]]
    return count


@njit(cache=True, nogil=True)
def _patch_kernel(m, ring_offsets, leaf_band_lo, leaf_ptr, rng_lo, rng_hi, positions,
                  normals, base, leaf_from, leaf_to, write, meta, bounds, pos_at, nrm_at, ind_at,
                  out_f32, out_u32):
    """The glTF data of leaves ``leaf_from .. leaf_to - 1`` of a patch tree.

    Leaf ``leaf`` covers bands ``leaf_band_lo[leaf] ..`` with the triangle ranges
    ``rng_lo/rng_hi[leaf_ptr[leaf] .. leaf_ptr[leaf + 1] - 1]``. Without ``write`` it fills
    ``meta[leaf]`` = (strip length, vertices, non-degenerate triangles) and ``bounds[leaf]`` =
    (min xyz, max xyz, centre xyz, radius) of its float32 positions (centre in float64
    from the float32 bounds, radius = the largest distance to it); row ``v - base`` of
    ``positions``/``normals`` is vertex v's (they may hold a window of rings only). With
    ``write`` it writes the patch's positions, normals (float32 rows of
    ``positions``/``normals`` of its sorted vertices) and uint32 local strip indices at
    the 4-byte word offsets ``pos_at/nrm_at/ind_at[leaf]`` of ``out_f32``/``out_u32``
    (two views of one buffer).
    """
    for leaf in range(leaf_from, leaf_to):
        p0 = leaf_ptr[leaf]
        nb = leaf_ptr[leaf + 1] - p0
        cap = 0
        for e in range(p0, p0 + nb):
            cap += 5 + 2 * max(rng_hi[e] - rng_lo[e], 0)
        strip = np.empty(cap, dtype=np.int64)
        length = _patch_strip(m, ring_offsets, leaf_band_lo[leaf], nb, rng_lo[p0:p0 + nb],
                              rng_hi[p0:p0 + nb], strip)
        if length < 3:
            if not write:
                meta[leaf, 0] = length
                meta[leaf, 1] = 0
                meta[leaf, 2] = 0
            continue
        vertices = np.empty(length, dtype=np.int64)
        local = np.empty(length, dtype=np.int64)
        nv = _patch_local(ring_offsets, strip, length, leaf_band_lo[leaf],
                          leaf_band_lo[leaf] + nb, vertices, local)
        if write:
            pa = pos_at[leaf]
            na = nrm_at[leaf]
            for q in range(nv):
                v = vertices[q]
                for c in range(3):
                    out_f32[pa + 3 * q + c] = positions[v - base, c]
                    out_f32[na + 3 * q + c] = normals[v - base, c]
            ia = ind_at[leaf]
            for k in range(length):
                out_u32[ia + k] = local[k]
            continue
        n_tri = 0
        for k in range(length - 2):
            a = strip[k]
            b = strip[k + 1]
            c = strip[k + 2]
            if a != b and b != c and a != c:
                n_tri += 1
        meta[leaf, 0] = length
        meta[leaf, 1] = nv
        meta[leaf, 2] = n_tri
        lo = positions[vertices[0] - base].copy()
        hi = positions[vertices[0] - base].copy()
        for q in range(1, nv):
            for c in range(3):
                x = positions[vertices[q] - base, c]
                if x < lo[c]:
                    lo[c] = x
                if x > hi[c]:
                    hi[c] = x
        centre = np.empty(3)
        for c in range(3):
            centre[c] = 0.5 * (np.float64(lo[c]) + np.float64(hi[c]))
            bounds[leaf, c] = lo[c]
            bounds[leaf, 3 + c] = hi[c]
            bounds[leaf, 6 + c] = centre[c]
        far = 0.0
        for q in range(nv):
            v = vertices[q]
            dx = np.float64(positions[v - base, 0]) - centre[0]
            dy = np.float64(positions[v - base, 1]) - centre[1]
            dz = np.float64(positions[v - base, 2]) - centre[2]
            d2 = dx * dx + dy * dy + dz * dz
            if d2 > far or q == 0:
                far = d2
        bounds[leaf, 9] = np.sqrt(far)
