"""Numba kernels of a crater made in the frame of its tilted base (issue 36: on steep
ground a crater stamped along the vertical - a body's radial, a DEM's z - is squeezed
along the dip into a streak). Shared by the writers of a DEM raster
(:mod:`craters._raster_stamp_kernels`), a lat/long body (:mod:`latlong._tilt_kernels`)
and the on-demand field (:mod:`latlong.ondemand._field_kernels`).

The frame: x east, y north, z the vertical at the crater's centre; the base plane of
slopes (gx, gy) has the unit normal N and in-plane axes E', N' (:func:`_tilted_frame`).
A point is taken at its foot on the base plane (where its vertical line meets it), with
in-plane coordinates u: the crater is the same function of u as it is of (x, y) on level
ground. Inside the rim the terrain is replaced by the base plane plus the crater's
surface, and the point can only move vertically, by the t that solves
``t N_z = W(u(t))`` (:func:`tilted_root`); outside, the profile (over N_z) and the rim
offset fading to the ejecta edge are added (:func:`_tilted_pixel`).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ._stamp_kernels import _fbm2 as fbm2
from ._stamp_kernels import _outer_weight as outer_weight
from ._stamp_kernels import _roughness_amp as roughness_amp
from ._stamp_kernels import _table as table
from ._stamp_kernels import _table_value as table_value
from ._stamp_kernels import _warp_x as warp_x

#: Tilt (degrees) of a crater's fitted base from the centre's radial above which it is
#: stamped in the base's own frame; below it the vertical (radial) frame differs from it
#: by less than 1.5 % in distance.
TILT_MIN_DEG = 10.0
#: Cosine of the steepest tilt stamped in the base's frame: beyond ~78 deg a radial
#: height cannot follow the surface (the crater is stamped as on gentler ground).
_TILT_MAX_COS = 0.2
_TILT_ITERATIONS = 40
_SECANT_ITERATIONS = 8  # before falling back to the bracketed root


@njit(cache=True)
def _tilted_frame(gx, gy, out):
    """The frame of a base of slopes (gx, gy) in the developed local frame (x east, y
    north, z the centre's radial): ``out`` = (E' (3), N' (3), N (3), N_z): N the base's
    unit normal, E' east projected on the base and N' = N x E'. Returns the tilt
    (degrees) from the radial."""
    ln = np.sqrt(1.0 + gx * gx + gy * gy)
    nx, ny, nz = -gx / ln, -gy / ln, 1.0 / ln
    ex, ey, ez = 1.0 - nx * nx, -nx * ny, -nx * nz  # east minus its normal part
    le = np.sqrt(ex * ex + ey * ey + ez * ez)
    ex, ey, ez = ex / le, ey / le, ez / le
    out[0], out[1], out[2] = ex, ey, ez
    out[3], out[4], out[5] = ny * ez - nz * ey, nz * ex - nx * ez, nx * ey - ny * ex
    out[6], out[7], out[8] = nx, ny, nz
    out[9] = nz
    return np.degrees(np.arccos(min(nz, 1.0)))


@njit(cache=True, inline="always")
def tilted_coords(x, y, z, fr, radius, rim_tab):
    """(u1, u2, w, azimuth, rim-relative radius) of the point (x, y, z) of the developed
    local frame in the tilted frame ``fr`` (:func:`_tilted_frame`): its in-plane
    coordinates along E' and N', its height along the base normal, the in-plane azimuth
    and its in-plane distance over the rim radius at that azimuth (``rim_tab``: the rim
    perturbation). One formula for the writers (module notes)."""
    u1 = x * fr[0] + y * fr[1] + z * fr[2]
    u2 = x * fr[3] + y * fr[4] + z * fr[5]
    w = x * fr[6] + y * fr[7] + z * fr[8]
    az = np.arctan2(u2, u1)
    return u1, u2, w, az, np.sqrt(u1 * u1 + u2 * u2) / (radius * (1.0 + table(rim_tab, az)))


@njit(cache=True)
def tilted_root(u1, u2, w0, radius, tab, scale, depth, xe, rim_tab, rough, warp, has_rough,
                seed, wavelength, octaves, gain, fr):
    """The vertical change t that puts a point inside the rim of a crater stamped in the
    tilted frame ``fr`` on the crater's surface over the base plane
    (module notes; the point's in-plane coordinates ``u1, u2`` and height ``w0``
    along the base normal; ``rough``: the bowl, wall and ejecta amplitudes, ``warp``:
    :func:`craters.kernels.warp_x`'s)."""
    c = (radius, tab, scale, depth, xe, rim_tab, rough, warp, has_rough, seed, wavelength,
         octaves, gain, fr)
    # the root of f(t) = g(t) - t, g(t) = (W(u(t)) - w0) / N_z. Where g' < 1 (f falls: a
    # single root; |grad W| tan(tilt) < 1, nearly every crater) the secant from t = 0 and
    # the fixed point's first step g(0) finds it in a few evaluations. Elsewhere (f rising
    # between two iterates, or no convergence): g is bounded (the crater's relief), so
    # stepping from t = 0 against f's sign brackets a root; then Illinois false position
    # (a plain fixed point diverges where |grad W| tan(tilt) > 1)
    ta = 0.0
    fa = _target(u1, u2, w0, ta, c) - ta
    if fa == 0.0:
        return 0.0
    tol = 1e-9 * radius
    t0, f0 = ta, fa
    t1 = fa
    f1 = _target(u1, u2, w0, t1, c) - t1
    for _ in range(_SECANT_ITERATIONS):
        if abs(f1) <= tol:
            return t1
        slope = (f1 - f0) / (t1 - t0)
        if not slope < 0.0:
            break
        t2 = t1 - f1 / slope
        if abs(t2 - t1) <= tol:
            return t2
        t0, f0 = t1, f1
        t1 = t2
        f1 = _target(u1, u2, w0, t1, c) - t1
    step = fa
    tb = ta + step
    fb = _target(u1, u2, w0, tb, c) - tb
    k = 0
    while fa * fb > 0.0 and k < 30:
        ta, fa = tb, fb
        step *= 2.0
        tb = ta + step
        fb = _target(u1, u2, w0, tb, c) - tb
        k += 1
    if fa * fb > 0.0:
        return 0.0  # no sign change (not reached: g is bounded)
    side = 0
    for _ in range(_TILT_ITERATIONS):
        t = (ta * fb - tb * fa) / (fb - fa)
        ft = _target(u1, u2, w0, t, c) - t
        if abs(ft) <= tol or abs(tb - ta) <= tol:
            return t
        if ft * fb > 0.0:
            tb, fb = t, ft
            if side == -1:
                fa *= 0.5
            side = -1
        else:
            ta, fa = t, ft
            if side == 1:
                fb *= 0.5
            side = 1
    return (ta * fb - tb * fa) / (fb - fa)


@njit(cache=True, inline="always")
def _target(u1, u2, w0, t, c):
    """:func:`_tilted_target` with the crater's constants ``c`` (:func:`tilted_root`)."""
    (radius, tab, scale, depth, xe, rim_tab, rough, warp, has_rough, seed, wavelength,
     octaves, gain, fr) = c
    return _tilted_target(u1, u2, fr[2], fr[5], fr[9], w0, t, radius, tab, scale, depth, xe,
                          rim_tab, rough, warp, has_rough, seed, wavelength, octaves, gain)


@njit(cache=True)
def _tilted_target(u1, u2, ez, mz, cz, w0, t, radius, tab, scale, depth, xe, rim_tab, rough,
                   warp, has_rough, seed, wavelength, octaves, gain):
    """g(t) of :func:`tilted_root`: the vertical change that would put the point moved
    vertically by t on the crater's surface inside the rim."""
    v1 = u1 + t * ez
    v2 = u2 + t * mz
    xv = (np.sqrt(v1 * v1 + v2 * v2)
          / (radius * (1.0 + table(rim_tab, np.arctan2(v2, v1)))))
    if xv > 1.0:  # beyond the rim: W as at the rim (bounded in t, so a root is bracketed)
        v1 /= xv
        v2 /= xv
        xv = 1.0
    target = scale * table_value(tab, warp_x(xv, v1, v2, radius, warp, seed), xe)
    if has_rough:
        target += (roughness_amp(xv, xe, rough[0], rough[1], rough[2]) * depth * scale
                   * fbm2(seed, v1, v2, wavelength, octaves, gain))
    return (target - w0) / cz


@njit(cache=True, inline="always")
def tilted_ejecta(x, xe, u1, u2, tab, scale, depth, rough, has_rough, seed, wavelength,
                  octaves, gain, cz):
    """Outside the rim (``x`` rim radii, in-plane coordinates ``u1, u2``) a tilted crater's
    profile and roughness overlay (``rough``: bowl, wall, ejecta amplitudes; added when
    ``has_rough``) along its base normal, as a vertical height (over N_z = ``cz``). The
    writers add it to the terrain (a body's, a raster's) or to the blended base (the
    on-demand field)."""
    add = scale * table_value(tab, x, xe)
    if has_rough:
        add += (roughness_amp(x, xe, rough[0], rough[1], rough[2]) * depth * scale
                * fbm2(seed, u1, u2, wavelength, octaves, gain))
    return add / cz


@njit(cache=True, inline="always")
def _tilted_pixel(hv, dx, dy, radius, tab, scale, depth, xe, rim_tab, delta, p0, gx, gy, rough,
                  seed, wavelength, octaves, gain, fr):
    """(inside the ejecta edge?, new height) of a raster pixel at (dx, dy) metres from the
    centre of a crater made in the frame ``fr`` of its tilted base plane
    ``p0 + gx dx + gy dy`` (module notes; ``hv``: the height before it; ``rough``:
    :func:`craters._stamp_kernels._crater_rough`): as the lat/long body's
    :func:`latlong._tilt_kernels._tilted_change` with a plane for the quadric."""
    r2 = gx * dx + gy * dy  # the foot on the base plane
    u1, u2, w0, az, x = tilted_coords(dx, dy, r2, fr, radius, rim_tab)
    if not x < xe:
        return False, hv
    has_rough = rough[0] > 0.0 or rough[1] > 0.0 or rough[2] > 0.0
    if x > 1.0:
        return True, (hv + tilted_ejecta(x, xe, u1, u2, tab, scale, depth, rough, has_rough,
                                         seed, wavelength, octaves, gain, fr[9])
                      + table(delta, az) * outer_weight(x, xe))
    t = tilted_root(u1, u2, w0, radius, tab, scale, depth, xe, rim_tab, rough, rough[3],
                    has_rough, seed, wavelength, octaves, gain, fr)
    return True, p0 + r2 + t
