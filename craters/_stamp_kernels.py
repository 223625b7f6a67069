"""Numba kernels for stamping Martin craters into a 2-D height grid.

Per-crater profile tables (``craters.diffusion.profile_tables``: fresh morphology and
diffusion) read linearly - the tests compare them with the numpy versions - plus a
counter-based 2-D gradient noise for the roughness overlay (a pure function of the
crater's seed and the position, so results never depend on threads or tiling). The
plane fit, bilinear sampling and hash come from ``_raster_kernels`` and ``_rng_kernels``.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ._raster_kernels import PLANE_SUMS0, _bilinear, _plane_solve, _plane_sums_add
from ._rng_kernels import GOLDEN, _mix64

N_RIM = 64  # samples of the rim perturbation and of the rim offset around a crater

# eight unit gradients for the 2-D noise
_GRAD = np.array([[1.0, 0.0], [0.70710678118654752, 0.70710678118654752], [0.0, 1.0],
                  [-0.70710678118654752, 0.70710678118654752], [-1.0, 0.0],
                  [-0.70710678118654752, -0.70710678118654752], [0.0, -1.0],
                  [0.70710678118654752, -0.70710678118654752]])


# --------------------------------------------------------------------------- profile
@njit(cache=True, inline="always")
def _table_value(tab, x, xe):
    """A crater's profile table (heights at ``tab.shape[0]`` evenly spaced radii over
    [0, xe], :func:`craters.diffusion.profile_tables`) at ``x`` radii: the Catmull-Rom
    spline through the samples (C1: a linear interpolant's slope steps at every sample
    showed as rings in low-sun close-ups of worn craters, 1.8 deg every 6 m on a 1 km
    crater), even about the centre (zero slope on the axis), continued by 0 beyond the
    last sample; 0 at and beyond ``xe``."""
    n = tab.shape[0]
    f = x / xe * (n - 1)
    if f >= n - 1:
        return 0.0
    i = int(f)
    p2 = tab[i + 1]
    return _catmull_rom(tab[i - 1] if i > 0 else p2, tab[i], p2,
                        tab[i + 2] if i + 2 < n else 0.0, f - i)


@njit(cache=True, inline="always")
def _table_row_value(tabs, k, x, xe):
    """:func:`_table_value` of the table ``tabs[k]``, read in place: a row view made in a
    parallel loop costs two atomic reference counts per call (4 % of the on-demand
    field's points kernel, 2026-12-06)."""
    n = tabs.shape[1]
    f = x / xe * (n - 1)
    if f >= n - 1:
        return 0.0
    i = int(f)
    p2 = tabs[k, i + 1]
    return _catmull_rom(tabs[k, i - 1] if i > 0 else p2, tabs[k, i], p2,
                        tabs[k, i + 2] if i + 2 < n else 0.0, f - i)


@njit(cache=True, inline="always")
def _catmull_rom(p0, p1, p2, p3, t):
    """The Catmull-Rom spline through p0..p3 at ``t`` in [0, 1) between p1 and p2."""
    return p1 + 0.5 * t * ((p2 - p0) + t * ((2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3)
                                              + t * (3.0 * (p1 - p2) + p3 - p0)))


@njit(cache=True, inline="always")
def _outer_weight(x, xe):
    """How much of the plane-to-terrain offset at the rim is carried at ``x`` outside the
    rim: 1 at the rim, falling quadratically to 0 at the ejecta edge."""
    u = (xe - x) / (xe - 1.0)
    return u * u


@njit(cache=True)
def _table_kernel(tabs, x, xe, out):
    """Profile tables at many x (for testing :func:`_table_value` against numpy)."""
    for c in range(tabs.shape[0]):
        for i in range(x.shape[0]):
            out[c, i] = _table_value(tabs[c], x[i], xe)


@njit(cache=True)
def _table_rows_kernel(tabs, x, xe, out):
    """:func:`_table_kernel` by :func:`_table_row_value` (tests: the same bytes)."""
    for c in range(tabs.shape[0]):
        for i in range(x.shape[0]):
            out[c, i] = _table_row_value(tabs, c, x[i], xe)


# --------------------------------------------------------------------------- noise
_KEY_Y = np.uint64(0xC2B2AE3D27D4EB4F)


@njit(cache=True, inline="always")
def _corner(sx, ky, fx, fy):
    """Gradient of the lattice point whose keys are ``sx`` (the seed xor the column's key
    ``uint64(ix) * GOLDEN``) and ``ky`` (the row's, ``uint64(iy) * _KEY_Y``): 64 random bits
    from one splitmix64 finaliser of the seed mixed with the point's key (a second
    finaliser of the key alone cost 6 % of the on-demand field's time and changed no
    statistic the noise is used for), dotted with (fx, fy)."""
    g = np.int64(_mix64((sx ^ ky) * GOLDEN) & np.uint64(7))
    return _GRAD[g, 0] * fx + _GRAD[g, 1] * fy


@njit(cache=True, inline="always")
def _lattice_coord(x):
    """(lattice index, fraction, the fraction's quintic fade) of the coordinate ``x``."""
    x0 = np.floor(x)
    f = x - x0
    return np.int64(x0), f, f * f * f * (f * (f * 6.0 - 15.0) + 10.0)


@njit(cache=True, inline="always")
def _noise2(seed, x, y):
    """2-D gradient noise in about [-0.8, 0.8], zero at integer lattice points."""
    ix, fx, u = _lattice_coord(x)
    iy, fy, v = _lattice_coord(y)
    # the keys of ix + 1 and iy + 1 by one addition each: (i + 1) c = i c + c mod 2^64
    kx = np.uint64(ix) * GOLDEN
    s0 = seed ^ kx
    s1 = seed ^ (kx + GOLDEN)
    k0 = np.uint64(iy) * _KEY_Y
    k1 = k0 + _KEY_Y
    n00 = _corner(s0, k0, fx, fy)
    n10 = _corner(s1, k0, fx - 1.0, fy)
    n01 = _corner(s0, k1, fx, fy - 1.0)
    n11 = _corner(s1, k1, fx - 1.0, fy - 1.0)
    a = n00 + u * (n10 - n00)
    b = n01 + u * (n11 - n01)
    return a + v * (b - a)


@njit(cache=True, inline="always")
def _fbm2(seed, x, y, wavelength, octaves, gain):
    """fBm of ``octaves`` octaves from ``wavelength`` (metres) halving each octave."""
    total = 0.0
    norm = 0.0
    amp = 1.0
    inv = 1.0 / wavelength
    for o in range(octaves):
        s = seed + np.uint64(o) * np.uint64(0x632BE59BD9B4E019)
        total += amp * _noise2(s, x * inv, y * inv)
        norm += amp
        amp *= gain
        inv *= 2.0
    return total / norm


# --------------------------------------------------------------------------- walls
# Irregular complex-crater interiors (issue 36; real terraces are scalloped, discontinuous
# slump blocks and central peaks are clusters of massifs: Pike 1977; Melosh 1989, ch. 8.3):
# inside the rim the radial coordinate x of the profile lookup is displaced by fBm noise of
# the position, so terraces wander, merge and split and the central peak breaks up. The
# displacement is ``warp`` (0 simple .. 1 complex, :func:`craters.stamp.stamping_profiles`)
# times WALL_WARP radii over the wall (fading to 0 at the rim, which keeps the rim where
# the rim perturbation puts it, and keeps x < 1 inside it) plus PEAK_WARP radii inside
# PEAK_ZONE. A pure function of the crater's seed and the position in its plane.
WALL_WARP = 0.25
WALL_WAVELENGTH = 0.8      # radii
PEAK_WARP = 0.2
PEAK_WAVELENGTH = 0.12     # radii
PEAK_ZONE = 0.3            # radii
_WARP_SALT = np.uint64(0xA24BAED4963EE407)


@njit(cache=True, inline="always")
def _warp_x(x, u, v, radius, warp, seed):
    """The profile coordinate of a point at ``x`` radii and (u, v) metres from the centre
    in the crater's plane, for a crater of ``warp`` in [0, 1] (module notes): ``x`` itself
    outside the rim or when ``warp`` is 0 (a compare inlined into the writers' loops, not a
    call: most craters are simple), else :func:`_warped_x`, in [0, 1)."""
    if warp <= 0.0 or x >= 1.0:
        return x
    return _warped_x(x, u, v, radius, warp, seed)


@njit(cache=True)
def _warped_x(x, u, v, radius, warp, seed):
    """:func:`_warp_x` inside the rim of a crater with a warp."""
    s = seed ^ _WARP_SALT
    d = WALL_WARP * min(1.0, 4.0 * (1.0 - x)) * _fbm2(s, u, v, WALL_WAVELENGTH * radius, 2,
                                                        0.5)
    if x < PEAK_ZONE:
        t = 1.0 - x / PEAK_ZONE
        d += PEAK_WARP * t * t * _fbm2(s + np.uint64(1), u, v, PEAK_WAVELENGTH * radius, 2,
                                       0.5)
    return abs(x + warp * d)


@njit(cache=True, inline="always")
def _crater_rough(rough, warp):
    """A crater's overlay settings for the writers: the bowl, wall and ejecta roughness
    amplitudes of ``rough`` and its wall ``warp`` (:func:`_warp_x`)."""
    out = np.empty(4)
    out[0] = rough[0]
    out[1] = rough[1]
    out[2] = rough[2]
    out[3] = warp
    return out


# --------------------------------------------------------------------------- helpers
@njit(cache=True)
def _fit_plane(h, cy, cx, r_px, pixel):
    """Least-squares plane over the pixels within ``r_px`` of (cy, cx).

    Returns (p0, gx, gy, n): height at the centre and gradients in height per metre.
    Fewer than 3 pixels or a degenerate set: the bilinear height at the centre, flat.
    """
    ny, nx = h.shape
    i_lo = max(0, int(np.ceil(cy - r_px)))
    i_hi = min(ny - 1, int(np.floor(cy + r_px)))
    j_lo = max(0, int(np.ceil(cx - r_px)))
    j_hi = min(nx - 1, int(np.floor(cx + r_px)))
    s = PLANE_SUMS0
    r2 = r_px * r_px
    for i in range(i_lo, i_hi + 1):
        dy = i - cy
        for j in range(j_lo, j_hi + 1):
            dx = j - cx
            if dx * dx + dy * dy > r2:
                continue
            s = _plane_sums_add(s, dx, dy, h[i, j])
    big = max(s[3], s[4], 1.0)  # a determinant's size: n * max(sxx, syy, 1)^2
    ok, p0, px, py = _plane_solve(s, s[0] * big * big)
    if ok:
        return p0, px / pixel, py / pixel, s[0]
    v = _bilinear(h, min(max(cy, 0.0), ny - 1.0), min(max(cx, 0.0), nx - 1.0), False)
    return v, 0.0, 0.0, s[0]


@njit(cache=True, inline="always")
def _table(tab, theta):
    """Periodic linear interpolation of ``tab`` (N_RIM samples over [-pi, pi))."""
    n = tab.shape[0]
    t = (theta + np.pi) * (n / (2.0 * np.pi))
    k0 = int(np.floor(t))
    w = t - k0
    if k0 < 0 or k0 >= n:  # an angle outside [-pi, pi): an integer division, rarely
        k0 = k0 % n
    k1 = k0 + 1
    if k1 == n:
        k1 = 0
    return tab[k0] + w * (tab[k1] - tab[k0])


@njit(cache=True, inline="always")
def _table_row(tabs, k, theta):
    """:func:`_table` of the row ``tabs[k]``, read in place (as :func:`_table_row_value`:
    no row view, whose reference counts are atomic in a parallel loop)."""
    n = tabs.shape[1]
    t = (theta + np.pi) * (n / (2.0 * np.pi))
    k0 = int(np.floor(t))
    w = t - k0
    if k0 < 0 or k0 >= n:
        k0 = k0 % n
    k1 = k0 + 1
    if k1 == n:
        k1 = 0
    return tabs[k, k0] + w * (tabs[k, k1] - tabs[k, k0])


@njit(cache=True, inline="always")
def _roughness_amp(x, xe, a_bowl, a_wall, a_ejecta):
    """Piecewise-linear overlay amplitude: bowl, wall, ejecta fading to 0 at xe."""
    if x <= 0.5:
        return a_bowl
    if x <= 0.9:
        return a_bowl + (a_wall - a_bowl) * (x - 0.5) / 0.4
    if x <= 1.1:
        return a_wall + (a_ejecta - a_wall) * (x - 0.9) / 0.2
    if x >= xe:
        return 0.0
    return a_ejecta * (xe - x) / (xe - 1.1)


@njit(cache=True, inline="always")
def _slope_factor(slope, onset_deg, full_deg):
    """Slope erosion: the share of a crater's relief kept on ground of ``slope`` degrees,
    1 below ``onset_deg`` falling linearly to 0 at ``full_deg`` (the caller erases the
    crater at or above ``full_deg``); degradation d becomes d + (1 - d)(1 - factor)."""
    return 1.0 - min(max((slope - onset_deg) / (full_deg - onset_deg), 0.0), 1.0)


@njit(cache=True, inline="always")
def _roughness_octaves(wavelength, spacing):
    """Octaves of the roughness fBm from ``wavelength`` (metres) halving down to two
    sample spacings (metres): 1 to 10."""
    octaves = 1
    while octaves < 10 and wavelength / 2.0**octaves >= 2.0 * spacing:
        octaves += 1
    return octaves


# --------------------------------------------------------------------------- stamping
# pixels above which a crater is written in parallel: a parallel region costs tens of
# microseconds, far more when the other core is busy, so small craters stay serial
PARALLEL_MIN = 40_000


@njit(cache=True)
def _rim_offsets(h, cy, cx, pixel, radius, rim_tab, p0, gx, gy, out):
    """delta(theta) = plane - terrain at the rim, sampled at N_RIM azimuths (0 outside)."""
    n = rim_tab.shape[0]
    for k in range(n):
        theta = -np.pi + 2.0 * np.pi * k / n
        r = radius * (1.0 + rim_tab[k])
        dx = r * np.cos(theta)
        dy = r * np.sin(theta)
        t = _bilinear(h, cy + dy / pixel, cx + dx / pixel, False)
        out[k] = 0.0 if np.isnan(t) else (p0 + gx * dx + gy * dy) - t
