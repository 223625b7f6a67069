"""Target bodies: size, surface gravity and the crater-morphology laws of each.

A :class:`Target` holds what makes craters on one body look like that body's: the radius
and surface gravity, the simple-to-complex transition diameter, the onset diameter of
peak-ring basins, the fresh rim-crest-to-floor depth and rim-height power laws of simple
and complex craters (``a D^b`` with D in km, result in km) and the topographic
diffusivity that degrades craters (:mod:`craters.diffusion`).

Measured values are used where published; otherwise lengths scale with 1/g from the
Moon's (the transition and peak-ring diameters, Pike 1980; Melosh 1989 ch. 8), and a
power law ``a D^b`` is carried over self-similarly in D / D_t (``a' = a (D_t'/D_t)^(1-b)``).
Where a depth law is measured but not the rim height, the rim is that depth times the
Moon's rim/depth ratio at the same D / D_t. Every entry names its source; ``scaled``
lists what was carried over from the Moon rather than measured.

Sources:
* Moon: Pike (1977) fresh lunar craters: simple depth 0.196 D^1.010, rim 0.036 D^1.014;
  complex depth 1.044 D^0.301, rim 0.236 D^0.399 (D in km), transition ~15 km
  (15-20 km; Sun et al. 2023 find the onset of transitional craters at 14-17 km).
  Peak-ring basins from ~200 km (Baker et al. 2011, Icarus 214, 377: protobasins and
  peak-ring basins above ~200 km). Diffusivity: Fassett & Thomson (2014, JGR Planets 119,
  2255) kappa = 5.5e-6 m^2/yr at D = 1 km, scaling as D^0.9 (Fassett & Thomson 2015).
  Small fresh craters are shallower than Pike's law (a weak regolith): Stopar et al.
  (2017, Icarus 298, 34; LROC NAC DTMs of 950 craters) class A d/D 0.13 at 40-100 m,
  0.15 at 100-200 m, 0.17 at 200-400 m, ~0.21 above (:attr:`Target.small_depth_ratio`).
* Mars: Garvin, Sakimoto & Frawley (2003, 6th Int. Conf. on Mars, abstract 3277; ~6000
  craters in gridded MOLA topography): fresh simple d = 0.21 D^0.81, complex d = 0.36
  D^0.49 (7-100 km), transition ~7 km (the 1998 MOLA-track fits, Garvin & Frawley 1998,
  GRL 25, 4405: 0.14 D^0.90 and 0.25 D^0.49 from 98 craters, were 30 % shallower).
  Rim heights: the depth times the Moon's rim/depth ratio at the same D / D_t. Below
  1 km, under the fit's range, d/D stays at its 1 km value 0.21 (the power law with
  b = 0.81 would pass 0.3 at 150 m, deeper than any fresh simple crater).
* Mercury: Pike (1988, in Mercury, Univ. Arizona Press): simple d = 0.199 D^0.995,
  complex d = 0.353 D^0.496, transition 10.3 km (MESSENGER laser altimetry of fresh
  craters agrees with these Mariner 10 values: Barnouin et al. 2012, Icarus 219, 414).
* Ceres: Hiesinger et al. (2016, Science 353, aaf4759): transition 7.5-12 km (10 km
  used), far below 1/g scaling (an icy, weak crust). Fresh simple craters d/D 0.11 +-
  0.04 (Gou et al. 2018, Icarus 302, 296: Dawn HAMO DTM, craters >= 1 km; degraded simple
  0.05, complex 0.08 +- 0.04): simple d = 0.11 D. Complex depth: Pike's lunar exponent
  0.301, continuous with the simple law at the transition (d/D 0.068 at 20 km, 0.036 at
  50 km; not a measured fit).
* Earth: transition ~2 km in sedimentary, ~4 km in crystalline targets (Grieve 1987);
  3 km used.
* small-body: fresh asteroid craters d/D = 0.2 (Marchi et al. 2015, as used by Li et al.
  2022 §4.2); gravity from the radius and a bulk density (:func:`small_body`).
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any

from ._shared import ParameterError, check_choice, check_positive, check_range

__all__ = ["SMALL_BODY_REFERENCE_M", "TARGETS", "Target", "get_target", "small_body"]

G_NEWTON = 6.674e-11  # m^3 kg^-1 s^-2
_MOON_G = 1.62
_MOON_DT_KM = 15.0
_MOON_DPR_KM = 200.0


@dataclasses.dataclass(frozen=True, slots=True)
class Target:
    """A target body and its crater-morphology laws (module notes). Power laws are
    ``(a, b)`` for ``a D^b`` with D in km and the result in km."""

    name: str
    """Short name (a key of :data:`TARGETS`)."""
    radius_m: float
    """Mean radius, metres."""
    gravity_m_s2: float
    """Surface gravity, m/s^2."""
    transition_m: float
    """Simple-to-complex transition diameter, metres."""
    peak_ring_m: float
    """Onset diameter of peak-ring basins, metres."""
    simple_depth: tuple[float, float]
    """Fresh simple craters: rim-crest-to-floor depth (a, b)."""
    simple_rim: tuple[float, float]
    """Fresh simple craters: rim height above the surroundings (a, b)."""
    complex_depth: tuple[float, float]
    """Fresh complex craters: rim-crest-to-floor depth (a, b)."""
    complex_rim: tuple[float, float]
    """Fresh complex craters: rim height (a, b)."""
    small_depth_ratio: tuple[tuple[float, float], ...] = ()
    """Fresh d/D of small craters measured shallower than the simple law: knots
    ``(diameter_m, d/D)`` in increasing diameter. Below the last knot the depth is the
    smaller of the simple law and D times the knots' d/D (linear in log D, constant
    below the first knot); the last knot's d/D is not below the law's there, so the two
    meet continuously, and above it the law holds alone. Rim heights in proportion.
    Empty: the simple law at all sizes."""
    kappa_1km_m2_yr: float = 5.5e-6
    """Topographic diffusivity at D = 1 km, m^2/yr (Fassett & Thomson 2014, lunar)."""
    kappa_exponent: float = 0.9
    """kappa(D) = kappa_1km (D / 1 km)^kappa_exponent (Fassett & Thomson 2015)."""
    flux_clock: str | None = None
    """Chronology system (:data:`craters.CHRONOLOGY_SYSTEMS`) whose cumulative impact flux
    paces the diffusion (:func:`craters.diffusion.tau_from_age`); None: constant rate."""
    kappa_calibration_gyr: float = 3.5
    """Age of the surfaces the diffusivity was measured on, Gyr (Fassett & Thomson 2014:
    mare craters): with a ``flux_clock`` a crater of that age diffuses for exactly
    ``kappa T``."""
    scaled: tuple[str, ...] = ()
    """Fields carried over from the Moon by 1/g (not measured on this body)."""
    source: str = ""
    """Where the numbers come from."""

    def __post_init__(self):
        for key in ("radius_m", "gravity_m_s2", "transition_m", "peak_ring_m",
                    "kappa_1km_m2_yr", "kappa_calibration_gyr"):
            check_positive(key, getattr(self, key))
        for key in ("simple_depth", "simple_rim", "complex_depth", "complex_rim"):
            a, b = getattr(self, key)
            check_positive(key, a)
            check_positive(key, b)
        knots = self.small_depth_ratio
        if knots:
            d = [k[0] for k in knots]
            if any(v <= 0 for k in knots for v in k) or d != sorted(set(d)):
                raise ParameterError("small_depth_ratio", "must be (diameter_m, d/D) pairs "
                                     f"> 0 in increasing diameter; got {knots!r}")
            d_top, r_top = knots[-1]
            law = self.simple_depth[0] * (d_top / 1000.0) ** (self.simple_depth[1] - 1.0)
            if r_top < law:
                raise ParameterError("small_depth_ratio", f"the last knot's d/D {r_top:g} "
                                     f"must be >= the simple law's {law:.4g} at {d_top:g} m")

    def with_gravity(self, gravity_m_s2: float) -> Target:
        """The same body under another surface gravity: the transition and peak-ring
        diameters and the complex laws scale with 1/g (simple laws stay)."""
        g = check_positive("gravity_m_s2", gravity_m_s2)
        f = self.gravity_m_s2 / g
        return dataclasses.replace(
            self, gravity_m_s2=g, transition_m=self.transition_m * f,
            peak_ring_m=self.peak_ring_m * f,
            complex_depth=_scaled_law(self.complex_depth, f),
            complex_rim=_scaled_law(self.complex_rim, f),
            scaled=tuple(sorted({*self.scaled, "transition_m", "peak_ring_m",
                                 "complex_depth", "complex_rim"})))


def _scaled_law(law: tuple[float, float], factor: float) -> tuple[float, float]:
    """``a D^b`` carried to a body whose lengths are ``factor`` times larger, self-similar
    in D / D_t: ``a factor^(1 - b)``."""
    a, b = law
    return (a * factor ** (1.0 - b), b)


# fresh lunar craters (Pike 1977): depth and rim height a D^b, D and result in km
_PIKE_SIMPLE_DEPTH = (0.196, 1.010)
_PIKE_SIMPLE_RIM = (0.036, 1.014)
_PIKE_COMPLEX_DEPTH = (1.044, 0.301)
_PIKE_COMPLEX_RIM = (0.236, 0.399)


# fresh (class A) lunar craters below 400 m (Stopar et al. 2017, Icarus 298, 34): d/D
# 0.13 at 40-100 m, 0.15 at 100-200 m, 0.17 at 200-400 m, 0.21 from 400 m; knots at the
# bins' geometric centres (Target.small_depth_ratio), Pike's law from 400 m
_STOPAR_FRESH = ((63.0, 0.13), (141.0, 0.15), (283.0, 0.17), (400.0, 0.21))


# fresh simple craters on Ceres (Gou et al. 2018): d/D 0.11
_CERES_SIMPLE_DEPTH = (0.11, 1.0)


def _from_moon(name: str, radius_m: float, gravity: float, source: str, **measured) -> Target:
    """A body whose unmeasured laws are the Moon's scaled by 1/g."""
    f = _MOON_G / gravity
    base: dict[str, Any] = {
        "transition_m": 1000.0 * _MOON_DT_KM * f, "peak_ring_m": 1000.0 * _MOON_DPR_KM * f,
        "simple_depth": _PIKE_SIMPLE_DEPTH, "simple_rim": _PIKE_SIMPLE_RIM,
        "complex_depth": _scaled_law(_PIKE_COMPLEX_DEPTH, f),
        "complex_rim": _scaled_law(_PIKE_COMPLEX_RIM, f)}
    scaled = tuple(k for k in base if k not in measured)
    if "transition_m" in measured:  # complex laws follow the measured transition
        ft = measured["transition_m"] / (1000.0 * _MOON_DT_KM)
        for key, law in (("complex_depth", _PIKE_COMPLEX_DEPTH),
                         ("complex_rim", _PIKE_COMPLEX_RIM)):
            base[key] = _scaled_law(law, ft)
    base.update(measured)
    ft = base["transition_m"] / (1000.0 * _MOON_DT_KM)
    for kind, (moon_depth, moon_rim) in (("simple", (_PIKE_SIMPLE_DEPTH, _PIKE_SIMPLE_RIM)),
                                         ("complex", (_PIKE_COMPLEX_DEPTH, _PIKE_COMPLEX_RIM))):
        if f"{kind}_depth" in measured and f"{kind}_rim" not in measured:
            # rim = measured depth x the Moon's rim/depth ratio at the same D / D_t
            a, b = base[f"{kind}_depth"]
            c = moon_rim[0] / moon_depth[0] * (1.0 / ft) ** (moon_rim[1] - moon_depth[1])
            base[f"{kind}_rim"] = (a * c, b + moon_rim[1] - moon_depth[1])
    return Target(name, radius_m, gravity, scaled=scaled, source=source, **base)


