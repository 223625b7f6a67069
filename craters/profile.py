"""The Martin crater profile (lunar paper III.A), with the printed problems repaired.

Heights are on flat terrain, relative to the pre-impact surface, as a function of
``x = r / R`` (R = D/2, rim crest at x = 1). With fresh depth H0, rim height Hr0 and
the degradation factors, ``H = f_H H0`` (rim crest to floor) and ``Hr = f_R Hr0``:

* bowl, ``0 <= x <= alpha``:       ``h1 = Hr - H + (H / alpha) x^2``
* interior rim, ``alpha <= x <= 1``: ``h2 = Hr - H (1 - x)^2 / (1 - alpha)``
* exterior rim, ``1 <= x <= beta``: cubic Hermite from (1, Hr, slope 0) to the ejecta
* ejecta, ``beta <= x <= x_e``:    ``h4 = E0 x^-3 + Fc(x)``

h1 and h2 join with equal value and slope at alpha for any alpha (solving the two join
conditions gives exactly these coefficients), and the rim crest is at x = 1 with zero
slope on both sides. ``E0 x^-3`` is McGetchin et al.'s ejecta thickness
``0.14 R^0.74 (r/R)^-3`` (metres, R in metres), capped at the rim height (for D < 31 m
the formula exceeds Pike's rim) and scaled by f_R. The corrective function
``Fc = c0 + c1 (x_e - x) + c2 (x_e - x)^2`` makes the ejecta end on the terrain with zero
slope at the ejecta edge x_e (``h4(x_e) = h4'(x_e) = 0``) and meet the rim,
``h4(1) = Hr + delta`` (delta = plane minus terrain at the rim, 0 on flat ground); h4 is
then convex and decreasing, so the Hermite cubic between the rim and beta is monotone.

alpha and beta follow the paper's joins on flat terrain with the sign error of the
printed beta repaired (DESIGN §4): with ``h_ = Hr0 - Hr + H``,
``alpha = 1 + (Hr - Hr0) / h_`` and ``beta = 1 + 1.5 (Hr0 - Hr) / h_``. A fresh crater
has alpha = beta = 1 (a sharp rim); degradation moves alpha towards the centre and beta
outwards (a rounded, C1 rim); at d = 1 the rim is gone (Hr = 0) and the crater is a
shallow rimless depression of depth h_end H0.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from ._shared import check_finite, check_positive, check_range
from .degradation import DEFAULT_DEGRADATION, DegradationModel, degradation_factors
from .morphometry import Morphometry, fresh_depth, fresh_rim_height

__all__ = ["DEFAULT_EJECTA_EDGE", "ProfileParams", "profile_params", "radial_profile"]

#: Default ejecta edge in crater radii: r = 1.5 D, one diameter beyond the rim.
DEFAULT_EJECTA_EDGE = 3.0


@dataclasses.dataclass(frozen=True, slots=True)
class ProfileParams:
    """Everything the profile needs, in metres and crater radii."""

    radius_m: float
    """R = D / 2, metres."""
    depth_m: float
    """H: rim crest to floor, metres (degraded)."""
    rim_height_m: float
    """Hr: rim crest above the surrounding terrain, metres (degraded)."""
    alpha: float
    """Join of bowl and interior rim, in radii (1 when fresh)."""
    beta: float
    """Join of exterior rim and ejecta, in radii (1 when fresh)."""
    ejecta_m: float
    """E0: ejecta thickness at the rim, metres (McGetchin, capped, degraded)."""
    ejecta_edge: float
    """x_e: end of the ejecta, in radii."""


def profile_params(diameter_m: float, degradation: float = 0.0, *,
                   morphometry: str | Morphometry | None = None,
                   model: DegradationModel = DEFAULT_DEGRADATION,
                   ejecta_edge: float = DEFAULT_EJECTA_EDGE) -> ProfileParams:
    """Compute :class:`ProfileParams` for one crater (see the module notes).

    Examples
    --------
    >>> p = profile_params(1000.0)
    >>> round(p.depth_m, 2), round(p.rim_height_m, 2), p.alpha, p.beta
    (196.0, 36.0, 1.0, 1.0)
    """
    diameter_m = check_positive("diameter_m", diameter_m)
    degradation = check_range("degradation", degradation, 0.0, 1.0)
    ejecta_edge = check_range("ejecta_edge", ejecta_edge, 1.5, 20.0)
    h0 = float(fresh_depth(diameter_m, morphometry))
    hr0 = float(fresh_rim_height(diameter_m, morphometry))
    f_h, f_r = (float(v) for v in degradation_factors(degradation, model))
    h, hr = f_h * h0, f_r * hr0
    h_ = hr0 - hr + h
    alpha = 1.0 + (hr - hr0) / h_
    beta = 1.0 + 1.5 * (hr0 - hr) / h_
    radius = diameter_m / 2.0
    e0 = min(0.14 * radius**0.74, hr0) * f_r
    return ProfileParams(radius, h, hr, alpha, beta, e0, ejecta_edge)


def _ejecta(x, p: ProfileParams, rim_value):
    """h4 and its derivative on [1, x_e] with h4(1) = rim_value (vectorised)."""
    xe, e0 = p.ejecta_edge, p.ejecta_m
    length = xe - 1.0
    c0 = -e0 * xe**-3
    c1 = -3.0 * e0 * xe**-4  # = E'(x_e)
    c2 = (rim_value - e0 - c0 - c1 * length) / length**2
    u = xe - x
    h = e0 * x**-3 + c0 + c1 * u + c2 * u * u
    dh = -3.0 * e0 * x**-4 - c1 - 2.0 * c2 * u
    return h, dh


def _profile(x, p: ProfileParams, delta):
    """Profile heights for x >= 0 (numpy arrays), ``delta`` added at the rim outside."""
    x = np.asarray(x, dtype=np.float64)
    out = np.zeros_like(x)
    h, hr, a, b, xe = p.depth_m, p.rim_height_m, p.alpha, p.beta, p.ejecta_edge
    bowl = x <= a
    out[bowl] = hr - h + (h / a) * x[bowl] ** 2
    wall = (x > a) & (x <= 1.0)
    if a < 1.0:
        out[wall] = hr - h * (1.0 - x[wall]) ** 2 / (1.0 - a)
    rim_value = hr + delta
    outer = (x > 1.0) & (x < xe)
    if outer.any():
        xo = x[outer]
        e_h, _ = _ejecta(np.maximum(xo, b), p, rim_value)
        cubic = xo < b
        if cubic.any():
            hb, db = _ejecta(np.array([b]), p, rim_value)
            t = (xo[cubic] - 1.0) / (b - 1.0)
            span = b - 1.0
            h00 = 2 * t**3 - 3 * t**2 + 1
            h01 = -2 * t**3 + 3 * t**2
            h11 = t**3 - t**2
            e_h[cubic] = h00 * rim_value + h01 * hb[0] + h11 * span * db[0]
        out[outer] = e_h
    return out


def radial_profile(x, diameter_m: float, degradation: float = 0.0, *,
                   morphometry: str | Morphometry | None = None,
                   model: DegradationModel = DEFAULT_DEGRADATION,
                   ejecta_edge: float = DEFAULT_EJECTA_EDGE, rim_offset_m: float = 0.0):
    """Crater heights (metres) at ``x = r / (D/2)`` on flat terrain.

    Parameters
    ----------
    x : array_like
        Radial distance in crater radii (>= 0; the rim crest is at 1).
    diameter_m : float
        Rim-crest diameter in metres.
    degradation : float
        0 (fresh) to 1 (fully degraded); see :mod:`craters.degradation`.
    morphometry : str or Morphometry
        Fresh depth / rim laws, default ``lunar-simple`` (Pike 1977).
    model : DegradationModel
        The baseline degradation curves.
    ejecta_edge : float
        End of the ejecta in radii (default 3, i.e. r = 1.5 D); zero beyond.
    rim_offset_m : float
        Height of the plane above the terrain at the rim (0 on flat ground); the
        exterior starts from ``rim height + rim_offset_m`` so that plane and terrain join.

    Returns
    -------
    float64 array of heights in metres: ``Hr - H`` at the centre, ``Hr`` at the rim,
    0 at and beyond the ejecta edge.

    Examples
    --------
    >>> h = radial_profile([0.0, 1.0, 3.0], 1000.0)
    >>> [round(float(v), 1) for v in h]
    [-160.0, 36.0, 0.0]
    """
    x = np.asarray(x, dtype=np.float64)
    if not np.isfinite(x).all() or (x < 0).any():
        raise ValueError("`x` must be finite and >= 0")
    p = profile_params(diameter_m, degradation, morphometry=morphometry, model=model,
                       ejecta_edge=ejecta_edge)
    delta = check_finite("rim_offset_m", rim_offset_m)
    return _profile(x, p, delta)

