"""Crater layers: the two kinds of size-frequency law a population is made of, with one
interface.

* :class:`CraterLayer`, a power law: cumulative ``N(>D) = c D^k`` per m^2 (D in metres,
  k < 0) on [d_min_m, d_max_m], ages uniform in [age_min_gyr, age_max_gyr]
  (``c=0.5,k=-2,d_min_m=5,d_max_m=800[,age_min_gyr=0,age_max_gyr=3.5]``). Diameters by
  inversion sampling (Li et al. 2022 eq. 17-21 with B = -k).
* :class:`ModelAgeLayer`, a surface of a model age: the production function and
  chronology of a body (:data:`craters.CHRONOLOGY_SYSTEMS`) at ``age_gyr``, formation
  ages from the chronology's flux, optionally capped at an equilibrium density
  (``npf=moon,age_gyr=3.8,d_min_m=1000,d_max_m=20000[,equilibrium=trask]``).

Both answer the same questions, which is all the consumers use
(:func:`craters.population`, ``latlong.body_population``, the banded draw of
``dem enhance``): :meth:`~CraterLayer.cumulative_m2` (N(>D) per m^2),
:meth:`~CraterLayer.expected_count` on an area and diameter range,
:meth:`~CraterLayer.sample_diameters`, :meth:`~CraterLayer.sample_ages` and
:meth:`~CraterLayer.draw` (count, diameters and ages on an area). A spec string, a TOML
table or Python keywords use the records' field names; :func:`parse_layer_spec` and
:func:`as_crater_layer` tell the kinds apart by ``npf`` and refuse mixtures.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping

import numpy as np

from . import chronology
from ._shared import (
    ParameterError,
    check_finite,
    check_int,
    check_positive,
    check_range,
    normalize_rng,
    parse_spec,
)

__all__ = ["LAYER_TYPES", "CraterLayer", "ModelAgeLayer", "as_crater_layer", "expected_count",
           "parse_layer_spec", "sample_power_law_diameters"]

_MAX_CRATERS = 50_000_000


def sample_power_law_diameters(n: int, d_left: float, d_right: float, B: float, *,
                               rng=None) -> np.ndarray:
    """``n`` diameters in [d_left, d_right] with pdf ~ D^(-B-1) (Li 2022 eq. 17-21).

    ``D = [(d_right^-B - d_left^-B) u + d_left^-B]^(-1/B)`` with u uniform in [0, 1)
    (eq. 21); B = 0 is the log-uniform limit.

    Examples
    --------
    >>> d = sample_power_law_diameters(1000, 10.0, 100.0, 2.0, rng=0)
    >>> bool(d.min() >= 10.0 and d.max() <= 100.0)
    True
    """
    n = check_int("n", n, 0, _MAX_CRATERS)
    d_left = check_positive("d_left", d_left)
    d_right = check_positive("d_right", d_right)
    if d_left >= d_right:
        raise ParameterError("d_left", f"must be < d_right ({d_right}); got {d_left}")
    B = check_finite("B", B)
    u = normalize_rng(rng).random(n)
    if B == 0:
        return d_left * (d_right / d_left) ** u
    lo, hi = d_left ** (-B), d_right ** (-B)
    d = ((hi - lo) * u + lo) ** (-1.0 / B)
    return np.clip(d, d_left, d_right)


def expected_count(area_m2: float, c: float, k: float, d_min_m: float, d_max_m: float) -> float:
    """Expected number of craters in [d_min, d_max] on ``area_m2``: A c (d_min^k - d_max^k)."""
    return area_m2 * c * (d_min_m**k - d_max_m**k)


def _check_kind(kind) -> None:
    if not isinstance(kind, str) or not kind or len(kind) > 16:
        raise ParameterError("kind", f"must be a short name (1-16 characters); got {kind!r}")


def _range(layer, d_min_m, d_max_m) -> tuple[float, float]:
    return (layer.d_min_m if d_min_m is None else d_min_m,
            layer.d_max_m if d_max_m is None else d_max_m)


@dataclasses.dataclass(frozen=True, slots=True)
class CraterLayer:
    """One power-law layer of a population (piecewise laws = several layers)."""

    c: float
    """Coefficient of N_cum = c D^k (D in metres, N per m^2); > 0."""
    k: float
    """Exponent of N_cum (< 0)."""
    d_min_m: float
    """Smallest diameter, metres."""
    d_max_m: float
    """Largest diameter, metres."""
    age_min_gyr: float = 0.0
    """Youngest age, Gyr."""
    age_max_gyr: float = 3.5
    """Oldest age, Gyr (ages uniform in between)."""
    degradation: float | None = None
    """Fixed degradation for every crater of the layer; None = from age."""
    kind: str = "crater"
    """A free label of the layer (e.g. ``mare``, ``old``, ``secondary``) recorded in the
    catalog's ``kind``; the shape class is the catalog's ``morphology``."""

    def __post_init__(self):
        check_positive("c", self.c)
        k = check_finite("k", self.k)
        if k >= 0:
            raise ParameterError("k", f"must be < 0 (a decreasing cumulative law); got {k!r}")
        dmin = check_positive("d_min_m", self.d_min_m)
        dmax = check_positive("d_max_m", self.d_max_m)
        if dmin >= dmax:
            raise ParameterError("d_min_m", f"must be < d_max_m ({dmax}); got {dmin}")
        amin = check_range("age_min_gyr", self.age_min_gyr, 0.0, 100.0)
        amax = check_range("age_max_gyr", self.age_max_gyr, 0.0, 100.0)
        if amax < amin:
            raise ParameterError("age_max_gyr", f"must be >= age_min_gyr ({amin}); got {amax}")
        if self.degradation is not None:
            check_range("degradation", self.degradation, 0.0, 1.0)
        _check_kind(self.kind)

    def cumulative_m2(self, diameter_m) -> np.ndarray:
        """N(>D) per m^2 of the law, ``c D^k`` (D in metres)."""
        return self.c * np.asarray(diameter_m, dtype=np.float64) ** self.k

    def expected_count(self, area_m2: float, d_min_m: float | None = None,
                       d_max_m: float | None = None) -> float:
        """Expected number of craters in [d_min_m, d_max_m] (default: the layer's range)
        on ``area_m2`` square metres: ``A c (d_min^k - d_max^k)``."""
        lo, hi = _range(self, d_min_m, d_max_m)
        return expected_count(area_m2, self.c, self.k, lo, hi)

    def sample_diameters(self, n: int, *, rng=None) -> np.ndarray:
        """``n`` diameters (m) of the truncated power law (Li 2022 eq. 21)."""
        return sample_power_law_diameters(n, self.d_min_m, self.d_max_m, -self.k, rng=rng)

    def sample_ages(self, n: int, *, rng=None) -> np.ndarray:
        """``n`` ages (Gyr) uniform in [age_min_gyr, age_max_gyr]."""
        rng = normalize_rng(rng)
        return rng.uniform(self.age_min_gyr, self.age_max_gyr, n) if n else np.zeros(0)

    def draw(self, area_m2: float, *, rng=None) -> tuple[np.ndarray, np.ndarray]:
        """Diameters (m) and ages (Gyr) of the layer's craters on ``area_m2``: a Poisson
        count of mean :meth:`expected_count`, then :meth:`sample_diameters` and
        :meth:`sample_ages` (in that order, from the one generator)."""
        rng = normalize_rng(rng)
        n = int(rng.poisson(self.expected_count(area_m2)))
        d = self.sample_diameters(n, rng=rng)
        return d, self.sample_ages(n, rng=rng)


@dataclasses.dataclass(frozen=True, slots=True)
class ModelAgeLayer:
    """Craters of a surface of model age ``age_gyr``: the production function and
    chronology ``npf`` (a key of :data:`craters.CHRONOLOGY_SYSTEMS`), formation ages
    from the chronology's flux over [0, age_gyr], optionally capped at an equilibrium
    density (:mod:`craters.chronology.sampling`).

    Examples
    --------
    >>> la = ModelAgeLayer("moon", 3.8, 1000.0, 20000.0)
    >>> round(la.expected_count(1e9))     # N(>1 km) - N(>20 km) on 1000 km^2
    18
    """

    npf: str
    """Chronology system (production function + chronology): ``moon``, ``mars``,
    ``mercury``, ``vesta``, ``ceres``, ``ida``, ``gaspra``, ``lutetia`` ...
    (:data:`craters.CHRONOLOGY_SYSTEMS`)."""
    age_gyr: float
    """Model age of the surface, Gyr, in (0, the chronology's oldest age (4.5)]."""
    d_min_m: float
    """Smallest diameter, metres (inside the production function's valid range)."""
    d_max_m: float
    """Largest diameter, metres (inside the production function's valid range)."""
    equilibrium: str | None = None
    """Cap the density at an equilibrium function: ``trask`` (Trask 1966) or ``hartmann``
    (Hartmann 1984); None = no cap."""
    degradation: float | None = None
    """Fixed degradation for every crater of the layer; None = from age."""
    kind: str = "crater"
    """A free label of the layer (e.g. ``mare``, ``old``, ``secondary``) recorded in the
    catalog's ``kind``; the shape class is the catalog's ``morphology``."""

    def __post_init__(self):
        system = chronology.get_chronology_system(self.npf)
        chronology.check_age(system, self.age_gyr)
        chronology.check_diameter_range(system, self.d_min_m, self.d_max_m)
        if self.equilibrium is not None:
            chronology.get_equilibrium(self.equilibrium)
        if self.degradation is not None:
            check_range("degradation", self.degradation, 0.0, 1.0)
        _check_kind(self.kind)

    @property
    def saturation_diameter_m(self) -> float | None:
        """Where the production function at ``age_gyr`` meets the equilibrium function
        (metres; below it the surface is saturated); None without ``equilibrium`` or if
        it never saturates."""
        if self.equilibrium is None:
            return None
        return chronology.saturation_diameter_m(self.npf, self.age_gyr, self.equilibrium)

    def cumulative_m2(self, diameter_m) -> np.ndarray:
        """N(>D) per m^2 of the production function at ``age_gyr`` (D in metres; before
        any equilibrium cap)."""
        return chronology.cumulative_density(self.npf, self.age_gyr, diameter_m)

    def expected_count(self, area_m2: float, d_min_m: float | None = None,
                       d_max_m: float | None = None) -> float:
        """Expected number of craters in [d_min_m, d_max_m] (default: the layer's range)
        on ``area_m2`` square metres: ``A (N(d_min) - N(d_max))``; with ``equilibrium``,
        after the cap (in saturated bins ``E[min(n, cap)]`` of the Poisson count n,
        :func:`craters.chronology.expected_survivors`)."""
        lo, hi = _range(self, d_min_m, d_max_m)
        system = chronology.get_chronology_system(self.npf)
        lo, hi = chronology.check_diameter_range(system, lo, hi)
        if self.equilibrium is None:
            n = self.cumulative_m2([lo, hi])
            return float(area_m2 * (n[0] - n[1]))
        edges = chronology.equilibrium_bin_edges(lo, hi)
        pf = self.cumulative_m2(edges)
        eq = chronology.equilibrium_density(self.equilibrium, edges)
        lam = area_m2 * (pf[:-1] - pf[1:])
        want = area_m2 * (eq[:-1] - eq[1:])
        saturated = lam > want
        return float(lam[~saturated].sum()
                     + chronology.expected_survivors(lam[saturated], want[saturated]).sum())

    def sample_diameters(self, n: int, *, rng=None) -> np.ndarray:
        """``n`` diameters (m) of the production function in [d_min_m, d_max_m]
        (without the equilibrium cap)."""
        return chronology.sample_pf_diameters(n, self.npf, self.d_min_m, self.d_max_m, rng=rng)

    def sample_ages(self, n: int, *, rng=None) -> np.ndarray:
        """``n`` formation ages (Gyr), ``P(age <= t) = N1(t) / N1(age_gyr)``."""
        return chronology.formation_ages(n, self.npf, self.age_gyr, rng=rng)

    def draw(self, area_m2: float, *, rng=None) -> tuple[np.ndarray, np.ndarray]:
        """Diameters (m) and formation ages (Gyr) of the layer's craters on ``area_m2``.

        Without ``equilibrium``: a Poisson count, :meth:`sample_diameters`,
        :meth:`sample_ages`. With it, bin by bin (20 a decade): a Poisson count n of
        produced craters, of which, in a saturated bin, the min(n, cap) youngest survive,
        cap being the equilibrium count of the bin on the area
        (:func:`craters.chronology.equilibrium_caps`). Their ages are the smallest order
        statistics of n formation ages, drawn directly (exponential spacings: the i-th
        smallest of n uniforms is ``S_i / (S_k + G)``, S the partial sums of k Exp(1)
        and G ~ Gamma(n - k + 1)), so a saturated bin costs its survivors, not the
        (possibly billions of) craters that erased each other. The same distribution
        as drawing all and removing the oldest (:func:`craters.cap_at_equilibrium`).
        """
        rng = normalize_rng(rng)
        if self.equilibrium is None:
            n = int(rng.poisson(self.expected_count(area_m2)))
            d = self.sample_diameters(n, rng=rng)
            return d, self.sample_ages(n, rng=rng)
        system = chronology.get_chronology_system(self.npf)
        edges, caps = chronology.equilibrium_caps(system, self.age_gyr, self.equilibrium,
                                                  area_m2, self.d_min_m, self.d_max_m, rng=rng)
        pf = self.cumulative_m2(edges)
        produced = rng.poisson(area_m2 * (pf[:-1] - pf[1:]))
        kept = np.where(caps >= 0, np.minimum(produced, caps), produced)
        cf = system.chronology
        n1_total = float(cf.n1(self.age_gyr))
        ds, ages = [], []
        for b in np.flatnonzero(kept):
            k, n = int(kept[b]), int(produced[b])
            ds.append(chronology.sample_pf_diameters(k, system, edges[b], edges[b + 1], rng=rng))
            if k == n:
                ages.append(chronology.formation_ages(k, system, self.age_gyr, rng=rng))
                continue
            s = np.cumsum(rng.standard_exponential(k))
            u = s / (s[-1] + rng.standard_gamma(n - k + 1))
            ages.append(np.clip(cf.age_gyr(u * n1_total), 0.0, self.age_gyr))
        if not ds:
            return np.zeros(0), np.zeros(0)
        return np.concatenate(ds), np.concatenate(ages)


#: The record types of a crater layer.
LAYER_TYPES = (CraterLayer, ModelAgeLayer)
_POWER_LAW = tuple(f.name for f in dataclasses.fields(CraterLayer))
_MODEL_AGE = tuple(f.name for f in dataclasses.fields(ModelAgeLayer))
_STR_KEYS = {"kind", "npf", "equilibrium"}
_SPEC = {name: (str if name in _STR_KEYS else float)
         for name in dict.fromkeys(_POWER_LAW + _MODEL_AGE)}
_OLD_KEYS = {"dmin": "d_min_m", "dmax": "d_max_m", "amin": "age_min_gyr",
             "amax": "age_max_gyr", "deg": "degradation"}


def _layer_from(values: dict, age_max_gyr: float | None):
    """The layer record ``values`` (field -> value) describe; ParameterError on a
    mixture of the two kinds or a missing field."""
    kind: type[ModelAgeLayer | CraterLayer]
    required: tuple[str, ...]
    if "npf" in values:
        for key in values:
            if key not in _MODEL_AGE:
                raise ParameterError(key, "does not go with npf: a model-age layer takes "
                                     f"{', '.join(_MODEL_AGE)} (its size distribution and "
                                     "ages come from the production function and "
                                     "chronology)")
        kind, required = ModelAgeLayer, ("age_gyr", "d_min_m", "d_max_m")
    else:
        for key in values:
            if key not in _POWER_LAW:
                raise ParameterError(key, f"needs npf=NAME (a model-age layer); a power-law "
                                     f"layer takes {', '.join(_POWER_LAW)}")
        kind, required = CraterLayer, ("c", "k", "d_min_m", "d_max_m")
        if age_max_gyr is not None:
            values.setdefault("age_max_gyr", age_max_gyr)
    missing = [k for k in required if k not in values]
    if missing:
        raise ParameterError(missing[0], f"is missing: a {kind.__name__} needs "
                             f"{', '.join(required)}")
    return kind(**values)


def parse_layer_spec(spec: str, *, age_max_gyr: float = 3.5):
    """Parse a crater layer spec into a :class:`CraterLayer` (power law,
    ``c=0.5,k=-2,d_min_m=2,d_max_m=50[,age_min_gyr=0,age_max_gyr=3.5,degradation=0.2,
    kind=mare]``) or a :class:`ModelAgeLayer` (``npf=moon,age_gyr=3.8,d_min_m=1000,
    d_max_m=20000[,equilibrium=trask,degradation=0.2,kind=mare]``): the records' fields.

    Diameters in metres, ages in Gyr; a power law's ``age_max_gyr`` defaults to the
    argument. A bad value raises the record's ParameterError with the spec appended.

    Examples
    --------
    >>> parse_layer_spec("c=0.5,k=-2,d_min_m=2,d_max_m=50").d_max_m
    50.0
    >>> parse_layer_spec("npf=moon,age_gyr=3.8,d_min_m=1000,d_max_m=20000").npf
    'moon'
    >>> parse_layer_spec("npf=moon,c=0.5,age_gyr=3.8,d_min_m=1000,d_max_m=20000")
    ... # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    craters._shared.validation.ParameterError: `c` does not go with npf: ...
    """
    values = parse_spec(spec, _SPEC, (), "crater layer", renamed=_OLD_KEYS)
    required = ("age_gyr", "d_min_m", "d_max_m") if "npf" in values else ("c", "k", "d_min_m",
                                                                           "d_max_m")
    missing = [k for k in required if k not in values]
    if missing:
        raise ValueError(f"crater layer {spec!r}: missing {', '.join(missing)}")
    try:
        return _layer_from(values, age_max_gyr)
    except ParameterError as exc:
        raise ParameterError(exc.name, f"{exc.rule} (crater layer {spec!r})",
                             see=exc.see) from None
    except (ValueError, TypeError) as exc:
        raise ValueError(f"crater layer {spec!r}: {exc}") from None


def as_crater_layer(value, *, age_max_gyr: float | None = None):
    """A crater layer record from a record, a spec string (:func:`parse_layer_spec`) or
    a mapping of its fields (a TOML table); unknown keys and mixtures of the two kinds
    are refused.

    Examples
    --------
    >>> as_crater_layer({"npf": "mars", "age_gyr": 3.5, "d_min_m": 1000, "d_max_m": 8000}).npf
    'mars'
    """
    if isinstance(value, LAYER_TYPES):
        return value
    if isinstance(value, str):
        return parse_layer_spec(value, **({} if age_max_gyr is None
                                          else {"age_max_gyr": age_max_gyr}))
    if isinstance(value, Mapping):
        unknown = sorted(set(value) - set(_SPEC))
        if unknown:
            raise ParameterError(unknown[0], f"is not a crater layer key; allowed: "
                                 f"{', '.join(_SPEC)}")
        return _layer_from(dict(value), age_max_gyr)
    raise TypeError(f"a crater layer must be a CraterLayer, a ModelAgeLayer, a spec string "
                    f"or a table; got {value!r}")
