r"""Fractal statistics of a DEM: local roughness, variograms and the fractal dimension.

Terrain model (the one :func:`dem.expand` continues): a fractional Brownian surface
with one Hurst exponent ``H`` (fractal dimension ``F = 3 - H``) whose amplitude varies
from place to place,

    E[(z(p + l) - z(p))^2] = (rho(p) R)^2 (l / R)^(2 H),

with ``R`` the DEM resolution and ``rho(p)`` the *local roughness*: the RMS height
difference between pixel ``p`` and its known axis neighbours divided by ``R`` (m/m),
i.e. the relief at the DEM's finest scale. Real terrain is like this: smooth mare next
to rough crater walls, so a single amplitude gives the wrong slope distribution.

Estimator of ``F`` (:func:`fractal_fit`): the *locally normalised variogram*

    G(l) = mean over pairs (p, p + l) of (z(p + l) - z(p))^2 / ((M(p) + M(p + l)) / 2)

along rows and columns at lags of 2..8 pixels (pairs of known pixels whose normaliser
is > 0). ``M(p)`` is the mean squared difference between neighbouring pixels
(:func:`local_msd`) averaged over the known pixels of a 9 x 9 window around ``p``:
dividing by it removes the mixture of smooth and rough areas (each area counts by its
share of the pixels, not by its relief). The log-log slope of ``G`` gives a reading
``F_read = 3 - slope / 2`` (:attr:`FractalFit.power_law_dimension`), and ``F`` is the
dimension of the *band-limited* fBm that reads the same (:func:`band_limited_dimension`).

Three choices make it measure what the power-spectrum slope measures (``F = (8 - beta) /
2``, :func:`dem.spectral_fit`); figures from ``tests/benchmarks/bench_fractal.py`` (means
of six 513 x 513 fBm surfaces made by spectral synthesis):

* The normaliser is averaged over a window. The first version divided by ``m(p)``
  itself, which holds the lag-1 differences of the pair, so F read 0.04-0.11 too low
  against the plain variogram (2.48 for F = 2.8, white noise 2.93); with the window the
  two agree within 0.02.
* The fit starts at lag 2, where the pixel grid matters less.
* The band limit. A DEM holds no power above its Nyquist frequency (its pixels average
  the surface), which takes a lag-dependent amount from the variogram at the shortest
  lags: the expected variogram of an fBm whose spectrum stops at the Nyquist square (an
  integral, :data:`BAND_LIMITED_READ_F`) reads F = 2.10 / 2.46 / 2.68 / 2.80 at lags 2-8
  for F = 2.1 / 2.5 / 2.8 / 3.0, and white noise (a flat spectrum, F = 4) reads 3. The
  reading is converted back. Point samples of a continuous fBm have no such deficit
  (they read F at every lag); for them the conversion overshoots, by 0.1 at F = 2.8.

Measured (bench_fractal.py): on the fBm surfaces the estimate is within 0.01 of the
synthesis' F from 2.4 to 2.8 and 0.10 above it at 2.1 (a periodic surface of 513 px
lacks the longest wavelengths that an H = 0.9 variogram needs); the spectral slope is
within 0.02 of F everywhere and the two agree within 0.10. What the two measure differs
where the terrain is not one fractal over all scales: the variogram sees wavelengths
of about 4 to 16 pixels, the default spectral band 4 px to a quarter of the DEM. Over
the same band (:data:`dem.terrain.MATCHED_BAND_PX`, 4-16 px) they agree on the LOLA
crop (2.60 and 2.52) and on RMD output of a noise seed (within 0.04); over the default
band the LOLA crop's spectrum reads 2.98 and its 16-64 px slope F = 3.22, which is no
surface dimension (the lunar surface at 120-480 km is rougher than any fBm).

F is not clipped: a value outside [2, 3] means the heights are not a fractal surface at
these scales (F < 2: smoother than any fBm, e.g. interpolated terrain; F > 3: white
noise or a pattern repeating at a few pixels); :attr:`FractalFit.warning` says so, and
the tools never print it as a surface dimension. :func:`expansion_fit` is the
different, older rule that :func:`dem.expand` continues a DEM with. :func:`variogram`
gives the plain variogram.
"""

from __future__ import annotations

import dataclasses
import math
from typing import cast

import numpy as np

from craters._shared import check_int

from .core import Dem

