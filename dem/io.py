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
from craters._shared import (
    ParameterError,
    ParameterTypeError,
    about,
    atomic_path,
    check_int,
    parameter_of,
    temp_file,
)
from craters._shared.files import check_regular_file

from .core import LEVEL_TAG, ORIGIN_TAG, PIXEL_SIZE_TAG, RADIUS_TAG, Dem
from .crscode import CRS_TAG, check_crs, crs_tags, restore_crs
from .pdsimage import check_read_memory, read_pds
from .zarrio import (
    ZARR_OPTIONS,
    ZARR_SUFFIXES,
    ChunkWriter,
    ZarrStore,
    check_zarr_output,
    drop_unresolvable_crs_id,
    is_zarr,
    is_zarr_store,
)

__all__ = ["DEM_SUFFIXES", "GEOTIFF_SUFFIXES", "PDS_SUFFIXES", "WindowWriter", "check_float32",
           "read", "write"]

logger = logging.getLogger(__name__)

#: GeoTIFF suffixes.
GEOTIFF_SUFFIXES = (".tif", ".tiff")
#: Suffixes :func:`write` accepts: GeoTIFF, or a Zarr store (:mod:`dem.zarrio`).
DEM_SUFFIXES = GEOTIFF_SUFFIXES + ZARR_SUFFIXES
#: Suffixes :func:`read` hands to the PDS3 reader (label checks, then GDAL's PDS driver).
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
         body: str | None = None, *, window=None, allow_unknown: bool = False,
         crs=None) -> Dem:
    """Read a DEM: a GeoTIFF (or any raster GDAL reads) or a PDS3 ``.IMG``/``.LBL`` pair.

    NoData pixels become NaN; the band's scale and offset are applied; the CRS (with
    its IAU or other authority code, also where the GeoTIFF keys lose it:
    :mod:`dem.crscode`), transform and tags are kept. PDS3 products (``.lbl`` or
    ``.img`` suffix, detached or attached label) are read through GDAL's PDS driver
    behind craterform's label checks, heights in metres, ``MISSING_CONSTANT`` as NaN, a
    simple-cylindrical map as the IAU_2015 CRS of its body's sphere where PROJ knows
    it (:mod:`dem.pdsimage`: pointers, units, ``OFFSET`` and the reference radius).

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
    crs : str or CRS, optional
        The CRS to use instead of the file's (an authority code such as
        ``IAU_2015:30100``, a WKT or a PROJ string): for a file without one, or with a
        wrong one (as ``gdal_edit -a_srs``).
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
    path = _check_source(path)
    with about("band"):
        band = check_int("band", band, 1)
    win = None if window is None else _check_window(window)
    given = None if crs is None else check_crs(crs)
    if path.suffix.lower() in PDS_SUFFIXES:
        heights, transform, crs, tags, label_radius = read_pds(path, band, win)
        if body_radius_m is None:
            body_radius_m = label_radius
    else:
        heights, transform, crs, tags = _read_gdal(path, band, win)
        crs = crs if given is None else given
        body_radius_m, pixel_size_m = _written_sizes(tags, path, crs, body_radius_m,
                                                     pixel_size_m)
    crs = crs if given is None else given
    if body_radius_m is None and body is not None and crs is not None and crs.is_geographic:
        body_radius_m = get_target(body).radius_m
    if not allow_unknown:
        _check_known(heights, path, win)
    level, origin = _lattice(tags, path)
    if win is not None:  # as Dem.crop: the window's transform and lattice origin
        transform = transform @ Affine.translation(win[1], win[0])
        origin = (origin[0] + win[0], origin[1] + win[1])
    try:
        return Dem._own(heights, transform, crs, pixel_size_m=pixel_size_m,
                        body_radius_m=body_radius_m, tags=tags, level=level, origin=origin)
    except (ValueError, TypeError) as exc:
        raise _naming_file(exc, path) from None


def _check_source(path) -> Path:
    """``path`` as a Path: a Zarr store's folder or a regular file."""
    path = Path(path)
    if is_zarr(path) and path.is_dir():
        if not is_zarr_store(path):
            raise ValueError(f"{str(path)!r} is a folder but not a Zarr store (no .zgroup, "
                             f".zarray or zarr.json)")
    else:
        check_regular_file(path, "DEM file")
    return path


def _check_known(heights: np.ndarray, path: Path, win) -> None:
    """At least one known pixel (of the window ``win``, if any)."""
    if not np.isfinite(heights).any():
        where = "" if win is None else f" of the window {_window_text(win)}"
        raise ValueError(f"{str(path)!r}: every pixel{where} is NoData/NaN; there is no "
                         f"terrain to work with")


