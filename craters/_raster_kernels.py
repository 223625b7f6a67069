"""Numba building blocks on height grids and point sets, shared by craters, latlong and dem.

* :func:`_bilinear`: bilinear sample at a fractional (row, col), NaN outside;
* :func:`_plane_sums_add` / :func:`_plane_solve`: the least-squares plane
  h = p0 + gx x + gy y from its nine running sums (3 x 3 normal equations by cofactors);
* :func:`_idw8`: the inverse-distance average of the nearest known cell along each of
  the 8 directions (:data:`DR8`, :data:`DC8`), the hole filler of local DEM mapping
  (Martin 2014, V.A) and of outside-in gap filling (Martin, Parkes & Dunstan 2014, IV.B).

No validation: callers validate first.
"""

from __future__ import annotations

import numpy as np
from numba import njit

# the eight directions (row step, col step), row by row
DR8 = np.array([-1, -1, -1, 0, 0, 1, 1, 1], dtype=np.int64)
DC8 = np.array([-1, 0, 1, -1, 1, -1, 0, 1], dtype=np.int64)

# running sums of a plane fit before the first point:
# (n, sum x, sum y, sum x^2, sum y^2, sum xy, sum h, sum hx, sum hy)
PLANE_SUMS0 = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)


@njit(cache=True, inline="always")
def _bilinear(h, fy, fx, blend):
    """Bilinear sample of ``h`` at fractional (row, col) = (fy, fx); NaN outside the
    cell centres (or at a NaN position).

    Two arithmetic forms of the same interpolation, which differ in the last bits:
    ``a + t (b - a)`` (``blend`` False) or ``(1 - t) a + t b`` (``blend`` True).
    """
    ny, nx = h.shape
    if not (0.0 <= fy <= ny - 1 and 0.0 <= fx <= nx - 1):
        return np.nan
    i0 = min(int(fy), ny - 2) if ny > 1 else 0
    j0 = min(int(fx), nx - 2) if nx > 1 else 0
    ty = fy - i0
    tx = fx - j0
    i1 = min(i0 + 1, ny - 1)
    j1 = min(j0 + 1, nx - 1)
    if blend:
        a = (1.0 - tx) * h[i0, j0] + tx * h[i0, j1]
        b = (1.0 - tx) * h[i1, j0] + tx * h[i1, j1]
        return (1.0 - ty) * a + ty * b
    a = h[i0, j0] + tx * (h[i0, j1] - h[i0, j0])
    b = h[i1, j0] + tx * (h[i1, j1] - h[i1, j0])
    return a + ty * (b - a)


@njit(cache=True, inline="always")
def _plane_sums_add(s, x, y, v):
    """The plane-fit sums ``s`` (a 9-tuple, :data:`PLANE_SUMS0` at first) with the point
    (x, y) of height v added."""
    return (s[0] + 1.0, s[1] + x, s[2] + y, s[3] + x * x, s[4] + y * y, s[5] + x * y,
            s[6] + v, s[7] + v * x, s[8] + v * y)


@njit(cache=True, inline="always")
def _plane_solve(s, scale):
    """Least-squares plane from its sums: (ok, p0, gx, gy) with h = p0 + gx x + gy y.

    Normal equations [[n sx sy] [sx sxx sxy] [sy sxy syy]] p = [sh shx shy], solved by
    cofactors. ``ok`` is False (and the rest 0) for fewer than 3 points or when
    |det| <= 1e-9 * ``scale`` (the caller's size of a non-degenerate determinant).
    """
    s1, sx, sy, sxx, syy, sxy, sh, shx, shy = s
    if s1 >= 3.0:
        c00 = sxx * syy - sxy * sxy
        c01 = -(sx * syy - sy * sxy)
        c02 = sx * sxy - sy * sxx
        det = s1 * c00 + sx * c01 + sy * c02
        if abs(det) > 1e-9 * scale:
            c11 = s1 * syy - sy * sy
            c12 = -(s1 * sxy - sx * sy)
            c22 = s1 * sxx - sx * sx
            return (True, (c00 * sh + c01 * shx + c02 * shy) / det,
                    (c01 * sh + c11 * shx + c12 * shy) / det,
                    (c02 * sh + c12 * shx + c22 * shy) / det)
    return False, 0.0, 0.0, 0.0


@njit(cache=True)
def _idw8(z, known, r, c, step_len, empty):
    """Inverse-distance average of the nearest known cell along each of the 8 directions
    from (r, c) (``DR8``, ``DC8``; the k-th cell along direction d is at distance
    ``k * step_len[d]``); ``empty`` when no direction meets a known cell."""
    rows, cols = z.shape
    s = 0.0
    w = 0.0
    for d in range(8):
        dr = DR8[d]
        dc = DC8[d]
        rr = r + dr
        cc = c + dc
        k = 1
        while 0 <= rr < rows and 0 <= cc < cols:
            if known[rr, cc]:
                wt = 1.0 / (k * step_len[d])
                s += wt * z[rr, cc]
                w += wt
                break
            rr += dr
            cc += dc
            k += 1
    if w == 0.0:
        return empty
    return s / w
