"""Argument checks and random generators shared by the three packages (DESIGN §3).

Every check returns the cleaned value or raises ``TypeError`` (wrong kind of object) or
``ValueError`` (bad value) naming the parameter, the rule and the value.
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Sequence

import numpy as np

__all__ = ["RngLike", "check_choice", "check_finite", "check_int", "check_positive",
           "check_range", "normalize_rng"]

RngLike = int | np.random.Generator | None


def normalize_rng(rng: RngLike) -> np.random.Generator:
    """Return a Generator from ``rng`` (int seed, Generator or None), SPEC 7 style."""
    if isinstance(rng, np.random.Generator):
        return rng
    if rng is None:
        return np.random.default_rng()
    if isinstance(rng, bool | float) or not isinstance(rng, numbers.Integral):
        raise TypeError(
            f"`rng` must be an int seed, a numpy.random.Generator or None; got {rng!r}"
        )
    if int(rng) < 0:
        raise ValueError(f"`rng` seed must be >= 0; got {rng!r}")
    return np.random.default_rng(int(rng))


def check_finite(name: str, value) -> float:
    """Return ``value`` as a float, raising if it is not a finite real number."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise TypeError(f"`{name}` must be a real number; got {value!r}")
    value = float(value)
    if not math.isfinite(value):
        raise ValueError(f"`{name}` must be finite; got {value!r}")
    return value


def check_positive(name: str, value, *, allow_zero: bool = False) -> float:
    """Return ``value`` as a float, raising unless it is finite and > 0 (>= 0)."""
    value = check_finite(name, value)
    if value < 0 or (value == 0 and not allow_zero):
        rule = ">= 0" if allow_zero else "> 0"
        raise ValueError(f"`{name}` must be finite and {rule}; got {value!r}")
    return value


def check_range(name: str, value, lo: float | None, hi: float | None) -> float:
    """Return ``value`` as a float, raising unless lo <= value <= hi (None = open)."""
    value = check_finite(name, value)
    if (lo is not None and value < lo) or (hi is not None and value > hi):
        lo_s = "-inf" if lo is None else f"{lo:g}"
        hi_s = "inf" if hi is None else f"{hi:g}"
        raise ValueError(f"`{name}` must be in [{lo_s}, {hi_s}]; got {value!r}")
    return value


def check_int(name: str, value, lo: int | None = None, hi: int | None = None) -> int:
    """Return ``value`` as an int, raising unless it is an integer in [lo, hi]."""
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        if isinstance(value, float) and value.is_integer():
            value = int(value)
        else:
            raise TypeError(f"`{name}` must be an integer; got {value!r}")
    value = int(value)
    if (lo is not None and value < lo) or (hi is not None and value > hi):
        lo_s = "-inf" if lo is None else str(lo)
        hi_s = "inf" if hi is None else str(hi)
        raise ValueError(f"`{name}` must be an integer in [{lo_s}, {hi_s}]; got {value!r}")
    return value


def check_choice(name: str, value, choices: Sequence[str]) -> str:
    """Return ``value`` if it is one of ``choices``, else raise ValueError."""
    if value not in choices:
        raise ValueError(f"`{name}` must be one of {', '.join(map(str, choices))}; got {value!r}")
    return value
