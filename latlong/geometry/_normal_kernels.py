"""Numba kernels of :mod:`latlong.geometry.normals`: facet contributions added to vertex
normals triangle by triangle (any mesh, or a lat/long body streamed band by band).

No validation here: :mod:`latlong.geometry.normals` checks and allocates. The band
kernels write every vertex's two bands in a fixed order (even bands first), so their
sums do not depend on the thread count.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from craters.kernels import azimuth, read_only_inputs

from .._grid_kernels import _lon_row, _ring_positions, _ring_size


@njit(cache=True, inline="always")
def _triangle_edges(pos, a, b, c):
    """The edges ``b - a`` and ``c - a`` of the triangle of rows a, b, c of ``pos``, as six
    components."""
    return (pos[b, 0] - pos[a, 0], pos[b, 1] - pos[a, 1], pos[b, 2] - pos[a, 2],
            pos[c, 0] - pos[a, 0], pos[c, 1] - pos[a, 1], pos[c, 2] - pos[a, 2])


@njit(cache=True, inline="always")
def _triangle_cross(pos, a, b, c):
    """``(b - a) x (c - a)`` of the triangle of rows a, b, c of ``pos``: twice its area
    along its normal."""
    e1x, e1y, e1z, e2x, e2y, e2z = _triangle_edges(pos, a, b, c)
    return e1y * e2z - e1z * e2y, e1z * e2x - e1x * e2z, e1x * e2y - e1y * e2x


@njit(cache=True, inline="always")
def _add_triangle_normal(pos, a, b, c, out):
    """Add triangle (a, b, c)'s area vector (its cross product / 2) to its vertices' rows
    of ``out`` (each addition in float64, stored in ``out``'s type); returns the area
    vector."""
    cx, cy, cz = _triangle_cross(pos, a, b, c)
    nx = 0.5 * cx
    ny = 0.5 * cy
    nz = 0.5 * cz
    for v in (a, b, c):
        out[v, 0] += nx
        out[v, 1] += ny
        out[v, 2] += nz
    return nx, ny, nz


@njit(cache=True, inline="always")
def _add_triangle_angle_normal(pos, a, b, c, out):
    """Add triangle (a, b, c)'s unit normal times its angle at each corner to that
    corner's row of ``out`` (the ``"angle"`` weighting: Mitsuba's and Blender's smooth
    normals); a degenerate triangle adds nothing. The angle between two edges is
    atan2(|cross|, dot), and the cross product of any corner's two edges has the length
    of the facet's: one square root a triangle, an arc tangent in plain arithmetic
    (:func:`craters.kernels.azimuth`) and no arc cosine, which also keeps its accuracy
    at angles near 0 and pi (acos of a rounded cosine does not)."""
    e1x, e1y, e1z, e2x, e2y, e2z = _triangle_edges(pos, a, b, c)  # b - a, c - a
    cx, cy, cz = e1y * e2z - e1z * e2y, e1z * e2x - e1x * e2z, e1x * e2y - e1y * e2x
    norm = np.sqrt(cx * cx + cy * cy + cz * cz)
    if not norm > 0.0:  # also every triangle with an edge of length 0
        return
    fx, fy, fz = e2x - e1x, e2y - e1y, e2z - e1z  # c - b
    d12 = e1x * e2x + e1y * e2y + e1z * e2z
    d13 = e1x * fx + e1y * fy + e1z * fz
    d23 = e2x * fx + e2y * fy + e2z * fz
    nx, ny, nz = cx / norm, cy / norm, cz / norm
    for v, ang in ((a, azimuth(norm, d12)), (b, azimuth(norm, -d13)),
                   (c, azimuth(norm, d23))):
        out[v, 0] += ang * nx
        out[v, 1] += ang * ny
        out[v, 2] += ang * nz


@read_only_inputs("out", "area")
@njit(cache=True)
def _area_normals_kernel(verts, tris, out, area):
    """Area-weighted vertex normal sums, triangle after triangle (the ``"faces"`` order):
    each triangle's area vector added to its three vertices' rows of ``out`` (float64 or
    float32), and a third of its area to their ``area`` (none when ``area`` is empty)."""
    with_area = area.shape[0] > 0
    for t in range(tris.shape[0]):
        a = tris[t, 0]
        b = tris[t, 1]
        c = tris[t, 2]
        nx, ny, nz = _add_triangle_normal(verts, a, b, c, out)
        if with_area:
            third = np.sqrt(nx * nx + ny * ny + nz * nz) / 3.0
            for v in (a, b, c):
                area[v] += third


@read_only_inputs("out")
@njit(cache=True)
def _angle_normals_kernel(verts, tris, out):
    """Angle-weighted vertex normal sums, triangle after triangle (the ``"faces"``
    order): each triangle's unit normal times its angle at each corner added to that
    corner's row of ``out``."""
    for t in range(tris.shape[0]):
        _add_triangle_angle_normal(verts, tris[t, 0], tris[t, 1], tris[t, 2], out)


@read_only_inputs("out")
@njit(cache=True)
def _max_normals_kernel(vertices, faces, out):
    """Unit vertex normals with Max's (1999) weights, triangle after triangle: the sum over
    the incident faces of the cross product of the two edges at the vertex divided by the
    product of their squared lengths (exact for vertices on a sphere), normalised (rows
    of norm 0 stay 0)."""
    out[:] = 0.0
    for f in range(faces.shape[0]):
        a, b, c = faces[f, 0], faces[f, 1], faces[f, 2]
        abx, aby, abz, acx, acy, acz = _triangle_edges(vertices, a, b, c)
        bcx, bcy, bcz = acx - abx, acy - aby, acz - abz
        nx = aby * acz - abz * acy
        ny = abz * acx - abx * acz
        nz = abx * acy - aby * acx
        lab = abx * abx + aby * aby + abz * abz
        lbc = bcx * bcx + bcy * bcy + bcz * bcz
        lca = acx * acx + acy * acy + acz * acz
        for v, den in ((a, lab * lca), (b, lab * lbc), (c, lbc * lca)):
            if den > 0.0:
                out[v, 0] += nx / den
                out[v, 1] += ny / den
                out[v, 2] += nz / den
    for v in range(out.shape[0]):
        n = np.sqrt(out[v, 0] ** 2 + out[v, 1] ** 2 + out[v, 2] ** 2)
        if n > 0.0:
            out[v, 0] /= n
            out[v, 1] /= n
            out[v, 2] /= n


