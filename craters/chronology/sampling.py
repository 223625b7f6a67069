"""Crater populations of a given model age, in metres: the cumulative density, diameters
drawn from a production function, formation ages drawn from a chronology, the
saturation diameter and the equilibrium cap.

* Density: ``N(>D, T) = N1(T) 10^(P(log10 D_km)) 1e-6`` per m^2 (the production
  function's shape ``P`` scaled by the chronology, :mod:`craters.chronology.functions`).
* Diameters: inversion sampling of the truncated distribution on [d_min, d_max]: a
  uniform ``u`` gives ``N* = N(d_min) - u (N(d_min) - N(d_max))`` and ``D = N^-1(N*)``,
  read off a table of ``log10 N`` against ``log10 D`` with 2000 points a decade
  (piecewise power laws between them: the polynomial's curvature over 1/2000 decade
  moves D by < 1e-7 relative).
* Formation ages: a surface of age T holds ``N1(T)`` craters >= 1 km per km^2, of which
  ``N1(t)`` formed in the last t Gyr, so a crater's age has the distribution
  ``P(age <= t) = N1(t) / N1(T)`` on [0, T] (the exponentially falling flux of
  Neukum et al. 2001: most craters of an old surface are nearly as old as the surface).
* Equilibrium: a surface cannot hold more craters than the equilibrium density (Trask
  1966; Hartmann 1984): new craters erase as many old ones as they add. The cap works
  bin by bin (20 bins a decade, the craterstats binning): in a bin where the production
  function at age T exceeds the equilibrium function, the area keeps at most
  ``A (N_eq(D_lo) - N_eq(D_hi))`` craters and the oldest beyond that number are removed
  (young craters erase old ones; :func:`equilibrium_caps`, :func:`cap_at_equilibrium`).
  The saturation diameter is where the production function at age T meets the
  equilibrium function (cumulative); below it the surface is saturated.
"""

from __future__ import annotations

import math

import numpy as np

from .._shared import ParameterError, check_int, check_positive, normalize_rng
from .systems import ChronologySystem, get_chronology_system, get_equilibrium

__all__ = ["cap_at_equilibrium", "check_age", "check_diameter_range", "cumulative_density",
           "equilibrium_bin_edges", "equilibrium_caps", "equilibrium_density",
           "expected_survivors", "formation_ages", "saturation_diameter_m",
           "sample_pf_diameters"]

_KM2_PER_M2 = 1e-6
_TABLE_PER_DECADE = 2000
_BINS_PER_DECADE = 20
_MAX_N = 50_000_000


def check_age(system: ChronologySystem, age_gyr, name: str = "age_gyr") -> float:
    """``age_gyr`` as a float if it lies in (0, the chronology's oldest age]; ParameterError
    under ``name`` otherwise."""
    t_max = system.chronology.t_max_gyr
    if isinstance(age_gyr, bool) or not isinstance(age_gyr, int | float | np.floating):
        raise ParameterError(name, f"must be a number of Gyr in (0, {t_max:g}]; got "
                             f"{age_gyr!r}")
    t = float(age_gyr)
    if not (math.isfinite(t) and 0.0 < t <= t_max):
        raise ParameterError(name, f"must be in (0, {t_max:g}] Gyr (the range of the "
                             f"{system.chronology.name} chronology); got {age_gyr!r}")
    return t


def check_diameter_range(system: ChronologySystem, d_min_m, d_max_m) -> tuple[float, float]:
    """``(d_min_m, d_max_m)`` as floats if they lie in the production function's valid
    range with ``d_min_m < d_max_m``; ParameterError naming the bad one otherwise."""
    lo, hi = system.d_range_m
    rule = (f"must be in [{lo:g}, {hi:g}] m (the valid range of the "
            f"{system.production.name} production function)")
    out = []
    for name, value in (("d_min_m", d_min_m), ("d_max_m", d_max_m)):
        v = check_positive(name, value)
        # a 1e-9 slack so that km ranges converted to metres round-trip
        if not lo * (1 - 1e-9) <= v <= hi * (1 + 1e-9):
            raise ParameterError(name, f"{rule}; got {value!r}")
        out.append(min(max(v, lo), hi))
    if out[0] >= out[1]:
        raise ParameterError("d_min_m", f"must be < d_max_m ({out[1]:g}); got {out[0]:g}")
    return out[0], out[1]


def cumulative_density(npf, age_gyr: float, diameter_m) -> np.ndarray:
    """N(>D) per m^2 of the production function ``npf`` (a name of
    :data:`craters.CHRONOLOGY_SYSTEMS`) on a surface of model age ``age_gyr``.

    Examples
    --------
    >>> float(cumulative_density("moon", 1.0, 1000.0)) * 1e6   # N(>1 km) per km^2
    0.000838
    """
    system = get_chronology_system(npf)
    t = check_age(system, age_gyr)
    d_km = np.asarray(diameter_m, dtype=np.float64) * 1e-3
    n1 = float(system.chronology.n1(t))
    return system.production.cumulative_km2(d_km, n1) * _KM2_PER_M2