#: Largest roughness a user may ask for, m/m (an RMS slope of 89.94 degrees between
#: neighbours): beyond it heights soon leave float32, the type of the GeoTIFFs written.
MAX_ROUGHNESS = 1000.0

__all__ = ["MAX_ROUGHNESS", "FractalFit", "SpectralFit", "dimension_warning", "expansion_fit",
           "fractal_dimension", "fractal_fit", "fractal_fit_rows", "local_msd",
           "local_roughness", "variogram", "window_mean"]

#: Lags (pixels) of the fractal-dimension estimate: the finest scales above the pixel.
DEFAULT_MIN_LAG_PX = 2
DEFAULT_MAX_LAG_PX = 8
#: Side (pixels) of the window the local normaliser is averaged over.
NORMALISER_WINDOW_PX = 9
# F within this of 2 or 3 counts as inside [2, 3] (a plane fits F = 2 to rounding)
_RANGE_EPS = 1e-9

#: Band-limited fBm: the fractal dimension F = (8 - beta) / 2 of a surface whose power
#: spectrum is ``|f|^-beta`` up to the Nyquist square ``|f_x|, |f_y| <= 1/2`` cycle/px
#: (F = 2.00, 2.05, ... 4.00) and the F that the plain power-law fit of its variogram at
#: lags 2..8 px reads (:data:`BAND_LIMITED_READ_F`). The expected variogram is the
#: integral of ``|f|^-beta (1 - cos(2 pi f_x l))`` over the square (a Bessel-function
#: integral over the inscribed disc plus the corners); ``tests/dem/test_fractal.py``
#: recomputes it.
BAND_LIMITED_F = tuple(round(2.0 + 0.05 * k, 2) for k in range(41))
BAND_LIMITED_READ_F = (
    2.00005, 2.04858, 2.09677, 2.14451, 2.19174, 2.23837, 2.28433, 2.32953, 2.37387,
    2.41724, 2.45954, 2.50067, 2.54051, 2.57895, 2.61588, 2.65119, 2.68480, 2.71663,
    2.74659, 2.77465, 2.80077, 2.82494, 2.84715, 2.86745, 2.88587, 2.90249, 2.91737,
    2.93061, 2.94230, 2.95255, 2.96148, 2.96918, 2.97578, 2.98137, 2.98605, 2.98992,
    2.99307, 2.99558, 2.99753, 2.99898, 3.00000)


def band_limited_dimension(read_f: float) -> float:
    """F of the band-limited fBm whose variogram (lags 2-8 px) reads ``read_f``.

    Inverts :data:`BAND_LIMITED_READ_F` by linear interpolation; below 2 the reading
    is kept (smoother than any fBm), above 3 it is shifted by 1 (rougher than white
    noise, whose flat spectrum is F = 4).

    Examples
    --------
    >>> round(band_limited_dimension(2.6848), 3), band_limited_dimension(1.8)
    (2.8, 1.8)
    """
    r = float(read_f)
    if not math.isfinite(r) or r <= BAND_LIMITED_READ_F[0]:
        return r
    if r >= BAND_LIMITED_READ_F[-1]:
        return r + 1.0
    return float(np.interp(r, BAND_LIMITED_READ_F, BAND_LIMITED_F))


def dimension_warning(fractal_dimension: float) -> str | None:
    """None for F in [2, 3]; otherwise the sentence that says it is no surface dimension.

    Examples
    --------
    >>> dimension_warning(2.4) is None
    True
    >>> dimension_warning(3.4)
    'not a surface fractal dimension: the slope gives F = 3.40, outside [2, 3]'
    """
    f = float(fractal_dimension)
    if math.isfinite(f) and 2.0 - _RANGE_EPS <= f <= 3.0 + _RANGE_EPS:
        return None
    return f"not a surface fractal dimension: the slope gives F = {f:.2f}, outside [2, 3]"


class _DimensionRange:
    """The [2, 3] check shared by the fit records (they define ``fractal_dimension``)."""

    __slots__ = ()
    fractal_dimension: float

    @property
    def is_surface_dimension(self) -> bool:
        """True when F lies in [2, 3], the range of a surface's fractal dimension."""
        return dimension_warning(self.fractal_dimension) is None

    @property
    def warning(self) -> str | None:
        """None, or why F is no surface dimension (F outside [2, 3])."""
        return dimension_warning(self.fractal_dimension)


