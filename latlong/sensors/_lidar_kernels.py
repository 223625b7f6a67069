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

from craters.kernels import hash_normal, mix64, read_only_inputs, splitmix64


@njit(cache=True, inline="always")
def _noise(key, beam, ret):
    """A standard normal deviate keyed by (key, beam, return number)."""
    return hash_normal(mix64(splitmix64(key ^ mix64(np.uint64(beam) + np.uint64(1)))
                             + np.uint64(ret)))


@njit(cache=True, inline="always")
def _cos_incidence(normals, f, d, i):
    c = abs(normals[f, 0] * d[i, 0] + normals[f, 1] * d[i, 1] + normals[f, 2] * d[i, 2])
    return min(c, 1.0)


@read_only_inputs("out_n", "out_range", "out_lambert", "out_best")
@njit(cache=True, parallel=True)
def _returns_kernel(t, face, d, normals, weight, spacing, cos_floor, multiple, separation,
                    max_returns, noise_sigma, key, beam0, out_n, out_range, out_lambert,
                    out_best):
    """Group the sub-ray hits of each beam into returns.

    ``t`` (beams, rays): sub-ray ranges (inf = no hit); ``face`` (beams, rays): the
    triangles hit; ``d`` (beams * rays, 3): unit sub-ray directions; ``normals``: unit
    face normals; ``weight`` (rays,): the beam profile. A hit's ``lambert`` is
    ``weight cos(i)`` (for the range-normalised intensity), its energy ``lambert / t^2``,
    its ``slack`` ``t tan(i) spacing`` with cos(i) floored at ``cos_floor`` (module
    notes). Writes ``out_n`` (beams,) the number of returns and, per return, ``out_range``
    (noisy), ``out_lambert`` and ``out_best`` (the sub-ray with the most energy), each
    (beams, max_returns). ``beam0``: the global index of the first beam (the noise key).
    """
    nb, nr = t.shape
    for b in prange(nb):
        order = np.argsort(t[b]) if nr > 1 else np.zeros(1, np.int64)
        k = -1
        last = 0.0
        last_slack = 0.0
        energy_sum = 0.0
        best_e = -1.0
        for s in range(nr):
            j = order[s]
            tj = t[b, j]
            if not np.isfinite(tj):
                break
            c = _cos_incidence(normals, face[b, j], d, b * nr + j)
            lam = weight[j] * c
            e = lam / (tj * tj) if tj > 0 else 0.0
            cf = max(c, cos_floor)
            slack = tj * np.sqrt(1.0 - cf * cf) / cf * spacing
            gap = separation + max(last_slack, slack)
            if k < 0 or (multiple and tj - last > gap and k < max_returns - 1):
                if k >= 0:
                    out_range[b, k] = out_range[b, k] / energy_sum if energy_sum > 0 \
                        else t[b, out_best[b, k]]
                k += 1
                out_range[b, k] = 0.0
                out_lambert[b, k] = 0.0
                out_best[b, k] = j
                energy_sum = 0.0
                best_e = -1.0
            out_range[b, k] += e * tj
            energy_sum += e
            out_lambert[b, k] += lam
            if e > best_e:
                best_e = e
                out_best[b, k] = j
            last = tj
            last_slack = slack
        if k >= 0:
            out_range[b, k] = out_range[b, k] / energy_sum if energy_sum > 0 \
                else t[b, out_best[b, k]]
        out_n[b] = k + 1
        if noise_sigma > 0:
            for r in range(k + 1):
                out_range[b, r] = max(out_range[b, r] + noise_sigma * _noise(key, beam0 + b, r),
                                      0.0)
