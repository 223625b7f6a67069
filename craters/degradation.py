"""Crater degradation: the baseline depth / rim-height curves, age scaling, slope erosion.

Degradation ``d`` in [0, 1] is the normalised erosional time of the baseline crater
(0 = fresh, 1 = fully degraded). Depth and rim height are the fresh values times

* rim:   ``f_R(d) = (exp(-k_R d) - exp(-k_R)) / (1 - exp(-k_R))``  (1 -> 0),
* depth: ``f_H(d) = 1 - (1 - h_end) (1 - exp(-k_H d)) / (1 - exp(-k_H))``  (1 -> h_end).

Why this curve: Ross (1968) describes degradation as a rim that is rounded and lowered
early while the bowl shallows slowly, ending as a rimless depression; diffusion models
(Fassett & Thomson 2014) explain it: the rim is the shortest-wavelength part of the
profile, so it decays fastest, and each wavelength decays exponentially in time. Two
exponentials with k_R = 3 > k_H = 1.5 give that order (at d = 0.3 the rim keeps 38 %,
the depth 63 %); the end depth h_end = 0.25 makes a fully degraded lunar crater
d/D = 0.049 and an asteroid one 0.05, the shallow end of the d/D range that Marchi et
al. (2015) report for degraded asteroid craters (Li et al. 2022 §4.2).

Age scaling (Ross; Soderblom; lunar paper eq. 11): a crater of diameter D_x and age
T_x is in the state the baseline crater (diameter D_b) reaches at
``T_b = T_x (sigma_b / sigma_x) (D_b / D_x)^P``, P in 1.0-1.2; ``d = T_b / lifetime_b``.
Default baseline: a 1 km crater fully degraded after 10 Gyr, P = 1.1, so after 3 Gyr a
300 m crater is gone (d = 1), a 1 km crater is flattened but distinct (d = 0.3) and a
3 km crater has only a softened rim (d = 0.09) - the behaviour of Li et al. 2022 Fig. 11.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from ._shared import check_positive, check_range

__all__ = ["DegradationModel", "degradation_factors", "degradation_from_age",
           "slope_erosion"]


@dataclasses.dataclass(frozen=True, slots=True)
class DegradationModel:
    """The baseline normalised depth and rim-height curves (module notes)."""

    rim_rate: float = 3.0
    """k_R: rate of the exponential rim-height decay over d in [0, 1]."""
    depth_rate: float = 1.5
    """k_H: rate of the exponential depth decay over d in [0, 1] (< rim_rate)."""
    final_depth: float = 0.25
    """h_end: depth of a fully degraded crater as a fraction of the fresh depth."""

    def __post_init__(self):
        check_positive("rim_rate", self.rim_rate)
        check_positive("depth_rate", self.depth_rate)
        check_range("final_depth", self.final_depth, 0.0, 1.0)


DEFAULT_DEGRADATION = DegradationModel()


def _check_degradation(degradation) -> np.ndarray:
    d = np.asarray(degradation, dtype=np.float64)
    if not np.isfinite(d).all() or (d < 0).any() or (d > 1).any():
        bad = d[~(np.isfinite(d) & (d >= 0) & (d <= 1))].ravel()[0]
        raise ValueError(f"`degradation` must be in [0, 1]; got {bad!r}")
    return d


def degradation_factors(degradation, model: DegradationModel = DEFAULT_DEGRADATION):
    """Depth and rim-height factors ``(f_H, f_R)`` for degradation ``d`` in [0, 1].

    Examples
    --------
    >>> fh, fr = degradation_factors([0.0, 1.0])
    >>> fh.tolist(), fr.tolist()
    ([1.0, 0.25], [1.0, 0.0])
    """
    d = _check_degradation(degradation)
    kr, kh = model.rim_rate, model.depth_rate
    f_r = (np.exp(-kr * d) - math.exp(-kr)) / (1.0 - math.exp(-kr))
    f_h = 1.0 - (1.0 - model.final_depth) * (1.0 - np.exp(-kh * d)) / (1.0 - math.exp(-kh))
    return f_h, np.clip(f_r, 0.0, 1.0)


def degradation_from_age(diameter_m, age_gyr, *, baseline_diameter_m: float = 1000.0,
                         baseline_lifetime_gyr: float = 10.0, exponent: float = 1.1,
                         density_ratio: float = 1.0):
    """Normalised degradation of craters of ``diameter_m`` and ``age_gyr``.

    ``T_b = T_x * density_ratio * (D_b / D_x)^exponent`` (lunar paper eq. 11) and
    ``d = min(T_b / baseline_lifetime_gyr, 1)``; ``density_ratio`` is sigma_b / sigma_x.

    Examples
    --------
    >>> [round(float(v), 3) for v in degradation_from_age([300.0, 1000.0, 3000.0], 3.0)]
    [1.0, 0.3, 0.09]
    """
    d = np.asarray(diameter_m, dtype=np.float64)
    t = np.asarray(age_gyr, dtype=np.float64)
    if not np.isfinite(d).all() or (d <= 0).any():
        raise ValueError("`diameter_m` must be finite and > 0")
    if not np.isfinite(t).all() or (t < 0).any():
        raise ValueError("`age_gyr` must be finite and >= 0")
    db = check_positive("baseline_diameter_m", baseline_diameter_m)
    life = check_positive("baseline_lifetime_gyr", baseline_lifetime_gyr)
    p = check_range("exponent", exponent, 0.0, 5.0)
    rho = check_positive("density_ratio", density_ratio)
    tb = t * rho * (db / d) ** p
    return np.clip(tb / life, 0.0, 1.0)


def slope_erosion(degradation, slope_deg, *, onset_deg: float = 20.0, full_deg: float = 45.0):
    """Extra degradation of craters formed on steep ground (surface creep).

    ``d' = d + (1 - d) s`` with ``s`` rising linearly from 0 at ``onset_deg`` to 1 at
    ``full_deg``: a crater on ground flatter than 20 degrees is unchanged, one on a
    45 degree slope is fully degraded. The stamping functions go one step further: a
    crater on ground at or above ``full_deg`` (steeper than the angle of repose of
    regolith, ~35-40 degrees) cannot keep its shape and is erased, not stamped.

    Examples
    --------
    >>> float(slope_erosion(0.2, 32.5))
    0.6
    """
    d = _check_degradation(degradation)
    s = np.asarray(slope_deg, dtype=np.float64)
    onset = check_range("onset_deg", onset_deg, 0.0, 90.0)
    full = check_range("full_deg", full_deg, 0.0, 90.0)
    if full <= onset:
        raise ValueError(f"`full_deg` must be > onset_deg ({onset}); got {full}")
    frac = np.clip((np.abs(s) - onset) / (full - onset), 0.0, 1.0)
    return d + (1.0 - d) * frac
