"""Variograms, local roughness and the fractal-dimension estimator; terrain statistics."""

from __future__ import annotations

import numpy as np
import pytest

import dem
from dem import Dem


def test_variogram_plain(rng):
    z = rng.normal(0, 1, (50, 60))
    z[3, 4] = np.nan
    lags, gamma, counts = dem.variogram(Dem(z, pixel_size_m=(2.0, 3.0)), 3)
    assert lags.tolist() == [2.0, 4.0, 6.0, 3.0, 6.0, 9.0]
    d = z[:, 2:] - z[:, :-2]
    assert gamma[1] == pytest.approx(np.nanmean(d**2)) and counts[1] == np.isfinite(d).sum()
    d = z[3:] - z[:-3]
    assert gamma[5] == pytest.approx(np.nanmean(d**2))


def test_local_roughness_reference(rng):
    z = rng.normal(0, 1, (7, 9))
    z[2, 2] = np.nan
    got = dem.local_roughness(Dem(z, pixel_size_m=2.0))
    want = np.full(z.shape, np.nan)
    for r in range(7):
        for c in range(9):
            if np.isnan(z[r, c]):
                continue
            d = [z[r + a, c + b] - z[r, c] for a, b in ((0, 1), (0, -1), (1, 0), (-1, 0))
                 if 0 <= r + a < 7 and 0 <= c + b < 9 and np.isfinite(z[r + a, c + b])]
            want[r, c] = np.sqrt(np.mean(np.square(d))) / 2.0
    np.testing.assert_allclose(got, want, rtol=1e-12, equal_nan=True)


def test_fit_plane_noise_and_flat(rng):
    plane = Dem(0.1 * np.add.outer(np.arange(40.0), np.arange(40.0)), pixel_size_m=1.0)
    fit = dem.fractal_fit(plane)
    assert fit.fractal_dimension == pytest.approx(2.0) and fit.roughness == pytest.approx(0.1)
    noise = Dem(rng.normal(0, 1, (300, 300)), pixel_size_m=5.0)
    assert abs(dem.fractal_dimension(noise) - 3.0) < 0.1  # measured 2.93 (see module doc)
    flat = dem.fractal_fit(Dem(np.zeros((10, 10)), pixel_size_m=1.0))
    assert (flat.fractal_dimension, flat.roughness) == (2.0, 0.0)
    # the normalised variogram ignores a change of amplitude across the DEM
    z = rng.normal(0, 1, (200, 200)).cumsum(axis=0).cumsum(axis=1)
    z2 = z * np.where(np.arange(200) < 100, 1.0, 20.0)[None, :]
    a = dem.fractal_dimension(Dem(z[:, 100:], pixel_size_m=1.0))
    b = dem.fractal_dimension(Dem(z2[:, 100:], pixel_size_m=1.0))
    assert a == pytest.approx(b)


def test_fit_too_small():
    with pytest.raises(ValueError, match="give `fractal_dimension` and `roughness`"):
        dem.fractal_fit(Dem(np.array([[1.0, 2.0]]), pixel_size_m=1.0))
    with pytest.raises(TypeError, match="Dem"):
        dem.fractal_fit(np.zeros((5, 5)))


def test_slope_laplacian_band_power(rng):
    x = np.arange(20.0)
    z = np.add.outer(0.5 * x, np.zeros(20))  # rises 0.5 m per 2 m row step
    d = Dem(z, pixel_size_m=2.0)
    s = dem.slope(d)
    assert np.isnan(s[0]).all() and np.allclose(s[1:-1, 1:-1], np.degrees(np.arctan(0.25)))
    assert np.allclose(dem.laplacian(d)[1:-1, 1:-1], 0.0)
    assert dem.band_power(d) < 1e-20  # a plane has no power once detrended
    noise = Dem(rng.normal(0, 3, (64, 64)), pixel_size_m=1.0)
    assert dem.band_power(noise, 0.0, 1.0) == pytest.approx(9.0, rel=0.15)
    with pytest.raises(ValueError, match="unknown"):
        dem.band_power(Dem(np.full((4, 4), np.nan), pixel_size_m=1.0))
