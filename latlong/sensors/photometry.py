"""Reflectance models of airless surfaces: the radiance factor I/F of a surface point
lit at incidence i, seen at emission e, at phase angle g (I/F = pi x the bidirectional
reflectance r of Hapke 2012; 0 where cos i <= 0 or cos e <= 0).

* :class:`Lambert`: I/F = A mu0 (mu0 = cos i, mu = cos e).
* :class:`LommelSeeliger` (Lommel 1887; Seeliger 1888), the single-scattering limit of
  a dark particulate surface: I/F = 2 A mu0 / (mu0 + mu).
* :class:`LunarLambert` (McEwen 1991, "Photometric functions for photoclinometry and
  other applications", Icarus 92, 298): I/F = A [2 L(g) mu0 / (mu0 + mu) + (1 - L(g))
  mu0], with the limb-darkening weight L(g) = 1 + a g + b g^2 + c g^3 (g in degrees)
  of McEwen's lunar fit (a = -0.019, b = 2.42e-4, c = -1.46e-6; the
  ``LunarLambertMcEwen`` model of USGS ISIS, McEwen 1996, LPSC 27, 841).
* :class:`Hapke`: Hapke's model as in his 2012 book ("Theory of Reflectance and
  Emittance Spectroscopy", 2nd ed., eq. 12.55 form): I/F = K (w/4) mu0e/(mu0e + mue)
  [p(g) (1 + B_SH(g)) + M(mu0e, mue)] (1 + B_CB(g)) S(i, e, psi), with a single-lobe
  Henyey–Greenstein particle phase function p (asymmetry xi < 0: back-scattering),
  the shadow-hiding opposition effect B_SH = B0 / (1 + tan(g/2)/h) (Hapke 1986), the
  coherent-backscatter opposition effect B_CB (Hapke 2002), multiple scattering M =
  H(mu0e/K) H(mue/K) - 1 with Hapke's (2002) H-function approximation, the porosity
  factor K (Hapke 2008) and the macroscopic roughness correction of Hapke (1984) with
  mean slope angle theta-bar (effective cosines mu0e, mue and shadowing S).

A, the *normal albedo* of the three simple models, is I/F at i = e = g = 0. Parameter
sets for Hapke's model (:data:`HAPKE_PRESETS`):

* ``c-type``: (162173) Ryugu before Hayabusa2, Ishiguro et al. 2014 (ApJ 792, 74): w =
  0.041, xi = -0.38, B0 = 1.43, h = 0.050 with theta-bar = 20 deg assumed.
* ``s-type``: (433) Eros from NEAR MSI at 550 nm, Li et al. 2004 (Icarus 172, 415): w =
  0.33, xi = -0.25, theta-bar = 28 deg; the opposition surge B0 = 1.32, h = 0.02 of
  Helfenstein & Veverka's (1989, Asteroids II, 557) average S asteroid.
* ``moon``: Helfenstein & Veverka 1987 (Icarus 72, 342), whole-disk Moon: w = 0.21,
  h = 0.07, theta-bar = 20 deg; their two-lobed phase function and S(0) = 0.71 taken
  as the single-lobe xi = -0.18 with B0 = 2.0 (the form in which the fit is usually
  quoted).

Examples
--------
>>> import numpy as np
>>> radiance_factor(LommelSeeliger(0.1), [1.0, 0.5], [1.0, 1.0], [1.0, 0.5]).round(6)
array([0.1     , 0.066667])
>>> float(radiance_factor(HAPKE_PRESETS["s-type"], 0.8, 0.9, np.cos(0.3))[0]) > 0
True
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from craters._shared import ParameterError, check_finite, check_range

from ._photometry_codes import HAPKE, LAMBERT, LOMMEL_SEELIGER, LUNAR_LAMBERT

__all__ = ["HAPKE_PRESETS", "REFLECTANCES", "Hapke", "Lambert", "LommelSeeliger",
           "LunarLambert", "Photometry", "radiance_factor", "reflectance_model", "with_albedo"]


@dataclass(frozen=True, slots=True)
class _AlbedoLaw:
    """A law scaled by a normal albedo (the three simple models)."""

    albedo: float = 0.12
    """Normal albedo A: I/F at i = e = g = 0, [0, 10]."""

    def __post_init__(self):
        object.__setattr__(self, "albedo", check_range("albedo", self.albedo, 0.0, 10.0))

    def vector(self) -> np.ndarray:
        return np.array([self.albedo], dtype=np.float64)


@dataclass(frozen=True, slots=True)
class Lambert(_AlbedoLaw):
    """Lambert's law (module notes)."""

    code = LAMBERT


@dataclass(frozen=True, slots=True)
class LommelSeeliger(_AlbedoLaw):
    """The Lommel–Seeliger law (module notes)."""

    code = LOMMEL_SEELIGER


@dataclass(frozen=True, slots=True)
class LunarLambert(_AlbedoLaw):
    """McEwen's lunar-Lambert function with a phase-dependent L(g) (module notes)."""

    l_coefficients: tuple[float, float, float] = (-0.019, 2.42e-4, -1.46e-6)
    """(a, b, c) of L(g) = 1 + a g + b g^2 + c g^3, g in degrees (McEwen's lunar fit)."""

    code = LUNAR_LAMBERT

    def __post_init__(self):
        _AlbedoLaw.__post_init__(self)
        coeffs = tuple(check_finite("l_coefficients", c) for c in self.l_coefficients)
        if len(coeffs) != 3:
            raise ParameterError("l_coefficients", f"must be three numbers; got {coeffs}")
        object.__setattr__(self, "l_coefficients", coeffs)

    def vector(self) -> np.ndarray:
        return np.array([self.albedo, *self.l_coefficients], dtype=np.float64)


