r"""Gap filling of DEMs bigger than memory: :func:`dem.fill_gaps` hole by hole, from a file.

:func:`dem.fill_gaps` fills each hole (8-connected component of unknown pixels) on its
own: its fill depends only on the seed, the fractal dimension F, the known pixels
within 6 pixels of it (the harmonic solve, the local relief), its position, the fills
of the holes filled before it in its box (the solver's start and tolerance read them)
and, for its craters, the known terrain within one hole size of it. So
:func:`fill_to_file` gives the same file, byte for byte, reading the input window by
window:

1. *Holes* (:mod:`dem.holes`): the unknown pixels are labelled tile by tile
   (8-connected, scipy) and the labels joined across tile edges (a graph of the labels
   that touch, its connected components); each hole gets its bounding box, pixel count
   and first pixel in raster order, the order in which ``fill_gaps`` fills them.
2. *F*, unless given: :func:`dem.fractal_fit_rows`, the whole DEM's estimate computed
   strip by strip with numpy's own summation order (:mod:`dem.streamsum`): the same
   number, not an approximation.
3. *Fills*, in that order: each hole's window (its box plus 6 pixels, or plus one hole
   size for the density of its craters) is read, the earlier fills in it are put back,
   the hole is filled (:func:`dem.gaps.fill_hole`, :func:`dem.gapcraters.
   stamp_gap_craters`) and its values (float64) kept in a sparse scratch file next to
   the output (disk used only where holes are).
4. *Output*: tile by tile, the input with the fills, into :class:`dem.io.WindowWriter`
   (the COG :func:`dem.write` makes of the whole), with the step's tags.

Memory: one tile of the input (about 30 bytes a pixel while labelling, ``tile_px``
squared), a strip of as many pixels for F, the per-hole table (about 50 bytes a hole)
and the largest hole's working set (:data:`HOLE_BYTES_PER_PX` of its box, plus
:data:`DENSITY_BYTES_PER_PX` of its crater-density window): a hole whose working set
exceeds ``max_memory_gb`` is refused up front, naming it.
"""

from __future__ import annotations

import contextlib
import dataclasses
import math
import os
from pathlib import Path
from typing import NamedTuple

import numpy as np

from craters._shared import (
    ParameterError,
    about,
    check_int,
    check_positive,
    physical_memory_bytes,
    progress_bar,
    temp_file,
)

from ._pds import find_object, label_number, label_text, parse_label
from .core import Dem, raster_pixel_size_m
from .fractal import NORMALISER_WINDOW_PX, fractal_fit_rows, local_msd, window_mean
from .frame import crater_target
from .gapcraters import stamp_gap_craters
from .gaps import fill_arguments, fill_hole, fill_parameters, record_craters
from .holes import Holes, holes_of_file, tile_windows
from .io import PDS_SUFFIXES, WindowWriter, check_float32, read

__all__ = ["DEFAULT_TILE_PX", "MEMORY_SHARE", "WHOLE_BYTES_PER_PX", "FilledFile", "fill_to_file",
           "fits_whole", "raster_shape"]

#: Default tile side (pixels) of :func:`fill_to_file`: a multiple of the COG's 256-pixel
#: blocks (about 0.5 GB of working memory while labelling).
DEFAULT_TILE_PX = 4096
#: The share of this machine's memory a fill may use unless ``max_memory_gb`` is given.
MEMORY_SHARE = 0.8
#: Working bytes per pixel of a hole's box (estimate: the noise box of 1.5^2 the box,
#: FFTs in complex128, the multigrid levels and the Conjugate-gradient vectors).
HOLE_BYTES_PER_PX = 400.0
#: Working bytes per pixel of the window a hole's crater density is measured on.
DENSITY_BYTES_PER_PX = 120.0
#: Working bytes per pixel of :func:`dem.fill_gaps` on a whole DEM (heights, the filled
#: copy, masks, labels, the relief and the fractal fit's arrays; an estimate).
WHOLE_BYTES_PER_PX = 150.0
# pixels around a hole that its fill reads: the 4-neighbours, then 5 more for the relief
_CONTEXT_PX = 6
# bytes per pixel of a tile while labelling (heights, masks, labels)
_TILE_BYTES_PER_PX = 30.0
# a scratch value that was never written (all bits 0) decodes to this NaN: the
# scratch holds bits(value) XOR _UNSET
_UNSET = np.uint64(0x7FF8000000000001)


class FilledFile(NamedTuple):
    """What :func:`fill_to_file` wrote."""

    path: Path
    """The cloud-optimised GeoTIFF."""
    shape: tuple[int, int]
    """Its rows and columns."""
    seed: int | None
    """The seed recorded (``rng`` when it is an int)."""
    parameters: dict
    """The step's parameters (``CRATERFORM_PARAMETERS``), as ``fill_gaps`` records them."""
    tiles: int
    """How many tiles were labelled and written."""


