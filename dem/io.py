"""Raster I/O: GeoTIFF (and anything GDAL reads) through rasterio, PDS3 ``.IMG`` + ``.LBL``.

All raster reading and writing of the ``dem`` package lives here. Every GeoTIFF written
is a cloud-optimised GeoTIFF (GDAL's COG driver: 256 x 256 tiles, overviews, the
header and overviews before the full-resolution tiles), deterministic to the byte.
"""

from __future__ import annotations

import logging
import math
import re
import warnings
from pathlib import Path

import numpy as np
import rasterio
from affine import Affine
from rasterio.crs import CRS
from rasterio.errors import NotGeoreferencedWarning, RasterioIOError

from craters import get_target
from craters._shared import about, atomic_path, check_int, parameter_of

from ._pds import Quantity, find_object, parse_label
from .core import LEVEL_TAG, ORIGIN_TAG, PIXEL_SIZE_TAG, RADIUS_TAG, Dem

__all__ = ["GEOTIFF_SUFFIXES", "PDS_SUFFIXES", "read", "write"]

logger = logging.getLogger(__name__)

#: Suffixes :func:`write` accepts.
GEOTIFF_SUFFIXES = (".tif", ".tiff")
#: Suffixes :func:`read` hands to the PDS3 reader instead of GDAL.
PDS_SUFFIXES = (".img", ".lbl")
# tile size of the written cloud-optimised GeoTIFFs, pixels
_BLOCK = 256
# GDAL COG creation options: deflate with the floating-point predictor, 256 x 256 tiles,
# overviews (averages of the known pixels) halving down to one tile, BigTIFF when needed,
# no statistics (nothing that depends on how the file was made)
_COG_OPTIONS = {"compress": "DEFLATE", "predictor": "FLOATING_POINT", "blocksize": _BLOCK,
                "bigtiff": "IF_SAFER", "overview_resampling": "AVERAGE", "statistics": "NO"}

