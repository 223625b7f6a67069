"""Numba kernels of the LIDAR: sub-ray hits of each beam -> returns (latlong.sensors.lidar).

Per beam, the sub-rays that hit are sorted by range and grouped into returns. With
multiple returns a new return starts where two consecutive ranges are more than
``separation`` plus the larger ``slack`` of the two apart (``slack`` = the range step
between neighbouring sub-rays on one tilted surface, so that a slope is not split into
returns), up to ``max_returns`` (later groups join the last); otherwise all hits form one
return. A return's range is the mean of its sub-ray ranges weighted by their received
energy, its energy their sum, its representative sub-ray (for the labels) the one with
the most energy. Range noise: one Gaussian deviate per (key, beam, return number),
counter-based, so a return's noise does not depend on the threads.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from craters.kernels import hash_normal, mix64, splitmix64


@njit(cache=True, inline="always")
def _noise(key, beam, ret):
    """A standard normal deviate keyed by (key, beam, return number)."""
    return hash_normal(mix64(splitmix64(key ^ mix64(np.uint64(beam) + np.uint64(1)))
                             + np.uint64(ret)))


@njit(cache=True, parallel=True)
def _returns_kernel(t, energy, lambert, slack, multiple, separation, max_returns, noise_sigma,
                    key, beam0, out_n, out_range, out_energy, out_lambert, out_best):
    """Group the sub-ray hits of each beam into returns.

    ``t`` (beams, rays): sub-ray ranges (inf = no hit); ``energy`` (beams, rays): received
    energy of each hit; ``lambert`` (beams, rays): beam weight x cos(incidence) (for the
    range-normalised intensity); ``slack`` (beams, rays): module notes. Writes ``out_n``
    (beams,) the number of returns and, per return, ``out_range`` (noisy), ``out_energy``,
    ``out_lambert`` and ``out_best`` (the sub-ray with the most energy), each (beams,
    max_returns). ``beam0``: the global index of the first beam (the noise key).
    """
    nb, nr = t.shape
    for b in prange(nb):
        order = np.argsort(t[b])
        k = -1
        last = 0.0
        last_slack = 0.0
        for s in range(nr):
            j = order[s]
            tj = t[b, j]
            if not np.isfinite(tj):
                break
            gap = separation + max(last_slack, slack[b, j])
            if k < 0 or (multiple and tj - last > gap and k < max_returns - 1):
                k += 1
                out_range[b, k] = 0.0
                out_energy[b, k] = 0.0
                out_lambert[b, k] = 0.0
                out_best[b, k] = j
            e = energy[b, j]
            out_range[b, k] += e * tj
            out_energy[b, k] += e
            out_lambert[b, k] += lambert[b, j]
            if e > energy[b, out_best[b, k]]:
                out_best[b, k] = j
            last = tj
            last_slack = slack[b, j]
        out_n[b] = k + 1
        for r in range(k + 1):
            rng_m = out_range[b, r] / out_energy[b, r] if out_energy[b, r] > 0 \
                else t[b, out_best[b, r]]
            if noise_sigma > 0:
                rng_m += noise_sigma * _noise(key, beam0 + b, r)
            out_range[b, r] = max(rng_m, 0.0)