def raster_shape(path) -> tuple[int, int]:
    """(rows, cols) of the raster :func:`dem.read` reads from ``path`` (call that first:
    it checks the file), without its pixels: the PDS3 label's LINES and LINE_SAMPLES, or
    GDAL's size."""
    import warnings

    import rasterio
    from rasterio.errors import NotGeoreferencedWarning

    path = Path(path)
    if path.suffix.lower() in PDS_SUFFIXES:
        text, label_path = label_text(path)
        image, _ = find_object(parse_label(text), "IMAGE")
        assert image is not None  # dem.read checked the label (call that first)
        return (int(label_number(image, "LINES", str(label_path))),
                int(label_number(image, "LINE_SAMPLES", str(label_path))))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", NotGeoreferencedWarning)
        with rasterio.open(path) as ds:
            return int(ds.height), int(ds.width)


def _budget(max_memory_gb) -> tuple[float, str]:
    if max_memory_gb is None:
        have = physical_memory_bytes()
        return MEMORY_SHARE * have, (f" (the default: {MEMORY_SHARE:g} x this machine's "
                                     f"{have / 1e9:.3g} GB)")
    with about("max_memory_gb"):
        return check_positive("max_memory_gb", max_memory_gb) * 1e9, ""


def fits_whole(shape, max_memory_gb: float | None = None) -> bool:
    """True when :func:`dem.fill_gaps` of a DEM of ``shape`` fits ``max_memory_gb`` (the
    default: :data:`MEMORY_SHARE` of this machine's memory)."""
    limit, _ = _budget(max_memory_gb)
    return WHOLE_BYTES_PER_PX * shape[0] * shape[1] <= limit


def _margin(box, auto: bool) -> int:
    """Pixels read around a hole: its context, or one hole size for the crater density."""
    size = int(max(box[1] - box[0], box[3] - box[2]))
    return max(_CONTEXT_PX, size) if auto else _CONTEXT_PX


def _window(box, margin: int, rows: int, cols: int) -> tuple[int, int, int, int]:
    r0, c0 = max(int(box[0]) - margin, 0), max(int(box[2]) - margin, 0)
    r1, c1 = min(int(box[1]) + margin, rows), min(int(box[3]) + margin, cols)
    return r0, c0, r1 - r0, c1 - c0


def hole_bytes(box, rows: int, cols: int, auto: bool) -> float:
    """Estimated working memory (bytes) of filling the hole of ``box``."""
    h, w = int(box[1] - box[0]), int(box[3] - box[2])
    _, _, wh, ww = _window(box, _margin(box, auto), rows, cols)
    return HOLE_BYTES_PER_PX * (h + 2) * (w + 2) + DENSITY_BYTES_PER_PX * wh * ww


