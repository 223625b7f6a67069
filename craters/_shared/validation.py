"""Argument checks and random generators shared by the three packages (DESIGN §3).

Every check returns the cleaned value or raises ``TypeError`` (wrong kind of object) or
``ValueError`` (bad value) naming the parameter, the rule and the value.
"""

from __future__ import annotations

import contextlib
import math
import numbers
from collections.abc import Iterator, Sequence
from typing import TYPE_CHECKING

__all__ = ["ParameterError", "ParameterTypeError", "about", "check_choice",
           "check_finite", "check_int", "check_positive", "check_range", "normalize_rng",
           "parameter_of"]

if TYPE_CHECKING:  # numpy loads where a generator is made (~90 ms of a command's --help)
    import numpy as np


class _Named:
    """A bad value of one named parameter: ``str()`` reads "`name` rule".

    ``name`` is the parameter of the function the user called (or the scene key); a
    command line shows the same rule under its own flag with :meth:`shown_as`, so
    messages are mapped through an option table, never by editing their text. A rule
    that names other parameters has ``{}`` where they go and lists them in ``see``.
    """

    def __init__(self, name: str, rule: str, *, see: tuple[str, ...] = ()):
        self.name, self.rule, self.see = name, rule, tuple(see)
        # a mixin: the next class is ValueError or TypeError
        super().__init__(self.shown_as(f"`{name}`"))  # type: ignore[call-arg]

    def shown_as(self, label: str, name_of=None) -> str:
        """The message with ``label`` (a flag, a key) in place of the parameter name and
        ``name_of(other)`` in place of each other parameter it names."""
        name_of = name_of or (lambda other: f"`{other}`")
        rule = self.rule.format(*map(name_of, self.see)) if self.see else self.rule
        return f"{label}{rule}" if rule.startswith(":") else f"{label} {rule}"

    def renamed(self, name: str):
        """The same error for the parameter ``name`` (the caller's name for the value)."""
        return type(self)(name, self.rule, see=self.see)


class ParameterError(_Named, ValueError):
    """A bad value of one named parameter (a ``ValueError``).

    Examples
    --------
    >>> e = ParameterError("radius_m", "must be > 0; got -1.0")
    >>> str(e), e.shown_as("--radius-m")
    ('`radius_m` must be > 0; got -1.0', '--radius-m must be > 0; got -1.0')
    """


class ParameterTypeError(_Named, TypeError):
    """The wrong kind of object for one named parameter (a ``TypeError``)."""


@contextlib.contextmanager
def about(parameter: str | None) -> Iterator[None]:
    """Tag a ``TypeError`` / ``ValueError`` raised inside with the library ``parameter`` it
    is about (its ``parameter`` attribute; message and type unchanged; the innermost tag
    wins; None tags nothing), for errors raised by deeper code under another name.

    Examples
    --------
    >>> try:
    ...     with about("levels"):
    ...         raise ValueError("`levels` must be >= 1; got 0")
    ... except ValueError as exc:
    ...     print(parameter_of(exc), "|", exc)
    levels | `levels` must be >= 1; got 0
    """
    try:
        yield
    except (TypeError, ValueError) as exc:
        if parameter is not None and getattr(exc, "parameter", None) is None:
            exc.parameter = parameter  # type: ignore[union-attr]  # a tag on any error
        raise


def parameter_of(exc: BaseException) -> str | None:
    """The parameter an error is about: its :func:`about` tag, else the name of a
    :class:`ParameterError`, else None."""
    tag = getattr(exc, "parameter", None)
    if tag is None and isinstance(exc, _Named):
        return exc.name
    return tag


def normalize_rng(rng: int | np.integer | np.random.Generator | None) -> np.random.Generator:
    """Return a Generator from ``rng`` (int seed, Generator or None), SPEC 7 style."""
    import numpy as np
    if isinstance(rng, np.random.Generator):
        return rng
    if rng is None:
        return np.random.default_rng()
    if isinstance(rng, bool | float) or not isinstance(rng, numbers.Integral):
        raise ParameterTypeError(
            "rng", f"must be an int seed, a numpy.random.Generator or None; got {rng!r}")
    if int(rng) < 0:
        raise ParameterError("rng", f"seed must be >= 0; got {rng!r}")
    return np.random.default_rng(int(rng))


def check_finite(name: str, value) -> float:
    """Return ``value`` as a float, raising if it is not a finite real number."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise ParameterTypeError(name, f"must be a real number; got {value!r}")
    value = float(value)
    if not math.isfinite(value):
        raise ParameterError(name, f"must be finite; got {value!r}")
    return value


def check_positive(name: str, value, *, allow_zero: bool = False) -> float:
    """Return ``value`` as a float, raising unless it is finite and > 0 (>= 0)."""
    value = check_finite(name, value)
    if value < 0 or (value == 0 and not allow_zero):
        rule = ">= 0" if allow_zero else "> 0"
        raise ParameterError(name, f"must be finite and {rule}; got {value!r}")
    return value


def check_range(name: str, value, lo: float | None, hi: float | None) -> float:
    """Return ``value`` as a float, raising unless lo <= value <= hi (None = open)."""
    value = check_finite(name, value)
    if (lo is not None and value < lo) or (hi is not None and value > hi):
        lo_s = "-inf" if lo is None else f"{lo:g}"
        hi_s = "inf" if hi is None else f"{hi:g}"
        raise ParameterError(name, f"must be in [{lo_s}, {hi_s}]; got {value!r}")
    return value


def check_int(name: str, value, lo: int | None = None, hi: int | None = None) -> int:
    """Return ``value`` as an int, raising unless it is an integer in [lo, hi]."""
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        if isinstance(value, float) and value.is_integer():
            value = int(value)
        else:
            raise ParameterTypeError(name, f"must be an integer; got {value!r}")
    value = int(value)
    if (lo is not None and value < lo) or (hi is not None and value > hi):
        lo_s = "-inf" if lo is None else str(lo)
        hi_s = "inf" if hi is None else str(hi)
        raise ParameterError(name, f"must be an integer in [{lo_s}, {hi_s}]; got {value!r}")
    return value


def check_choice(name: str, value, choices: Sequence[str]) -> str:
    """Return ``value`` if it is one of ``choices``, else raise ValueError."""
    if value not in choices:
        raise ParameterError(name, f"must be one of {', '.join(map(str, choices))}; got {value!r}")
    return value
