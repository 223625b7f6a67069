"""``key=value,key=value`` specs (crater, boulder, LCSN layers, Gabor noise)."""

from __future__ import annotations

from collections.abc import Sequence

__all__ = ["parse_spec"]


def parse_spec(spec, items: dict, required: Sequence[str], what: str) -> dict:
    """Parse a ``key=value,key=value`` spec: ``items`` maps each short key to (field
    name, converter); returns {field: converted value}; ValueError names the spec."""
    if not isinstance(spec, str):
        raise TypeError(f"a {what} spec must be a string; got {spec!r}")
    values = {}
    for part in spec.split(","):
        key, sep, raw = part.partition("=")
        key = key.strip()
        if not sep or key not in items:
            raise ValueError(f"{what} {spec!r}: unknown item {part.strip()!r}; allowed keys: "
                             f"{', '.join(items)}")
        field, convert = items[key]
        try:
            values[field] = convert(raw.strip())
        except ValueError:
            raise ValueError(f"{what} {spec!r}: {key} must be a number; got {raw!r}") from None
    missing = [k for k in required if items[k][0] not in values]
    if missing:
        raise ValueError(f"{what} {spec!r}: missing {', '.join(missing)}")
    return values
