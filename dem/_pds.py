"""A small PDS3 (ODL) label parser and reader of its facts: the checks made before GDAL
reads a product (:mod:`dem.pdsimage`) and the georeference of simple-cylindrical maps.

Label text handling and what the label says (sample types, constants, georeference);
the image's bytes are read in :mod:`dem.io`. The label becomes nested dictionaries:
``KEY = value`` pairs at each level and ``OBJECT``/``GROUP`` blocks as sub-dictionaries
under their name (the first block of a name wins). Values: ``int``, ``float``, ``str``
(quoted strings with their line breaks collapsed, bare identifiers, dates, radix numbers
such as ``16#FF7FFFFB#`` kept as text), lists for ``(...)`` and ``{...}``, and
:class:`Quantity` (a float with a ``unit``) for numbers followed by ``<unit>``.
"""

from __future__ import annotations

import logging
import math
import re
from pathlib import Path

import numpy as np
from affine import Affine
from rasterio.crs import CRS

from craters._shared.files import check_regular_file

__all__ = ["SAMPLE_TYPES", "SIMPLE_CYLINDRICAL", "Quantity", "axis_radius_m", "data_file",
           "find_file", "find_object", "georeference", "label_number", "label_text",
           "parse_label", "sample_constant"]

logger = logging.getLogger(__name__)

_TOKEN = re.compile(
    r'"(?P<str>[^"]*)"'  # double-quoted string (may span lines)
    r"|'(?P<lit>[^']*)'"  # single-quoted literal
    r"|<(?P<unit>[^>]*)>"  # unit
    r"|(?P<punct>[=(){},])"
    r"|(?P<word>[^\s=(){},<>\"']+)",
    re.S,
)
#: Deepest nesting of OBJECT/GROUP blocks and lists (real labels: 3 or 4 levels).
MAX_NESTING = 64
#: Largest detached label read, bytes (real ones: a few kilobytes).
MAX_LABEL_BYTES = 16 << 20
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
            assert kind is not None  # every alternative of _TOKEN is a named group
            value = m.group(kind)
            if kind == "str":
                value = " ".join(value.split())
            self.tokens.append((kind, value))
        self.pos = 0
        self.depth = 0

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

    def nest(self):
        self.depth += 1
        if self.depth > MAX_NESTING:
            raise ValueError(f"PDS label: OBJECT/GROUP blocks or lists nested deeper than "
                             f"{MAX_NESTING} levels")

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
                self.nest()
                inner = self.block("END_" + key)
                self.depth -= 1
                out.setdefault(str(name).upper(), inner)
            else:
                out.setdefault(key, self.value())

    def value(self):
        kind, tok = self.take()
        if tok in ("(", "{"):
            close = ")" if tok == "(" else "}"
            self.nest()
            items = []
            while self.peek()[1] != close:
                if self.peek()[0] is None:
                    raise ValueError(f"PDS label: missing {close!r}")
                items.append(self.value())
                if self.peek()[1] == ",":
                    self.take()
            self.take()
            self.depth -= 1
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


#: PDS3 SAMPLE_TYPE -> (numpy kind, byte order)
SAMPLE_TYPES = {
    "LSB_INTEGER": ("i", "<"), "PC_INTEGER": ("i", "<"), "VAX_INTEGER": ("i", "<"),
    "MSB_INTEGER": ("i", ">"), "INTEGER": ("i", ">"), "MAC_INTEGER": ("i", ">"),
    "SUN_INTEGER": ("i", ">"),
    "LSB_UNSIGNED_INTEGER": ("u", "<"), "PC_UNSIGNED_INTEGER": ("u", "<"),
    "VAX_UNSIGNED_INTEGER": ("u", "<"),
    "MSB_UNSIGNED_INTEGER": ("u", ">"), "UNSIGNED_INTEGER": ("u", ">"),
    "MAC_UNSIGNED_INTEGER": ("u", ">"), "SUN_UNSIGNED_INTEGER": ("u", ">"),
    "PC_REAL": ("f", "<"), "IEEE_REAL": ("f", ">"), "REAL": ("f", ">"),
    "MAC_REAL": ("f", ">"), "SUN_REAL": ("f", ">"), "FLOAT": ("f", ">"),
}
SIMPLE_CYLINDRICAL = ("SIMPLE CYLINDRICAL", "SIMPLE_CYLINDRICAL", "EQUIRECTANGULAR")


