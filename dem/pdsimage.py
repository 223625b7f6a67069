"""PDS3 images read through GDAL's PDS driver, behind craterform's own label checks.

craterform parses the label first (:mod:`dem._pds`: size limits, nesting depth, the
sample type, the ``^IMAGE`` pointer, which may only name a file beside the label or
below its folder) and only then hands GDAL a label it wrote itself: the checked
facts of the image (sizes, sample type, line prefix/suffix, the byte offset of the
image) and of its map projection, in a private temporary folder whose one data file
is a link to the checked data file. GDAL so never opens a file the label names
unless craterform resolved and checked it, and never sees a label craterform could
not parse. GDAL decodes the samples and understands every map projection its PDS
driver knows (polar stereographic, ...); heights follow craterform's rules (the
label's ``SCALING_FACTOR``, ``MISSING_CONSTANT`` pixels NaN, the LOLA ``OFFSET``
rule of :func:`dem.read`). A simple-cylindrical map centred on the equator keeps
craterform's geographic georeference (degrees on the label's sphere, exactly the
label's ``MAP_RESOLUTION``), which GDAL's (metres) matches to a small fraction of a
pixel; every other projection is GDAL's (CRS and transform).
"""

from __future__ import annotations

import contextlib
import math
import os
import re
import tempfile
import warnings
from pathlib import Path
from typing import NamedTuple

import numpy as np
import rasterio
from affine import Affine
from rasterio.crs import CRS
from rasterio.errors import NotGeoreferencedWarning, RasterioIOError
from rasterio.windows import Window

from craters._shared import ParameterError, about

from ._pds import (
    SAMPLE_TYPES,
    SIMPLE_CYLINDRICAL,
    Quantity,
    axis_radius_m,
    data_file,
    find_object,
    georeference,
    label_number,
    label_text,
    parse_label,
    sample_constant,
)
from .budget import check_memory_need

__all__ = ["read_pds"]

# the sample types GDAL's PDS driver is given: (numpy kind, byte order) -> PDS name
_GDAL_TYPES = {("i", "<"): "LSB_INTEGER", ("i", ">"): "MSB_INTEGER",
               ("u", "<"): "LSB_UNSIGNED_INTEGER", ("u", ">"): "MSB_UNSIGNED_INTEGER",
               ("f", "<"): "PC_REAL", ("f", ">"): "IEEE_REAL"}
_WORD = re.compile(r"[A-Za-z_][A-Za-z0-9_]*|\d+#[0-9A-Fa-f]+#")
_KEY = re.compile(r"[A-Z][A-Z0-9_]*")  # keywords passed on (no pointers: no other files)
_KM = ("KM", "KILOMETER", "KILOMETERS", "KILOMETRE", "KILOMETRES")
# the names of the files in the private folder GDAL opens
_LABEL, _DATA = "LABEL.LBL", "DATA.IMG"


class _Image(NamedTuple):
    """The checked layout of a PDS3 ``IMAGE`` object."""

    lines: int
    samples: int
    bands: int
    kind: str
    """numpy kind of the samples: ``i``, ``u`` or ``f``."""
    order: str
    """Byte order: ``<`` or ``>``."""
    bits: int
    prefix: int
    """Bytes before each line's samples."""
    suffix: int
    """Bytes after each line's samples."""

    @property
    def stride(self) -> int:
        """Bytes per line."""
        return self.prefix + self.samples * self.bits // 8 + self.suffix


#: Memory a pixel of a raster read takes at its peak: the float64 heights and the float64
#: copy the NoData fill makes (the file's own samples and mask are smaller and freed).
READ_BYTES_PER_PIXEL = 16


def check_read_memory(path, rows: int, cols: int) -> None:
    """Refuse up front (one line naming the file) a read of ``rows`` x ``cols`` pixels that
    this machine's memory cannot hold (:func:`dem.read`, GDAL rasters and PDS3 images)."""
    check_memory_need(READ_BYTES_PER_PIXEL * float(rows) * float(cols),
                      f"reading {str(path)!r} ({rows} x {cols} pixels)",
                      "crop it first (gdal_translate -srcwin) or read a window "
                      "(dem.read(..., window=...))")