@dataclass(frozen=True, slots=True)
class Hapke:
    """Hapke's model (module notes; defaults: the ``s-type`` preset)."""

    w: float = 0.33
    """Single-scattering albedo, [0, 1)."""
    xi: float = -0.25
    """Henyey–Greenstein asymmetry of the particle phase function, (-1, 1); < 0
    back-scattering."""
    b0: float = 1.32
    """Amplitude of the shadow-hiding opposition effect B0, >= 0."""
    h: float = 0.02
    """Angular width of the shadow-hiding opposition effect, > 0."""
    theta_bar_deg: float = 28.0
    """Mean slope angle of the macroscopic roughness, degrees, [0, 60]."""
    bc0: float = 0.0
    """Amplitude of the coherent-backscatter opposition effect, >= 0 (0: off)."""
    hc: float = 0.0
    """Angular width of the coherent-backscatter opposition effect (> 0 when bc0 > 0)."""
    porosity_k: float = 1.0
    """Porosity factor K of Hapke (2008), >= 1 (1: the classical model)."""

    code = HAPKE

    def __post_init__(self):
        object.__setattr__(self, "w", check_range("w", self.w, 0.0, 0.999999))
        object.__setattr__(self, "xi", check_range("xi", self.xi, -0.999, 0.999))
        object.__setattr__(self, "b0", check_range("b0", self.b0, 0.0, 100.0))
        h = check_range("h", self.h, 0.0, 10.0)
        if h == 0.0 and self.b0 > 0.0:
            raise ParameterError("h", "must be > 0 when `b0` > 0")
        object.__setattr__(self, "h", h)
        object.__setattr__(self, "theta_bar_deg",
                           check_range("theta_bar_deg", self.theta_bar_deg, 0.0, 60.0))
        object.__setattr__(self, "bc0", check_range("bc0", self.bc0, 0.0, 100.0))
        hc = check_range("hc", self.hc, 0.0, 10.0)
        if hc == 0.0 and self.bc0 > 0.0:
            raise ParameterError("hc", "must be > 0 when `bc0` > 0")
        object.__setattr__(self, "hc", hc)
        object.__setattr__(self, "porosity_k", check_range("porosity_k", self.porosity_k,
                                                           1.0, 10.0))

    def vector(self) -> np.ndarray:
        return np.array([self.w, self.xi, self.b0, self.h,
                         math.tan(math.radians(self.theta_bar_deg)), self.bc0, self.hc,
                         self.porosity_k], dtype=np.float64)


Photometry = Lambert | LommelSeeliger | LunarLambert | Hapke

#: Hapke parameter sets (module notes for the sources).
HAPKE_PRESETS = {
    "moon": Hapke(w=0.21, xi=-0.18, b0=2.0, h=0.07, theta_bar_deg=20.0),
    "s-type": Hapke(w=0.33, xi=-0.25, b0=1.32, h=0.02, theta_bar_deg=28.0),
    "c-type": Hapke(w=0.041, xi=-0.38, b0=1.43, h=0.050, theta_bar_deg=20.0),
}

#: The reflectance names of the command line and :func:`reflectance_model`.
REFLECTANCES = {"lambert": Lambert, "lommel-seeliger": LommelSeeliger,
                "lunar-lambert": LunarLambert, "hapke": Hapke}


def reflectance_model(name: str, *, albedo: float | None = None,
                      preset: str | None = None) -> Photometry:
    """A model by its name (:data:`REFLECTANCES`): ``albedo`` for the simple models,
    ``preset`` (:data:`HAPKE_PRESETS`, default ``s-type``) for Hapke's."""
    if name not in REFLECTANCES:
        raise ParameterError("reflectance", f"must be one of {', '.join(REFLECTANCES)}; "
                             f"got {name!r}")
    if name == "hapke":
        if albedo is not None:
            raise ParameterError("albedo", "does not apply to hapke (choose a preset)")
        key = "s-type" if preset is None else preset
        if key not in HAPKE_PRESETS:
            raise ParameterError("preset", f"must be one of {', '.join(HAPKE_PRESETS)}; "
                                 f"got {preset!r}")
        return HAPKE_PRESETS[key]
    if preset is not None:
        raise ParameterError("preset", f"applies to hapke only, not {name}")
    return REFLECTANCES[name]() if albedo is None else REFLECTANCES[name](albedo)


def with_albedo(model: Photometry, albedo: float) -> Photometry:
    """``model`` with another albedo: the normal albedo of the simple models, the
    single-scattering albedo ``w`` of Hapke's (a band of a multi-band camera)."""
    if isinstance(model, Hapke):
        return dataclasses.replace(model, w=albedo)
    if not isinstance(model, Lambert | LommelSeeliger | LunarLambert):
        raise TypeError(f"`model` must be a reflectance model; got {type(model).__name__}")
    return dataclasses.replace(model, albedo=albedo)


def radiance_factor(model: Photometry, cos_i, cos_e, cos_g) -> np.ndarray:
    """I/F for arrays of cos i, cos e and cos g (broadcast; flattened result)."""
    from ._photometry_kernels import _radiance_factor_kernel  # numba loads here
    if not isinstance(model, Lambert | LommelSeeliger | LunarLambert | Hapke):
        raise TypeError(f"`model` must be a reflectance model; got {type(model).__name__}")
    mu0, mu, cg = (np.ascontiguousarray(a, dtype=np.float64).ravel()
                   for a in np.broadcast_arrays(cos_i, cos_e, cos_g))
    out = np.empty(mu0.shape)
    _radiance_factor_kernel(model.code, model.vector(), mu0, mu, cg, out)
    return out