def find_file(folder: Path, name: str) -> Path | None:
    """``folder / name``, matching the name case-insensitively (PDS names are upper-case)."""
    exact = folder / name
    if exact.is_file():
        return exact
    lower = name.lower()
    for p in folder.iterdir():
        if p.name.lower() == lower and p.is_file():
            return p
    return None


def data_file(label_path: Path, name: str) -> Path | None:
    """The data file a label's pointer names: only a file beside the label or below its
    folder (a relative name without ``..`` that stays inside it through symlinks too),
    matched case-insensitively; None if it is missing. A pointer naming any other file (an
    absolute path, ``../../etc/passwd``) is a one-line ValueError: a label never makes us
    read a file the user did not give."""
    folder = label_path.parent
    parts = Path(name).parts
    bad = not name or Path(name).is_absolute() or "\\" in name or ".." in parts
    if not bad:
        found = find_file(folder, name) if len(parts) == 1 else \
            (folder / name if (folder / name).is_file() else None)
        if found is None:
            return None
        if found.resolve().is_relative_to(folder.resolve()):
            return found
    raise ValueError(f"{str(label_path)!r}: the image pointer names {name!r}, which is not a "
                     f"file beside the label or below its folder; refusing to read it")


def label_text(path: Path) -> tuple[str, Path]:
    """The label text and the file it came from (detached ``.lbl`` or attached)."""
    if path.suffix.lower() == ".lbl":
        return check_regular_file(path, "PDS label", MAX_LABEL_BYTES).read_text(
            encoding="latin-1"), path
    with open(path, "rb") as fh:
        head = fh.read(1 << 20)
    if head.startswith(b"PDS_VERSION_ID"):
        text = head.decode("latin-1")
        end = re.search(r"^\s*END\s*$", text, re.M)
        return (text[:end.end()] if end else text), path
    for suffix in (".lbl", ".LBL", ".Lbl"):
        label = find_file(path.parent, path.stem + suffix)
        if label is not None:
            check_regular_file(label, "PDS label", MAX_LABEL_BYTES)
            return label.read_text(encoding="latin-1"), label
    raise ValueError(f"{str(path)!r}: no PDS label found (neither attached nor a .LBL "
                     f"file next to it)")


def label_number(block: dict, key: str, where: str, default=None, unit_scale=None) -> float:
    """A numeric label value; ``unit_scale`` maps lower-case units to factors."""
    value = block.get(key, default)
    if value is None:
        raise ValueError(f"{where}: the label has no {key}")
    if not isinstance(value, int | float):
        raise ValueError(f"{where}: label {key} = {value!r} is not a number")
    factor = 1.0
    if unit_scale is not None and isinstance(value, Quantity):
        unit = value.unit.lower()
        if unit not in unit_scale:
            raise ValueError(f"{where}: label {key} has unit <{value.unit}>; expected one of "
                             f"{', '.join(unit_scale)}")
        factor = unit_scale[unit]
    return float(value) * factor


def sample_constant(value, kind: str, nbytes: int):
    """A label constant (decimal or PDS radix ``16#...#``) in the raw sample's terms."""
    if isinstance(value, int | float):
        return value
    m = re.fullmatch(r"(\d+)#([0-9A-Fa-f]+)#", str(value).strip())
    if not m:
        return None
    raw = int(m.group(2), int(m.group(1)))
    if kind == "f":
        return float(np.frombuffer(raw.to_bytes(nbytes, "big"), dtype=f">f{nbytes}")[0])
    return raw


def axis_radius_m(proj: dict, where: str) -> float:
    """The map projection's ``A_AXIS_RADIUS`` in metres (km without a unit), checked."""
    km = {"km": 1000.0, "kilometers": 1000.0, "kilometres": 1000.0, "m": 1.0, "meters": 1.0,
          "metres": 1.0, "meter": 1.0, "metre": 1.0}
    radius_m = label_number(proj, "A_AXIS_RADIUS", where, unit_scale=km)
    if not isinstance(proj["A_AXIS_RADIUS"], Quantity):
        radius_m *= 1000.0  # PDS3 gives axis radii in km
    if not (math.isfinite(radius_m) and radius_m > 0):
        raise ValueError(f"{where!r}: A_AXIS_RADIUS must be finite and > 0; got {radius_m!r}")
    return radius_m


