"""``key=value,key=value`` specs (crater, boulder, LCSN layers, Gabor noise).

A spec's keys are the names of the record's fields, the same names as in a TOML table
and as Python arguments (``c=0.5,k=-2,d_min_m=2,d_max_m=50``); the short keys of
craterform 0.1 (``dmin``, ``amax`` ...) are refused with their new name.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence

__all__ = ["parse_spec"]


def parse_spec(spec, converters: Mapping[str, Callable], required: Sequence[str], what: str,
               *, renamed: Mapping[str, str] | None = None) -> dict:
    """Parse a ``key=value,key=value`` spec whose keys are field names.

    ``converters`` maps each field to the function that reads its value; ``required``
    lists the fields that must be given; ``renamed`` maps old keys to their field (for
    the message). Returns {field: value}; ValueError names the spec and the item.

    Examples
    --------
    >>> parse_spec("a=1,b=x", {"a": float, "b": str}, ("a",), "demo")
    {'a': 1.0, 'b': 'x'}
    >>> parse_spec("n=1", {"count": int}, (), "demo", renamed={"n": "count"})
    Traceback (most recent call last):
    ...
    ValueError: demo 'n=1': unknown item 'n=1' (now count=); allowed keys: count
    """
    if not isinstance(spec, str):
        raise TypeError(f"a {what} spec must be a string; got {spec!r}")
    values = {}
    for part in spec.split(","):
        key, sep, raw = part.partition("=")
        key = key.strip()
        if not sep or key not in converters:
            hint = f" (now {renamed[key]}=)" if renamed and key in renamed else ""
            raise ValueError(f"{what} {spec!r}: unknown item {part.strip()!r}{hint}; allowed "
                             f"keys: {', '.join(converters)}")
        if key in values:
            raise ValueError(f"{what} {spec!r}: {key} is given twice")
        try:
            values[key] = converters[key](raw.strip())
        except ValueError:
            raise ValueError(f"{what} {spec!r}: {key} must be a number; got {raw!r}") from None
    missing = [k for k in required if k not in values]
    if missing:
        raise ValueError(f"{what} {spec!r}: missing {', '.join(missing)}")
    return values