@read_only_inputs("out")
@njit(cache=True)
def _scatter_add_kernel(index, values, out):
    """``out[index[t]] += values[t]`` in the order of t (``np.add.at``, (N,) or (N, k))."""
    for t in range(index.shape[0]):
        out[index[t]] += values[t]


# --------------------------------------------------------------------------- lat/long body
@njit(cache=True, inline="always")
def _band_normals(pos, oa, na, ob, nb, south, out, angle):
    """Area vectors (``angle``: unit normals times corner angles) of a band's triangles,
    in :func:`_band_triangles_kernel`'s order and winding (the same zipper), added to
    ``out`` as they are made (no triangle array)."""
    if na == 1:  # pole fan
        for j in range(nb):
            b, c = (ob + (j + 1) % nb, ob + j) if south else (ob + j, ob + (j + 1) % nb)
            if angle:
                _add_triangle_angle_normal(pos, oa, b, c, out)
            else:
                _add_triangle_normal(pos, oa, b, c, out)
        return
    i = 0
    j = 0
    for _ in range(na + nb):
        if i < na and (j >= nb or (i + 1) * nb <= (j + 1) * na):
            p, q, r = oa + i, ob + j % nb, oa + (i + 1) % na
            i += 1
        else:
            p, q, r = oa + i % na, ob + j, ob + (j + 1) % nb
            j += 1
        if south:
            q, r = r, q
        if angle:
            _add_triangle_angle_normal(pos, p, q, r, out)
        else:
            _add_triangle_normal(pos, p, q, r, out)


# a call, not inlined into the parallel loops: numba's parfor passes scale with the loop
# body (the window normals' first compile 14.0 -> 6.5 s; the same bytes and speed)
@njit(cache=True)
def _band_area_vectors(m, ring_offsets, radii, stretch, lon_table, band, acc, base, angle):
    """Band ``band``'s two rings positioned locally (:func:`_ring_positions`; longitudes
    from ``lon_table``, or computed when it is empty) and its triangles' area vectors
    (``angle``: angle-weighted unit normals) added to ``acc`` (row ``v - base`` is vertex
    v's)."""
    if band < m:
        ra, rb, south = band, band + 1, False
    else:
        ra, rb, south = band + 1, band, True
    na = _ring_size(ra, m)
    nb = _ring_size(rb, m)
    oa = ring_offsets[ra]
    ob = ring_offsets[rb]
    lo = min(oa, ob)
    pos = np.empty((na + nb, 3))
    ta = _lon_row(m, ra, ring_offsets) if lon_table.shape[0] else 0
    tb = _lon_row(m, rb, ring_offsets) if lon_table.shape[0] else 0
    _ring_positions(m, ra, oa, radii, stretch, lon_table, ta, pos[oa - lo:oa - lo + na])
    _ring_positions(m, rb, ob, radii, stretch, lon_table, tb, pos[ob - lo:ob - lo + nb])
    _band_normals(pos, oa - lo, na, ob - lo, nb, south, acc[lo - base:lo - base + na + nb],
                  angle)


@read_only_inputs("acc")
@njit(cache=True, parallel=True)
def _normals_from_radii_kernel(m, ring_offsets, band_offsets, radii, stretch, lon_table, acc,
                               angle):
    """Area-weighted (``angle``: angle-weighted) vertex normals of the body into ``acc``,
    streamed band by band (no
    triangle or vertex array of the whole body): each band's two rings (consecutive
    vertex numbers) are positioned locally and its triangles' area vectors added as the
    zipper makes them (:func:`_band_normals`; 40 % less time than triangulating into an
    array first, the same values). Even bands first, then odd bands: the bands of one
    pass share no ring, so they run in parallel and every vertex receives its two bands'
    contributions in a fixed order (deterministic). The longitudes' cosines and sines come
    from ``lon_table`` (:func:`~latlong._grid_kernels.lon_table`)."""
    n_bands = 2 * m
    for parity in range(2):
        for hb in prange((n_bands - parity + 1) // 2):
            band = 2 * hb + parity
            if band >= n_bands:
                continue
            # base: ring_offsets[0] (0) as an int64, not a literal 0, as the window
            # kernel's: one compile of _band_area_vectors for both
            _band_area_vectors(m, ring_offsets, radii, stretch, lon_table, band, acc,
                               ring_offsets[0], angle)


@njit(cache=True, parallel=True)
def _normalize_rows_kernel(acc):
    """Scale the float32 rows of ``acc`` to unit length in place: the norm in float64,
    ``sqrt((x^2 + y^2) + z^2)``, rounded to float32 and divided into each component
    (rows of norm 0 are left alone)."""
    for i in prange(acc.shape[0]):
        x = np.float64(acc[i, 0])
        y = np.float64(acc[i, 1])
        z = np.float64(acc[i, 2])
        norm = np.sqrt((x * x + y * y) + z * z)
        if norm > 0:
            d = np.float32(norm)
            for c in range(3):
                acc[i, c] = acc[i, c] / d
