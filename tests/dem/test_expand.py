"""RMD expansion: kernel against a numpy reference, exactness, georeferencing, tiles, F."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
import rasterio.transform
from affine import Affine
from rasterio.coords import BoundingBox
from rasterio.windows import Window
from scipy import ndimage

import dem
from dem import Dem
from dem._expand_kernels import _expand_kernel
from dem._rng_kernels import STREAM_EXPAND, _normals_kernel
from dem.expansion import CONTEXT_PX, displacement_scales, midpoint_factor


def reference_expand(old, key, level, row0, col0, sd_sq, sd_dia, amp, amp0, inv_scale):
    """Plain numpy diamond-square doubling (NaN-aware means, bilinear amplitude)."""
    rows, cols = old.shape
    n_r, n_c = 2 * rows - 1, 2 * cols - 1
    out = np.full((n_r, n_c), np.nan)
    out[::2, ::2] = old
    ii, jj = np.mgrid[0:n_r, 0:n_c]

    def noise(mask, sd):
        r, c = row0 + ii[mask], col0 + jj[mask]
        g = np.empty(r.size)
        _normals_kernel(key, STREAM_EXPAND, level, r.astype(np.int64), c.astype(np.int64), g)
        y = np.clip(r * inv_scale - amp0[0], 0, amp.shape[0] - 1)
        x = np.clip(c * inv_scale - amp0[1], 0, amp.shape[1] - 1)
        a = ndimage.map_coordinates(amp, [y, x], order=1, mode="nearest")
        return sd * a * g

    corners = np.stack([old[:-1, :-1], old[:-1, 1:], old[1:, :-1], old[1:, 1:]])
    sq = (ii % 2 == 1) & (jj % 2 == 1)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # all-NaN corners -> NaN
        out[1::2, 1::2] = np.nanmean(corners, axis=0)
    out[sq] += noise(sq, sd_sq)
    pad = np.pad(out, 1, constant_values=np.nan)
    nbrs = np.stack([pad[:-2, 1:-1], pad[2:, 1:-1], pad[1:-1, :-2], pad[1:-1, 2:]])
    dia = (ii + jj) % 2 == 1
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        mean = np.nanmean(nbrs, axis=0)
    out[dia] = mean[dia] + noise(dia, sd_dia)
    return out


@pytest.mark.parametrize("shape", [(2, 2), (3, 5), (9, 9), (6, 4)])
@pytest.mark.parametrize("with_nan", [False, True])
def test_kernel_matches_reference(shape, with_nan, rng):
    old = rng.normal(0, 10, shape)
    if with_nan:
        old[0, -1] = np.nan
    amp = rng.uniform(0.5, 2.0, (shape[0] + 2, shape[1] + 3))
    args = (12345, 3, 40, -6, 0.7, 0.4, amp, 19.0, -4.0, 0.5)
    out = np.empty((2 * shape[0] - 1, 2 * shape[1] - 1))
    _expand_kernel(old, *args, out)
    want = reference_expand(old, *args[:6], amp, args[7:9], args[9])
    np.testing.assert_allclose(out, want, rtol=1e-12, atol=1e-12)
    assert np.array_equal(out[::2, ::2], old, equal_nan=True)


def test_midpoint_factor_is_the_variogram_algebra():
    """k(H) from the closed form equals -1/2 sum w w gamma over the actual square."""
    pts = np.array([[1, 0], [0, 1], [-1, 0], [0, -1]], float)  # neighbours at rho = 1
    w = np.array([-0.75, 0.25, 0.25, 0.25])
    for hurst in (0.0, 0.2, 0.5, 0.8, 1.0):
        dist = np.linalg.norm(pts[:, None] - pts[None], axis=2)
        gamma = np.where(dist > 0, dist ** (2 * hurst), 0.0)
        var_mean_minus_a1 = -0.5 * (w[:, None] * w[None] * gamma).sum()
        assert midpoint_factor(hurst) == pytest.approx(1 - var_mean_minus_a1, abs=1e-12)
    assert midpoint_factor(1.0) == 0.0 and midpoint_factor(0.5) == pytest.approx(0.3964, 1e-3)


@pytest.mark.parametrize("f", [2.0, 2.2, 2.5, 3.0])
def test_displacement_scales(f):
    h = 3 - f
    scales = [s for lev in (1, 2, 3) for s in displacement_scales(lev, f, 2.0)]
    if f == 2.0:
        assert scales == [0.0] * 6
        return
    ratios = np.array(scales[1:]) / np.array(scales[:-1])
    np.testing.assert_allclose(ratios, 2 ** (-h / 2), rtol=1e-12)  # Peitgen & Saupe
    assert scales[0] == pytest.approx(2.0 * math.sqrt(midpoint_factor(h)) * 2 ** (-h / 2))


@pytest.mark.parametrize("levels", [1, 2])
def test_even_pixels_and_georeferencing(lola_crop, levels):
    e = dem.expand(lola_crop, levels, rng=3)
    s = 2**levels
    assert e.shape == (256 * s + 1,) * 2
    assert np.array_equal(e.heights[::s, ::s], lola_crop.heights)
    assert e.crs == lola_crop.crs and e.body_radius_m == lola_crop.body_radius_m
    rows, cols = np.mgrid[0:257:16, 0:257:16]
    x0, y0 = rasterio.transform.xy(lola_crop.transform, rows.ravel(), cols.ravel())
    x1, y1 = rasterio.transform.xy(e.transform, s * rows.ravel(), s * cols.ravel())
    assert np.abs(np.subtract(x0, x1)).max() < 1e-9 and np.abs(np.subtract(y0, y1)).max() < 1e-9
    assert e.transform.a == lola_crop.transform.a / s
    assert e.pixel_size_m[1] == pytest.approx(lola_crop.pixel_size_m[1] / s)
    assert e.level == levels and e.origin == (0, 0)
    step = e.history[-1]
    assert step["op"] == "dem.expand" and step["seed"] == 3
    assert step["parameters"]["roughness"] == "local"
    assert 2.0 <= step["parameters"]["fractal_dimension"] <= 3.0


def test_no_crs_pixel_size_and_determinism():
    d = Dem(np.random.default_rng(0).normal(0, 5, (9, 9)), pixel_size_m=(4.0, 8.0))
    a = dem.expand(d, 2, rng=7)
    assert a.pixel_size_m == (1.0, 2.0)
    assert np.array_equal(a.heights, dem.expand(d, 2, rng=7).heights)
    assert not np.array_equal(a.heights, dem.expand(d, 2, rng=8).heights)
    assert d.level == 0 and np.array_equal(  # input untouched
        d.heights, np.random.default_rng(0).normal(0, 5, (9, 9)))


def test_zero_roughness_keeps_a_plane():
    y, x = np.mgrid[0:17, 0:17]
    d = Dem(3.0 * x - 2.0 * y + 5.0, pixel_size_m=1.0)
    e = dem.expand(d, 2, fractal_dimension=2.5, roughness=0.0, rng=0)
    yy, xx = np.mgrid[0:65, 0:65] / 4.0
    inner = (slice(4, -4), slice(4, -4))  # border diamonds average three neighbours
    np.testing.assert_allclose(e.heights[inner], (3.0 * xx - 2.0 * yy + 5.0)[inner],
                               atol=1e-12)


def test_relief_of_the_input_itself_is_the_default():
    d = Dem(np.random.default_rng(3).normal(0, 5, (17, 17)), pixel_size_m=8.0)
    a = dem.expand(d, 2, 2.3, rng=4)
    b = dem.expand(d, 2, 2.3, rng=4, relief=dem.local_relief(d))
    assert np.array_equal(a.heights, b.heights)


@pytest.mark.parametrize("region,then", [(None, None), ((4, 4, 9), (8, 8, 17))])
def test_carried_relief_makes_one_level_at_a_time_the_multilevel_expansion(region, then):
    # layer after layer with the source's relief (dem.enhance) is exactly expanding the
    # source two levels at once: the displacement scale 2^(-H) per level is carried
    d = Dem(np.random.default_rng(5).normal(0, 5, (17, 17)), pixel_size_m=8.0)
    relief = dem.local_relief(d, median_px=3)
    two = dem.expand(d, 2, 2.3, rng=6, relief=relief, region=region)
    one = dem.expand(d, 1, 2.3, rng=6, relief=relief)
    assert not np.array_equal(one.heights, dem.expand(d, 1, 2.3, rng=6).heights)
    again = dem.expand(one, 1, 2.3, rng=6, relief=relief, region=then)
    assert (again.level, again.origin) == (two.level, two.origin)
    assert np.array_equal(again.heights, two.heights)


def test_local_relief_median_window():
    z = np.zeros((9, 9))
    z[:, 5:] = 100.0  # a cliff: relief only beside it, robustly removed by the median
    d = Dem(z, pixel_size_m=1.0)
    pointwise = dem.local_relief(d).heights
    assert pointwise[4, 4] == pytest.approx(50.0) and pointwise[4, 0] == 0.0
    assert dem.local_relief(d, median_px=5).heights[4, 4] == 0.0
    assert dem.local_relief(d, median_px=5).heights.shape == (9, 9)


@pytest.mark.parametrize("kwargs,match", [
    ({"relief": np.ones((9, 9))}, "`relief` must be a dem.Dem"),
    ({"relief": "coarser", "roughness": 0.1}, "`relief` or `roughness`"),
    ({"relief": "finer"}, "level of the DEM or coarser"),
    ({"relief": "negative"}, ">= 0 metres"),
    ({"relief": "small"}, "does not cover"),
])
def test_bad_relief(kwargs, match):
    d = Dem(np.random.default_rng(1).normal(0, 5, (9, 9)), pixel_size_m=8.0)
    fine = dem.expand(d, 1, 2.3, rng=1)
    made = {"coarser": dem.local_relief(d), "finer": dem.local_relief(fine),
            "negative": d.replace(heights=-np.ones((9, 9))),
            "small": dem.local_relief(d.crop(Window(0, 0, 4, 4)))}
    value = kwargs["relief"]
    kwargs = {**kwargs, "relief": made.get(value, value) if isinstance(value, str) else value}
    with pytest.raises((ValueError, TypeError), match=match):
        dem.expand(d, 1, 2.3, **kwargs)
    with pytest.raises(ValueError, match="median_px"):
        dem.local_relief(d, median_px=4)


@pytest.mark.parametrize("kwargs,match", [
    ({}, r"is 257 x 256 pixels.*2\^n \+ 1.*3, 5, 9, 17"),
    ({"region": Window(0, 0, 10, 10)}, r"10 x 10 pixels.*2\^n \+ 1"),
    ({"region": Window(0, 0, 9, 17)}, r"17 x 9"),
    ({"region": Window(250, 0, 9, 9)}, "not inside the DEM"),
    ({"region": BoundingBox(0.0, 0.0, 1.0, 1.0)}, "not inside the DEM"),
    ({"region": 9}, "Window"),
    ({"region": "0,0"}, "ROW,COL,SIZE"),
    ({"region": Window(0, 0, 9, 9), "levels": 0}, "levels"),
    ({"region": Window(0, 0, 9, 9), "levels": 17}, "levels"),
    ({"region": Window(0, 0, 9, 9), "fractal_dimension": 3.5}, "fractal_dimension"),
    ({"region": Window(0, 0, 9, 9), "roughness": -1.0}, "roughness"),
    ({"region": Window(0, 0, 9, 9), "rng": "x"}, "rng"),
    ({"region": Window(0, 0, 2049, 2049)}, "not inside"),
])
def test_bad_requests(lola_crop, kwargs, match):
    d = lola_crop.crop(Window(0, 0, 256, 257))
    with pytest.raises((ValueError, TypeError), match=match):
        dem.expand(d, **{"levels": 1, **kwargs})


def test_unknown_pixels_and_memory(lola_crop):
    z = lola_crop.heights.copy()
    z[5, 5] = np.nan
    with pytest.raises(ValueError, match="1 unknown.*fill_gaps"):
        dem.expand(lola_crop.replace(heights=z), 1)
    assert dem.expand(lola_crop.replace(heights=z), 1, region=Window(100, 100, 9, 9), rng=1)
    with pytest.raises(ValueError, match="no known pixel"):
        dem.expand(Dem(np.full((5, 5), np.nan), pixel_size_m=1.0), 1)
    with pytest.raises(ValueError, match="memory"):
        dem.expand(lola_crop, 16)


def test_region_by_window_and_bounds(lola_crop):
    win = Window(64, 32, 129, 129)
    a = dem.expand(lola_crop, 1, region=win, rng=2)
    x0, y0 = lola_crop.xy(32, 64)
    x1, y1 = lola_crop.xy(32 + 128, 64 + 128)
    b = dem.expand(lola_crop, 1, region=BoundingBox(x0, y1, x1, y0), rng=2)
    assert np.array_equal(a.heights, b.heights) and a.transform == b.transform
    assert np.array_equal(a.heights[::2, ::2], lola_crop.heights[32:161, 64:193])
    assert a.origin == (64, 128)
    # as the command line gives them: (row, col, size) or bounds, a tuple or the text
    for region in ((32, 64, 129), "32,64,129", (x0, y1, x1, y0), f"{x0},{y1},{x1},{y0}"):
        c = dem.expand(lola_crop, 1, region=region, rng=2)
        assert np.array_equal(a.heights, c.heights) and a.transform == c.transform


@pytest.mark.parametrize("levels", [1, 2, 3])
@pytest.mark.parametrize("roughness", [None, 0.03])
def test_four_tiles_equal_the_whole(lola_crop, levels, roughness):
    d = lola_crop.crop(Window(40, 60, 129, 129)) if levels == 3 else lola_crop
    n = d.shape[0] - 1
    half = n // 2
    whole = dem.expand(d, levels, fractal_dimension=2.4, roughness=roughness, rng=11)
    s = 2**levels
    mosaic = np.full(whole.shape, np.nan)
    for r0 in (0, half):
        for c0 in (0, half):
            t = dem.expand(d, levels, fractal_dimension=2.4, roughness=roughness,
                           region=Window(c0, r0, half + 1, half + 1), rng=11)
            block = mosaic[r0 * s:r0 * s + t.shape[0], c0 * s:c0 * s + t.shape[1]]
            seen = np.isfinite(block)  # the shared edge row / column
            assert np.array_equal(block[seen], t.heights[seen])
            block[...] = t.heights
            assert t.transform == whole.transform @ Affine.translation(c0 * s, r0 * s)
    assert np.array_equal(mosaic, whole.heights)


def test_separately_cut_tile_with_context(lola_crop):
    fd = dem.fractal_dimension(lola_crop)
    whole = dem.expand(lola_crop, 2, fractal_dimension=fd, rng=4)
    k = CONTEXT_PX
    tile = lola_crop.crop(Window(128 - k, 0, 129 + k, 129 + k))
    part = dem.expand(tile, 2, fractal_dimension=fd, region=Window(k, 0, 129, 129), rng=4)
    assert np.array_equal(part.heights, whole.heights[:513, 512:])


def test_level_origin_and_history_survive_a_file(tmp_path):
    d = Dem(np.zeros((5, 5)), pixel_size_m=1.0)
    e = dem.expand(d, 1, fractal_dimension=2.5, roughness=0.0, region=None, rng=0)
    back = dem.read(dem.write(e, tmp_path / "e.tif"))
    assert (back.level, back.origin) == (1, (0, 0))
    assert back.pixel_size_m == (0.5, 0.5)  # no CRS: the pixel size travels in a tag
    assert back.history[-1]["op"] == "dem.expand"


def expanded_seed(f, roughness, levels=7):
    seed = Dem(np.random.default_rng(3).normal(0, 100, (17, 17)), pixel_size_m=128.0)
    return dem.expand(seed, levels, fractal_dimension=f, roughness=roughness, rng=5)


# RMD's finest lag falls short of the fBm model by this much in variance (measured
# 0.82 at F = 2.2, 0.98 at F = 2.5: the independence approximation of the derivation)
VARIOGRAM_TOL = 0.25


@pytest.mark.parametrize("f", [2.2, 2.5])
@pytest.mark.parametrize("roughness", [1.0, None])
def test_fractal_dimension_of_a_17px_seed_expanded_7_levels(f, roughness):
    e = expanded_seed(f, roughness)
    assert e.shape == (2049, 2049)
    # the spectral slope over 4-512 px reads 2.15 / 2.50; RMD's finest scales are rougher:
    # the variogram (lags 2-8 px) and the spectrum at 4-16 px read 2.30 / 2.63 and 2.36 / 2.64
    assert abs(dem.spectral_fit(e).fractal_dimension - f) <= 0.1
    fine = dem.fractal_dimension(e)
    assert abs(fine - dem.spectral_fit(e, 4.0, 16.0).fractal_dimension) <= 0.15
    assert 0.0 < fine - f <= 0.15
    if roughness is not None:  # the amplitude follows the model too
        lags, gamma, _ = dem.variogram(e, 1)
        model = (roughness * 128.0) ** 2 * (1.0 / 128.0) ** (2 * (3 - f))
        assert abs(gamma.mean() / model - 1) <= VARIOGRAM_TOL


@pytest.mark.parametrize("region,levels,roughness,tile_px", [
    ((40, 60, 129), 3, None, 129),      # the local amplitude, 64 tiles of 17 input pixels
    ((40, 60, 129), 3, 0.03, 257),      # a uniform one, 16 tiles
    ((0, 0, 257), 1, None, 100),        # tiles of 33 pixels (97 once expanded)
    ((7, 9, 33), 2, None, 5),           # the smallest tiles: 3 input pixels
])
def test_tiled_file_has_the_bytes_of_the_whole(tmp_path, lola_crop, region, levels,
                                               roughness, tile_px):
    whole = dem.expand(lola_crop, levels, roughness=roughness, region=region, rng=8)
    a = dem.write(whole, tmp_path / "whole.tif")
    made = dem.expand_to_file(lola_crop, tmp_path / "tiled.tif", levels, roughness=roughness,
                              region=region, rng=8, tile_px=tile_px)
    assert made.tiles > 1 and made.shape == whole.shape and made.seed == 8
    assert made.parameters == whole.history[-1]["parameters"]
    assert made.path.read_bytes() == a.read_bytes()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["tiled.tif", "whole.tif"]


def test_tiled_file_without_crs_and_its_errors(tmp_path):
    d = Dem(np.random.default_rng(2).normal(0, 3, (33, 33)), pixel_size_m=(2.0, 3.0),
            tags={"SOURCE": "test"})
    a = dem.write(dem.expand(d, 2, 2.2, 0.1, rng=1), tmp_path / "a.tif")
    b = dem.expand_to_file(d, tmp_path / "b.tif", 2, 2.2, 0.1, rng=1, tile_px=33)
    assert b.tiles == 16 and a.read_bytes() == b.path.read_bytes()
    back = dem.read(b.path)
    assert back.pixel_size_m == (0.5, 0.75) and back.tags["SOURCE"] == "test"
    with pytest.raises(ValueError, match="`tile_px`"):
        dem.expand_to_file(d, tmp_path / "c.tif", 1, tile_px=2)
    with pytest.raises(ValueError, match="GeoTIFF"):
        dem.expand_to_file(d, tmp_path / "c.png", 1)
    z = d.heights.copy()
    z[3, 3] = np.nan
    with pytest.raises(ValueError, match="unknown"):
        dem.expand_to_file(d.replace(heights=z), tmp_path / "c.tif", 1)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.tif", "b.tif"]


def test_cli_expand_goes_tile_by_tile(tmp_path, lola_crop, monkeypatch, capsys):
    import dem.expandfile
    from dem.cli import main

    src = dem.write(lola_crop, tmp_path / "in.tif")
    want = dem.write(dem.expand(lola_crop, 2, region=(0, 0, 129), rng=3), tmp_path / "w.tif")
    monkeypatch.setattr(dem.expandfile, "TILE_PX", 65)  # 16 tiles of 17 input pixels
    assert main(["expand", str(src), "-o", str(tmp_path / "t.tif"), "--levels", "2",
                 "--region", "0,0,129", "--seed", "3", "-q"]) == 0
    assert (tmp_path / "t.tif").read_bytes() == want.read_bytes()
    assert capsys.readouterr().out == ""