def read_pds(path: Path, band: int, win=None):
    """Heights, transform, CRS, tags and body radius (m, or None) of a PDS3 image.

    ``win`` is ``(row_off, col_off, rows, cols)`` inside the image, or None for all of
    it. Errors are one-line ValueErrors naming the label.
    """
    text, label_path = label_text(path)
    where = str(label_path)
    try:
        label = parse_label(text)
    except ValueError as exc:
        raise ValueError(f"{where!r}: cannot parse the PDS label ({exc})") from None
    image, parent = find_object(label, "IMAGE")
    if image is None:
        raise ValueError(f"{where!r}: the PDS label has no IMAGE object")
    layout = _image_layout(image, band, where)
    assert parent is not None  # found with the image
    data_path, offset = _image_start(label, parent, label_path, where)
    _check_extent(layout, data_path, offset + (band - 1) * layout.lines * layout.stride)
    r0, c0, n_lines, n_samples = (0, 0, layout.lines, layout.samples) if win is None else win
    if r0 + n_lines > layout.lines or c0 + n_samples > layout.samples:
        with about("window"):
            raise ValueError(f"`window` (row_off, col_off, rows, cols) = {tuple(win)} is not "
                             f"inside {str(path)!r} ({layout.lines} x {layout.samples} "
                             f"pixels)")
    check_read_memory(path, n_lines, n_samples)
    proj, _ = find_object(label, "IMAGE_MAP_PROJECTION")
    dtype = np.dtype(f"{layout.kind}{layout.bits // 8}")
    raw, gdal_transform, gdal_crs = _read_with_gdal(
        _gdal_label(label, proj, layout, offset), data_path, band,
        Window(c0, r0, n_samples, n_lines), dtype, where)
    heights = raw.astype(np.float64)
    missing = sample_constant(image.get("MISSING_CONSTANT"), layout.kind, dtype.itemsize)
    if missing is not None:
        heights[raw == missing] = np.nan
    # heights in kilometres (UNIT = KILOMETER, as LOLA's floating-point polar products
    # give them, with OFFSET = 1737.4): metres, the OFFSET too
    unit_m = 1000.0 if str(image.get("UNIT", "")).upper() in _KM else 1.0
    heights *= label_number(image, "SCALING_FACTOR", where, 1.0) * unit_m
    tags = {"PDS_LABEL": label_path.name}
    for key in ("PRODUCT_ID", "TARGET_NAME", "DATA_SET_ID"):
        if isinstance(label.get(key), str):
            tags[f"PDS_{key}"] = label[key]
    transform, crs, radius_m = Affine.identity(), None, None
    if proj is not None:
        if _craterform_georeference(proj):
            transform, crs, radius_m = georeference(proj, label, where)
        else:
            transform, crs, radius_m = _gdal_georeference(proj, gdal_transform, gdal_crs,
                                                          where)
    pds_offset = label_number(image, "OFFSET", where, 0.0) * unit_m
    if pds_offset:
        if radius_m is not None and abs(pds_offset - radius_m) <= 0.1 * radius_m:
            tags["PDS_REFERENCE_RADIUS_M"] = repr(pds_offset)
        else:
            heights += pds_offset
    return heights, transform, crs, tags, radius_m


def _image_layout(image: dict, band: int, where: str) -> _Image:
    """The IMAGE object's sizes, sample type and line padding, checked (and ``band``
    against its bands)."""
    lines = int(label_number(image, "LINES", where))
    samples = int(label_number(image, "LINE_SAMPLES", where))
    bands = int(label_number(image, "BANDS", where, 1))
    bits = int(label_number(image, "SAMPLE_BITS", where))
    if min(lines, samples, bands) < 1:
        raise ValueError(f"{where!r}: LINES, LINE_SAMPLES and BANDS must be >= 1; got "
                         f"{lines}, {samples}, {bands}")
    stype = str(image.get("SAMPLE_TYPE", "")).upper().replace(" ", "_")
    if stype not in SAMPLE_TYPES:
        raise ValueError(f"{where!r}: unsupported SAMPLE_TYPE {stype or '(none)'!r}")
    kind, order = SAMPLE_TYPES[stype]
    if bits not in (8, 16, 32, 64) or (kind == "f" and bits < 32):
        raise ValueError(f"{where!r}: unsupported SAMPLE_BITS {bits} for {stype}")
    if band > bands:
        with about("band"):
            raise ParameterError("band", f"must be in [1, {bands}] for {where!r}; got {band}")
    if bands > 1 and str(image.get("BAND_STORAGE_TYPE", "BAND_SEQUENTIAL")).upper() != \
            "BAND_SEQUENTIAL":
        raise ValueError(f"{where!r}: only BAND_SEQUENTIAL multi-band images are supported")
    prefix = int(label_number(image, "LINE_PREFIX_BYTES", where, 0))
    suffix = int(label_number(image, "LINE_SUFFIX_BYTES", where, 0))
    if prefix < 0 or suffix < 0:
        raise ValueError(f"{where!r}: LINE_PREFIX_BYTES and LINE_SUFFIX_BYTES must be >= 0")
    return _Image(lines, samples, bands, kind, order, bits, prefix, suffix)


