"""Crater populations: power-law size-frequency distributions, positions and ages.

Cumulative size-frequency distribution ``N_cum(D) = c D^k`` (D in metres, N per m^2;
k < 0, about -1.8 for lunar mare and -2 for a saturated, self-similar surface, where c
is dimensionless). The expected number of craters with diameter in [d_min, d_max] on an
area A is ``A c (d_min^k - d_max^k)`` (Martin eq. 12); the count is drawn from a
Poisson distribution with that mean. Diameters follow the truncated power law by
inversion sampling (Li et al. 2022 eq. 17-21 with B = -k). Positions are uniform on
the sphere (normalised Gaussian vectors, Martin 2014 eq. 1-4) or in a rectangle;
ages are uniform in [age_min, age_max] (the "linear" age distribution of the lunar
paper) unless given; catalogs come sorted oldest first, the stamping order.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from ._shared import check_finite, check_int, check_positive, check_range, normalize_rng, parse_spec
from .catalog import make_catalog, sort_oldest_first

__all__ = ["CraterLayer", "expected_count", "fit_power_law_exponent", "parse_layer_spec",
           "population",
           "power_law_population", "sample_power_law_diameters",
           "uniform_sphere_directions"]

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
        raise ValueError(f"`d_left` must be < d_right ({d_right}); got {d_left}")
    B = check_finite("B", B)
    u = normalize_rng(rng).random(n)
    if B == 0:
        return d_left * (d_right / d_left) ** u
    lo, hi = d_left ** (-B), d_right ** (-B)
    d = ((hi - lo) * u + lo) ** (-1.0 / B)
    return np.clip(d, d_left, d_right)


def fit_power_law_exponent(diameters_m, d_min_m: float, d_max_m: float) -> float:
    """Maximum-likelihood exponent k of N_cum ~ D^k for diameters in [d_min, d_max].

    Solves the likelihood equation of the truncated power law (pdf ~ D^(k-1)).

    Examples
    --------
    >>> d = sample_power_law_diameters(20000, 5.0, 500.0, 2.0, rng=3)
    >>> round(fit_power_law_exponent(d, 5.0, 500.0), 1)
    -2.0
    """
    from scipy.optimize import brentq

    d = np.asarray(diameters_m, dtype=np.float64)
    a = check_positive("d_min_m", d_min_m)
    b = check_positive("d_max_m", d_max_m)
    if d.size < 2 or a >= b:
        raise ValueError("need at least two diameters and d_min_m < d_max_m")
    if d.min() < a or d.max() > b:
        raise ValueError("all diameters must lie in [d_min_m, d_max_m]")
    mean_log = float(np.log(d).mean())
    la, lb = math.log(a), math.log(b)

    def score(beta: float) -> float:  # d/dB of the mean log-likelihood, B = -k
        ea, eb = a**-beta, b**-beta
        return 1.0 / beta - (eb * lb - ea * la) / (ea - eb) - mean_log

    return -brentq(score, 1e-6, 50.0)


def expected_count(area_m2: float, c: float, k: float, d_min_m: float, d_max_m: float) -> float:
    """Expected number of craters in [d_min, d_max] on ``area_m2``: A c (d_min^k - d_max^k)."""
    return area_m2 * c * (d_min_m**k - d_max_m**k)


def uniform_sphere_directions(n: int, *, rng=None) -> tuple[np.ndarray, np.ndarray]:
    """Latitudes and longitudes (degrees) of ``n`` points uniform on the sphere.

    Normalised standard-normal 3-vectors (Martin 2014 eq. 1-4); longitude in [0, 360).
    """
    rng = normalize_rng(rng)
    v = rng.standard_normal((n, 3))
    norm = np.linalg.norm(v, axis=1)
    bad = norm < 1e-12
    while bad.any():
        v[bad] = rng.standard_normal((int(bad.sum()), 3))
        norm = np.linalg.norm(v, axis=1)
        bad = norm < 1e-12
    v /= norm[:, None]
    lat = np.degrees(np.arcsin(np.clip(v[:, 2], -1.0, 1.0)))
    lon = np.mod(np.degrees(np.arctan2(v[:, 1], v[:, 0])), 360.0)
    return lat, lon


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
    kind: str = "simple"
    """Crater kind recorded in the catalog."""

    def __post_init__(self):
        check_positive("c", self.c)
        k = check_finite("k", self.k)
        if k >= 0:
            raise ValueError(f"`k` must be < 0 (a decreasing cumulative law); got {k!r}")
        dmin = check_positive("d_min_m", self.d_min_m)
        dmax = check_positive("d_max_m", self.d_max_m)
        if dmin >= dmax:
            raise ValueError(f"`d_min_m` must be < d_max_m ({dmax}); got {dmin}")
        amin = check_range("age_min_gyr", self.age_min_gyr, 0.0, 100.0)
        amax = check_range("age_max_gyr", self.age_max_gyr, 0.0, 100.0)
        if amax < amin:
            raise ValueError(f"`age_max_gyr` must be >= age_min_gyr ({amin}); got {amax}")
        if self.degradation is not None:
            check_range("degradation", self.degradation, 0.0, 1.0)
        if not isinstance(self.kind, str) or not self.kind or len(self.kind) > 16:
            raise ValueError(f"`kind` must be a short name (1-16 characters); got {self.kind!r}")


_SPEC = {f.name: (str if f.name == "kind" else float)
         for f in dataclasses.fields(CraterLayer)}
_OLD_KEYS = {"dmin": "d_min_m", "dmax": "d_max_m", "amin": "age_min_gyr",
             "amax": "age_max_gyr", "deg": "degradation"}


def parse_layer_spec(spec: str, *, age_max_gyr: float = 3.5) -> CraterLayer:
    """Parse ``c=0.5,k=-2,d_min_m=2,d_max_m=50[,age_min_gyr=0,age_max_gyr=3.5,
    degradation=0.2,kind=simple]``: the fields of :class:`CraterLayer`.

    Diameters in metres, ages in Gyr; ``age_max_gyr`` defaults to the argument.

    Examples
    --------
    >>> parse_layer_spec("c=0.5,k=-2,d_min_m=2,d_max_m=50").d_max_m
    50.0
    """
    values = parse_spec(spec, _SPEC, ("c", "k", "d_min_m", "d_max_m"), "crater layer",
                        renamed=_OLD_KEYS)
    values.setdefault("age_max_gyr", age_max_gyr)
    try:
        return CraterLayer(**values)
    except (ValueError, TypeError) as exc:
        raise ValueError(f"crater layer {spec!r}: {exc}") from None


def _area(radius_m, area_m2, x_range_m, y_range_m) -> tuple[float, str]:
    given = [v is not None for v in (radius_m, area_m2)]
    rect = x_range_m is not None or y_range_m is not None
    if rect:
        if any(given):
            raise ValueError("give either `x_range_m` and `y_range_m` or radius_m/area_m2")
        if x_range_m is None or y_range_m is None:
            raise ValueError("a rectangle needs both `x_range_m` and `y_range_m`")
        (x0, x1), (y0, y1) = x_range_m, y_range_m
        for name, a, b in (("x_range_m", x0, x1), ("y_range_m", y0, y1)):
            check_finite(name, a)
            check_finite(name, b)
            if b <= a:
                raise ValueError(f"`{name}` must be (low, high) with low < high; got {(a, b)}")
        return (x1 - x0) * (y1 - y0), "plane"
    if sum(given) != 1:
        raise ValueError("give exactly one of `radius_m` (a sphere) or `area_m2`")
    if radius_m is not None:
        r = check_positive("radius_m", radius_m)
        return 4.0 * math.pi * r * r, "sphere"
    return check_positive("area_m2", area_m2), "sphere"


def population(layers, *, radius_m: float | None = None, area_m2: float | None = None,
               x_range_m=None, y_range_m=None, rng=None) -> np.ndarray:
    """A crater catalog from one or more :class:`CraterLayer` s, sorted oldest first.

    Positions: uniform on the sphere (``lat_deg, lon_deg``) when ``radius_m`` or
    ``area_m2`` is given (``area_m2`` sets the count for a body of any shape), or
    uniform in the rectangle ``x_range_m`` x ``y_range_m`` (``x_m, y_m``).
    ``degradation`` is NaN (the stamping diffuses each crater for its age) unless the
    layer fixes it. Adds a ``layer`` column.
    """
    if isinstance(layers, CraterLayer):
        layers = [layers]
    layers = list(layers)
    if not layers or not all(isinstance(la, CraterLayer) for la in layers):
        raise TypeError("`layers` must be a CraterLayer or a non-empty list of them")
    area, where = _area(radius_m, area_m2, x_range_m, y_range_m)
    rng = normalize_rng(rng)
    parts = []
    for idx, la in enumerate(layers):
        mean = expected_count(area, la.c, la.k, la.d_min_m, la.d_max_m)
        if mean > _MAX_CRATERS:
            raise ValueError(f"layer {idx} asks for about {mean:.3g} craters (limit "
                             f"{_MAX_CRATERS:.0e}); raise d_min_m or lower c")
        n = int(rng.poisson(mean))
        d = sample_power_law_diameters(n, la.d_min_m, la.d_max_m, -la.k, rng=rng)
        age = rng.uniform(la.age_min_gyr, la.age_max_gyr, n) if n else np.zeros(0)
        if la.degradation is None:  # from the age, by diffusion when stamped
            deg = np.full(n, np.nan)
        else:
            deg = np.full(n, la.degradation)
        if where == "sphere":
            lat, lon = uniform_sphere_directions(n, rng=rng)
            pos = {"lat_deg": lat, "lon_deg": lon}
        else:
            (x0, x1), (y0, y1) = x_range_m, y_range_m
            pos = {"x_m": rng.uniform(x0, x1, n), "y_m": rng.uniform(y0, y1, n)}
        parts.append(make_catalog(**pos, diameter_m=d, age_gyr=age, degradation=deg,
                                  kind=np.full(n, la.kind), layer=np.full(n, idx)))
    return sort_oldest_first(np.concatenate(parts))


def power_law_population(*, c: float, k: float, d_min: float, d_max: float,
                         radius: float | None = None, area: float | None = None,
                         age_max_gyr: float = 3.5, x_range=None, y_range=None,
                         rng=None) -> np.ndarray:
    """One power-law layer (metres, m^2): shorthand for :func:`population`.

    Examples
    --------
    >>> cat = power_law_population(radius=500.0, c=0.5, k=-2.0, d_min=5.0, d_max=100.0,
    ...                            rng=1)
    >>> cat.dtype.names[:2], bool((cat["age_gyr"][:-1] >= cat["age_gyr"][1:]).all())
    (('lat_deg', 'lon_deg'), True)
    """
    layer = CraterLayer(c, k, d_min, d_max, 0.0, age_max_gyr)
    return population([layer], radius_m=radius, area_m2=area, x_range_m=x_range,
                      y_range_m=y_range, rng=rng)
