"""Numba kernels of :mod:`latlong.sensors.photometry`: the radiance factor I/F of one
surface point from the cosines of its incidence, emission and phase angles.

``params`` is the model's parameter vector (:meth:`Photometry.vector`); ``code``
selects the model (0 Lambert, 1 Lommel–Seeliger, 2 lunar-Lambert, 3 Hapke). Points
that are not lit or not seen (cos i <= 0 or cos e <= 0) give 0.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from ._photometry_codes import LAMBERT, LOMMEL_SEELIGER, LUNAR_LAMBERT


@njit(cache=True, inline="always")
def _h_function(x, w, k):
    """Chandrasekhar's H function, Hapke's (2002) approximation, with the porosity
    factor K of Hapke (2008): H(x / K)."""
    x = x / k
    if x <= 0.0:
        return 1.0
    gamma = math.sqrt(1.0 - w)
    r0 = (1.0 - gamma) / (1.0 + gamma)
    return 1.0 / (1.0 - w * x * (r0 + 0.5 * (1.0 - 2.0 * r0 * x) * math.log((1.0 + x) / x)))


@njit(cache=True, inline="always")
def _roughness(mu0, mu, cos_g, tan_t):
    """Hapke (1984) macroscopic roughness: effective cosines (mu0e, mue) and the
    shadowing function S(i, e, psi), for a mean slope angle with tangent ``tan_t``."""
    if tan_t <= 0.0:
        return mu0, mu, 1.0
    chi = 1.0 / math.sqrt(1.0 + math.pi * tan_t * tan_t)
    si = math.sqrt(max(0.0, 1.0 - mu0 * mu0))
    se = math.sqrt(max(0.0, 1.0 - mu * mu))
    # azimuth psi between the planes of incidence and emission
    if si * se > 1e-12:
        cos_psi = min(1.0, max(-1.0, (cos_g - mu0 * mu) / (si * se)))
    else:
        cos_psi = 1.0
    psi = math.acos(cos_psi)
    sin2_half = math.sin(0.5 * psi) ** 2
    f = math.exp(-2.0 * math.tan(min(0.5 * psi, 0.5 * math.pi - 1e-9)))
    ti = si / mu0 if mu0 > 0.0 else np.inf
    te = se / mu if mu > 0.0 else np.inf
    # E1, E2 of Hapke (1984) eq. 45-46 (0 at normal incidence / emission)
    e1i = math.exp(-2.0 / (math.pi * tan_t * ti)) if ti > 0.0 else 0.0
    e1e = math.exp(-2.0 / (math.pi * tan_t * te)) if te > 0.0 else 0.0
    e2i = math.exp(-1.0 / (math.pi * tan_t * tan_t * ti * ti)) if ti > 0.0 else 0.0
    e2e = math.exp(-1.0 / (math.pi * tan_t * tan_t * te * te)) if te > 0.0 else 0.0
    eta0 = chi * (mu0 + si * tan_t * e2i / (2.0 - e1i))
    eta = chi * (mu + se * tan_t * e2e / (2.0 - e1e))
    if mu0 >= mu:  # i <= e
        den = 2.0 - e1e - (psi / math.pi) * e1i
        mu0e = chi * (mu0 + si * tan_t * (cos_psi * e2e + sin2_half * e2i) / den)
        mue = chi * (mu + se * tan_t * (e2e - sin2_half * e2i) / den)
        s = mue / eta * mu0 / eta0 * chi / (1.0 - f + f * chi * mu0 / eta0)
    else:  # e < i
        den = 2.0 - e1i - (psi / math.pi) * e1e
        mu0e = chi * (mu0 + si * tan_t * (e2i - sin2_half * e2e) / den)
        mue = chi * (mu + se * tan_t * (cos_psi * e2i + sin2_half * e2e) / den)
        s = mue / eta * mu0 / eta0 * chi / (1.0 - f + f * chi * mu / eta)
    return mu0e, mue, s


@njit(cache=True, inline="always")
def _hapke(mu0, mu, cos_g, p):
    """Hapke's radiance factor I/F = pi r (Hapke 2012, eq. 12.55 form): K w/4
    mu0e/(mu0e + mue) [p(g) (1 + B_SH) + M] (1 + B_CB) S; p = (w, xi, b0, h, tan theta,
    bc0, hc, K)."""
    w, xi, b0, h, tan_t, bc0, hc, k = p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7]
    mu0e, mue, s = _roughness(mu0, mu, cos_g, tan_t)
    g = math.acos(min(1.0, max(-1.0, cos_g)))
    # single-lobe Henyey-Greenstein, xi < 0: back-scattering (Hapke's sign convention)
    phase = (1.0 - xi * xi) / (1.0 + 2.0 * xi * cos_g + xi * xi) ** 1.5
    tan_half = math.tan(0.5 * g)
    b_sh = b0 / (1.0 + tan_half / h) if h > 0.0 else 0.0  # Hapke (1986) SHOE
    b_cb = 0.0
    if bc0 > 0.0 and hc > 0.0:  # Hapke (2002) CBOE
        z = tan_half / hc
        if z > 1e-8:
            b_cb = bc0 * (1.0 + (1.0 - math.exp(-z)) / z) / (2.0 * (1.0 + z) ** 2)
        else:
            b_cb = bc0
    m = _h_function(mu0e, w, k) * _h_function(mue, w, k) - 1.0
    return k * 0.25 * w * mu0e / (mu0e + mue) * (phase * (1.0 + b_sh) + m) * (1.0 + b_cb) * s


@njit(cache=True, inline="always")
def _radiance_factor(code, p, mu0, mu, cos_g):
    """I/F of one point (module notes)."""
    if mu0 <= 0.0 or mu <= 0.0:
        return 0.0
    if code == LAMBERT:
        return p[0] * mu0
    if code == LOMMEL_SEELIGER:
        return p[0] * 2.0 * mu0 / (mu0 + mu)
    if code == LUNAR_LAMBERT:
        g = math.degrees(math.acos(min(1.0, max(-1.0, cos_g))))
        lg = 1.0 + g * (p[1] + g * (p[2] + g * p[3]))
        return p[0] * (2.0 * lg * mu0 / (mu0 + mu) + (1.0 - lg) * mu0)
    return _hapke(mu0, mu, cos_g, p)


@njit(cache=True, parallel=True)
def _radiance_factor_kernel(code, p, mu0, mu, cos_g, out):
    for i in prange(mu0.shape[0]):
        out[i] = _radiance_factor(code, p, mu0[i], mu[i], cos_g[i])