def _check_extent(layout: _Image, data_path: Path, band_offset: int) -> None:
    """The data file holds the band's lines from ``band_offset`` on."""
    if data_path.stat().st_size < band_offset + layout.lines * layout.stride:
        raise ValueError(f"{str(data_path)!r} is truncated: {layout.lines} x "
                         f"{layout.samples} samples of {layout.bits // 8} bytes need "
                         f"{layout.lines * layout.stride} bytes from offset {band_offset}")


def _image_start(label: dict, parent: dict, label_path: Path, where: str):
    """The checked data file of the image and the byte offset of its first sample."""
    # ^IMAGE = "F.IMG" | ("F.IMG", record) | ("F.IMG", n <BYTES>) | record | n <BYTES>
    pointer = parent.get("^IMAGE", label.get("^IMAGE"))
    record_bytes = parent.get("RECORD_BYTES", label.get("RECORD_BYTES"))
    data_name: str | None = None
    start: float = 1
    if isinstance(pointer, list) and pointer:
        data_name = str(pointer[0])
        start = pointer[1] if len(pointer) > 1 else 1
    elif isinstance(pointer, str):
        data_name = pointer
    elif isinstance(pointer, int | float):
        start = pointer
    else:
        raise ValueError(f"{where!r}: the PDS label has no usable ^IMAGE pointer")
    if not isinstance(start, int | float) or not math.isfinite(start) or start < 1:
        raise ValueError(f"{where!r}: the ^IMAGE pointer's start {start!r} is not a record "
                         f"or byte number >= 1")
    if isinstance(start, Quantity) and start.unit.upper() == "BYTES":
        offset = int(start) - 1
    elif int(start) == 1:
        offset = 0
    elif not isinstance(record_bytes, int) or record_bytes < 1:
        raise ValueError(f"{where!r}: ^IMAGE points to record {int(start)} but the label has "
                         f"no RECORD_BYTES")
    else:
        offset = (int(start) - 1) * record_bytes
    if data_name is None:
        return label_path, offset
    found = data_file(label_path, data_name)  # refuses a file outside the label's folder
    if found is None:
        raise FileNotFoundError(f"{where!r}: the image file {data_name!r} it points to is "
                                f"missing")
    return found, offset


def _craterform_georeference(proj: dict) -> bool:
    """Whether craterform's own geographic georeference applies (simple cylindrical,
    centred on the equator: what :func:`dem._pds.georeference` reads)."""
    ptype = " ".join(str(proj.get("MAP_PROJECTION_TYPE", "")).upper().split())
    if ptype not in SIMPLE_CYLINDRICAL:
        return False
    center = proj.get("CENTER_LATITUDE", 0.0)
    return not isinstance(center, int | float) or float(center) == 0.0


def _gdal_georeference(proj: dict, transform: Affine, crs, where: str):
    """GDAL's CRS and transform of a map projection craterform does not read itself,
    checked, with the label's A_AXIS_RADIUS (m) as the body radius."""
    ptype = " ".join(str(proj.get("MAP_PROJECTION_TYPE", "")).upper().split())
    if str(proj.get("POSITIVE_LONGITUDE_DIRECTION", "EAST")).upper() != "EAST":
        raise ValueError(f"{where!r}: only POSITIVE_LONGITUDE_DIRECTION = EAST is supported")
    radius_m = axis_radius_m(proj, where)
    scale = label_number(proj, "MAP_SCALE", where, 0.0)
    if not (math.isfinite(scale) and scale > 0):
        raise ValueError(f"{where!r}: MAP_SCALE must be finite and > 0; got {scale!r}")
    if crs is None:
        raise ValueError(f"{where!r}: GDAL's PDS driver gives no CRS for MAP_PROJECTION_TYPE "
                         f"{ptype or '(none)'!r} (unsupported, or the label lacks "
                         f"C_AXIS_RADIUS)")
    if not (all(math.isfinite(v) for v in transform[:6]) and transform.determinant != 0):
        raise ValueError(f"{where!r}: GDAL's PDS driver gives no usable georeference "
                         f"({ptype})")
    if crs.is_projected and crs.linear_units == "unknown":  # GDAL's transform is in metres
        crs = CRS.from_wkt(crs.to_wkt().replace('UNIT["unknown",1]',
                                                'UNIT["metre",1,AUTHORITY["EPSG","9001"]]'))
    return transform, crs, radius_m