@dataclasses.dataclass(frozen=True, slots=True)
class FractalFit(_DimensionRange):
    """Fractal statistics of a DEM at its finest lags (see the module docstring)."""

    fractal_dimension: float
    """F from the locally normalised variogram (not clipped; see :attr:`warning`): the
    band-limited fBm's F that reads :attr:`power_law_dimension` (lags 2-8 px; other lags:
    the reading itself)."""
    hurst: float
    """Hurst exponent H = 3 - F."""
    roughness: float
    """RMS height difference of neighbouring known pixels over ``resolution_m`` (m/m)."""
    resolution_m: float
    """The DEM resolution R, metres."""
    lags_m: tuple[float, ...]
    """Lags used, metres (x lags, then y lags)."""
    normalized_variogram_m2: tuple[float, ...]
    """G(l) at ``lags_m`` (dimensionless: squared differences over the local ones)."""
    lag_range_px: tuple[int, int] = (DEFAULT_MIN_LAG_PX, DEFAULT_MAX_LAG_PX)
    """Shortest and longest lag of the fit, pixels."""
    power_law_dimension: float = math.nan
    """3 - (half the log-log slope of G): the plain power-law reading."""


@dataclasses.dataclass(frozen=True, slots=True)
class SpectralFit(_DimensionRange):
    """Slope of a DEM's radially averaged power spectrum over a band of wavelengths
    (:func:`dem.spectral_fit`)."""

    fractal_dimension: float
    """F = (8 - beta) / 2 (not clipped; see :attr:`warning`)."""
    beta: float
    """Spectral exponent: psd ~ f^-beta (2-D spectral density)."""
    band_m: tuple[float, float]
    """Shortest and longest wavelength of the fit, metres."""
    band_px: tuple[float, float]
    """The same in pixels (of the mean pixel size)."""


def _check_dem(dem) -> Dem:
    if not isinstance(dem, Dem):
        raise TypeError(f"`dem` must be a Dem; got {type(dem).__name__}")
    return dem


def _axis_diffs(z: np.ndarray, k: int, axis: int) -> np.ndarray:
    return z[:, k:] - z[:, :-k] if axis == 1 else z[k:, :] - z[:-k, :]


def local_msd(z: np.ndarray) -> np.ndarray:
    """m(p): mean squared height difference to the known axis neighbours (NaN if none)."""
    acc = np.zeros_like(z)
    cnt = np.zeros(z.shape, dtype=np.int64)
    for axis in (1, 0):
        d = _axis_diffs(z, 1, axis)
        ok = np.isfinite(d)
        d2 = np.where(ok, d * d, 0.0)
        lo = (slice(None), slice(None, -1)) if axis == 1 else (slice(None, -1), slice(None))
        hi = (slice(None), slice(1, None)) if axis == 1 else (slice(1, None), slice(None))
        acc[lo] += d2
        acc[hi] += d2
        cnt[lo] += ok
        cnt[hi] += ok
    return np.where(cnt > 0, acc / np.maximum(cnt, 1), np.nan)


def local_roughness(dem: Dem) -> np.ndarray:
    """Local roughness rho(p): RMS height difference to the known axis neighbours over R.

    ``R`` is :attr:`Dem.resolution_m`. Returns a (rows, cols) float64 array in m/m, NaN
    where the pixel or all of its four axis neighbours are unknown.

    Examples
    --------
    >>> d = Dem(np.array([[0.0, 1.0, 2.0], [0.0, 1.0, 2.0]]), pixel_size_m=1.0)
    >>> local_roughness(d).round(3).tolist()   # x differences 1, y differences 0
    [[0.707, 0.816, 0.707], [0.707, 0.816, 0.707]]
    """
    dem = _check_dem(dem)
    return np.sqrt(local_msd(dem.heights)) / dem.resolution_m


