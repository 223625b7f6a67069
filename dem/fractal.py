r"""Fractal statistics of a DEM: local roughness, variograms and the fractal dimension.

Terrain model (the one :func:`dem.expand` continues): a fractional Brownian surface
with one Hurst exponent ``H`` (fractal dimension ``F = 3 - H``) whose amplitude varies
from place to place,

    E[(z(p + l) - z(p))^2] = (rho(p) R)^2 (l / R)^(2 H),

with ``R`` the DEM resolution and ``rho(p)`` the *local roughness*: the RMS height
difference between pixel ``p`` and its known axis neighbours divided by ``R`` (m/m),
i.e. the relief at the DEM's finest scale. Real terrain is like this: smooth mare next
to rough crater walls, so a single amplitude gives the wrong slope distribution.

Estimator of ``F`` (:func:`fractal_dimension`): the *locally normalised variogram*

    G(l) = mean over pairs (p, p + l) of (z(p + l) - z(p))^2 / ((m(p) + m(p + l)) / 2)

with ``m(p) = (rho(p) R)^2`` the mean squared difference between ``p`` and its known axis
neighbours,

along rows and columns at lags of 1..4 pixels (pairs of known pixels whose
normaliser is > 0), and ``2 H`` is the least-squares slope of ``log G`` against
``log l``. Dividing by the local roughness removes the mixture of smooth and rough
areas, which otherwise dominates the plain variogram (mean of squares: the rough areas
win). Measured behaviour (``tests/benchmarks/bench_dem.py``): a 17 x 17 seed expanded
7 levels by :func:`dem.expand` with F = 2.2 / 2.5 / 2.8 reads 2.25 / 2.46 / 2.61 (the
finest lags of random-midpoint-displacement terrain are not exactly fBm, and the gap
grows towards F = 3); because the normaliser contains the lag-1 differences themselves,
the estimate is 0.07-0.11 lower than the plain variogram slope on such homogeneous
surfaces, and white noise reads 2.93 instead of 3.
:func:`variogram` gives the plain variogram too.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from craters._shared import check_int

from .core import Dem

__all__ = ["FractalFit", "fractal_dimension", "fractal_fit", "local_msd", "local_roughness",
           "variogram"]

#: Lags (pixels) of the fractal-dimension estimate: the finest scales.
DEFAULT_MAX_LAG_PX = 4


@dataclasses.dataclass(frozen=True, slots=True)
class FractalFit:
    """Fractal statistics of a DEM at its finest lags (see the module docstring)."""

    fractal_dimension: float
    """F = 3 - H from the locally normalised variogram (not clipped; 2 = smooth)."""
    hurst: float
    """Hurst exponent H, half the log-log slope of the normalised variogram."""
    roughness: float
    """RMS height difference of neighbouring known pixels over ``resolution_m`` (m/m)."""
    resolution_m: float
    """The DEM resolution R, metres."""
    lags_m: tuple[float, ...]
    """Lags used, metres (x lags, then y lags)."""
    normalized_variogram_m2: tuple[float, ...]
    """G(l) at ``lags_m`` (dimensionless: squared differences over the local ones)."""


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
            if k >= z.shape[1 - axis]:
                gam.append(np.nan)
                cnt.append(0)
                continue
            d = _axis_diffs(z, k, axis)
            d = d[np.isfinite(d)]
            cnt.append(d.size)
            gam.append(float(np.mean(d * d)) if d.size else np.nan)
    return (np.array(lags, dtype=np.float64), np.array(gam, dtype=np.float64),
            np.array(cnt, dtype=np.int64))


def fractal_fit(dem: Dem, max_lag_px: int = DEFAULT_MAX_LAG_PX) -> FractalFit:
    """Fractal dimension (locally normalised variogram) and RMS roughness of ``dem``.

    A DEM without relief (every normaliser zero) gives F = 2 and roughness 0.
    Raises ValueError when fewer than two lags have usable pixel pairs (the DEM is too
    small or too sparse: give the parameters explicitly).

    Examples
    --------
    >>> plane = 0.1 * np.add.outer(np.arange(50.0), np.arange(50.0))  # slope 0.1 m/m
    >>> f = fractal_fit(Dem(plane, pixel_size_m=1.0))
    >>> round(f.fractal_dimension, 6), round(f.roughness, 6)
    (2.0, 0.1)
    """
    dem = _check_dem(dem)
    max_lag_px = check_int("max_lag_px", max_lag_px, 1)
    z = dem.heights
    dx, dy = dem.pixel_size_m
    msd = local_msd(z)
    finite = np.isfinite(msd)
    roughness = (math.sqrt(float(np.mean(msd[finite]))) / dem.resolution_m if finite.any()
                 else math.nan)
    lags, gam = [], []
    for axis, size in ((1, dx), (0, dy)):
        for k in range(1, min(max_lag_px, z.shape[1 - axis] - 1) + 1):
            d = _axis_diffs(z, k, axis)
            norm = 0.5 * (msd[:, k:] + msd[:, :-k] if axis == 1 else msd[k:] + msd[:-k])
            ok = np.isfinite(d) & (norm > 0)
            if ok.any():
                lags.append(k * size)
                gam.append(float(np.mean(d[ok] ** 2 / norm[ok])))
    if not math.isfinite(roughness) or len(set(lags)) < 2:
        if math.isfinite(roughness) and roughness == 0.0:
            return FractalFit(2.0, 1.0, 0.0, dem.resolution_m, tuple(lags), tuple(gam))
        raise ValueError(
            f"cannot estimate the fractal statistics of a {z.shape[0]} x {z.shape[1]} DEM with "
            f"{len(set(lags))} usable lag(s): give `fractal_dimension` and `roughness` "
            f"explicitly")
    slope = float(np.polyfit(np.log(lags), np.log(gam), 1)[0])
    hurst = slope / 2.0
    return FractalFit(3.0 - hurst, hurst, roughness, dem.resolution_m,
                      tuple(float(v) for v in lags), tuple(gam))


def fractal_dimension(dem: Dem, max_lag_px: int = DEFAULT_MAX_LAG_PX) -> float:
    """Fractal dimension F = 3 - H of ``dem`` (locally normalised variogram, lags 1..4 px).

    See the module docstring for the estimator. The value is not clipped: F < 2 means
    smoother than any fBm at these lags (e.g. interpolated terrain), F near 3
    uncorrelated noise.

    Examples
    --------
    >>> rng = np.random.default_rng(1)
    >>> noise = Dem(rng.standard_normal((200, 200)), pixel_size_m=1.0)
    >>> bool(abs(fractal_dimension(noise) - 3.0) < 0.1)   # white noise: H = 0
    True
    """
    return fractal_fit(dem, max_lag_px).fractal_dimension
