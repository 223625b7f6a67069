"""Slope distributions and power spectra of DEMs (Martin, Parkes & Dunstan 2014, V.E).

* :func:`slope` - Horn's (1981) 3 x 3 slope (or 2-point central differences) in degrees,
  with the true ground size of every row on a geographic CRS (the pixel width shrinks
  with the cosine of the latitude); NaN next to unknown pixels and on the border.
* :func:`slope_distribution` - the area histogram of slopes (3-degree bins by default)
  and the cumulative share of steeper ground, weighted by the pixels' ground areas.
* :func:`power_spectrum` - the radially averaged power spectral density of the heights
  (plane removed, 2-D Hann window, normalised so that it integrates to the height
  variance), against wavelength in metres; a fractal surface shows a straight line of
  slope -beta on log axes (beta = 8 - 2F for a surface of fractal dimension F).
* :func:`spectral_fit` - the fractal dimension ``F = (8 - beta) / 2`` from that slope over
  a band of wavelengths (in pixels), flagged when it falls outside [2, 3]; over 4-16 px
  it measures the scales of :func:`dem.fractal_fit`'s lags (see :mod:`dem.fractal`).
* :func:`roughness` - the fractal fit used by :func:`dem.expand` (dimension and scale).
"""

from __future__ import annotations

import math

import numpy as np

from craters._shared import (
    ParameterError,
    about,
    check_choice,
    check_int,
    check_range,
)
from craters.exact import abs2, plane_residual
from latlong.geometry.stats import area_slope_summary

from .core import Dem
from .fractal import FractalFit, SpectralFit, fractal_fit

__all__ = ["SpectralFit", "pixel_sizes_by_row", "power_spectrum", "roughness", "slope",
           "slope_distribution", "spectral_exponent", "spectral_fit"]

#: Wavelength band (pixels) of :func:`spectral_fit` that matches the variogram's lags 2-8.
MATCHED_BAND_PX = (4.0, 16.0)


def _check(dem) -> Dem:
    if not isinstance(dem, Dem):
        raise TypeError(f"`dem` must be a Dem; got {type(dem).__name__}")
    return dem


def pixel_sizes_by_row(dem: Dem) -> tuple[np.ndarray, float]:
    """Ground pixel width of every row and the pixel height, metres.

    On a geographic CRS the width of row r is ``R * dlon * cos(lat_r)`` at the row's
    centre latitude; otherwise every row has the DEM's pixel width.
    """
    dem = _check(dem)
    rows = dem.shape[0]
    dx, dy = dem.pixel_size_m
    crs = dem.crs
    if crs is not None and crs.is_geographic:
        t = dem.transform
        if t.b != 0 or t.d != 0:
            raise ValueError("rotated geographic rasters are not supported")
        rad = crs.units_factor[1]
        lat = (t.f + t.e * (np.arange(rows) + 0.5)) * rad
        width = dem.body_radius_m * rad * abs(t.a) * np.abs(np.cos(lat))
        return width, dem.body_radius_m * rad * abs(t.e)
    return np.full(rows, dx), dy