# PDS3 SAMPLE_TYPE -> (numpy kind, byte order)
_PDS_TYPES = {
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
_SIMPLE_CYLINDRICAL = ("SIMPLE CYLINDRICAL", "SIMPLE_CYLINDRICAL", "EQUIRECTANGULAR")


# --------------------------------------------------------------------------- read
def read(path, band: int = 1, pixel_size_m=None, body_radius_m: float | None = None,
         body: str | None = None) -> Dem:
    """Read a DEM: a GeoTIFF (or any raster GDAL reads) or a PDS3 ``.IMG``/``.LBL`` pair.

    NoData pixels become NaN; the band's scale and offset are applied; the CRS,
    transform and tags are kept. PDS3 products (``.lbl`` or ``.img`` suffix, detached or
    attached label) are read by craterform itself: heights are ``DN * SCALING_FACTOR``,
    ``MISSING_CONSTANT`` pixels are NaN, and a simple-cylindrical map projection gives
    a geographic CRS on a sphere of the label's ``A_AXIS_RADIUS`` (which is then also
    the body radius). A label ``OFFSET`` within 10 % of that radius is the reference
    radius of the heights (as in LOLA's GDR products: radius = height + OFFSET), so it
    is recorded in the tag ``PDS_REFERENCE_RADIUS_M`` and not added; any other
    ``OFFSET`` is added as the PDS standard says.

    Parameters
    ----------
    path : str or Path
    band : int
        1-based band number.
    pixel_size_m : float or (float, float), optional
        Pixel size in metres, required (and only allowed) when the file has no CRS,
        unless craterform wrote the file (tag ``CRATERFORM_PIXEL_SIZE_M``; an explicit
        value wins).
    body_radius_m : float, optional
        Body radius in metres, required for a geographic CRS unless a PDS label or the
        ``CRATERFORM_BODY_RADIUS_M`` tag of a file craterform wrote gives it (an explicit
        value wins).
    body : str, optional
        A body of :data:`craters.TARGETS` (``moon``, ``mars`` ...): its mean radius when
        neither ``body_radius_m`` nor the file gives one (a geographic CRS needs it).

    Returns
    -------
    Dem

    Raises
    ------
    ValueError
        For a missing or non-raster file, a bad band, a DEM without CRS and without
        ``pixel_size_m``, a geographic CRS without body radius, or a DEM with no known
        pixel; the message is one line naming the file.
    """
    path = Path(path)
    if not path.is_file():
        raise ValueError(f"DEM file {str(path)!r} does not exist")
    with about("band"):
        band = check_int("band", band, 1)
    if path.suffix.lower() in PDS_SUFFIXES:
        heights, transform, crs, tags, label_radius = _read_pds(path, band)
        if body_radius_m is None:
            body_radius_m = label_radius
    else:
        heights, transform, crs, tags = _read_gdal(path, band)
        # written by craterform: the body radius / the pixel size of a DEM without CRS
        try:
            if body_radius_m is None and RADIUS_TAG in tags:
                body_radius_m = float(tags[RADIUS_TAG])
            if pixel_size_m is None and crs is None and PIXEL_SIZE_TAG in tags:
                pixel_size_m = tuple(float(v) for v in tags[PIXEL_SIZE_TAG].split(","))
        except ValueError:
            logger.warning("%s: ignoring malformed %s/%s tags", path, RADIUS_TAG,
                           PIXEL_SIZE_TAG)
    if body_radius_m is None and body is not None and crs is not None and crs.is_geographic:
        body_radius_m = get_target(body).radius_m
    if not np.isfinite(heights).any():
        raise ValueError(f"{str(path)!r}: every pixel is NoData/NaN; there is no terrain to "
                         f"work with")
    level, origin = 0, (0, 0)
    try:
        if LEVEL_TAG in tags:
            level = int(tags[LEVEL_TAG])
            origin = tuple(int(v) for v in tags.get(ORIGIN_TAG, "0,0").split(","))
    except ValueError:
        logger.warning("%s: ignoring malformed %s/%s tags", path, LEVEL_TAG, ORIGIN_TAG)
        level, origin = 0, (0, 0)
    try:
        return Dem._own(heights, transform, crs, pixel_size_m=pixel_size_m,
                        body_radius_m=body_radius_m, tags=tags, level=level, origin=origin)
    except (ValueError, TypeError) as exc:
        with about(parameter_of(exc)):  # the file named, the parameter kept
            raise type(exc)(f"{str(path)!r}: {exc}") from None


def _read_gdal(path: Path, band: int):
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", NotGeoreferencedWarning)
            with rasterio.open(path) as ds:
                if band > ds.count:
                    with about("band"):
                        raise ValueError(f"`band` must be in [1, {ds.count}] for "
                                         f"{str(path)!r}; got {band}")
                data = ds.read(band, masked=True)
                scale, offset = ds.scales[band - 1], ds.offsets[band - 1]
                transform, crs = ds.transform, ds.crs
                tags = ds.tags()
    except RasterioIOError as exc:
        reason = str(exc).replace(str(path), "").strip(" :'")
        raise ValueError(f"{str(path)!r} is not a raster file GDAL can read ({reason})") from None
    heights = np.ma.filled(data.astype(np.float64), np.nan)
    if scale not in (None, 1.0):
        heights *= scale
    if offset not in (None, 0.0):
        heights += offset
    return heights, transform, crs, {str(k): str(v) for k, v in tags.items()}


# --------------------------------------------------------------------------- PDS3
def _find_file(folder: Path, name: str) -> Path | None:
    """``folder / name``, matching the name case-insensitively (PDS names are upper-case)."""
    exact = folder / name
    if exact.is_file():
        return exact
    lower = name.lower()
    for p in folder.iterdir():
        if p.name.lower() == lower and p.is_file():
            return p
    return None


def _label_text(path: Path) -> tuple[str, Path]:
    """The label text and the file it came from (detached ``.lbl`` or attached)."""
    if path.suffix.lower() == ".lbl":
        return path.read_text(encoding="latin-1"), path
    with open(path, "rb") as fh:
        head = fh.read(1 << 20)
    if head.startswith(b"PDS_VERSION_ID"):
        text = head.decode("latin-1")
        end = re.search(r"^\s*END\s*$", text, re.M)
        return (text[:end.end()] if end else text), path
    for suffix in (".lbl", ".LBL", ".Lbl"):
        label = _find_file(path.parent, path.stem + suffix)
        if label is not None:
            return label.read_text(encoding="latin-1"), label
    raise ValueError(f"{str(path)!r}: no PDS label found (neither attached nor a .LBL "
                     f"file next to it)")


def _number(block: dict, key: str, where: str, default=None, unit_scale=None) -> float:
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


def _pds_constant(value, kind: str, nbytes: int):
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


def _read_pds(path: Path, band: int):
    text, label_path = _label_text(path)
    where = str(label_path)
    try:
        label = parse_label(text)
    except ValueError as exc:
        raise ValueError(f"{where!r}: cannot parse the PDS label ({exc})") from None
    image, parent = find_object(label, "IMAGE")
    if image is None:
        raise ValueError(f"{where!r}: the PDS label has no IMAGE object")
    lines = int(_number(image, "LINES", where))
    samples = int(_number(image, "LINE_SAMPLES", where))
    bands = int(_number(image, "BANDS", where, 1))
    bits = int(_number(image, "SAMPLE_BITS", where))
    stype = str(image.get("SAMPLE_TYPE", "")).upper().replace(" ", "_")
    if stype not in _PDS_TYPES:
        raise ValueError(f"{where!r}: unsupported SAMPLE_TYPE {stype or '(none)'!r}")
    kind, order = _PDS_TYPES[stype]
    if bits not in (8, 16, 32, 64) or (kind == "f" and bits < 32):
        raise ValueError(f"{where!r}: unsupported SAMPLE_BITS {bits} for {stype}")
    nbytes = bits // 8
    dtype = np.dtype(f"{order if nbytes > 1 else '|'}{kind}{nbytes}")
    if band > bands:
        with about("band"):
            raise ValueError(f"`band` must be in [1, {bands}] for {where!r}; got {band}")
    if bands > 1 and str(image.get("BAND_STORAGE_TYPE", "BAND_SEQUENTIAL")).upper() != \
            "BAND_SEQUENTIAL":
        raise ValueError(f"{where!r}: only BAND_SEQUENTIAL multi-band images are supported")
    prefix = int(_number(image, "LINE_PREFIX_BYTES", where, 0))
    suffix = int(_number(image, "LINE_SUFFIX_BYTES", where, 0))
    stride = prefix + samples * nbytes + suffix

    # where the samples are: ^IMAGE = "F.IMG" | ("F.IMG", record) | record | n <BYTES>
    pointer = parent.get("^IMAGE", label.get("^IMAGE"))
    record_bytes = parent.get("RECORD_BYTES", label.get("RECORD_BYTES"))
    data_name, start = None, 1
    if isinstance(pointer, list) and pointer:
        data_name = str(pointer[0])
        start = pointer[1] if len(pointer) > 1 else 1
    elif isinstance(pointer, str):
        data_name = pointer
    elif isinstance(pointer, int | float):
        start = pointer
    else:
        raise ValueError(f"{where!r}: the PDS label has no usable ^IMAGE pointer")
    if isinstance(start, Quantity) and start.unit.upper() == "BYTES":
        offset = int(start) - 1
    elif int(start) == 1:
        offset = 0
    elif record_bytes is None:
        raise ValueError(f"{where!r}: ^IMAGE points to record {int(start)} but the label has "
                         f"no RECORD_BYTES")
    else:
        offset = (int(start) - 1) * int(record_bytes)
    if data_name is None:
        data_path = label_path
    else:
        data_path = _find_file(label_path.parent, data_name)
        if data_path is None:
            raise ValueError(f"{where!r}: the image file {data_name!r} it points to is missing")
    offset += (band - 1) * lines * stride
    need = lines * stride
    with open(data_path, "rb") as fh:
        fh.seek(offset)
        buf = fh.read(need)
    if len(buf) < need:
        raise ValueError(f"{str(data_path)!r} is truncated: {lines} x {samples} samples of "
                         f"{nbytes} bytes need {need} bytes from offset {offset}; got "
                         f"{len(buf)}")
    rows = np.frombuffer(buf, dtype=np.uint8).reshape(lines, stride)
    raw = np.ascontiguousarray(rows[:, prefix:prefix + samples * nbytes]).view(dtype)
    raw = raw.reshape(lines, samples)
    heights = raw.astype(np.float64)
    missing = _pds_constant(image.get("MISSING_CONSTANT"), kind, nbytes)
    if missing is not None:
        heights[raw == missing] = np.nan
    scale = _number(image, "SCALING_FACTOR", where, 1.0)
    heights *= scale

    proj, _ = find_object(label, "IMAGE_MAP_PROJECTION")
    tags = {"PDS_LABEL": label_path.name}
    for key in ("PRODUCT_ID", "TARGET_NAME", "DATA_SET_ID"):
        if isinstance(label.get(key), str):
            tags[f"PDS_{key}"] = label[key]
    transform, crs, radius_m = Affine.identity(), None, None
    if proj is not None:
        transform, crs, radius_m = _pds_georef(proj, label, where)
    pds_offset = float(image.get("OFFSET", 0.0) or 0.0)
    if pds_offset:
        if radius_m is not None and abs(pds_offset - radius_m) <= 0.1 * radius_m:
            tags["PDS_REFERENCE_RADIUS_M"] = repr(pds_offset)
        else:
            heights += pds_offset
    return heights, transform, crs, tags, radius_m


def _pds_georef(proj: dict, label: dict, where: str):
    """Transform (degrees), geographic CRS and radius (m) of a simple-cylindrical map."""
    ptype = " ".join(str(proj.get("MAP_PROJECTION_TYPE", "")).upper().split())
    if ptype not in _SIMPLE_CYLINDRICAL:
        raise ValueError(f"{where!r}: unsupported MAP_PROJECTION_TYPE {ptype or '(none)'!r}; "
                         f"only simple cylindrical DEMs are read")
    km = {"km": 1000.0, "kilometers": 1000.0, "kilometres": 1000.0, "m": 1.0, "meters": 1.0,
          "metres": 1.0, "meter": 1.0, "metre": 1.0}
    radius_m = _number(proj, "A_AXIS_RADIUS", where, unit_scale=km)
    if not isinstance(proj["A_AXIS_RADIUS"], Quantity):
        radius_m *= 1000.0  # PDS3 gives axis radii in km
    deg = {"deg": 1.0, "degree": 1.0, "degrees": 1.0}
    center_lat = _number(proj, "CENTER_LATITUDE", where, 0.0, deg)
    if center_lat != 0.0:
        raise ValueError(f"{where!r}: EQUIRECTANGULAR with CENTER_LATITUDE {center_lat:g} is "
                         f"not supported (only 0, simple cylindrical)")
    if str(proj.get("POSITIVE_LONGITUDE_DIRECTION", "EAST")).upper() != "EAST":
        raise ValueError(f"{where!r}: only POSITIVE_LONGITUDE_DIRECTION = EAST is supported")
    if "MAP_RESOLUTION" in proj:
        res = _number(proj, "MAP_RESOLUTION", where, unit_scale={"pix/deg": 1.0,
                                                                 "pixel/degree": 1.0,
                                                                 "pixels/degree": 1.0})
    else:
        scale_m = _number(proj, "MAP_SCALE", where, unit_scale={
            "m/pix": 1.0, "m/pixel": 1.0, "meters/pixel": 1.0, "metres/pixel": 1.0,
            "km/pix": 1000.0, "km/pixel": 1000.0})
        res = radius_m * math.pi / 180.0 / scale_m
    if not res > 0:
        raise ValueError(f"{where!r}: MAP_RESOLUTION must be > 0; got {res!r}")
    center_lon = _number(proj, "CENTER_LONGITUDE", where, 0.0, deg)
    pix = {"pix": 1.0, "pixel": 1.0, "pixels": 1.0}
    if "SAMPLE_PROJECTION_OFFSET" in proj and "LINE_PROJECTION_OFFSET" in proj:
        # PDS3: sample (0-based, pixel centre) = SAMPLE_PROJECTION_OFFSET + res (lon - lon0)
        spo = _number(proj, "SAMPLE_PROJECTION_OFFSET", where, unit_scale=pix)
        lpo = _number(proj, "LINE_PROJECTION_OFFSET", where, unit_scale=pix)
        west = center_lon - (spo + 0.5) / res
        north = center_lat + (lpo + 0.5) / res
    else:
        west = _number(proj, "WESTERNMOST_LONGITUDE", where, unit_scale=deg)
        north = _number(proj, "MAXIMUM_LATITUDE", where, unit_scale=deg)
    for key, value in (("MAXIMUM_LATITUDE", north), ("WESTERNMOST_LONGITUDE", west)):
        if key in proj and isinstance(proj[key], int | float):
            stated = float(proj[key])
            gap = abs(stated - value) * res
            if key == "WESTERNMOST_LONGITUDE":
                gap = min(gap, abs(abs(stated - value) - 360.0) * res)
            if gap > 0.01:
                logger.warning("%s: label %s = %g but the projection offsets put the edge at "
                               "%g; using the offsets", where, key, stated, value)
    target = str(label.get("TARGET_NAME", "body")).title()
    crs = CRS.from_wkt(
        f'GEOGCS["{target} (sphere, PDS label)",DATUM["D_{target}",'
        f'SPHEROID["{target}",{radius_m!r},0]],PRIMEM["Reference_Meridian",0],'
        f'UNIT["degree",0.0174532925199433]]')
    transform = Affine(1.0 / res, 0.0, west, 0.0, -1.0 / res, north)
    return transform, crs, radius_m


# --------------------------------------------------------------------------- write
def write(dem: Dem, path) -> Path:
    """Write ``dem`` to a cloud-optimised GeoTIFF, atomically; the same DEM always gives
    the same bytes.

    float32 heights with a NaN NoData value, GDAL's COG layout: deflate compression with
    the floating-point predictor, 256 x 256 tiles, overviews (averages) down to one
    tile, BigTIFF when needed. The CRS, transform and tags (including how the layer was
    made: ``CRATERFORM_GENERATOR``, ``_VERSION``, ``_SEED``, ``_PARAMETERS``,
    ``_HISTORY``, the body radius if known, ``CRATERFORM_BODY_RADIUS_M``, and without a
    CRS the pixel size, ``CRATERFORM_PIXEL_SIZE_M``) are written. An existing file is
    replaced.

    Examples
    --------
    >>> import tempfile, numpy as np
    >>> d = Dem(np.arange(12.0).reshape(3, 4), pixel_size_m=5.0)
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     back = read(write(d, f"{tmp}/d.tif"))
    >>> bool((back.heights == d.heights).all()), back.pixel_size_m
    (True, (5.0, 5.0))
    """
    if not isinstance(dem, Dem):
        raise TypeError(f"`dem` must be a Dem; got {type(dem).__name__}")
    path = _check_geotiff_path(path)
    rows, cols = dem.shape
    data = dem.heights.astype(np.float32)
    with atomic_path(path) as tmp:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", NotGeoreferencedWarning)
            # a copy-only driver: rasterio fills a MEM dataset, GDAL copies it on close
            with rasterio.open(tmp, "w", driver="COG", width=cols, height=rows, count=1,
                               dtype="float32", nodata=np.nan, crs=dem.crs,
                               transform=dem.transform, **_COG_OPTIONS) as ds:
                ds.write(data, 1)
                _write_metadata(ds, dem)
    return path


def _check_geotiff_path(path) -> Path:
    path = Path(path)
    if path.suffix.lower() not in GEOTIFF_SUFFIXES:
        raise ValueError(f"output {str(path)!r}: a DEM is written as GeoTIFF; allowed: "
                         f"{' '.join(GEOTIFF_SUFFIXES)}")
    return path


def _file_tags(dem: Dem) -> dict:
    """The tags written with ``dem``: its own, the body radius, the pixel size (no CRS)."""
    tags = dict(dem.tags)
    if dem.body_radius_m is not None:
        tags[RADIUS_TAG] = repr(dem.body_radius_m)
    if dem.crs is None:
        tags[PIXEL_SIZE_TAG] = ",".join(map(repr, dem.pixel_size_m))
    return tags


def _write_metadata(ds, dem: Dem) -> None:
    ds.update_tags(**_file_tags(dem))
    ds.set_band_description(1, "height")
    ds.units = ("metre",)
