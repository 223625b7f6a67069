"""Geodesic Gaussian smoothing against the spherical heat kernel (closed form)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.special import sph_harm_y

from latlong import LatLongGrid, area_mean, fwhm_to_sigma, heat_smooth, smooth

# A Gaussian of geodesic std sigma (unit sphere) multiplies Y_lm by exp(-l(l+1) sigma^2/2).
ATTENUATION_TOL = 0.01  # absolute, on factors in [0, 1]


def real_harmonic(grid, degree, order):
    theta = np.pi / 2 - grid.latitudes()
    return np.real(sph_harm_y(degree, order, theta, grid.longitudes()))


@pytest.mark.parametrize("sigma", [0.02, 0.1, 0.3])
@pytest.mark.parametrize("lm", [(1, 0), (2, 1), (4, 4), (8, 3), (16, 0), (24, 12)])
def test_heat_kernel_attenuation(sigma, lm):
    g = LatLongGrid(64)
    y = real_harmonic(g, *lm)
    s = heat_smooth(g, y, sigma)
    w = g.vertex_areas()
    factor = np.dot(w, s * y) / np.dot(w, y * y)
    deg = lm[0]
    assert abs(factor - math.exp(-deg * (deg + 1) * sigma**2 / 2)) < ATTENUATION_TOL
    # and the shape is kept: the smoothed field is still (nearly) that harmonic
    resid = s - factor * y
    assert np.sqrt(np.dot(w, resid**2) / np.dot(w, y * y)) < 0.02


def test_width_in_metres_and_passes():
    g = LatLongGrid(32)
    y = real_harmonic(g, 6, 2)
    radius = 80.0
    a = smooth(g, y, 20.0, radius_m=radius, passes=3)
    b = heat_smooth(g, y, fwhm_to_sigma(20.0) * math.sqrt(3) / radius)
    assert np.allclose(a, b)
    assert np.isclose(fwhm_to_sigma(2.354820045), 1.0)


def test_mean_kept_and_high_frequencies_removed(rng):
    g = LatLongGrid(80)
    f = 5.0 + rng.standard_normal(g.n_vertices)
    s = smooth(g, f, 20.0, radius_m=100.0, passes=3)
    assert abs(area_mean(g, s) - area_mean(g, f)) < 1e-12
    e = g.edges()
    # neighbour-to-neighbour differences (the highest frequencies) nearly vanish
    assert np.abs(np.diff(s[e], axis=1)).mean() < 0.02 * np.abs(np.diff(f[e], axis=1)).mean()


def test_constant_and_zero_width():
    g = LatLongGrid(10)
    c = np.full(g.n_vertices, 3.25)
    assert np.allclose(smooth(g, c, 5.0, radius_m=10.0), 3.25, atol=1e-12)
    f = np.arange(g.n_vertices, dtype=float)
    assert np.array_equal(smooth(g, f, 0.0, radius_m=10.0), f)
    assert np.array_equal(smooth(g, f, 5.0, radius_m=10.0, passes=0), f)


def test_input_not_modified(rng):
    g = LatLongGrid(10)
    f = rng.standard_normal(g.n_vertices)
    keep = f.copy()
    smooth(g, f, 5.0, radius_m=10.0)
    assert np.array_equal(f, keep)


def test_bad_inputs():
    g = LatLongGrid(4)
    f = np.zeros(g.n_vertices)
    with pytest.raises(ValueError, match="width_m"):
        smooth(g, f, -1.0, radius_m=1.0)
    with pytest.raises(ValueError, match="radius_m"):
        smooth(g, f, 1.0, radius_m=0.0)
    with pytest.raises(ValueError, match="passes"):
        smooth(g, f, 1.0, radius_m=1.0, passes=-2)
    with pytest.raises(ValueError, match="shape"):
        smooth(g, f[:-1], 1.0, radius_m=1.0)
    with pytest.raises(ValueError, match="finite"):
        smooth(g, np.full(g.n_vertices, np.nan), 1.0, radius_m=1.0)