def _sphere_crs(target: str, radius_m: float):
    """The longitude/latitude CRS of ``target``'s sphere: the IAU_2015 one when PROJ knows
    that body with that radius (the Moon's 1737.4 km sphere: ``IAU_2015:30100``), else a
    WKT of its own."""
    crs = CRS.from_wkt(
        f'GEOGCS["{target} (sphere, PDS label)",DATUM["D_{target}",'
        f'SPHEROID["{target}",{radius_m!r},0]],PRIMEM["Reference_Meridian",0],'
        f'UNIT["degree",0.0174532925199433]]')
    code = crs.to_authority(confidence_threshold=50)
    if code and code[0].startswith("IAU"):
        coded = CRS.from_user_input(":".join(code))
        if coded.to_wkt().split('"')[1].startswith(target):  # the same body, not a namesake
            return coded
    return crs


def georeference(proj: dict, label: dict, where: str):
    """Transform (degrees), geographic CRS and radius (m) of a simple-cylindrical map."""
    ptype = " ".join(str(proj.get("MAP_PROJECTION_TYPE", "")).upper().split())
    if ptype not in SIMPLE_CYLINDRICAL:
        raise ValueError(f"{where!r}: unsupported MAP_PROJECTION_TYPE {ptype or '(none)'!r}; "
                         f"only simple cylindrical DEMs are read")
    radius_m = axis_radius_m(proj, where)
    deg = {"deg": 1.0, "degree": 1.0, "degrees": 1.0}
    center_lat = label_number(proj, "CENTER_LATITUDE", where, 0.0, deg)
    if center_lat != 0.0:
        raise ValueError(f"{where!r}: EQUIRECTANGULAR with CENTER_LATITUDE {center_lat:g} is "
                         f"not supported (only 0, simple cylindrical)")
    if str(proj.get("POSITIVE_LONGITUDE_DIRECTION", "EAST")).upper() != "EAST":
        raise ValueError(f"{where!r}: only POSITIVE_LONGITUDE_DIRECTION = EAST is supported")
    if "MAP_RESOLUTION" in proj:
        res = label_number(proj, "MAP_RESOLUTION", where, unit_scale={"pix/deg": 1.0,
                                                                 "pixel/degree": 1.0,
                                                                 "pixels/degree": 1.0})
    else:
        scale_m = label_number(proj, "MAP_SCALE", where, unit_scale={
            "m/pix": 1.0, "m/pixel": 1.0, "meters/pixel": 1.0, "metres/pixel": 1.0,
            "km/pix": 1000.0, "km/pixel": 1000.0})
        if not (math.isfinite(scale_m) and scale_m > 0):
            raise ValueError(f"{where!r}: MAP_SCALE must be finite and > 0; got {scale_m!r}")
        res = radius_m * math.pi / 180.0 / scale_m
    if not (math.isfinite(res) and res > 0):
        raise ValueError(f"{where!r}: MAP_RESOLUTION must be finite and > 0; got {res!r}")
    center_lon = label_number(proj, "CENTER_LONGITUDE", where, 0.0, deg)
    pix = {"pix": 1.0, "pixel": 1.0, "pixels": 1.0}
    if "SAMPLE_PROJECTION_OFFSET" in proj and "LINE_PROJECTION_OFFSET" in proj:
        # PDS3: sample (0-based, pixel centre) = SAMPLE_PROJECTION_OFFSET + res (lon - lon0)
        spo = label_number(proj, "SAMPLE_PROJECTION_OFFSET", where, unit_scale=pix)
        lpo = label_number(proj, "LINE_PROJECTION_OFFSET", where, unit_scale=pix)
        west = center_lon - (spo + 0.5) / res
        north = center_lat + (lpo + 0.5) / res
    else:
        west = label_number(proj, "WESTERNMOST_LONGITUDE", where, unit_scale=deg)
        north = label_number(proj, "MAXIMUM_LATITUDE", where, unit_scale=deg)
    for key, value in (("MAXIMUM_LATITUDE", north), ("WESTERNMOST_LONGITUDE", west)):
        if key in proj and isinstance(proj[key], int | float):
            stated = float(proj[key])
            gap = abs(stated - value) * res
            if key == "WESTERNMOST_LONGITUDE":
                gap = min(gap, abs(abs(stated - value) - 360.0) * res)
            if gap > 0.01:
                logger.warning("%s: label %s = %g but the projection offsets put the edge at "
                               "%g; using the offsets", where, key, stated, value)
    crs = _sphere_crs(str(label.get("TARGET_NAME", "body")).title(), radius_m)
    transform = Affine(1.0 / res, 0.0, west, 0.0, -1.0 / res, north)
    return transform, crs, radius_m
