"""Raster I/O: GeoTIFF (and anything GDAL reads) through rasterio, PDS3 ``.IMG`` + ``.LBL``.

All raster reading and writing of the ``dem`` package lives here. Every GeoTIFF written
is a cloud-optimised GeoTIFF (GDAL's COG driver: 256 x 256 tiles, overviews, the
header and overviews before the full-resolution tiles), deterministic to the byte.
DEMs bigger than memory: :func:`read` takes a ``window``, and :class:`WindowWriter`
writes a raster window by window into the same COG :func:`write` makes of the whole.
"""

from __future__ import annotations

import contextlib
import logging
import warnings
from pathlib import Path

import numpy as np
import rasterio
import rasterio.shutil
from affine import Affine
from rasterio.errors import NotGeoreferencedWarning, RasterioIOError
from rasterio.windows import Window

from craters import get_target
from craters._shared import about, atomic_path, check_int, parameter_of, temp_file

from ._pds import (
    SAMPLE_TYPES,
    Quantity,
    data_file,
    find_object,
    georeference,
    label_number,
    label_text,
    parse_label,
    sample_constant,
)
from .core import LEVEL_TAG, ORIGIN_TAG, PIXEL_SIZE_TAG, RADIUS_TAG, Dem

__all__ = ["GEOTIFF_SUFFIXES", "PDS_SUFFIXES", "WindowWriter", "read", "write"]

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

# --------------------------------------------------------------------------- read
def read(path, band: int = 1, pixel_size_m=None, body_radius_m: float | None = None,
         body: str | None = None, *, window=None, allow_unknown: bool = False) -> Dem:
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
    window : rasterio Window or (row_off, col_off, rows, cols), optional
        Read only these pixels (integers, inside the raster): the result is
        ``read(path).crop(window)`` - its transform, lattice origin and pixel size are
        the window's - without reading the rest of the file (GeoTIFFs read their
        blocks, PDS3 images their lines), so a window of a DEM bigger than memory can
        be worked on. A window whose every pixel is NoData is an error unless
        ``allow_unknown`` (a tile in a gap of a DEM bigger than memory).

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
    win = None if window is None else _check_window(window)
    if path.suffix.lower() in PDS_SUFFIXES:
        heights, transform, crs, tags, label_radius = _read_pds(path, band, win)
        if body_radius_m is None:
            body_radius_m = label_radius
    else:
        heights, transform, crs, tags = _read_gdal(path, band, win)
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
    if not allow_unknown and not np.isfinite(heights).any():
        where = "" if win is None else f" of the window {_window_text(win)}"
        raise ValueError(f"{str(path)!r}: every pixel{where} is NoData/NaN; there is no "
                         f"terrain to work with")
    level, origin = 0, (0, 0)
    try:
        if LEVEL_TAG in tags:
            level = int(tags[LEVEL_TAG])
            origin = tuple(int(v) for v in tags.get(ORIGIN_TAG, "0,0").split(","))
    except ValueError:
        logger.warning("%s: ignoring malformed %s/%s tags", path, LEVEL_TAG, ORIGIN_TAG)
        level, origin = 0, (0, 0)
    if win is not None:  # as Dem.crop: the window's transform and lattice origin
        r0, c0 = win[0], win[1]
        transform = transform @ Affine.translation(c0, r0)
        origin = (origin[0] + r0, origin[1] + c0)
    try:
        return Dem._own(heights, transform, crs, pixel_size_m=pixel_size_m,
                        body_radius_m=body_radius_m, tags=tags, level=level, origin=origin)
    except (ValueError, TypeError) as exc:
        with about(parameter_of(exc)):  # the file named, the parameter kept
            kind = ValueError if isinstance(exc, ValueError) else TypeError  # plain kinds:
            raise kind(f"{str(path)!r}: {exc}") from None  # a ParameterError needs a rule


def _check_window(window) -> tuple[int, int, int, int]:
    """(row_off, col_off, rows, cols) of a rasterio Window or a 4-tuple of integers."""
    with about("window"):
        if isinstance(window, Window):
            vals = (window.row_off, window.col_off, window.height, window.width)
        else:
            try:
                vals = tuple(window)
            except TypeError:
                vals = ()
            if len(vals) != 4:
                raise TypeError(f"`window` must be a rasterio Window or (row_off, col_off, "
                                f"rows, cols); got {window!r}")
        if any(isinstance(v, bool) or not float(v).is_integer() for v in vals):
            raise ValueError(f"`window` must have integer offsets and sizes; got {window!r}")
        r0, c0, h, w = (int(v) for v in vals)
        if r0 < 0 or c0 < 0 or h < 1 or w < 1:
            raise ValueError(f"`window` must have offsets >= 0 and sizes >= 1; got "
                             f"(row_off, col_off, rows, cols) = {(r0, c0, h, w)}")
    return r0, c0, h, w


def _window_text(win) -> str:
    return f"(row_off, col_off, rows, cols) = {tuple(win)}"


