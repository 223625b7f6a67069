"""Crater populations: catalogs of craters from layers, with positions, sizes and ages.

Each layer (:mod:`craters.layers`) is a power law or a model-age surface. A power law
has cumulative size-frequency distribution ``N_cum(D) = c D^k`` (D in metres, N per m^2;
k < 0, about -1.8 for lunar mare and -2 for a saturated, self-similar surface, where c
is dimensionless): the expected number of craters with diameter in [d_min, d_max] on an
area A is ``A c (d_min^k - d_max^k)`` (Martin eq. 12), the count is drawn from a
Poisson distribution with that mean, diameters follow the truncated power law by
inversion sampling (Li et al. 2022 eq. 17-21 with B = -k) and ages are uniform in
[age_min, age_max] (the "linear" age distribution of Martin, Parkes & Dunstan 2014). A model-age
layer takes sizes from a body's production function and ages from its chronology
(:mod:`craters.chronology`). Positions are uniform on the sphere (normalised Gaussian
vectors, Martin 2014 eq. 1-4) or in a rectangle; catalogs come sorted oldest first, the
stamping order.
"""

from __future__ import annotations

import math

import numpy as np

from ._shared import check_finite, check_positive, normalize_rng
from .catalog import make_catalog, sort_oldest_first
from .layers import (
    LAYER_TYPES,
    CraterLayer,
    expected_count,
    parse_layer_spec,
    sample_power_law_diameters,
)

__all__ = ["CraterLayer", "expected_count", "fit_power_law_exponent", "parse_layer_spec",
           "population", "power_law_population", "sample_power_law_diameters",
           "uniform_sphere_directions"]

_MAX_CRATERS = 50_000_000


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
    """A crater catalog from one or more crater layers (:class:`CraterLayer` power laws,
    :class:`craters.ModelAgeLayer` model ages), sorted oldest first.

    Positions: uniform on the sphere (``lat_deg, lon_deg``) when ``radius_m`` or
    ``area_m2`` is given (``area_m2`` sets the count for a body of any shape), or
    uniform in the rectangle ``x_range_m`` x ``y_range_m`` (``x_m, y_m``).
    ``degradation`` is NaN (the stamping diffuses each crater for its age) unless the
    layer fixes it. Adds a ``layer`` column. Each layer draws its craters with its own
    :meth:`~CraterLayer.draw` (count, diameters, ages; a model-age layer with
    ``equilibrium`` capped there), then their positions, in layer order from the one
    generator.
    """
    if isinstance(layers, LAYER_TYPES):
        layers = [layers]
    layers = list(layers)
    if not layers or not all(isinstance(la, LAYER_TYPES) for la in layers):
        raise TypeError("`layers` must be a crater layer (CraterLayer, ModelAgeLayer) or a "
                        "non-empty list of them")
    area, where = _area(radius_m, area_m2, x_range_m, y_range_m)
    rng = normalize_rng(rng)
    parts = []
    for idx, la in enumerate(layers):
        mean = la.expected_count(area)
        if mean > _MAX_CRATERS:
            raise ValueError(f"layer {idx} asks for about {mean:.3g} craters (limit "
                             f"{_MAX_CRATERS:.0e}); raise d_min_m or lower c")
        d, age = la.draw(area, rng=rng)
        n = len(d)
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