#: The named target bodies (module notes for the sources).
TARGETS: dict[str, Target] = {
    "moon": Target("moon", 1_737_400.0, 1.62, 15_000.0, 200_000.0, _PIKE_SIMPLE_DEPTH,
                   _PIKE_SIMPLE_RIM, _PIKE_COMPLEX_DEPTH, _PIKE_COMPLEX_RIM,
                   small_depth_ratio=_STOPAR_FRESH, flux_clock="moon",
                   source="Pike 1977; Stopar et al. 2017; Baker et al. 2011; "
                          "Fassett & Thomson 2014"),
    "mars": _from_moon("mars", 3_389_500.0, 3.71, "Garvin, Sakimoto & Frawley 2003 (MOLA)",
                       transition_m=7_000.0, simple_depth=(0.21, 0.81),
                       complex_depth=(0.36, 0.49), small_depth_ratio=((1000.0, 0.21),),
                       flux_clock="mars"),
    "mercury": _from_moon("mercury", 2_439_700.0, 3.70, "Pike 1988",
                          transition_m=10_300.0, simple_depth=(0.199, 0.995),
                          complex_depth=(0.353, 0.496), flux_clock="mercury"),
    "earth": _from_moon("earth", 6_371_000.0, 9.81, "Grieve 1987 (transition)",
                        transition_m=3_000.0),
    "ceres": _from_moon("ceres", 469_700.0, 0.28,
                        "Hiesinger et al. 2016 (transition); Gou et al. 2018 (simple d/D)",
                        transition_m=10_000.0, simple_depth=_CERES_SIMPLE_DEPTH,
                        complex_depth=(_CERES_SIMPLE_DEPTH[0] * 10.0 ** (1.0 - 0.301), 0.301)),
    "vesta": _from_moon("vesta", 262_700.0, 0.25, "1/g scaling from the Moon"),
}