def slope(dem: Dem, method: str = "horn") -> np.ndarray:
    """Slope in degrees.

    ``method="horn"``: ``dz/dx = ((c + 2f + i) - (a + 2d + g)) / (8 dx)`` on the 3 x 3
    window ``a b c / d e f / g h i`` (Horn 1981; ArcGIS/GDAL's default);
    ``"central"``: ``(f - d) / (2 dx)`` (Zevenbergen & Thorne 1987). NaN on the border and
    wherever the window holds an unknown pixel.

    Examples
    --------
    >>> tilted = Dem(np.add.outer(np.zeros(5), np.arange(5.0)) * math.tan(math.radians(30)),
    ...              pixel_size_m=1.0)
    >>> float(np.round(slope(tilted)[2, 2], 9))
    30.0
    """
    dem = _check(dem)
    with about("method"):
        check_choice("method", method, ("horn", "central"))
    z = dem.heights
    out = np.full(z.shape, np.nan)
    if min(z.shape) < 3:
        return out
    width, dy = pixel_sizes_by_row(dem)
    dx = width[1:-1, None]
    if method == "horn":
        a, b, c = z[:-2, :-2], z[:-2, 1:-1], z[:-2, 2:]
        d, f = z[1:-1, :-2], z[1:-1, 2:]
        g, h, i = z[2:, :-2], z[2:, 1:-1], z[2:, 2:]
        gx = ((c + 2 * f + i) - (a + 2 * d + g)) / (8 * dx)
        gy = ((g + 2 * h + i) - (a + 2 * b + c)) / (8 * dy)
    else:
        gx = (z[1:-1, 2:] - z[1:-1, :-2]) / (2 * dx)
        gy = (z[2:, 1:-1] - z[:-2, 1:-1]) / (2 * dy)
        # the same NaN rule as Horn's: any unknown pixel of the 3 x 3 window
        window = np.zeros_like(gx)
        for di in range(3):
            for dj in range(3):
                window += z[di:di + gx.shape[0], dj:dj + gx.shape[1]]
        gx = np.where(np.isnan(window), np.nan, gx)
    res = np.degrees(np.arctan(np.hypot(gx, gy)))
    res[np.isnan(z[1:-1, 1:-1])] = np.nan  # Horn skips the centre pixel; unknown stays unknown
    out[1:-1, 1:-1] = res
    return out


def slope_distribution(dem: Dem, bin_deg: float = 3.0, method: str = "horn") -> dict:
    """Area-weighted slope histogram and cumulative share of steeper ground.

    Returns ``edges_deg``, ``area_fraction`` (per bin, sums to 1), ``above_percent``,
    ``median_deg``, ``mean_deg`` and ``percent_above`` (10, 20, 30 degrees); each pixel
    counts with its ground area (rows shrink with latitude on a geographic CRS).
    """
    with about("bin_deg"):  # before the work (area_slope_summary checks it too)
        check_range("bin_deg", bin_deg, 0.01, 90.0)
    s = slope(dem, method)
    width, dy = pixel_sizes_by_row(dem)
    area = np.broadcast_to((width * dy)[:, None], s.shape)
    return area_slope_summary(s, area, bin_deg=bin_deg)