def fill_to_file(path, out, roughness: float | None = None, *,
                 fractal_dimension: float | None = None, craters="auto", rng=None,
                 target=None, band: int = 1, pixel_size_m=None,
                 body_radius_m: float | None = None, body: str | None = None,
                 tile_px: int | None = None, max_memory_gb: float | None = None,
                 progress: bool = False) -> FilledFile:
    """:func:`dem.fill_gaps` of the DEM file ``path`` written to ``out`` tile by tile: the
    same bytes as ``dem.write(fill_gaps(dem.read(path), ...), out)`` for DEMs bigger than
    memory (see the module notes).

    Parameters are those of :func:`dem.fill_gaps` (``craters``, ``rng``, ``target``,
    ``roughness``, ``fractal_dimension``) and :func:`dem.read` (``band``,
    ``pixel_size_m``, ``body_radius_m``, ``body``), plus:

    out : str or Path
        The ``.tif`` to write (atomically; an existing file is replaced).
    tile_px : int, optional
        Tile side in pixels (>= 16) for labelling, the F strips and writing; default
        :data:`DEFAULT_TILE_PX`, or smaller to fit ``max_memory_gb``.
    max_memory_gb : float, optional
        Memory the fill may use, GB (1e9 bytes); default :data:`MEMORY_SHARE` of this
        machine's. A hole too large to fill within it is refused before anything is
        written.

    Returns
    -------
    FilledFile

    Examples
    --------
    >>> import tempfile
    >>> from dem import Dem, fill_gaps, write
    >>> z = np.random.default_rng(0).normal(0, 5, (40, 50))
    >>> z[3:30, 10:14] = np.nan
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     src = write(Dem(z, pixel_size_m=8.0), f"{tmp}/in.tif")
    ...     info = fill_to_file(src, f"{tmp}/t.tif", rng=1, tile_px=16)
    ...     whole = write(fill_gaps(read(src), rng=1), f"{tmp}/w.tif")
    ...     same = info.path.read_bytes() == whole.read_bytes()
    >>> info.shape, info.tiles, same
    ((40, 50), 12, True)
    """
    roughness, fractal_dimension, layer, key, seed = fill_arguments(
        roughness, fractal_dimension, craters, rng)
    limit, whose = _budget(max_memory_gb)
    tile_px = _tile_side(tile_px, limit)
    src = _open_source(path, {"band": band, "pixel_size_m": pixel_size_m,
                              "body_radius_m": body_radius_m, "body": body,
                              "allow_unknown": True})
    rows, cols = src.shape
    holes = holes_of_file(src.heights, src.shape, tile_px, progress=progress)
    if holes.known == 0:
        raise ValueError("`dem` has no known pixel (all NaN): there is nothing to fill from")
    _check_hole_memory(holes, src.shape, layer == "auto", limit, whose)
    params, fractal_dimension = fill_parameters(
        roughness, fractal_dimension, key, lambda: _file_dimension(src, holes, tile_px),
        filled_pixels=int(holes.pixels.sum()), holes=len(holes.box))
    if layer is not None and target is None:
        target = crater_target(src.head)
    uniform = None if roughness is None else roughness * src.resolution_m
    scratch = temp_file(out, ".fill")
    try:
        with open(scratch, "r+b") as fh:
            fh.truncate(rows * cols * 8)  # sparse: disk only where holes are written
        catalogs, notes = [], []
        for i in progress_bar(range(len(holes.box)), enabled=progress, desc="fill: holes"):
            cat, note = _fill_one(src, scratch, holes.box[i], int(holes.first[i]), layer,
                                  key, target, uniform, fractal_dimension)
            if note is not None:
                notes.append(note)
            if cat is not None:
                catalogs.append(cat)
        record_craters(params, catalogs, notes, layer, src.pixel_size_m)
        tags = src.head.step_tags("dem.fill_gaps", seed, params)
        written, tiles = _write_filled(src, scratch, out, tags, tile_px, progress=progress)
    finally:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(scratch)
    return FilledFile(written, (rows, cols), seed, params, tiles)


@dataclasses.dataclass(frozen=True)
class _Source:
    """The input DEM file of :func:`fill_to_file`, read window by window."""

    path: Path
    options: dict
    """:func:`dem.read`'s options."""
    head: Dem
    """Its first pixel (CRS, transform, tags, lattice)."""
    shape: tuple[int, int]
    pixel_size_m: tuple[float, float]
    """The whole DEM's pixel size (metres)."""

    @property
    def resolution_m(self) -> float:
        return math.sqrt(self.pixel_size_m[0] * self.pixel_size_m[1])

    def read(self, win) -> Dem:
        """The window ``(row_off, col_off, rows, cols)`` as a :class:`Dem`."""
        return read(self.path, window=win, **self.options)

    def heights(self, r: int, c: int, h: int, w: int) -> np.ndarray:
        """The heights of a window (a writable copy)."""
        return np.array(self.read((r, c, h, w)).heights)


def _open_source(path, options: dict) -> _Source:
    """The input's first pixel, shape and pixel size (that of the whole DEM: a geographic
    CRS's depends on the centre latitude)."""
    head = read(path, window=(0, 0, 1, 1), **options)
    rows, cols = raster_shape(path)
    px = (head.pixel_size_m if head.crs is None  # given, or the file's tag
          else raster_pixel_size_m(head.transform, head.crs, (rows, cols),
                                   body_radius_m=head.body_radius_m))
    return _Source(Path(path), options, head, (rows, cols), px)


def _tile_side(tile_px, limit: float) -> int:
    """``tile_px`` checked; by default :data:`DEFAULT_TILE_PX`, halved (down to 256)
    while labelling a tile would take more than a quarter of ``limit`` bytes."""
    if tile_px is None:
        tile_px = DEFAULT_TILE_PX
        while tile_px > 256 and _TILE_BYTES_PER_PX * tile_px**2 > 0.25 * limit:
            tile_px //= 2
    with about("tile_px"):
        return check_int("tile_px", tile_px, 16)


def _check_hole_memory(holes: Holes, shape, auto: bool, limit: float, whose: str) -> None:
    """Every hole can be filled within ``limit`` bytes (else an error naming the first
    that cannot)."""
    rows, cols = shape
    for box, first in zip(holes.box, holes.first, strict=True):
        need = hole_bytes(box, rows, cols, auto)
        if need > limit:
            raise ParameterError(
                "max_memory_gb", f"is too small for the hole at rows {box[0]}..{box[1] - 1}, "
                f"cols {box[2]}..{box[3] - 1} ({box[1] - box[0]} x {box[3] - box[2]} pixels,"
                f" first pixel ({first // cols}, {first % cols})): filling it needs about "
                f"{need / 1e9:.3g} GB, more than {limit / 1e9:.3g} GB{whose}")