#: Reference diameter of a small body's fresh d/D when it varies with size, metres.
SMALL_BODY_REFERENCE_M = 10.0


def small_body(radius_m: float, density_kg_m3: float = 2000.0,
               depth_ratio: float = 0.2, depth_exponent: float = 1.0) -> Target:
    """A generic small body: surface gravity ``4/3 pi G rho R`` of a sphere of that size
    and bulk density, asteroid fresh craters (d/D = ``depth_ratio``, default 0.2 (Marchi et
    al. 2015); rim/depth as Pike's (1977) lunar simple craters), transition and peak-ring
    diameters by 1/g from the Moon's. A measured body's own d/D goes in ``depth_ratio``,
    e.g. Bennu 0.10 +- 0.03 for craters >= 10 m (Daly et al. 2020, GRL 47, e2020GL089672).
    With ``depth_exponent`` b != 1 the depth is ``d = depth_ratio D (D / 10 m)^(b - 1)``
    (``depth_ratio`` is then the d/D at :data:`SMALL_BODY_REFERENCE_M`): b < 1 makes
    larger craters relatively shallower, as measured on Bennu (0.13 +- 0.04 below 10 m,
    0.10 +- 0.03 above; Daly et al. 2020).

    Examples
    --------
    >>> t = small_body(8_000.0, 2670.0)        # an Eros-sized body
    >>> round(t.gravity_m_s2, 4), t.transition_m > 1e6   # every crater is simple
    (0.006, True)
    """
    r = check_positive("radius_m", radius_m)
    rho = check_positive("density_kg_m3", density_kg_m3)
    dd = check_range("depth_ratio", depth_ratio, 0.01, 0.5)
    b = check_range("depth_exponent", depth_exponent, 0.5, 1.5)
    g = 4.0 / 3.0 * math.pi * G_NEWTON * rho * r
    source = ("Marchi et al. 2015 d/D" if dd == 0.2 and b == 1.0 else
              f"d/D = {dd:g}" + ("" if b == 1.0 else
                                 f" (D / {SMALL_BODY_REFERENCE_M:g} m)^{b - 1.0:g}"))
    a = dd * (SMALL_BODY_REFERENCE_M / 1000.0) ** (1.0 - b)   # d = a D^b, km
    return _from_moon("small-body", r, g, source + "; 1/g scaling",
                      simple_depth=(a, b), simple_rim=(a * 0.036 / 0.196, b))