def equilibrium_density(equilibrium, diameter_m) -> np.ndarray:
    """Equilibrium N(>D) per m^2 (``trask`` or ``hartmann``) at ``diameter_m``."""
    eq = get_equilibrium(equilibrium)
    return eq.cumulative_km2(np.asarray(diameter_m, dtype=np.float64) * 1e-3) * _KM2_PER_M2


def sample_pf_diameters(n: int, npf, d_min_m: float, d_max_m: float, *, rng=None
                        ) -> np.ndarray:
    """``n`` diameters (m) in [d_min_m, d_max_m] distributed as the production function
    ``npf`` (module notes; the shape does not depend on the age).

    Examples
    --------
    >>> d = sample_pf_diameters(2000, "moon", 1000.0, 20000.0, rng=1)
    >>> bool(d.min() >= 1000.0 and d.max() <= 20000.0)
    True
    """
    n = check_int("n", n, 0, _MAX_N)
    system = get_chronology_system(npf)
    lo, hi = check_diameter_range(system, d_min_m, d_max_m)
    x_lo, x_hi = math.log10(lo * 1e-3), math.log10(hi * 1e-3)
    m = max(257, int(math.ceil((x_hi - x_lo) * _TABLE_PER_DECADE)) + 1)
    x = np.linspace(x_lo, x_hi, m)
    y = system.production.shape_log10(10.0 ** x)     # log10 N(>D) / N1, decreasing
    y0 = y[0]
    rel = 10.0 ** (y - y0)                           # N(>D) / N(>d_min), 1 .. r_hi
    u = normalize_rng(rng).random(n)
    target = 1.0 - u * (1.0 - rel[-1])
    xs = np.interp(-np.log10(target), -(y - y0), x)
    return np.clip(1e3 * 10.0 ** xs, lo, hi)


def formation_ages(n: int, npf, age_gyr: float, *, rng=None) -> np.ndarray:
    """``n`` crater formation ages (Gyr before present) on a surface of model age
    ``age_gyr``: ``P(age <= t) = N1(t) / N1(age_gyr)`` (module notes).

    Examples
    --------
    >>> a = formation_ages(10000, "moon", 3.8, rng=1)
    >>> bool(a.max() <= 3.8), round(float((a > 3.5).mean()), 2)   # 73 % older than 3.5 Gyr
    (True, 0.73)
    """
    n = check_int("n", n, 0, _MAX_N)
    system = get_chronology_system(npf)
    t = check_age(system, age_gyr)
    cf = system.chronology
    u = normalize_rng(rng).random(n)
    ages = cf.age_gyr(u * float(cf.n1(t)))
    return np.clip(ages, 0.0, t)


def saturation_diameter_m(npf, age_gyr: float, equilibrium) -> float | None:
    """The diameter (m) below which a surface of model age ``age_gyr`` is saturated: the
    largest D in the production function's range where its N(>D) meets the
    equilibrium function's (``trask`` or ``hartmann``). None if the production function
    stays below equilibrium over its whole range.

    Examples
    --------
    >>> round(saturation_diameter_m("moon", 3.8, "trask"))
    420
    """
    system = get_chronology_system(npf)
    t = check_age(system, age_gyr)
    eq = get_equilibrium(equilibrium)
    n1 = float(system.chronology.n1(t))
    lo, hi = system.production.d_range_km

    def excess(x):  # log10 N_pf - log10 N_eq at log10 D_km = x
        return (math.log10(n1) + float(system.production.shape_log10(10.0 ** x))
                - (eq.coefficients[0] + eq.coefficients[1] * x))

    xs = np.linspace(math.log10(lo), math.log10(hi), 2001)
    ex = np.array([excess(x) for x in xs])
    above = np.flatnonzero(ex >= 0)
    if not above.size:
        return None
    i = int(above[-1])
    if i == len(xs) - 1:
        return hi * 1e3
    from scipy.optimize import brentq

    return 1e3 * 10.0 ** brentq(excess, xs[i], xs[i + 1], xtol=1e-13)


def equilibrium_bin_edges(d_min_m: float, d_max_m: float) -> np.ndarray:
    """The bins of the equilibrium cap (m): 20 a decade (10^(j/20) m, the craterstats
    binning) inside (d_min_m, d_max_m), plus the ends."""
    j0 = math.floor(math.log10(d_min_m) * _BINS_PER_DECADE) + 1
    j1 = math.ceil(math.log10(d_max_m) * _BINS_PER_DECADE) - 1
    inner = 10.0 ** (np.arange(j0, j1 + 1) / _BINS_PER_DECADE)
    inner = inner[(inner > d_min_m) & (inner < d_max_m)]
    return np.concatenate([[d_min_m], inner, [d_max_m]])


