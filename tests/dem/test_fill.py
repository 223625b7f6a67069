"""Outside-in gap filling: kernel against a numpy reference, invariants, real terrain."""

from __future__ import annotations

import numpy as np
import pytest

import dem
from dem import Dem
from dem._rng_kernels import STREAM_FILL, _normals_kernel
from dem.gaps import _fill, _step_lengths

DIRS = [(-1, -1), (-1, 0), (-1, 1), (0, -1), (0, 1), (1, -1), (1, 0), (1, 1)]


def reference_fill(z, key, level, origin, sigma, steps):
    """The paper's algorithm, literally: waves of the pixels with the most known neighbours."""
    z = z.copy()
    known = np.isfinite(z)
    order = np.full(z.shape, -1)
    rows, cols = z.shape
    wave = 0
    while not known.all():
        pad = np.pad(known, 1)
        count = sum(pad[1 + dr:1 + dr + rows, 1 + dc:1 + dc + cols] for dr, dc in DIRS)
        count = np.where(known, -1, count)
        rr, cc = np.nonzero(count == count.max())
        vals = []
        for r, c in zip(rr, cc, strict=True):
            s = w = 0.0
            for d, (dr, dc) in enumerate(DIRS):
                k = 1
                while 0 <= r + k * dr < rows and 0 <= c + k * dc < cols:
                    if known[r + k * dr, c + k * dc]:
                        s += z[r + k * dr, c + k * dc] / (k * steps[d])
                        w += 1.0 / (k * steps[d])
                        break
                    k += 1
            vals.append(s / w)
        g = np.empty(rr.size)
        _normals_kernel(key, STREAM_FILL, level, (rr + origin[0]).astype(np.int64),
                        (cc + origin[1]).astype(np.int64), g)
        z[rr, cc] = np.array(vals) + sigma * g
        known[rr, cc] = True
        order[rr, cc] = wave
        wave += 1
    return z, order


def holes(shape, frac, rng, rmax=4.0):
    yy, xx = np.mgrid[0:shape[0], 0:shape[1]]
    mask = np.zeros(shape, bool)
    while mask.mean() < frac:
        cy, cx = rng.uniform(0, shape[0]), rng.uniform(0, shape[1])
        mask |= (yy - cy) ** 2 + (xx - cx) ** 2 <= rng.uniform(1.0, rmax) ** 2
    return mask


@pytest.mark.parametrize("shape,frac", [((12, 15), 0.3), ((20, 9), 0.6), ((6, 6), 0.9)])
@pytest.mark.parametrize("sigma", [0.0, 0.3])
@pytest.mark.parametrize("px", [(1.0, 1.0), (1.0, 2.5)])
def test_kernel_matches_reference(shape, frac, sigma, px, rng):
    z = rng.normal(0, 1, shape)
    mask = holes(shape, frac, rng)
    mask[shape[0] // 2, 0] = False  # keep one known pixel at least
    z[mask] = np.nan
    d = Dem(z, pixel_size_m=px, origin=(7, -3), level=2)
    got, order, n_waves = _fill(d, sigma, key=99)
    want, want_order = reference_fill(z, 99, 2, (7, -3), sigma, _step_lengths(d))
    np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-12)
    assert np.array_equal(order, want_order) and n_waves == want_order.max() + 1


def test_known_pixels_kept_no_nan_deterministic(lola_crop):
    mask = holes(lola_crop.shape, 0.1, np.random.default_rng(1), rmax=12)
    z = lola_crop.heights.copy()
    z[mask] = np.nan
    gappy = lola_crop.replace(heights=z)
    f = dem.fill_gaps(gappy, rng=5)
    assert np.array_equal(f.heights[~mask], lola_crop.heights[~mask])  # bit for bit
    assert np.isfinite(f.heights).all()
    assert np.array_equal(f.heights, dem.fill_gaps(gappy, rng=5).heights)
    assert not np.array_equal(f.heights, dem.fill_gaps(gappy, rng=6).heights)
    assert np.isnan(gappy.heights[mask]).all()  # input untouched
    step = f.history[-1]
    assert step["op"] == "dem.fill_gaps" and step["parameters"]["filled_pixels"] == mask.sum()
    assert step["parameters"]["estimated"] and step["parameters"]["roughness"] > 0


def test_holes_on_the_border_and_no_holes(rng):
    z = rng.normal(0, 1, (10, 10))
    z[:, :4] = np.nan
    f = dem.fill_gaps(Dem(z, pixel_size_m=1.0), 0.0, rng=1)
    assert np.isfinite(f.heights).all()
    # a column far from the known half is a weighted mean of known values: inside their range
    assert np.nanmin(z) <= f.heights[:, 0].min() and f.heights[:, 0].max() <= np.nanmax(z)
    full = Dem(z[:, 4:], pixel_size_m=1.0)
    assert np.array_equal(dem.fill_gaps(full, rng=1).heights, full.heights)


def test_bad_input():
    with pytest.raises(ValueError, match="no known pixel"):
        dem.fill_gaps(Dem(np.full((3, 3), np.nan), pixel_size_m=1.0))
    with pytest.raises(ValueError, match="roughness"):
        dem.fill_gaps(Dem(np.zeros((3, 3)), pixel_size_m=1.0), -0.1)
    with pytest.raises(TypeError, match="Dem"):
        dem.fill_gaps(np.zeros((3, 3)))


@pytest.mark.parametrize("seed", [1, 2, 3])
@pytest.mark.parametrize("rmax", [6.0, 20.0])
def test_filled_terrain_as_rough_as_known(lola_crop, seed, rmax):
    """10 % of a real DEM cut out in blobs: the fill's Laplacian std within 2x the known."""
    mask = holes(lola_crop.shape, 0.10, np.random.default_rng(seed), rmax=rmax)
    z = lola_crop.heights.copy()
    z[mask] = np.nan
    f = dem.fill_gaps(lola_crop.replace(heights=z), rng=seed)
    lap = dem.laplacian(f)
    k = ~mask
    known_stencil = k.copy()
    for dr, dc in ((0, 1), (0, -1), (1, 0), (-1, 0)):
        known_stencil &= np.roll(k, (dr, dc), axis=(0, 1))
    inner = np.isfinite(lap)
    ratio = np.std(lap[mask & inner]) / np.std(lap[known_stencil & inner])
    assert 0.5 <= ratio <= 2.0, ratio  # measured 0.7-0.9
