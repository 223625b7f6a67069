"""Errors that know which parameter they are about.

Library functions raise ``TypeError`` / ``ValueError`` whose message names the *library*
parameter (``fractal_dimension``). Inside :func:`about` such an error also gets that name
as its ``parameter`` attribute (message and type unchanged), so the command line can say
which of its options or config keys the error is about (:func:`parameter_of`, mapped
through the option table of :mod:`dem.cli.options`) without rewriting the message.
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterator

__all__ = ["about", "parameter_of"]


@contextlib.contextmanager
def about(parameter: str | None) -> Iterator[None]:
    """Tag a ``TypeError`` / ``ValueError`` raised inside with ``parameter`` (the innermost
    tag wins; None tags nothing).

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
        if parameter is not None and parameter_of(exc) is None:
            exc.parameter = parameter
        raise


def parameter_of(exc: BaseException) -> str | None:
    """The library parameter an error is about (see :func:`about`), or None."""
    return getattr(exc, "parameter", None)
