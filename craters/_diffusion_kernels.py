"""Numba kernels of the stamping tables (:mod:`craters.diffusion`, :mod:`craters.stamp`):
the tables of many craters as the bilinear blend (in log D and log tau) of the cached
node shapes, times each crater's fresh depth; their rim and floor heights; the irregular
rims' spectra and scaling. Elementwise per crater, so the result does not depend on the
thread count; ``tests/craters/test_diffusion_kernels.py`` compares each with the numpy
expression it replaces, bit for bit (the numpy versions made a third of a 50 000-crater
stamp's serial time, issue 20)."""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from ._calls import read_only_inputs


@njit(cache=True, parallel=True)
def _blend_tables(stack, a, b, j0, fd, ft, depth, rows, out):
    """``out[rows[c]] = ((1 - fd)((1 - ft) S[a, j0] + ft S[a, j0 + 1])
    + fd ((1 - ft) S[b, j0] + ft S[b, j0 + 1])) depth[c]`` for every crater c, with S =
    ``stack`` (nodes, tau nodes, table) in float32 (straight into the caller's rows: no
    (n, table) temporary and copy, 0.23 s of a 50 000-crater stamp)."""
    m = out.shape[1]
    for c in prange(a.shape[0]):
        ia, ib, j = a[c], b[c], j0[c]
        wd, wt = fd[c], ft[c]
        s = depth[c]
        r = rows[c]
        for k in range(m):  # the numpy expression's order of operations, for the same bits
            lo = (1.0 - wt) * stack[ia, j, k] + wt * stack[ia, j + 1, k]
            hi = (1.0 - wt) * stack[ib, j, k] + wt * stack[ib, j + 1, k]
            out[r, k] = ((1.0 - wd) * lo + wd * hi) * s


@njit(cache=True, parallel=True)
def _rim_and_floor(tabs, n_rim_cols, n_inner_cols, rim, floor):
    """Per row of ``tabs``: ``rim`` = max of the first ``n_rim_cols`` columns, ``floor`` =
    min of the first ``n_inner_cols`` (numpy's max/min of those slices, one pass)."""
    for c in prange(tabs.shape[0]):
        hi = tabs[c, 0]
        for k in range(1, n_rim_cols):
            hi = max(hi, tabs[c, k])
        lo = tabs[c, 0]
        for k in range(1, n_inner_cols):
            lo = min(lo, tabs[c, k])
        rim[c] = hi
        floor[c] = lo


@njit(cache=True, parallel=True)
def _rim_spectra(phases, coef, sign, harmonics, spec):
    """``spec[c, harmonics[k]] = coef[k] * exp(1j phases[c, k]) * sign[k]`` (numpy's order
    of operations, for the same bits; ``spec`` zeroed elsewhere by the caller)."""
    for c in prange(phases.shape[0]):
        for k in range(harmonics.shape[0]):
            spec[c, harmonics[k]] = coef[k] * np.exp(1j * phases[c, k]) * sign[k]


@read_only_inputs("out")
@njit(cache=True, parallel=True)
def _scale_rims(rho, irr, out):
    """``out[c] = rho[c] / peak * irr[c]`` with peak = max |rho[c]| (1 where 0)."""
    for c in prange(rho.shape[0]):
        peak = 0.0
        for k in range(rho.shape[1]):
            peak = max(peak, abs(rho[c, k]))
        if peak <= 0.0:
            peak = 1.0
        for k in range(rho.shape[1]):
            out[c, k] = rho[c, k] / peak * irr[c]
