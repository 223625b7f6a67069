"""A real DEM decimated 4x and expanded back 2 levels looks like the original.

The LOLA LDEM_4 crop in tests/data (257 x 257, 7.6 km/px, centred on the equator at
180 E) is decimated to every 4th pixel (65 x 65) and expanded 2 levels with default
parameters (everything estimated from the 65 x 65 input). Figures are in the closing
note of issue 5 and in ``tests/benchmarks/bench_dem.py``.
"""

from __future__ import annotations

import numpy as np
import pytest
from affine import Affine
from scipy.interpolate import RectBivariateSpline

import dem
from dem import Dem


def decimate(d: Dem, k: int) -> Dem:
    """Every k-th pixel, with pixel centres on the kept pixels' centres."""
    t = d.transform @ Affine.translation(-(k - 1) / 2, -(k - 1) / 2) @ Affine.scale(k)
    return Dem(d.heights[::k, ::k], t, d.crs, body_radius_m=d.body_radius_m)


def bicubic(coarse: Dem, like: Dem, k: int) -> Dem:
    n = coarse.shape[0]
    spline = RectBivariateSpline(np.arange(n) * k, np.arange(n) * k, coarse.heights,
                                 kx=3, ky=3)
    fine = np.arange(like.shape[0])
    return like.replace(heights=spline(fine, fine))


def ratios(test: Dem, ref: Dem) -> tuple[float, float, float]:
    """(median Horn slope, top-octave power, Laplacian std) of ``test`` over ``ref``."""
    return (np.nanmedian(dem.slope(test)) / np.nanmedian(dem.slope(ref)),
            dem.band_power(test) / dem.band_power(ref),
            np.nanstd(dem.laplacian(test)) / np.nanstd(dem.laplacian(ref)))


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_expanded_like_the_original(lola_crop, seed):
    coarse = decimate(lola_crop, 4)
    assert coarse.shape == (65, 65)
    e = dem.expand(coarse, 2, rng=seed)
    assert e.shape == lola_crop.shape
    assert np.array_equal(e.heights[::4, ::4], coarse.heights)
    assert np.allclose(tuple(e.transform), tuple(lola_crop.transform), rtol=0, atol=1e-12)
    slope, power, lap = ratios(e, lola_crop)
    assert 0.75 <= slope <= 1.33, slope  # measured 0.90
    assert 1 / 3 <= power <= 3, power  # measured ~1.3
    assert 0.5 <= lap <= 2, lap  # measured ~1.37


def test_bicubic_is_far_too_smooth(lola_crop):
    coarse = decimate(lola_crop, 4)
    slope, power, lap = ratios(bicubic(coarse, lola_crop, 4), lola_crop)
    assert power < 0.01 and lap < 0.5  # measured ~3e-4 and ~0.25