def variogram(dem: Dem, max_lag_px: int = DEFAULT_MAX_LAG_PX):
    """The plain variogram along rows (x) and columns (y) at lags 1..max_lag_px.

    Mean squared height difference of pairs of known pixels.

    Returns
    -------
    lags_m : (2 L,) float64
        The x lags (``k * pixel_size_m[0]``) then the y lags, metres.
    gamma_m2 : (2 L,) float64
        Mean squared differences (NaN where no pair is known), square metres.
    counts : (2 L,) int64
        Number of pairs.

    Examples
    --------
    >>> d = Dem(np.add.outer(np.zeros(4), np.arange(5.0)), pixel_size_m=1.0)
    >>> lags, g, n = variogram(d, 2)
    >>> lags.tolist(), g.tolist()
    ([1.0, 2.0, 1.0, 2.0], [1.0, 4.0, 0.0, 0.0])
    """
    dem = _check_dem(dem)
    max_lag_px = check_int("max_lag_px", max_lag_px, 1)
    z = dem.heights
    lags, gam, cnt = [], [], []
    for axis, size in ((1, dem.pixel_size_m[0]), (0, dem.pixel_size_m[1])):
        for k in range(1, max_lag_px + 1):
            lags.append(k * size)
            if k >= z.shape[axis]:
                gam.append(np.nan)
                cnt.append(0)
                continue
            d = _axis_diffs(z, k, axis)
            d = d[np.isfinite(d)]
            cnt.append(d.size)
            gam.append(float(np.mean(d * d)) if d.size else np.nan)
    return (np.array(lags, dtype=np.float64), np.array(gam, dtype=np.float64),
            np.array(cnt, dtype=np.int64))


def window_mean(values: np.ndarray, window_px: int) -> np.ndarray:
    """Mean of the finite ``values`` in the ``window_px`` x ``window_px`` window around each
    pixel (clipped at the borders; NaN where the window holds none).

    Examples
    --------
    >>> window_mean(np.array([[1.0, np.nan, 3.0]]), 3).tolist()
    [[1.0, 2.0, 3.0]]
    """
    v = np.asarray(values, dtype=np.float64)
    ok = np.isfinite(v)
    h = window_px // 2
    # shifted sums in a fixed order (rows, then columns): every pixel adds the same
    # neighbours in the same order, so a crop gives the same bits as the whole array
    out = []
    for a in (np.where(ok, v, 0.0), ok.astype(np.float64)):
        p = np.pad(a, h)
        # sum() of a non-empty range: an array, never its start 0
        rows = cast(np.ndarray, sum(p[k:k + a.shape[0], :] for k in range(2 * h + 1)))
        out.append(sum(rows[:, k:k + a.shape[1]] for k in range(2 * h + 1)))
    total, count = out
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(count > 0.5, total / count, np.nan)


def _lag_range(shape, min_lag_px: int, max_lag_px: int) -> list[int]:
    """Lags from ``min_lag_px`` to ``max_lag_px`` that fit the DEM; from 1 if < 2 fit."""
    top = min(max_lag_px, max(shape) - 1)
    lags = list(range(min_lag_px, top + 1))
    return lags if len(lags) >= 2 else list(range(1, top + 1))


def fractal_fit(dem: Dem, max_lag_px: int = DEFAULT_MAX_LAG_PX, *,
                min_lag_px: int = DEFAULT_MIN_LAG_PX) -> FractalFit:
    """Fractal dimension (locally normalised variogram) and RMS roughness of ``dem``.

    Lags ``min_lag_px..max_lag_px`` (2..8 by default; from 1 on a DEM too small for two
    lags), the normaliser averaged over :data:`NORMALISER_WINDOW_PX` (see the module
    docstring). A DEM without relief (every normaliser zero) gives F = 2 and roughness 0.
    Raises ValueError when fewer than two lags have usable pixel pairs (the DEM is too
    small or too sparse: give the parameters explicitly).

    Examples
    --------
    >>> plane = 0.1 * np.add.outer(np.arange(50.0), np.arange(50.0))  # slope 0.1 m/m
    >>> f = fractal_fit(Dem(plane, pixel_size_m=1.0))
    >>> round(f.fractal_dimension, 6), round(f.roughness, 6), f.is_surface_dimension
    (2.0, 0.1, True)
    """
    dem = _check_dem(dem)
    max_lag_px = check_int("max_lag_px", max_lag_px, 1)
    min_lag_px = check_int("min_lag_px", min_lag_px, 1, max_lag_px)
    fit = _normalised_fit(dem, _lag_range(dem.shape, min_lag_px, max_lag_px),
                          NORMALISER_WINDOW_PX)
    return _band_limited(fit)


def _band_limited(fit: FractalFit) -> FractalFit:
    if fit.lag_range_px != (2, 8) or fit.roughness == 0.0:
        return fit
    f = band_limited_dimension(fit.power_law_dimension)
    return dataclasses.replace(fit, fractal_dimension=f, hurst=3.0 - f)


