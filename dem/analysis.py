"""Terrain statistics used to compare DEMs: Laplacian and band power (slopes and spectra
are in :mod:`dem.terrain`)."""

from __future__ import annotations

import numpy as np

from craters._shared import check_range
from craters.exact import abs2, plane_residual

from .core import Dem

__all__ = ["band_power", "laplacian"]


def _check(dem) -> Dem:
    if not isinstance(dem, Dem):
        raise TypeError(f"`dem` must be a Dem; got {type(dem).__name__}")
    return dem


def _stencil_input(dem) -> tuple[np.ndarray, float, float, np.ndarray]:
    """Heights, pixel sizes and an all-NaN output for a 3 x 3 stencil statistic."""
    dem = _check(dem)
    return dem.heights, *dem.pixel_size_m, np.full(dem.shape, np.nan)


def laplacian(dem: Dem) -> np.ndarray:
    """Five-point Laplacian ``d2z/dx2 + d2z/dy2`` in 1/m; NaN on the border and near gaps.

    Examples
    --------
    >>> x = np.arange(5.0)
    >>> d = Dem(np.add.outer(x**2, x**2), pixel_size_m=1.0)   # z = x^2 + y^2
    >>> float(laplacian(d)[2, 2])
    4.0
    """
    z, dx, dy, out = _stencil_input(dem)
    if min(z.shape) < 3:
        return out
    c = z[1:-1, 1:-1]
    out[1:-1, 1:-1] = ((z[1:-1, 2:] + z[1:-1, :-2] - 2 * c) / dx**2
                       + (z[2:, 1:-1] + z[:-2, 1:-1] - 2 * c) / dy**2)
    return out


def band_power(dem: Dem, lo_cycles_per_px: float = 0.25,
               hi_cycles_per_px: float = 0.5) -> float:
    """Height variance (m^2) in a band of radial spatial frequencies.

    The heights minus their least-squares plane are multiplied by a 2-D Hann window;
    the periodogram is normalised by the window's energy, so summed over all
    frequencies it is the mean squared (detrended) height. Returns the sum over
    frequencies with ``lo <= |f| <= hi`` cycles per pixel; the default is the top
    octave below the Nyquist frequency. The DEM must have no unknown pixel.

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> d = Dem(rng.standard_normal((128, 128)), pixel_size_m=1.0)
    >>> total = band_power(d, 0.0, 1.0)          # white noise: variance ~1
    >>> bool(abs(total - 1) < 0.1), bool(abs(band_power(d) / total - 0.59) < 0.05)
    (True, True)
    """
    dem = _check(dem)
    lo = check_range("lo_cycles_per_px", lo_cycles_per_px, 0.0, None)
    hi = check_range("hi_cycles_per_px", hi_cycles_per_px, lo, None)
    z = dem.heights
    if not dem.known.all():
        raise ValueError("`dem` has unknown (NaN) pixels; fill them first")
    rows, cols = z.shape
    resid = plane_residual(z)  # the same bytes on every CPU (craters.exact)
    window = np.outer(np.hanning(rows), np.hanning(cols))
    power = abs2(np.fft.fft2(resid * window)) / (window**2).sum() / z.size
    f = np.hypot(np.fft.fftfreq(rows)[:, None], np.fft.fftfreq(cols)[None, :])
    return float(power[(f >= lo) & (f <= hi)].sum())