def power_spectrum(dem: Dem, n_bins: int | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Radially averaged power spectral density of the heights.

    The heights minus their least-squares plane are multiplied by a 2-D Hann window;
    the periodogram, normalised by the window's energy, is averaged over rings of radial
    spatial frequency ``f`` (cycles per metre, with the mean pixel size). Returns
    ``(wavelength_m, psd)`` from the longest wavelength to the shortest (two pixels),
    ``psd`` in m^2 per (cycle/m)^2: summed over the 2-D frequency plane it is the height
    variance. The DEM must have no unknown pixels.

    Examples
    --------
    >>> rng = np.random.default_rng(1)
    >>> wl, p = power_spectrum(Dem(rng.standard_normal((64, 64)), pixel_size_m=2.0))
    >>> bool(wl[0] > wl[-1] >= 4.0)
    True
    """
    dem = _check(dem)
    if not dem.known.all():
        raise ValueError("`dem` has unknown (NaN) pixels; fill them first (dem fill)")
    z = dem.heights
    rows, cols = z.shape
    if min(rows, cols) < 8:
        raise ParameterError("dem", f"must be at least 8 x 8 pixels; got {rows} x {cols}")
    width, dy = pixel_sizes_by_row(dem)
    dx = float(width.mean())
    resid = plane_residual(z)  # the same bytes on every CPU (craters.exact)
    window = np.outer(np.hanning(rows), np.hanning(cols))
    spec = abs2(np.fft.fft2(resid * window)) / (window**2).sum()
    spec *= dx * dy  # density: per unit area of the frequency plane (cycles/m)^2
    fy = np.fft.fftfreq(rows, d=dy)
    fx = np.fft.fftfreq(cols, d=dx)
    f = np.hypot(*np.meshgrid(fy, fx, indexing="ij"))
    f_min, f_max = 1.0 / (min(rows * dy, cols * dx)), 0.5 / max(dx, dy)
    n_bins = check_int("n_bins", n_bins if n_bins is not None else
                       max(8, int(2 * math.log2(min(rows, cols)) * 4)), 2, 10_000)
    from craters.counter import portable_geomspace  # numba loads here

    edges = portable_geomspace(f_min, f_max, n_bins + 1)  # the same bytes on every CPU
    which = np.digitize(f.ravel(), edges) - 1
    valid = (which >= 0) & (which < n_bins)
    sums = np.bincount(which[valid], weights=spec.ravel()[valid], minlength=n_bins)
    counts = np.bincount(which[valid], minlength=n_bins)
    keep = counts > 0
    centres = np.sqrt(edges[:-1] * edges[1:])[keep]
    return 1.0 / centres, sums[keep] / counts[keep]


def spectral_exponent(wavelength_m, psd, lo_m: float | None = None,
                      hi_m: float | None = None) -> float:
    """beta of ``psd ~ f^-beta`` by a least-squares line in log-log between wavelengths
    ``lo_m`` and ``hi_m`` (default: from 4 pixels to a quarter of the longest)."""
    wl = np.asarray(wavelength_m, dtype=np.float64)
    p = np.asarray(psd, dtype=np.float64)
    lo = lo_m if lo_m is not None else 2.0 * wl.min()
    hi = hi_m if hi_m is not None else wl.max() / 4.0
    sel = (wl >= lo) & (wl <= hi) & (p > 0)
    if sel.sum() < 3:
        raise ValueError("fewer than 3 spectrum points in the wavelength range")
    return float(np.polyfit(np.log(1.0 / wl[sel]), np.log(p[sel]), 1)[0] * -1.0)


def spectral_fit(dem: Dem, lo_px: float | None = None,
                 hi_px: float | None = None) -> SpectralFit:
    """Fractal dimension from the power-spectrum slope between two wavelengths (pixels).

    ``beta`` is fitted by :func:`spectral_exponent` to :func:`power_spectrum` between
    ``lo_px`` and ``hi_px`` pixels (default: :func:`spectral_exponent`'s, about 4 pixels
    to a quarter of the longest wavelength); ``F = (8 - beta) / 2`` for an fBm surface
    (``beta = 2 H + 2``).
    :data:`MATCHED_BAND_PX` (4-16 px) measures the scales of :func:`dem.fractal_fit`'s
    lags 2-8 px. The DEM must have no unknown pixel.

    Examples
    --------
    >>> noise = np.random.default_rng(0).standard_normal((64, 64))
    >>> fit = spectral_fit(Dem(noise, pixel_size_m=1.0))   # white noise: beta ~ 0
    >>> fit.is_surface_dimension, fit.warning[:30]
    (False, 'not a surface fractal dimensio')
    """
    wl, psd = power_spectrum(dem)
    width, dy = pixel_sizes_by_row(dem)
    px = math.sqrt(float(width.mean()) * dy)  # the pixel, as power_spectrum sees it
    lo = 2.0 * float(wl.min()) if lo_px is None else check_range("lo_px", lo_px, 2.0, None) * px
    hi = (float(wl.max()) / 4.0 if hi_px is None
          else check_range("hi_px", hi_px, lo / px, None) * px)
    beta = spectral_exponent(wl, psd, lo, hi)
    return SpectralFit((8.0 - beta) / 2.0, beta, (lo, hi), (lo / px, hi / px))


def roughness(dem: Dem) -> FractalFit:
    """The fractal fit (dimension F and height scale) that ``dem.expand`` uses."""
    return fractal_fit(_check(dem))