def _odl(value) -> str:
    """A label value as ODL text: numbers, units, lists, identifiers, quoted text."""
    if isinstance(value, Quantity):
        return f"{float(value)!r} <{_plain(value.unit)}>"
    if isinstance(value, bool):
        return str(value).upper()
    if isinstance(value, int | float):
        return repr(value)
    if isinstance(value, list):
        return "(" + ", ".join(_odl(v) for v in value) + ")"
    text = _plain(str(value)).replace('"', "'")
    return text if _WORD.fullmatch(text) else f'"{text}"'


def _plain(text: str) -> str:
    """One line without comment marks (no value can end the label GDAL reads)."""
    return " ".join(text.replace("/*", "/ *").replace("*/", "* /").split())


def _gdal_label(label: dict, proj: dict | None, layout: _Image, offset: int) -> str:
    """The label GDAL reads: the checked image facts and the map projection's values."""
    out = ["PDS_VERSION_ID = PDS3", "RECORD_TYPE = FIXED_LENGTH",
           f"RECORD_BYTES = {layout.stride}",
           f'^IMAGE = ("{_DATA}", {offset + 1} <BYTES>)']
    if isinstance(label.get("TARGET_NAME"), str):
        out.append(f"TARGET_NAME = {_odl(label['TARGET_NAME'])}")
    out += ["OBJECT = IMAGE", f"  LINES = {layout.lines}",
            f"  LINE_SAMPLES = {layout.samples}", f"  BANDS = {layout.bands}",
            "  BAND_STORAGE_TYPE = BAND_SEQUENTIAL",
            f"  SAMPLE_TYPE = {_GDAL_TYPES[layout.kind, layout.order]}",
            f"  SAMPLE_BITS = {layout.bits}", f"  LINE_PREFIX_BYTES = {layout.prefix}",
            f"  LINE_SUFFIX_BYTES = {layout.suffix}", "END_OBJECT = IMAGE"]
    if proj is not None:
        out.append("OBJECT = IMAGE_MAP_PROJECTION")
        out += [f"  {key} = {_odl(value)}" for key, value in proj.items()
                if _KEY.fullmatch(key) and not isinstance(value, dict)]
        out.append("END_OBJECT = IMAGE_MAP_PROJECTION")
    return "\r\n".join([*out, "END", ""])


def _read_with_gdal(gdal_label: str, data_path: Path, band: int, window: Window, dtype,
                    where: str):
    """The raw samples of ``window`` of ``band``, GDAL's transform and CRS (or None)."""
    with tempfile.TemporaryDirectory(prefix="craterform-pds-") as tmp:
        folder = Path(tmp)
        (folder / _LABEL).write_text(gdal_label, encoding="ascii", errors="replace")
        os.symlink(data_path.resolve(), folder / _DATA)
        try:
            with warnings.catch_warnings(), contextlib.ExitStack() as stack:
                warnings.simplefilter("ignore", NotGeoreferencedWarning)
                ds = stack.enter_context(rasterio.open(folder / _LABEL, driver="PDS"))
                if any(Path(f).parent != folder for f in ds.files):  # never happens
                    raise ValueError(f"{where!r}: GDAL's PDS driver opened other files than "
                                     f"the label and its image ({ds.files})")
                got = np.dtype(ds.dtypes[band - 1])
                if got.itemsize != dtype.itemsize:
                    raise ValueError(f"{where!r}: GDAL's PDS driver reads the samples as "
                                     f"{got.name}, not {dtype.name}")
                # GDAL reads 32- and 64-bit integers as floats of their size and signed
                # bytes as unsigned, byte order handled: the same bits, named as the label
                raw = ds.read(band, window=window).view(dtype)
                transform, crs = ds.transform, ds.crs
        except RasterioIOError as exc:
            reason = str(exc).replace(str(folder), "").strip(" :'/")
            raise ValueError(f"{where!r}: GDAL's PDS driver cannot read the image "
                             f"({reason})") from None
    return raw, transform, crs
