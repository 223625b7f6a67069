"""Numba kernels that stamp Martin craters into a 2-D height grid (a DEM raster), in
place, oldest first: per crater the plane fit, slope erosion, rim offsets and the writer
(on steep ground in the frame of the tilted base: :mod:`craters._tilt_kernels`). The
profile, noise and plane primitives are in :mod:`craters._stamp_kernels`; the wave-parallel
scheduler over :func:`_stamp_one` is :mod:`craters._wave_kernels`.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from ._stamp_kernels import (
    PARALLEL_MIN,
    _crater_rough,
    _fbm2,
    _fit_plane,
    _outer_weight,
    _rim_offsets,
    _roughness_amp,
    _roughness_octaves,
    _slope_factor,
    _table,
    _table_value,
    _warp_x,
)
from ._tilt_kernels import _TILT_MAX_COS, TILT_MIN_DEG, _tilted_frame, _tilted_pixel


@njit(cache=True)
def _crater_box(h, cy, cx, pixel, radius, xe, rim_tab):
    """Row and column bounds of a crater's reach in the grid."""
    ny, nx = h.shape
    rho_max = 0.0
    for k in range(rim_tab.shape[0]):
        rho_max = max(rho_max, rim_tab[k])
    reach = xe * radius * (1.0 + rho_max) / pixel + 1.0
    return (max(0, int(np.floor(cy - reach))), min(ny - 1, int(np.ceil(cy + reach))),
            max(0, int(np.floor(cx - reach))), min(nx - 1, int(np.ceil(cx + reach))))


@njit(cache=True, parallel=True)
def _write_crater_parallel(h, cy, cx, pixel, radius, tab, scale, depth, xe, rim_tab,
                           delta_tab, p0, gx, gy, rough, seed, wavelength, octaves, gain, fr):
    """:func:`_write_rows` row by row in parallel (pixels are independent)."""
    i_lo, i_hi, j_lo, j_hi = _crater_box(h, cy, cx, pixel, radius, xe, rim_tab)
    for i in prange(i_lo, i_hi + 1):
        _write_rows(i, i + 1, j_lo, j_hi, h, cy, cx, pixel, radius, tab, scale, depth, xe,
                    rim_tab, delta_tab, p0, gx, gy, rough, seed, wavelength, octaves, gain, fr)


@njit(cache=True)
def _write_crater(h, cy, cx, pixel, radius, tab, scale, depth, xe, rim_tab, delta_tab, p0, gx,
                  gy, rough, seed, wavelength, octaves, gain, fr):
    """Write one crater into ``h`` in place (in parallel when it is large)."""
    i_lo, i_hi, j_lo, j_hi = _crater_box(h, cy, cx, pixel, radius, xe, rim_tab)
    if (i_hi - i_lo + 1) * (j_hi - j_lo + 1) >= PARALLEL_MIN:
        _write_crater_parallel(h, cy, cx, pixel, radius, tab, scale, depth, xe, rim_tab,
                               delta_tab, p0, gx, gy, rough, seed, wavelength, octaves, gain,
                               fr)
    else:
        _write_rows(i_lo, i_hi + 1, j_lo, j_hi, h, cy, cx, pixel, radius, tab, scale, depth,
                    xe, rim_tab, delta_tab, p0, gx, gy, rough, seed, wavelength, octaves, gain,
                    fr)


@njit(cache=True)
def _write_rows(r_lo, r_hi, j_lo, j_hi, h, cy, cx, pixel, radius, tab, scale, depth, xe,
                rim_tab, delta_tab, p0, gx, gy, rough, seed, wavelength, octaves, gain, fr):
    """Write rows r_lo..r_hi-1 (columns j_lo..j_hi) of a crater into ``h`` in place:
    inside the rim the plane plus ``scale`` x the profile table (at the warped radius,
    :func:`_warp_x`), outside the terrain plus it (and the plane-to-terrain offset at the
    rim, carried out to the ejecta edge); ``rough``: :func:`_crater_rough`. On a base
    tilted by ``fr`` (``fr[9]`` > 0) the same crater in the base's frame
    (:func:`craters._tilt_kernels._tilted_pixel`)."""
    tilted = fr[9] > 0.0
    for i in range(r_lo, r_hi):
        dy = (i - cy) * pixel
        for j in range(j_lo, j_hi + 1):
            dx = (j - cx) * pixel
            if tilted:
                inside, v = _tilted_pixel(h[i, j], dx, dy, radius, tab, scale, depth, xe,
                                          rim_tab, delta_tab, p0, gx, gy, rough, seed,
                                          wavelength, octaves, gain, fr)
                if inside:
                    h[i, j] = v
                continue
            r = np.sqrt(dx * dx + dy * dy)
            theta = np.arctan2(dy, dx)
            r_theta = radius * (1.0 + _table(rim_tab, theta))
            x = r / r_theta
            if x >= xe:
                continue
            if x <= 1.0:
                v = p0 + gx * dx + gy * dy + scale * _table_value(
                    tab, _warp_x(x, dx, dy, radius, rough[3], seed), xe)
            else:
                v = (h[i, j] + scale * _table_value(tab, x, xe)
                     + _table(delta_tab, theta) * _outer_weight(x, xe))
            if rough[0] > 0.0 or rough[1] > 0.0 or rough[2] > 0.0:
                amp = _roughness_amp(x, xe, rough[0], rough[1], rough[2]) * depth * scale
                v += amp * _fbm2(seed, dx, dy, wavelength, octaves, gain)
            h[i, j] = v


