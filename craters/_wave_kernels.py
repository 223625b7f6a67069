"""Numba kernels that stamp craters on a raster in parallel waves (issue 20).

Craters whose boxes (:func:`craters._raster_stamp_kernels._crater_box`: every pixel a crater
reads or writes) are disjoint commute: stamping them in either order gives the same
heights, bit for bit. :func:`_wave_schedule_kernel` gives each crater, in stamping order,
the first wave after every earlier crater it may overlap (a greedy independent set per
wave, in age order), through a grid of square cells: a crater's wave is one more than
the latest wave of any crater touching one of the cells its box touches (two boxes that
overlap share a cell, so they never share a wave; sharing a cell without overlapping
only costs a later wave). :func:`_stamp_waves_kernel` stamps the waves in order, the
craters of a wave in parallel, each exactly as the serial kernel does: the result is
the serial age-ordered stamp whatever the thread count.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from ._raster_stamp_kernels import _stamp_one

# pixels added around each crater's box in the schedule: the box already holds the plane
# fit, the bilinear rim samples and the writes; the margin makes rounding moot
WAVE_MARGIN = 2


@njit(cache=True, inline="always")
def _span(c, reach, n):
    """First and last pixel (of ``n``) that a crater centred at ``c`` pixels with ``reach``
    pixels may touch, plus :data:`WAVE_MARGIN`; never empty: a crater off the raster
    still samples the pixels next to its centre clamped onto it (the plane fit's
    fallback)."""
    cc = min(max(c, 0.0), n - 1.0)
    lo = max(np.floor(min(c, cc) - reach) - WAVE_MARGIN, 0.0)
    hi = min(np.ceil(max(c, cc) + reach) + WAVE_MARGIN, n - 1.0)
    return int(lo), int(hi)


@njit(cache=True)
def _wave_schedule_kernel(ny, nx, cy, cx, reach, cell, out_wave):
    """Wave (0-based) of each crater, in order, from its box: centre ``cy, cx`` and
    ``reach`` (pixels) on an ``ny`` x ``nx`` raster, through square cells of ``cell``
    pixels; returns the number of waves. Work: the cells the boxes touch."""
    n_cj = (nx + cell - 1) // cell
    latest = np.zeros(((ny + cell - 1) // cell) * n_cj, np.int64)  # 1 + its latest wave
    n_waves = 0
    for c in range(cy.shape[0]):
        i0, i1 = _span(cy[c], reach[c], ny)
        j0, j1 = _span(cx[c], reach[c], nx)
        i0 //= cell
        i1 //= cell
        j0 //= cell
        j1 //= cell
        w = 0
        for i in range(i0, i1 + 1):
            for j in range(j0, j1 + 1):
                w = max(w, latest[i * n_cj + j])
        out_wave[c] = w
        n_waves = max(n_waves, w + 1)
        for i in range(i0, i1 + 1):
            for j in range(j0, j1 + 1):
                latest[i * n_cj + j] = w + 1
    return n_waves


@njit(cache=True, parallel=True)
def _stamp_waves_kernel(order, starts, alone, n_threads, h, pixel, cx, cy, diam, tabs, depths,
                        warps, rim_tabs, seeds, xe, slope_erosion, onset_deg, full_deg, rough,
                        gain, out_scale, out_slope, out_erased):
    """Stamp the waves ``order[starts[w]:starts[w + 1]]`` one after the other (arguments
    from ``h`` on: :func:`craters._raster_stamp_kernels._stamp_many_kernel`'s, full arrays).

    ``order`` puts a wave's costliest craters first. Those with ``alone`` set (boxes of
    PARALLEL_MIN pixels and more), and a wave's only crater, are stamped one at a time
    with their rows written in parallel; the rest of the wave in parallel, thread t of
    ``n_threads`` taking every nt-th crater, rows written serially.
    """
    n_rim = rim_tabs.shape[1]
    delta = np.empty(n_rim)
    for w in range(starts.shape[0] - 1):
        s = starts[w]
        e = starts[w + 1]
        while s < e and (alone[order[s]] or e - s == 1):
            _stamp_one(h, order[s], pixel, cx, cy, diam, tabs, depths, warps, rim_tabs, seeds,
                       xe, slope_erosion, onset_deg, full_deg, rough, gain, out_scale, out_slope,
                       out_erased, delta, np.bool_(True))
            s += 1
        nt = min(n_threads, e - s)
        for t in prange(nt):  # thread t takes every nt-th crater (costliest first)
            scratch = np.empty(n_rim)
            for k in range(s + t, e, nt):
                _stamp_one(h, order[k], pixel, cx, cy, diam, tabs, depths, warps, rim_tabs,
                           seeds, xe, slope_erosion, onset_deg, full_deg, rough, gain, out_scale,
                           out_slope, out_erased, scratch, np.bool_(False))
