"""A small PDS3 (ODL) label parser: enough for simple-cylindrical DEM products.

Pure text handling, no file access beyond what the caller passes in (raster reading is
in :mod:`dem.io`). The label becomes nested dictionaries: ``KEY = value`` pairs at each
level and ``OBJECT``/``GROUP`` blocks as sub-dictionaries under their name (the first
block of a name wins). Values: ``int``, ``float``, ``str`` (quoted strings with their
line breaks collapsed, bare identifiers, dates, radix numbers such as ``16#FF7FFFFB#``
kept as text), lists for ``(...)`` and ``{...}``, and :class:`Quantity` (a float with a
``unit``) for numbers followed by ``<unit>``.
"""

from __future__ import annotations

import re

__all__ = ["Quantity", "find_object", "parse_label"]

_TOKEN = re.compile(
    r'"(?P<str>[^"]*)"'  # double-quoted string (may span lines)
    r"|'(?P<lit>[^']*)'"  # single-quoted literal
    r"|<(?P<unit>[^>]*)>"  # unit
    r"|(?P<punct>[=(){},])"
    r"|(?P<word>[^\s=(){},<>\"']+)",
    re.S,
)
_COMMENT = re.compile(r"/\*.*?\*/", re.S)
_INT = re.compile(r"[+-]?\d+")
_FLOAT = re.compile(r"[+-]?(\d+\.\d*|\.\d+|\d+)([eE][+-]?\d+)?")


class Quantity(float):
    """A number with a unit from the label, e.g. ``MAP_SCALE = 7580.84 <m/pix>``."""

    unit: str

    def __new__(cls, value: float, unit: str):
        obj = super().__new__(cls, value)
        obj.unit = unit
        return obj

    def __repr__(self) -> str:
        return f"Quantity({float(self)!r}, {self.unit!r})"


def _word(text: str):
    if _INT.fullmatch(text):
        return int(text)
    if _FLOAT.fullmatch(text):
        return float(text)
    return text


class _Parser:
    def __init__(self, text: str):
        text = _COMMENT.sub(" ", text)
        self.tokens = []
        for m in _TOKEN.finditer(text):
            kind = m.lastgroup
            value = m.group(kind)
            if kind == "str":
                value = " ".join(value.split())
            self.tokens.append((kind, value))
        self.pos = 0

    def peek(self):
        return self.tokens[self.pos] if self.pos < len(self.tokens) else (None, None)

    def take(self):
        tok = self.peek()
        self.pos += 1
        return tok

    def expect(self, value: str):
        kind, got = self.take()
        if got != value:
            raise ValueError(f"PDS label: expected {value!r}, got {got!r}")

    def block(self, end: str | None) -> dict:
        out: dict = {}
        while True:
            kind, word = self.take()
            if kind is None:
                if end is None:
                    return out
                raise ValueError(f"PDS label: missing {end}")
            if kind != "word":
                raise ValueError(f"PDS label: expected a keyword, got {word!r}")
            key = word.upper()
            if key == "END" and end is None:
                return out
            if key == end:
                if self.peek()[1] == "=":
                    self.take()
                    self.take()
                return out
            self.expect("=")
            if key in ("OBJECT", "GROUP"):
                _, name = self.take()
                inner = self.block("END_" + key)
                out.setdefault(str(name).upper(), inner)
            else:
                out.setdefault(key, self.value())

    def value(self):
        kind, tok = self.take()
        if tok in ("(", "{"):
            close = ")" if tok == "(" else "}"
            items = []
            while self.peek()[1] != close:
                if self.peek()[0] is None:
                    raise ValueError(f"PDS label: missing {close!r}")
                items.append(self.value())
                if self.peek()[1] == ",":
                    self.take()
            self.take()
            return items
        if kind in ("str", "lit"):
            return tok
        if kind != "word":
            raise ValueError(f"PDS label: unexpected {tok!r}")
        value = _word(tok)
        if self.peek()[0] == "unit":
            unit = self.take()[1].strip()
            if isinstance(value, int | float):
                return Quantity(float(value), unit)
        return value


def parse_label(text: str) -> dict:
    """Parse the text of a PDS3 label into nested dictionaries (keys upper-case).

    Examples
    --------
    >>> lab = parse_label('''PDS_VERSION_ID = PDS3
    ... RECORD_BYTES = 8 /* a comment */
    ... ^IMAGE = ("X.IMG", 2)
    ... OBJECT = IMAGE
    ...   LINES = 4
    ...   SCALING_FACTOR = 0.5
    ... END_OBJECT = IMAGE
    ... OBJECT = IMAGE_MAP_PROJECTION
    ...   MAP_SCALE = 7.5 <KM/PIXEL>
    ... END_OBJECT
    ... END''')
    >>> lab["^IMAGE"], lab["IMAGE"]["LINES"], lab["IMAGE"]["SCALING_FACTOR"]
    (['X.IMG', 2], 4, 0.5)
    >>> lab["IMAGE_MAP_PROJECTION"]["MAP_SCALE"].unit
    'KM/PIXEL'
    """
    return _Parser(text).block(None)


def find_object(label: dict, name: str) -> tuple[dict, dict] | tuple[None, None]:
    """The first OBJECT/GROUP called ``name`` anywhere in ``label`` (depth first).

    Returns ``(block, parent)``: the object's dictionary and the block that holds it
    (where its ``^NAME`` pointer and ``RECORD_BYTES`` usually are), or ``(None, None)``.
    """
    for key, value in label.items():
        if isinstance(value, dict):
            if key == name:
                return value, label
            found = find_object(value, name)
            if found[0] is not None:
                return found
    return None, None