def equilibrium_caps(npf, age_gyr: float, equilibrium, area_m2: float, d_min_m: float,
                     d_max_m: float, *, rng=None) -> tuple[np.ndarray, np.ndarray]:
    """The equilibrium cap on an area: (bin edges in m, per bin the most craters the area
    holds).

    A bin is saturated where the production function's increment over it exceeds the
    equilibrium function's (a comparison of densities, whatever the area); there the cap
    is the equilibrium count ``A (N_eq(D_lo) - N_eq(D_hi))``, rounded down or up at
    random with the probability of its fraction (so that it is unbiased on small areas,
    where it is below one crater a bin). Unsaturated bins have no cap (-1).

    Examples
    --------
    >>> edges, caps = equilibrium_caps("moon", 3.8, "trask", 1e9, 100.0, 1000.0, rng=1)
    >>> int(caps[0]) > 0, int(caps[-1])     # 100 m: saturated; 1 km: not
    (True, -1)
    """
    system = get_chronology_system(npf)
    area = check_positive("area_m2", area_m2)
    lo, hi = check_diameter_range(system, d_min_m, d_max_m)
    edges = equilibrium_bin_edges(lo, hi)
    pf = cumulative_density(system, age_gyr, edges)
    eq = equilibrium_density(equilibrium, edges)
    want = area * (eq[:-1] - eq[1:])
    fraction = want - np.floor(want)
    caps = (np.floor(want) + (normalize_rng(rng).random(want.size) < fraction)).astype(np.int64)
    saturated = (pf[:-1] - pf[1:]) > (eq[:-1] - eq[1:])
    return edges, np.where(saturated, caps, -1)


def expected_survivors(lam, want) -> np.ndarray:
    """Expected ``min(N, C)`` for N ~ Poisson(``lam``) and the randomly rounded cap C of
    :func:`equilibrium_caps` (mean ``want``): with ``E[min(N, c)] = lam P(N <= c - 2) +
    c P(N >= c)``, mixed over floor(want) and floor(want) + 1."""
    # scipy.special's Poisson tails (what scipy.stats.poisson.cdf/sf evaluate, without
    # importing scipy.stats: 0.4-1 s of a site stack's start, issue 20)
    from scipy.special import pdtr, pdtrc

    lam = np.asarray(lam, dtype=np.float64)
    want = np.asarray(want, dtype=np.float64)
    lo = np.floor(want)
    f = want - lo

    def cdf(k):  # P(N <= k)
        return np.where(k < 0, 0.0, pdtr(np.maximum(k, 0.0), lam))

    def sf(k):  # P(N > k)
        return np.where(k < 0, 1.0, pdtrc(np.maximum(k, 0.0), lam))

    def e_min(c):
        return lam * cdf(c - 2) + c * sf(c - 1)

    return (1.0 - f) * e_min(lo) + f * e_min(lo + 1.0)


def cap_at_equilibrium(diameter_m, age_gyr, edges_m, caps) -> np.ndarray:
    """Which craters survive the equilibrium cap ``caps`` over the bins ``edges_m``
    (:func:`equilibrium_caps`; -1 = no cap): a boolean mask; per capped bin the oldest
    beyond the cap go (young craters erase old ones; ties by position in the input).

    Examples
    --------
    >>> d = np.full(5, 150.0); a = np.array([3.0, 1.0, 2.0, 0.5, 3.5])
    >>> cap_at_equilibrium(d, a, [100.0, 200.0], [3]).tolist()
    [False, True, True, True, False]
    """
    d = np.asarray(diameter_m, dtype=np.float64)
    a = np.asarray(age_gyr, dtype=np.float64)
    if d.shape != a.shape or d.ndim != 1:
        raise ParameterError("age_gyr", f"must have the shape of diameter_m {d.shape}; got "
                             f"{a.shape}")
    edges = np.asarray(edges_m, dtype=np.float64)
    caps = np.asarray(caps, dtype=np.int64)
    if edges.ndim != 1 or caps.shape != (edges.size - 1,):
        raise ParameterError("caps", f"must have one entry per bin ({edges.size - 1}); got "
                             f"{caps.shape}")
    idx = np.clip(np.searchsorted(edges, d, side="right") - 1, 0, len(caps) - 1)
    keep = np.ones(d.shape, dtype=bool)
    order = np.lexsort((np.arange(d.size), a, idx))  # by bin, then youngest first
    sorted_bins = idx[order]
    starts = np.searchsorted(sorted_bins, np.arange(len(caps)))
    ends = np.searchsorted(sorted_bins, np.arange(len(caps)), side="right")
    for b in np.flatnonzero((caps >= 0) & (ends - starts > caps)):
        keep[order[starts[b] + caps[b]:ends[b]]] = False
    return keep