def get_target(body: str | Target = "moon", *, gravity_m_s2: float | None = None,
               radius_m: float | None = None, density_kg_m3: float | None = None,
               depth_ratio: float | None = None,
               depth_exponent: float | None = None) -> Target:
    """A target by name (:data:`TARGETS` or ``small-body``), optionally under another
    gravity. ``small-body`` needs ``radius_m`` (and takes ``density_kg_m3``, default
    2000, and the fresh ``depth_ratio``, default 0.2, and ``depth_exponent``, default 1,
    :func:`small_body`) unless ``gravity_m_s2`` is given.

    Examples
    --------
    >>> get_target("mars").transition_m, get_target("moon", gravity_m_s2=3.24).transition_m
    (7000.0, 7500.0)
    """
    if isinstance(body, Target):
        target = body
    else:
        names = (*TARGETS, "small-body")
        check_choice("body", body, names)
        if body == "small-body":
            if radius_m is None and gravity_m_s2 is None:
                raise ParameterError("body", "small-body needs {} (or {})",
                                     see=("radius_m", "gravity_m_s2"))
            target = small_body(radius_m if radius_m is not None else 1000.0,
                                density_kg_m3 if density_kg_m3 is not None else 2000.0,
                                depth_ratio if depth_ratio is not None else 0.2,
                                depth_exponent if depth_exponent is not None else 1.0)
        elif depth_ratio is not None or depth_exponent is not None:
            key = "depth_ratio" if depth_ratio is not None else "depth_exponent"
            raise ParameterError(key, f"applies to small-body only (the {body}'s "
                                 "crater depths follow its published laws)")
        else:
            target = TARGETS[body]
    if gravity_m_s2 is not None:
        target = target.with_gravity(gravity_m_s2)
    return target