def _check_inside(win, rows: int, cols: int, path: Path) -> None:
    r0, c0, h, w = win
    if r0 + h > rows or c0 + w > cols:
        with about("window"):
            raise ValueError(f"`window` {_window_text(win)} is not inside {str(path)!r} "
                             f"({rows} x {cols} pixels)")


def _read_gdal(path: Path, band: int, win=None):
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", NotGeoreferencedWarning)
            with rasterio.open(path) as ds:
                if band > ds.count:
                    with about("band"):
                        raise ValueError(f"`band` must be in [1, {ds.count}] for "
                                         f"{str(path)!r}; got {band}")
                if np.dtype(ds.dtypes[band - 1]).kind == "c":
                    raise ValueError(f"{str(path)!r}: band {band} holds complex numbers "
                                     f"({ds.dtypes[band - 1]}); heights must be real")
                if win is None:
                    data = ds.read(band, masked=True)
                else:
                    _check_inside(win, ds.height, ds.width, path)
                    data = ds.read(band, masked=True, window=Window(win[1], win[0], win[3],
                                                                    win[2]))
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
def _read_pds(path: Path, band: int, win=None):
    text, label_path = label_text(path)
    where = str(label_path)
    try:
        label = parse_label(text)
    except ValueError as exc:
        raise ValueError(f"{where!r}: cannot parse the PDS label ({exc})") from None
    image, parent = find_object(label, "IMAGE")
    if image is None:
        raise ValueError(f"{where!r}: the PDS label has no IMAGE object")
    lines = int(label_number(image, "LINES", where))
    samples = int(label_number(image, "LINE_SAMPLES", where))
    bands = int(label_number(image, "BANDS", where, 1))
    bits = int(label_number(image, "SAMPLE_BITS", where))
    stype = str(image.get("SAMPLE_TYPE", "")).upper().replace(" ", "_")
    if stype not in SAMPLE_TYPES:
        raise ValueError(f"{where!r}: unsupported SAMPLE_TYPE {stype or '(none)'!r}")
    kind, order = SAMPLE_TYPES[stype]
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
    prefix = int(label_number(image, "LINE_PREFIX_BYTES", where, 0))
    suffix = int(label_number(image, "LINE_SUFFIX_BYTES", where, 0))
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
        data_path = data_file(label_path, data_name)
        if data_path is None:
            raise ValueError(f"{where!r}: the image file {data_name!r} it points to is missing")
    offset += (band - 1) * lines * stride
    r0, c0, n_lines, n_samples = (0, 0, lines, samples) if win is None else win
    if win is not None:
        _check_inside(win, lines, samples, path)
    need = n_lines * stride
    with open(data_path, "rb") as fh:
        fh.seek(offset + r0 * stride)
        buf = fh.read(need)
    if len(buf) < need:
        raise ValueError(f"{str(data_path)!r} is truncated: {lines} x {samples} samples of "
                         f"{nbytes} bytes need {lines * stride} bytes from offset {offset}")
    rows = np.frombuffer(buf, dtype=np.uint8).reshape(n_lines, stride)
    first = prefix + c0 * nbytes
    raw = np.ascontiguousarray(rows[:, first:first + n_samples * nbytes]).view(dtype)
    raw = raw.reshape(n_lines, n_samples)
    heights = raw.astype(np.float64)
    missing = sample_constant(image.get("MISSING_CONSTANT"), kind, nbytes)
    if missing is not None:
        heights[raw == missing] = np.nan
    scale = label_number(image, "SCALING_FACTOR", where, 1.0)
    heights *= scale

    proj, _ = find_object(label, "IMAGE_MAP_PROJECTION")
    tags = {"PDS_LABEL": label_path.name}
    for key in ("PRODUCT_ID", "TARGET_NAME", "DATA_SET_ID"):
        if isinstance(label.get(key), str):
            tags[f"PDS_{key}"] = label[key]
    transform, crs, radius_m = Affine.identity(), None, None
    if proj is not None:
        transform, crs, radius_m = georeference(proj, label, where)
    pds_offset = float(image.get("OFFSET", 0.0) or 0.0)
    if pds_offset:
        if radius_m is not None and abs(pds_offset - radius_m) <= 0.1 * radius_m:
            tags["PDS_REFERENCE_RADIUS_M"] = repr(pds_offset)
        else:
            heights += pds_offset
    return heights, transform, crs, tags, radius_m


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
    top = float(np.nanmax(np.abs(dem.heights))) if dem.known.any() else 0.0
    if top > np.finfo(np.float32).max:
        raise ValueError(f"output {str(path)!r}: heights up to {top:.6g} m do not fit the "
                         f"GeoTIFF's float32 (at most {np.finfo(np.float32).max:.6g})")
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


def _file_tags(tags, crs, body_radius_m, pixel_size_m) -> dict:
    """The tags written with a DEM: its own, the body radius, the pixel size (no CRS)."""
    tags = dict(tags)
    if body_radius_m is not None:
        tags[RADIUS_TAG] = repr(body_radius_m)
    if crs is None:
        tags[PIXEL_SIZE_TAG] = ",".join(map(repr, pixel_size_m))
    return tags