def _file_dimension(src: _Source, holes: Holes, tile_px: int) -> float:
    """F of the whole DEM file (:func:`dem.fractal_fit_rows`, strips of about a tile's
    pixels), NaN without holes or when it cannot be estimated."""
    if not len(holes.box):
        return math.nan
    rows, cols = src.shape
    strip = max(1, tile_px * tile_px // cols)
    try:
        return float(fractal_fit_rows(lambda a, b: src.heights(a, 0, b - a, cols), src.shape,
                                      src.pixel_size_m, src.resolution_m,
                                      strip_rows=strip).fractal_dimension)
    except ValueError:
        return math.nan


def _write_filled(src: _Source, scratch, out, tags: dict, tile_px: int, *,
                  progress: bool) -> tuple[Path, int]:
    """The input with the fills of the scratch file, written tile by tile into ``out``;
    its path and the number of tiles."""
    rows, cols = src.shape
    tiles = tile_windows(rows, cols, tile_px)
    with WindowWriter(out, src.shape, transform=src.head.transform, crs=src.head.crs,
                      tags=tags, body_radius_m=src.head.body_radius_m,
                      pixel_size_m=src.pixel_size_m) as writer:
        for r, c, h, w in progress_bar(tiles, enabled=progress, desc="fill: write"):
            z = src.heights(r, c, h, w)
            gaps = np.isnan(z)
            if gaps.any():
                z[gaps] = _scratch_read(scratch, cols, (r, c, h, w))[gaps]
            check_float32(z, out)
            writer.write(z, r, c)
    return writer.path, len(tiles)


def _scratch_read(scratch, cols: int, win) -> np.ndarray:
    """The fills (float64, NaN where none) of a window of the scratch file."""
    r, c, h, w = win
    mm = np.memmap(scratch, dtype=np.uint64, mode="r", offset=r * cols * 8, shape=(h, cols))
    try:
        return (np.array(mm[:, c:c + w]) ^ _UNSET).view(np.float64)
    finally:
        del mm  # unmapped: the pages leave this process's memory


def _scratch_write(scratch, cols: int, win, mask, values) -> None:
    r, c, h, w = win
    mm = np.memmap(scratch, dtype=np.uint64, mode="r+", offset=r * cols * 8, shape=(h, cols))
    try:
        block = mm[:, c:c + w]
        block[mask] = np.ascontiguousarray(values, dtype=np.float64).view(np.uint64) ^ _UNSET
        mm.flush()
    finally:
        del mm


def _fill_one(src: _Source, scratch, box, first, layer, key, target, uniform, fd):
    """Fill the hole of ``box`` (global rows/cols) and keep its values in the scratch."""
    from scipy import ndimage

    rows, cols = src.shape
    win = _window(box, _margin(box, layer == "auto"), rows, cols)
    wr, wc, wh, ww = win
    dem = src.read(win)
    z = np.array(dem.heights)
    sl = (slice(int(box[0]) - wr, int(box[1]) - wr), slice(int(box[2]) - wc, int(box[3]) - wc))
    # the hole: the component of the unknown pixels of its box that holds its first pixel
    lab, _ = ndimage.label(np.isnan(z[sl]), structure=np.ones((3, 3), dtype=bool))
    hole = lab == lab[0, first % cols - int(box[2])]
    # earlier fills in the hole's 4-neighbour window (fill_gaps's z holds them)
    a0, a1 = max(sl[0].start - 1, 0), min(sl[0].stop + 1, wh)
    b0, b1 = max(sl[1].start - 1, 0), min(sl[1].stop + 1, ww)
    part = z[a0:a1, b0:b1]
    gaps = np.isnan(part)
    if gaps.any():
        part[gaps] = _scratch_read(scratch, cols, (wr + a0, wc + b0, a1 - a0, b1 - b0))[gaps]
    amp = (None if uniform is not None
           else np.sqrt(window_mean(local_msd(dem.heights), NORMALISER_WINDOW_PX)))
    head = src.head
    origin = (head.origin[0] + wr, head.origin[1] + wc)
    fill_hole(z, sl, hole, amp, uniform, fd, key, level=head.level, origin=origin)
    cat = note = None
    if layer is not None:
        def around(w0, w1, v0, v1):
            if (w0, w1, v0, v1) == (0, wh, 0, ww):
                return dem
            return src.read((wr + w0, wc + v0, w1 - w0, v1 - v0))

        cat, note = stamp_gap_craters(z, sl, hole, layer, key, target,
                                      pixel_size_m=src.pixel_size_m, level=head.level,
                                      origin=head.origin, around=around, offset=(wr, wc))
    _scratch_write(scratch, cols, (int(box[0]), int(box[2]), int(box[1] - box[0]),
                                   int(box[3] - box[2])), hole, z[sl][hole])
    return cat, note