@njit(cache=True)
def _stamp_one(h, c, pixel, cx, cy, diam, tabs, depths, warps, rim_tabs, seeds, xe,
               slope_erosion, onset_deg, full_deg, rough, gain, out_scale, out_slope, out_erased,
               delta, inner_parallel):
    """Stamp crater ``c`` into ``h`` in place (one step of :func:`_stamp_many_kernel`;
    ``delta``: scratch of N_RIM). Its rows are written in parallel when it is large and
    ``inner_parallel`` (False inside a parallel loop: numba does not nest them)."""
    rough = _crater_rough(rough, warps[c])
    radius = 0.5 * diam[c]
    r_px = radius / pixel
    p0, gx, gy, _ = _fit_plane(h, cy[c], cx[c], r_px, pixel)
    slope = np.degrees(np.arctan(np.sqrt(gx * gx + gy * gy)))
    out_slope[c] = slope
    scale = 1.0
    if slope_erosion:
        if slope >= full_deg:
            out_erased[c] = True
            return
        scale = _slope_factor(slope, onset_deg, full_deg)
    _rim_offsets(h, cy[c], cx[c], pixel, radius, rim_tabs[c], p0, gx, gy, delta)
    octaves = _roughness_octaves(radius, pixel)
    # on steep ground the crater is made in its base's frame (issue 36), as on a body
    fr = np.zeros(10)
    if _tilted_frame(gx, gy, fr) < TILT_MIN_DEG or fr[9] < _TILT_MAX_COS:
        fr[9] = 0.0
    if inner_parallel:
        _write_crater(h, cy[c], cx[c], pixel, radius, tabs[c], scale, depths[c], xe,
                      rim_tabs[c], delta, p0, gx, gy, rough, seeds[c], radius, octaves, gain,
                      fr)
    else:
        i_lo, i_hi, j_lo, j_hi = _crater_box(h, cy[c], cx[c], pixel, radius, xe, rim_tabs[c])
        _write_rows(i_lo, i_hi + 1, j_lo, j_hi, h, cy[c], cx[c], pixel, radius, tabs[c], scale,
                    depths[c], xe, rim_tabs[c], delta, p0, gx, gy, rough, seeds[c], radius,
                    octaves, gain, fr)
    out_scale[c] = scale


@njit(cache=True)
def _stamp_many_kernel(h, pixel, cx, cy, diam, tabs, depths, warps, rim_tabs, seeds, xe,
                       slope_erosion, onset_deg, full_deg, rough, gain, out_scale, out_slope,
                       out_erased):
    """Stamp craters in the given order (the caller sorts oldest first), in place.

    For each crater: fit the plane to the obliterated region of the current heights,
    erode on steep ground (ground at or above ``full_deg`` erases the crater: it is not
    written and ``out_erased`` is set; below, the relief is scaled by
    :func:`_slope_factor`, recorded in ``out_scale``), sample the rim offsets, write the
    profile table ``tabs[c]`` (``depths[c]``: its depth, for the roughness amplitude;
    ``warps[c]``: its wall warp, :func:`_warp_x`).
    The serial reference of :func:`craters._wave_kernels._stamp_waves_kernel`.
    """
    delta = np.empty(rim_tabs.shape[1])
    for c in range(cx.shape[0]):
        _stamp_one(h, c, pixel, cx, cy, diam, tabs, depths, warps, rim_tabs, seeds, xe,
                   slope_erosion, onset_deg, full_deg, rough, gain, out_scale, out_slope,
                   out_erased, delta, np.bool_(True))
