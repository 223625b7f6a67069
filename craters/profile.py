"""A crater's radial profile on any body, fresh or degraded: the public face of
:mod:`craters.morphology` (fresh shapes) and :mod:`craters.diffusion` (degradation).

Heights are relative to the pre-impact surface, at ``x = r / R`` (R = D/2, rim crest at
x = 1 when fresh), 0 at and beyond the ejecta edge (``DEFAULT_EJECTA_EDGE`` = 3 radii,
r = 1.5 D). A crater's state is its age (diffused with the body's diffusivity for that
time) or a fixed ``degradation``: the share of its fresh depth removed (0 fresh,
1 no relief left).
"""

from __future__ import annotations

import numpy as np

from ._shared import ParameterError, check_range
from .diffusion import (
    TAU_FRESH,
    diffuse_profiles,
    diffusion_nodes,
    tau_from_age,
    tau_from_degradation,
)
from .morphology import EJECTA_EDGE, fresh_morphometry, fresh_profile, morphology_class
from .targets import Target, get_target

__all__ = ["DEFAULT_EJECTA_EDGE", "DIAMETER_RANGE_M", "crater_morphometry", "crater_tau",
           "radial_profile", "slope_erosion"]

#: Diameters of one crater's profile, metres (a 1 mm pit to a 10 000 km basin): depths,
#: rims and the diffusion time D^-2 stay finite and non-zero.
DIAMETER_RANGE_M = (1e-3, 1e7)

#: Default ejecta edge in crater radii: r = 1.5 D, one diameter beyond the rim.
DEFAULT_EJECTA_EDGE = EJECTA_EDGE


def crater_tau(diameter_m: float, *, age_gyr: float | None = None,
               degradation: float | None = None, target: str | Target = "moon") -> float:
    """The dimensionless diffusion time kappa t / R^2 of a crater of that age, or of the
    one that has lost ``degradation`` of its fresh depth (give one of them, or neither
    for a fresh crater)."""
    d = check_range("diameter_m", diameter_m, *DIAMETER_RANGE_M)
    if age_gyr is not None and degradation is not None:
        raise ParameterError("age_gyr", "and {} cannot both be given", see=("degradation",))
    if age_gyr is not None:
        check_range("age_gyr", age_gyr, 0.0, 4.6)
        return float(tau_from_age(d, age_gyr, target))
    if degradation is not None:
        check_range("degradation", degradation, 0.0, 1.0)
        return float(tau_from_degradation(d, degradation, target)[0])
    return 0.0


def radial_profile(x, diameter_m: float, *, target: str | Target = "moon",
                   age_gyr: float | None = None, degradation: float | None = None,
                   ejecta_edge: float = DEFAULT_EJECTA_EDGE) -> np.ndarray:
    """Crater heights (metres) at ``x = r / R`` on flat terrain (module notes).

    A degraded profile is the fresh one evolved exactly by the radial diffusion solve of
    :mod:`craters.diffusion` (not the stamping tables' interpolation).

    Examples
    --------
    >>> h = radial_profile([0.0, 1.0, 3.0], 1000.0)
    >>> [round(float(v), 1) for v in h]
    [-160.0, 36.0, 0.0]
    >>> h = radial_profile([0.0, 1.0], 1000.0, age_gyr=3.5)
    >>> bool(h[1] - h[0] < 196.0 * 0.7)
    True
    """
    t = get_target(target)
    x = np.asarray(x, dtype=np.float64)
    if not np.isfinite(x).all() or (x < 0).any():
        raise ParameterError("x", "must be finite and >= 0 (radii)")
    ejecta_edge = check_range("ejecta_edge", ejecta_edge, 1.5, 20.0)
    tau = crater_tau(diameter_m, age_gyr=age_gyr, degradation=degradation, target=t)
    if tau < TAU_FRESH:
        return fresh_profile(x, diameter_m, t, ejecta_edge=ejecta_edge)
    nodes = diffusion_nodes()
    fresh = fresh_profile(nodes, diameter_m, t, ejecta_edge=ejecta_edge)
    evolved = diffuse_profiles(fresh[None, :], [tau])[0]
    taper = np.clip((ejecta_edge - x) / (0.2 * (ejecta_edge - 1.0)), 0.0, 1.0)
    return np.interp(x, nodes, evolved, left=evolved[0]) * taper * taper * (3 - 2 * taper)


def crater_morphometry(diameter_m: float, *, target: str | Target = "moon",
                       age_gyr: float | None = None, degradation: float | None = None) -> dict:
    """Dimensions of one crater, fresh or degraded: ``depth_m`` (rim crest to floor),
    ``rim_height_m``, ``depth_diameter`` (d/D), ``degradation`` (share of the fresh depth
    removed), ``tau``, ``morphology`` (simple, transitional, complex, peak-ring) and the
    fresh ``floor_diameter_m`` and ``peak_height_m``.

    Examples
    --------
    >>> m = crater_morphometry(100_000.0)
    >>> m["morphology"], round(m["depth_m"]), round(m["peak_height_m"])
    ('complex', 4175, 2019)
    """
    t = get_target(target)
    x = np.linspace(0.0, 1.5, 3001)
    h = radial_profile(x, diameter_m, target=t, age_gyr=age_gyr, degradation=degradation)
    fresh = fresh_morphometry(diameter_m, t)
    rim = float(h.max())
    depth = rim - float(h[x <= 1.2].min())
    return {"depth_m": depth, "rim_height_m": rim, "depth_diameter": depth / diameter_m,
            "degradation": float(np.clip(1.0 - depth / float(fresh["depth_m"]), 0.0, 1.0)),
            "tau": crater_tau(diameter_m, age_gyr=age_gyr, degradation=degradation,
                              target=t),
            "morphology": str(morphology_class(diameter_m, t)),
            "floor_diameter_m": float(fresh["floor_diameter_m"]),
            "peak_height_m": float(fresh["peak_height_m"])}


def slope_erosion(degradation, slope_deg, *, onset_deg: float = 20.0, full_deg: float = 45.0):
    """Extra degradation of craters formed on steep ground (surface creep).

    ``d' = d + (1 - d) s`` with ``s`` rising linearly from 0 at ``onset_deg`` to 1 at
    ``full_deg``: the relief is multiplied by ``1 - s``. A crater on ground flatter than
    20 degrees is unchanged, one on a 45 degree slope keeps no relief; the stamping
    functions erase craters on ground at or above ``full_deg`` (steeper than the angle
    of repose of regolith, ~35-40 degrees).

    Examples
    --------
    >>> float(slope_erosion(0.2, 32.5))
    0.6
    """
    d = np.asarray(degradation, dtype=np.float64)
    if not np.isfinite(d).all() or (d < 0).any() or (d > 1).any():
        raise ParameterError("degradation", "must be in [0, 1]")
    s = np.asarray(slope_deg, dtype=np.float64)
    onset = check_range("onset_deg", onset_deg, 0.0, 90.0)
    full = check_range("full_deg", full_deg, 0.0, 90.0)
    if full <= onset:
        raise ParameterError("full_deg", f"must be > onset_deg ({onset}); got {full}")
    frac = np.clip((np.abs(s) - onset) / (full - onset), 0.0, 1.0)
    return d + (1.0 - d) * frac