def _written_sizes(tags: dict, path: Path, crs, body_radius_m, pixel_size_m):
    """(body radius, pixel size) with what craterform wrote in the tags where not given:
    the body radius, and the pixel size of a DEM without CRS."""
    try:
        if body_radius_m is None and RADIUS_TAG in tags:
            body_radius_m = float(tags[RADIUS_TAG])
        if pixel_size_m is None and crs is None and PIXEL_SIZE_TAG in tags:
            pixel_size_m = tuple(float(v) for v in tags[PIXEL_SIZE_TAG].split(","))
    except ValueError:
        logger.warning("%s: ignoring malformed %s/%s tags", path, RADIUS_TAG, PIXEL_SIZE_TAG)
    return body_radius_m, pixel_size_m


def _lattice(tags: dict, path: Path) -> tuple[int, tuple[int, int]]:
    """The expansion level and lattice origin the tags record ((0, (0, 0)) if none)."""
    try:
        if LEVEL_TAG in tags:
            row, col = (int(v) for v in tags.get(ORIGIN_TAG, "0,0").split(","))
            return int(tags[LEVEL_TAG]), (row, col)
    except ValueError:
        logger.warning("%s: ignoring malformed %s/%s tags", path, LEVEL_TAG, ORIGIN_TAG)
    return 0, (0, 0)


def _naming_file(exc: ValueError | TypeError, path: Path) -> ValueError | TypeError:
    """A bad DEM's error with the file named, its parameter kept."""
    if isinstance(exc, ParameterError | ParameterTypeError):  # the file named, the rule
        shown = str(path).replace("{", "{{").replace("}", "}}") if exc.see else str(path)
        return type(exc)(exc.name, f"{exc.rule} (reading {shown!r})", see=exc.see)
    kind = ValueError if isinstance(exc, ValueError) else TypeError  # plain kinds: a
    out = kind(f"{str(path)!r}: {exc}")  # ParameterError needs a rule
    tag = parameter_of(exc)
    if tag is not None:
        out.parameter = tag  # type: ignore[union-attr]  # a tag (parameter_of)
    return out


def _check_window(window) -> tuple[int, int, int, int]:
    """(row_off, col_off, rows, cols) of a rasterio Window or a 4-tuple of integers."""
    with about("window"):
        if isinstance(window, Window):
            vals: tuple = (window.row_off, window.col_off, window.height, window.width)
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
        raise ParameterError("window", f"{_window_text(win)} is not inside {str(path)!r} "
                             f"({rows} x {cols} pixels)")


def _read_gdal(path: Path, band: int, win=None):
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", NotGeoreferencedWarning)
            with rasterio.open(path) as ds:
                if band > ds.count:
                    raise ParameterError("band", f"must be in [1, {ds.count}] for "
                                         f"{str(path)!r}; got {band}")
                if np.dtype(ds.dtypes[band - 1]).kind == "c":
                    raise ValueError(f"{str(path)!r}: band {band} holds complex numbers "
                                     f"({ds.dtypes[band - 1]}); heights must be real")
                check_read_memory(path, *((ds.height, ds.width) if win is None else win[2:]))
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
    tags = {str(k): str(v) for k, v in tags.items()}
    crs = restore_crs(crs, tags, str(path))  # an IAU code the GeoTIFF keys lost
    heights = np.ma.filled(data.astype(np.float64), np.nan)
    if scale not in (None, 1.0):
        heights *= scale
    if offset not in (None, 0.0):
        heights += offset
    return heights, transform, crs, tags


# --------------------------------------------------------------------------- write
def write(dem: Dem, path) -> Path:
    """Write ``dem`` to a cloud-optimised GeoTIFF, atomically; the same DEM always gives
    the same bytes.

    float32 heights with a NaN NoData value, GDAL's COG layout: deflate compression with
    the floating-point predictor, 256 x 256 tiles, overviews (averages) down to one
    tile, BigTIFF when needed. The CRS, transform and tags (including how the layer was
    made: ``CRATERFORM_GENERATOR``, ``_VERSION``, ``_SEED``, ``_PARAMETERS``,
    ``_HISTORY``, the body radius if known, ``CRATERFORM_BODY_RADIUS_M``, without a
    CRS the pixel size, ``CRATERFORM_PIXEL_SIZE_M``, and a CRS code the GeoTIFF keys
    cannot hold, e.g. ``IAU_2015:30135``, ``CRATERFORM_CRS``) are written. An existing file is
    replaced. A ``.zarr`` path writes a Zarr store instead (:mod:`dem.zarrio`: the same
    heights and tags, no overviews), replacing only a Zarr DEM.

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
    path = _check_dem_path(path)
    rows, cols = dem.shape
    check_float32(dem.heights, path)
    data = dem.heights.astype(np.float32)
    if is_zarr(path):  # the chunks of a Zarr store: one window
        with WindowWriter(path, dem.shape, transform=dem.transform, crs=dem.crs,
                          tags=dem.tags, body_radius_m=dem.body_radius_m,
                          pixel_size_m=dem.pixel_size_m) as out:
            out.write(data, 0, 0)
        return path
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


def check_float32(heights: np.ndarray, path) -> None:
    """The known ``heights`` fit the output's float32 (one-line ValueError naming it)."""
    known = ~np.isnan(heights)
    top = float(np.abs(heights[known]).max()) if known.any() else 0.0
    if top > np.finfo(np.float32).max:
        raise ValueError(f"output {str(path)!r}: heights up to {top:.6g} m do not fit the "
                         f"output's float32 (at most {np.finfo(np.float32).max:.6g})")