def fractal_fit_rows(read_rows, shape, pixel_size_m, resolution_m: float, *,
                     strip_rows: int = 256) -> FractalFit:
    """:func:`fractal_fit` (default lags) of a DEM read strip by strip: the same result,
    bit for bit, for DEMs bigger than memory.

    ``read_rows(a, b)`` returns rows ``a..b-1`` of the heights (all columns, float64,
    NaN = unknown); ``shape``, ``pixel_size_m`` (x, y) and ``resolution_m`` are the
    whole DEM's. Every local quantity (neighbour differences, the 9 x 9 normaliser) is
    computed on strips of ``strip_rows`` rows with enough rows around them to be the
    whole DEM's values, and every mean is a :class:`dem.streamsum.PairwiseSum` over the
    same values in the same order as numpy's mean of the whole: so it reads the DEM
    twice (the counts, then the sums). Raises ValueError as :func:`fractal_fit` does.
    """
    from .streamsum import PairwiseSum

    rows, cols = (int(v) for v in shape)
    strip_rows = check_int("strip_rows", strip_rows, 1)
    lag_px = _lag_range((rows, cols), DEFAULT_MIN_LAG_PX, DEFAULT_MAX_LAG_PX)
    keys: list[tuple[int | str, int]] = [("msd", 0)] + [(axis, k) for axis in (1, 0) for k in lag_px
                           if k < (cols if axis == 1 else rows)]
    halo = NORMALISER_WINDOW_PX // 2 + 1  # the normaliser: msd within 4 px, z within 1

    def strips():
        """Per strip, per key: the values the whole-DEM mean adds, in its order."""
        for a in range(0, rows, strip_rows):
            b = min(a + strip_rows, rows)
            lo, hi = max(a - halo, 0), min(b + max(lag_px) + halo, rows)
            z = np.asarray(read_rows(lo, hi), dtype=np.float64)
            msd = local_msd(z)
            norm_px = window_mean(msd, NORMALISER_WINDOW_PX)
            part = msd[a - lo:b - lo]
            out = {("msd", 0): part[np.isfinite(part)]}
            for axis, k in keys[1:]:
                if axis == 1:
                    zz, nn = z[a - lo:b - lo], norm_px[a - lo:b - lo]
                    d = _axis_diffs(zz, k, 1)
                    norm = 0.5 * (nn[:, k:] + nn[:, :-k])
                else:  # pairs (i, i + k) for i in a..b-1
                    e = min(b, rows - k)
                    if e <= a:
                        out[(axis, k)] = np.zeros(0)
                        continue
                    d = z[a - lo + k:e - lo + k] - z[a - lo:e - lo]
                    norm = 0.5 * (norm_px[a - lo + k:e - lo + k] + norm_px[a - lo:e - lo])
                ok = np.isfinite(d) & (norm > 0)
                out[(axis, k)] = d[ok] ** 2 / norm[ok]
            yield out

    counts = dict.fromkeys(keys, 0)
    for part in strips():
        for key in keys:
            counts[key] += part[key].size
    sums = {key: PairwiseSum(counts[key]) for key in keys}
    for part in strips():
        for key in keys:
            sums[key].push(part[key])
    n_msd = counts[("msd", 0)]
    roughness = (math.sqrt(sums[("msd", 0)].total / n_msd) / resolution_m if n_msd
                 else math.nan)
    dx, dy = pixel_size_m
    lags, gam, used = [], [], []
    for axis, k in keys[1:]:
        if counts[(axis, k)]:
            lags.append(k * (dx if axis == 1 else dy))
            used.append(k)
            gam.append(sums[(axis, k)].total / counts[(axis, k)])
    return _band_limited(_fit_result((rows, cols), resolution_m, lag_px, roughness, lags,
                                     gam, used))


def expansion_fit(dem: Dem) -> FractalFit:
    """The fit :func:`dem.expand` and :func:`dem.enhance` continue a DEM with by default.

    Not the fractal dimension of the DEM (that is :func:`fractal_fit`) but the rule the
    expansion has used since issue 5, kept because it is what reproduces real terrain
    below the pixel: the normalised variogram at lags 1-4 with the pointwise normaliser
    ``m(p)``, which reads F 0.1-0.3 *below* :func:`fractal_fit` (fBm: 2.48 for 2.8;
    the LOLA crop: 2.21 for 2.54). The Moon is smoother at shorter scales than at the
    scales a DEM's pixels can measure (F about 2.1-2.25 at 17 m - 2.7 km baselines,
    Rosenburg et al. 2011, JGR 116, E02001; 2.5-2.8 at 15-240 km in the LOLA crop), and
    expanding with the DEM's own F overshoots: the LOLA crop decimated 4x and expanded 2
    levels gets 1.3x the original's top-octave height power with this rule and 3.8x
    with :func:`fractal_fit`'s F (``tests/dem/test_realism.py``). Measured, not
    derived: give ``fractal_dimension`` to the expansion to choose it yourself.
    """
    dem = _check_dem(dem)
    return _normalised_fit(dem, _lag_range(dem.shape, 1, 4), 1)


