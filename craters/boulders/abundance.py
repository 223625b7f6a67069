"""Rock abundance: Golombek & Rapp's (1997) model as boulder layers.

The cumulative fractional area covered by rocks of diameter D or larger is

    F_k(D) = k exp(-q(k) D),   q(k) = 1.79 + 0.152 / k       (D in metres)

with ``k`` the total area covered by rocks (Golombek & Rapp 1997, JGR 102(E2), 4117; the
form and q(k) as quoted by Golombek et al. 2003, LPSC XXXIV, NTRS 20030111177: "a family
of noncrossing curves that flatten out at small rock diameter at a total rock abundance
of 5-40 %"). Rocks of diameter x cover ``pi x^2 / 4`` each, so the number of rocks per
m^2 at least D across is

    N(D) = int_D^inf (-dF/dx) 4 / (pi x^2) dx = (4 k q / pi) [exp(-q D) / D - q E1(q D)]

(E1 the exponential integral). :func:`golombek_layers` cuts [d_min, d_max] into bins of
``bins_per_octave`` per factor 2 and gives each bin the power law ``c D^s`` through N at
both of its ends, so every bin holds exactly the model's count and the layers are
ordinary :class:`BoulderLayer` records every placement path draws.
"""

from __future__ import annotations

import math

import numpy as np

from .._shared import ParameterError, check_int, check_positive, check_range, parse_spec
from .placement import BoulderLayer, parse_boulder_spec

__all__ = ["golombek_cumulative_area", "golombek_cumulative_number", "golombek_layers",
           "golombek_q", "parse_boulder_specs", "parse_golombek_spec"]


def golombek_q(k: float) -> float:
    """q(k) = 1.79 + 0.152 / k (1/m): how fast the covered area falls with diameter."""
    return 1.79 + 0.152 / check_range("k", k, 1e-4, 0.9)


def golombek_cumulative_area(d_m, k: float) -> np.ndarray:
    """F_k(D): fractional area covered by rocks at least ``d_m`` metres across.

    Examples
    --------
    >>> round(float(golombek_cumulative_area(0.0, 0.1)), 6)   # all rocks: k
    0.1
    """
    return k * np.exp(-golombek_q(k) * np.asarray(d_m, dtype=np.float64))


def golombek_cumulative_number(d_m, k: float) -> np.ndarray:
    """N(D): rocks per m^2 at least ``d_m`` (> 0) metres across (module notes)."""
    d = np.asarray(d_m, dtype=np.float64)
    if not np.all(d > 0):
        raise ParameterError("d_m", f"must be > 0 metres; got {d_m!r}")
    from scipy.special import exp1  # scipy on use: ``import craters`` stays light

    q = golombek_q(k)
    return 4.0 * k * q / math.pi * (np.exp(-q * d) / d - q * exp1(q * d))


def golombek_layers(k: float, d_min_m: float, d_max_m: float, *, burial_max: float = 0.5,
                    near: float = 0.0, bins_per_octave: int = 2) -> tuple[BoulderLayer, ...]:
    """Boulder layers following Golombek & Rapp's model of total rock area ``k`` between
    ``d_min_m`` and ``d_max_m`` (module notes): one power law per bin, exact counts.

    Examples
    --------
    >>> layers = golombek_layers(0.1, 0.5, 2.0)
    >>> len(layers), layers[0].d_min_m, layers[-1].d_max_m
    (4, 0.5, 2.0)
    """
    check_positive("d_min_m", d_min_m)
    check_positive("d_max_m", d_max_m)
    if d_min_m >= d_max_m:
        raise ParameterError("d_min_m", f"must be < d_max_m ({d_max_m}); got {d_min_m}")
    n_bins = max(1, math.ceil(check_int("bins_per_octave", bins_per_octave, 1, 16)
                              * math.log2(d_max_m / d_min_m) - 1e-9))
    edges = np.geomspace(d_min_m, d_max_m, n_bins + 1)
    edges[0], edges[-1] = d_min_m, d_max_m
    n = golombek_cumulative_number(edges, k)
    layers = []
    for a, b, na, nb in zip(edges[:-1], edges[1:], n[:-1], n[1:], strict=True):
        s = math.log(nb / na) / math.log(b / a)
        layers.append(BoulderLayer(c=float(na / a**s), k=float(s), d_min_m=float(a),
                                   d_max_m=float(b), burial_max=burial_max, near=near))
    return tuple(layers)


_SPEC = {"k": float, "d_min_m": float, "d_max_m": float, "burial_max": float, "near": float,
         "bins_per_octave": int}


def parse_golombek_spec(spec: str) -> tuple[BoulderLayer, ...]:
    """``golombek,k=0.1,d_min_m=0.1,d_max_m=3[,burial_max,near,bins_per_octave]``: the
    layers of :func:`golombek_layers` (``k`` the total rock area fraction, metres).

    Examples
    --------
    >>> len(parse_golombek_spec("golombek,k=0.05,d_min_m=0.25,d_max_m=1"))
    4
    """
    head, _, rest = str(spec).partition(",")
    if head.strip() != "golombek":
        raise ValueError(f"a Golombek rock layer starts with 'golombek,'; got {spec!r}")
    values = parse_spec(rest, _SPEC, ("k", "d_min_m", "d_max_m"), "Golombek rock layer")
    try:
        return golombek_layers(**values)
    except ValueError as exc:
        raise ValueError(f"Golombek rock layer {spec!r}: {exc}") from None


def parse_boulder_specs(spec: str) -> tuple[BoulderLayer, ...]:
    """One boulder spec as layers: ``golombek,...`` (:func:`parse_golombek_spec`) or a
    power law ``c=..,k=..,d_min_m=..,d_max_m=..`` (one layer)."""
    if str(spec).strip().startswith("golombek"):
        return parse_golombek_spec(spec)
    return (parse_boulder_spec(spec),)