def _check_dem_path(path) -> Path:
    path = Path(path)
    if path.suffix.lower() not in DEM_SUFFIXES:
        raise ValueError(f"output {str(path)!r}: a DEM is written as GeoTIFF or Zarr; "
                         f"allowed: {' '.join(DEM_SUFFIXES)}")
    return path


def _open_zarr(store: Path, rows: int, cols: int, crs, transform):
    """A new Zarr store (GDAL's driver, :data:`dem.zarrio.ZARR_OPTIONS`) to write into."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", NotGeoreferencedWarning)
        return rasterio.open(store, "w", driver="Zarr", width=cols, height=rows, count=1,
                             dtype="float32", nodata=np.nan, crs=crs,
                             transform=Affine.identity() if transform is None else transform,
                             **ZARR_OPTIONS)


def _file_tags(tags, crs, body_radius_m, pixel_size_m) -> dict:
    """The tags written with a DEM: its own, the body radius, the pixel size (no CRS),
    the CRS's code where the GeoTIFF keys lose it."""
    tags = {k: v for k, v in tags.items() if k != CRS_TAG}
    tags.update(crs_tags(crs))
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
    makes of the whole (the same bytes), for DEMs bigger than memory; a ``.zarr`` path
    writes the windows straight into the Zarr store's chunks (the same files as
    :func:`write` makes).

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
        self.path = _check_dem_path(path)
        rows, cols = (check_int("shape", v, 1) for v in shape)
        self.shape = (rows, cols)
        transform = Affine.identity() if transform is None else transform
        if crs is None:  # the pixel size tag, as a Dem without CRS writes it
            if pixel_size_m is None:
                raise ParameterError("pixel_size_m", "is needed for a DEM without CRS")
            pair = np.broadcast_to(np.asarray(pixel_size_m, dtype=np.float64), (2,))
            pixel_size_m = tuple(float(v) for v in pair)
        self._tmp = self._zarr = None
        if is_zarr(self.path):  # straight into the store's chunks
            check_zarr_output(self.path, force=True)
            self._zarr = ZarrStore(self.path)
        else:
            self._tmp = temp_file(self.path, ".part.tif")
        self._env = rasterio.Env(GDAL_CACHEMAX=int(cache_mb))
        self._env.__enter__()
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", NotGeoreferencedWarning)
                if self._zarr is not None:
                    self._ds = _open_zarr(self._zarr.store, rows, cols, crs, transform)
                else:
                    self._ds = rasterio.open(self._tmp, "w", driver="GTiff", width=cols,
                                             height=rows, count=1, dtype="float32",
                                             nodata=np.nan, crs=crs, transform=transform,
                                             tiled=True, blockxsize=_BLOCK,
                                             blockysize=_BLOCK, bigtiff="IF_SAFER",
                                             sparse_ok=True)
                _set_metadata(self._ds, _file_tags(tags or {}, crs, body_radius_m,
                                                   pixel_size_m))
            if self._zarr is not None:  # GDAL wrote the metadata; the heights go in chunks
                self._ds.close()
                drop_unresolvable_crs_id(self._zarr.store)
                self._chunks = ChunkWriter(self._zarr.store)
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
        if self._zarr is not None:
            self._chunks.write(z, win[0], win[1])
        else:
            self._ds.write(z, 1, window=Window(win[1], win[0], win[3], win[2]))

    def close(self) -> Path:
        """Turn the written windows into the COG at ``path`` (unwritten pixels: NoData)."""
        if self._ds is None:
            return self.path
        try:
            self._ds.close()
            if self._zarr is not None:
                store, self._zarr = self._zarr, None
                return store.commit()
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
        if self._tmp is not None:
            with contextlib.suppress(FileNotFoundError):
                self._tmp.unlink()
        store, self._zarr = getattr(self, "_zarr", None), None
        if store is not None:
            store.discard()
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
