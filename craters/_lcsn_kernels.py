"""Numba form of the four LCSN crater kernels (:mod:`craters.lcsn`, Li et al. 2022 eq. 3,
6, 12), the one definition of their formulas for compiled code.

Other packages reach it through :mod:`craters.kernels` (``lcsn_height``): the implicit
backend of ``latlong`` evaluates it at the squared distance of every grid point from a
crater's axis; :func:`craters.lcsn_kernel` evaluates arrays through
:func:`_lcsn_heights_kernel`, so both get the same bits (and none of numpy's
CPU-dependent SIMD ``exp``/``log``). The tests compare it with a pure-numpy reference of
the equations.
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True, inline="always")
def _lcsn_height(kind, r2, kappa, beta, gamma, a, b):
    """Height of LCSN kernel ``kind`` at squared distance ``r2`` (m^2), metres.

    ``-a exp(-b r2)`` (kind 1), ``-a exp(-b r2^2)`` (kind 2), ``kappa L -+ a exp(-b r2)``
    (kinds 3 and 4) with the ring ``L = exp(-beta ln(gamma r2)^2)``, 0 at r2 = 0. Raw
    parameters as :func:`craters.lcsn_kernel` takes them (kappa, beta, gamma unused by
    kinds 1-2); no validation.
    """
    if kind == 1:
        return -a * np.exp(-b * r2)
    if kind == 2:
        return -a * np.exp(-b * r2 * r2)
    ring = 0.0
    if r2 > 0.0:
        lg = np.log(gamma * r2)
        ring = kappa * np.exp(-beta * lg * lg)
    if kind == 3:
        return ring - a * np.exp(-b * r2)
    return ring + a * np.exp(-b * r2)


@njit(cache=True)
def _lcsn_heights_kernel(kind, r, params, out):
    """``out[q]`` = kernel ``kind`` at distance ``r[q]`` (metres); ``params`` =
    (kappa, beta, gamma, a, b). The array form of :func:`_lcsn_height`."""
    for q in range(r.shape[0]):
        out[q] = _lcsn_height(kind, r[q] * r[q], params[0], params[1], params[2], params[3],
                              params[4])