def _normalised_fit(dem: Dem, lag_px: list[int], window_px: int) -> FractalFit:
    """The normalised-variogram fit at ``lag_px``, normaliser averaged over ``window_px``
    (1: the pointwise ``m(p)``)."""
    z = dem.heights
    dx, dy = dem.pixel_size_m
    msd = local_msd(z)
    finite = np.isfinite(msd)
    roughness = (math.sqrt(float(np.mean(msd[finite]))) / dem.resolution_m if finite.any()
                 else math.nan)
    norm_px = msd if window_px == 1 else window_mean(msd, window_px)
    lags, gam, used = [], [], []
    for axis, size in ((1, dx), (0, dy)):
        for k in lag_px:
            if k >= z.shape[axis]:
                continue
            d = _axis_diffs(z, k, axis)
            norm = 0.5 * (norm_px[:, k:] + norm_px[:, :-k] if axis == 1
                          else norm_px[k:] + norm_px[:-k])
            ok = np.isfinite(d) & (norm > 0)
            if ok.any():
                lags.append(k * size)
                used.append(k)
                gam.append(float(np.mean(d[ok] ** 2 / norm[ok])))
    return _fit_result(z.shape, dem.resolution_m, lag_px, roughness, lags, gam, used)


def _fit_result(shape, resolution_m: float, lag_px, roughness: float, lags, gam,
                used) -> FractalFit:
    """The :class:`FractalFit` of the normalised variogram ``gam`` at ``lags`` (metres;
    ``used``: in pixels) and the RMS ``roughness`` (m/m)."""
    span = (min(used), max(used)) if used else (min(lag_px, default=1), max(lag_px, default=1))
    if not math.isfinite(roughness) or len(set(lags)) < 2:
        if math.isfinite(roughness) and roughness == 0.0:
            return FractalFit(2.0, 1.0, 0.0, resolution_m, tuple(lags), tuple(gam), span, 2.0)
        raise ValueError(
            f"cannot estimate the fractal statistics of a {shape[0]} x {shape[1]} DEM with "
            f"{len(set(lags))} usable lag(s): give `fractal_dimension` and `roughness` "
            f"explicitly")
    keep = [i for i, g in enumerate(gam) if g > 0.0]  # a direction without relief (a ramp)
    if len({lags[i] for i in keep}) < 2:
        return FractalFit(2.0, 1.0, roughness, resolution_m, tuple(lags), tuple(gam), span, 2.0)
    slope = float(np.polyfit(np.log(np.take(lags, keep)), np.log(np.take(gam, keep)), 1)[0])
    hurst = slope / 2.0
    return FractalFit(3.0 - hurst, hurst, roughness, resolution_m,
                      tuple(float(v) for v in lags), tuple(gam), span, 3.0 - hurst)


def fractal_dimension(dem: Dem, max_lag_px: int = DEFAULT_MAX_LAG_PX, *,
                      min_lag_px: int = DEFAULT_MIN_LAG_PX) -> float:
    """Fractal dimension F = 3 - H of ``dem`` (locally normalised variogram, lags 2..8 px).

    See the module docstring for the estimator. The value is not clipped: F < 2 means
    smoother than any fBm at these lags (e.g. interpolated terrain), F near 3
    uncorrelated noise, F > 3 no surface at all (:func:`dimension_warning`).

    Examples
    --------
    >>> rng = np.random.default_rng(1)
    >>> noise = Dem(rng.standard_normal((200, 200)), pixel_size_m=1.0)
    >>> bool(fractal_dimension(noise) > 3.5)   # white noise: flat spectrum, F = 4
    True
    >>> sheet = Dem(rng.standard_normal((200, 200)).cumsum(0).cumsum(1), pixel_size_m=1.0)
    >>> bool(abs(fractal_dimension(sheet) - 2.5) < 0.1)   # a Brownian sheet: H = 1/2
    True
    """
    return fractal_fit(dem, max_lag_px, min_lag_px=min_lag_px).fractal_dimension