def _write_metadata(ds, dem: Dem) -> None:
    _set_metadata(ds, _file_tags(dem.tags, dem.crs, dem.body_radius_m, dem.pixel_size_m))


def _set_metadata(ds, tags: dict) -> None:
    ds.update_tags(**tags)
    ds.set_band_description(1, "height")
    ds.units = ("metre",)


class WindowWriter:
    """A DEM written window by window into the cloud-optimised GeoTIFF :func:`write`
    makes of the whole (the same bytes), for DEMs bigger than memory.

    The windows go into a temporary tiled GeoTIFF next to ``path`` (256 x 256 blocks,
    uncompressed: 4 bytes a pixel on disk while it exists); :meth:`close` copies it into
    the COG at ``path`` (atomically) and removes it. Windows aligned to 256-pixel blocks
    are written without reading anything back. GDAL's block cache is limited to
    ``cache_mb`` while the writer is open, which bounds its memory. Use as a context
    manager: an exception leaves ``path`` untouched and removes the temporary file.

    Parameters
    ----------
    path : str or Path
        The ``.tif`` to write.
    shape : (int, int)
        Rows and columns of the whole DEM.
    transform, crs, tags, body_radius_m, pixel_size_m
        What the whole DEM's ``Dem`` would have (``pixel_size_m`` only without a CRS).

    Examples
    --------
    >>> import tempfile
    >>> whole = Dem(np.arange(20.0).reshape(4, 5), pixel_size_m=2.0)
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     with WindowWriter(f"{tmp}/w.tif", (4, 5), pixel_size_m=2.0) as out:
    ...         out.write(whole.heights[:2], 0, 0)
    ...         out.write(whole.heights[2:], 2, 0)
    ...     same = out.path.read_bytes() == write(whole, f"{tmp}/a.tif").read_bytes()
    >>> same
    True
    """

    def __init__(self, path, shape, *, transform: Affine | None = None, crs=None,
                 tags=None, body_radius_m: float | None = None, pixel_size_m=None,
                 cache_mb: int = 256):
        self.path = _check_geotiff_path(path)
        rows, cols = (check_int("shape", v, 1) for v in shape)
        self.shape = (rows, cols)
        transform = Affine.identity() if transform is None else transform
        if crs is None:  # the pixel size tag, as a Dem without CRS writes it
            if pixel_size_m is None:
                with about("pixel_size_m"):
                    raise ValueError("a DEM without CRS needs `pixel_size_m`")
            pair = np.broadcast_to(np.asarray(pixel_size_m, dtype=np.float64), (2,))
            pixel_size_m = tuple(float(v) for v in pair)
        self._tmp = temp_file(self.path, ".part.tif")
        self._env = rasterio.Env(GDAL_CACHEMAX=int(cache_mb))
        self._env.__enter__()
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", NotGeoreferencedWarning)
                self._ds = rasterio.open(self._tmp, "w", driver="GTiff", width=cols,
                                         height=rows, count=1, dtype="float32",
                                         nodata=np.nan, crs=crs, transform=transform,
                                         tiled=True, blockxsize=_BLOCK, blockysize=_BLOCK,
                                         bigtiff="IF_SAFER", sparse_ok=True)
                _set_metadata(self._ds, _file_tags(tags or {}, self._ds.crs, body_radius_m,
                                                   pixel_size_m))
        except BaseException:
            self._discard()
            raise

    def write(self, heights, row_off: int, col_off: int) -> None:
        """Write ``heights`` (rows, cols; metres, NaN = unknown) at pixel (row_off, col_off)."""
        z = np.asarray(heights, dtype=np.float32)
        if z.ndim != 2:
            raise ValueError(f"`heights` must be 2-D; got shape {z.shape}")
        win = (int(row_off), int(col_off), *z.shape)
        _check_inside(win, *self.shape, self.path)
        self._ds.write(z, 1, window=Window(win[1], win[0], win[3], win[2]))

    def close(self) -> Path:
        """Turn the written windows into the COG at ``path`` (unwritten pixels: NoData)."""
        if self._ds is None:
            return self.path
        try:
            self._ds.close()
            with atomic_path(self.path) as tmp:
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore", NotGeoreferencedWarning)
                    rasterio.shutil.copy(self._tmp, tmp, driver="COG", **_COG_OPTIONS)
        finally:
            self._discard()
        return self.path

    def _discard(self) -> None:
        ds, self._ds = getattr(self, "_ds", None), None
        if ds is not None and not ds.closed:
            ds.close()
        with contextlib.suppress(FileNotFoundError):
            self._tmp.unlink()
        env, self._env = self._env, None
        if env is not None:
            env.__exit__(None, None, None)

    def __enter__(self) -> WindowWriter:
        return self

    def __exit__(self, exc_type, *exc) -> None:
        if exc_type is None:
            self.close()
        else:
            self._discard()
