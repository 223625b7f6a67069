"""Crater gap filling (warped synthetic craters) and crater replacement (Dem and Stack)."""

from __future__ import annotations

import numpy as np
import pytest
from affine import Affine
from scipy.ndimage import gaussian_filter

import craters
import dem
from dem.craterfill import fill_crater_gaps, harmonic_warp, replace_crater


def reference_warp(z, synth, region, sweeps=20000):
    """Jacobi iteration of the same discrete Laplace problem (pure numpy reference)."""
    known = np.isfinite(z)
    mismatch = np.where(known, z - np.where(known, synth, 0.0), 0.0)
    c = np.zeros(z.shape)
    for _ in range(sweeps):
        total = np.zeros(z.shape)
        count = np.zeros(z.shape)
        for axis, shift in ((0, 1), (0, -1), (1, 1), (1, -1)):
            vals = np.roll(np.where(region, c, mismatch), shift, axis)
            ok = np.roll(region | known, shift, axis)
            edge = [slice(None)] * 2
            edge[axis] = 0 if shift == 1 else -1
            ok[tuple(edge)] = False  # no wrap-around
            total += np.where(ok, vals, 0.0)
            count += ok
        c = np.where(region, total / np.maximum(count, 1), 0.0)
    return c


def test_harmonic_warp_matches_a_jacobi_reference():
    rng = np.random.default_rng(0)
    z = rng.normal(0, 1, (9, 12))
    region = np.zeros(z.shape, bool)
    region[2:7, 3:10] = True
    region[4, 1:3] = True  # a tongue reaching an unknown, non-region pixel at (4, 0)
    z[region] = np.nan
    z[4, 0] = np.nan  # natural boundary there
    synth = rng.normal(0, 1, z.shape)
    got = harmonic_warp(z, synth, region)
    want = reference_warp(z, synth, region)
    assert np.abs(got - want).max() < 1e-6
    assert (got[~region] == 0).all()


def test_harmonic_warp_keeps_offsets_and_tilts():
    yy, xx = np.mgrid[0:20, 0:20].astype(float)
    region = np.hypot(yy - 10, xx - 10) < 6
    z = np.where(region, np.nan, 0.0)
    synth = -(3.0 + 0.5 * xx - 0.25 * yy)  # mismatch = a plane
    w = harmonic_warp(z, synth, region)
    assert np.allclose(w[region], -synth[region], atol=1e-6)
    # a region without known neighbours gets no warp
    lone = np.full((5, 5), np.nan)
    assert (harmonic_warp(lone, np.ones((5, 5)), np.isnan(lone)) == 0).all()


@pytest.fixture(scope="module")
def crater_scene():
    """Rough terrain (10 m pixels) with a degraded 1.2 km crater whose floor is unknown."""
    seed = dem.Dem(np.random.default_rng(3).normal(0, 20, (17, 17)), pixel_size_m=160.0)
    terr = dem.expand(seed, 4, fractal_dimension=2.3, roughness=0.1, rng=1)  # 257^2
    p, diameter = 10.0, 1200.0
    truth = craters.stamp(terr.heights, p, craters.Crater(128 * p, 128 * p, diameter, 0.2),
                          rng=4)
    yy, xx = np.mgrid[0:257, 0:257]
    x = np.hypot(yy - 128, xx - 128) * p / (diameter / 2)
    gap = x < 0.75  # the shadowed floor
    other = (np.abs(yy - 20) < 4) & (np.abs(xx - 30) < 4)  # a gap outside every crater
    z = np.where(gap | other, np.nan, truth)
    d = dem.Dem(z, Affine(p, 0, 5000.0, 0, -p, 9000.0), "EPSG:32633")
    return d, truth, gap, other, [craters.Crater(0.0, 0.0, diameter, 0.2)]


def border_steps(h, gap):
    out = []
    for axis in (0, 1):
        for shift in (1, -1):
            across = gap & ~np.roll(gap, shift, axis)
            out.append(np.abs(h - np.roll(h, shift, axis))[across])
    return np.concatenate(out)


def test_fill_crater_gaps_recovers_the_floor_without_steps(crater_scene):
    d, truth, gap, other, crater = crater_scene
    f, cat = fill_crater_gaps(d, crater, rng=2, return_catalog=True)
    known = d.known
    assert np.array_equal(f.heights[known], d.heights[known])  # bit for bit
    assert np.isfinite(f.heights[gap]).all() and np.isnan(f.heights[other]).all()
    depth = truth[~gap].max() - truth[gap].min()
    rms = np.sqrt(np.mean((f.heights[gap] - truth[gap]) ** 2))
    plain = dem.fill_gaps(d, rng=2).heights
    rms_plain = np.sqrt(np.mean((plain[gap] - truth[gap]) ** 2))
    assert rms < 0.02 * depth and rms_plain > 0.2 * depth  # measured: 0.9 m, 67 m of 218 m
    # no steps at the border of the filled region: like the real terrain's, while the same
    # synthetic crater pasted in unwarped steps by tens of metres
    steps = np.median(border_steps(f.heights, gap))
    true_steps = np.median(border_steps(truth, gap))
    base = dem.fill_gaps(d, rng=2)
    raw = craters.stamp(base.heights, 10.0, craters.Crater(1280.0, 1280.0, 1200.0, 0.2),
                        rng=3)
    pasted = np.median(border_steps(np.where(gap, raw, truth), gap))
    assert steps < 1.25 * true_steps and pasted > 4 * true_steps
    assert len(cat) == 1 and cat["x_m"][0] == 0.0 and cat["depth_m"][0] > 100
    assert f.history[-1]["op"] == "dem.fill_crater_gaps"


def test_fill_crater_gaps_same_seed_same_pixels_and_nothing_to_do(crater_scene):
    d, _, gap, _, crater = crater_scene
    a, b = fill_crater_gaps(d, crater, rng=5), fill_crater_gaps(d, crater, rng=5)
    assert np.array_equal(a.heights, b.heights, equal_nan=True)
    far = [craters.Crater(-900.0, 900.0, 100.0)]  # its interior is all known
    same = fill_crater_gaps(d, far, rng=1)
    assert np.array_equal(same.heights, d.heights, equal_nan=True)
    assert same.history[-1]["parameters"]["filled_pixels"] == 0


@pytest.mark.parametrize("craters_,kwargs,error,match", [
    ("crater", {}, TypeError, "catalog"),
    ([], {}, TypeError, "non-empty"),
    (None, {"extent": 3.0}, ValueError, "extent"),
    (None, {"frame": "here"}, TypeError, "LocalFrame"),
])
def test_fill_crater_gaps_bad_input(crater_scene, craters_, kwargs, error, match):
    d, *_ = crater_scene
    arg = crater_scene[4] if craters_ is None else craters_
    with pytest.raises(error, match=match):
        fill_crater_gaps(d, arg, **kwargs)


def test_craters_need_square_pixels():
    d = dem.Dem(np.full((9, 9), np.nan), pixel_size_m=(1.0, 2.0))
    with pytest.raises(ValueError, match="square pixels"):
        fill_crater_gaps(d, [craters.Crater(0.0, 0.0, 4.0)])


def test_replace_crater_in_a_dem_sharpens_and_stays_local():
    seed = dem.Dem(np.random.default_rng(3).normal(0, 20, (17, 17)), pixel_size_m=160.0)
    terr = dem.expand(seed, 4, fractal_dimension=2.3, roughness=0.1, rng=1)  # 257^2, 10 m
    real = craters.stamp(terr.heights, 10.0, craters.Crater(1280.0, 1280.0, 600.0), rng=4)
    blurred = gaussian_filter(real, 10.0)  # the crater after many expansions
    d = dem.Dem(blurred, pixel_size_m=10.0)
    r = replace_crater(d, craters.Crater(0.0, 0.0, 600.0, 0.0), rng=3)
    yy, xx = np.mgrid[0:257, 0:257]
    rad = np.hypot(yy - 128, xx - 128) * 10.0
    reach = craters.DEFAULT_EJECTA_EDGE * 1.02 * 300.0
    outside = rad >= reach
    assert np.array_equal(r.heights[outside], blurred[outside])
    fresh_depth = float(craters.fresh_morphometry(600.0)["depth_m"])
    rim = (rad > 280) & (rad < 320)
    floor = rad < 50

    def relief(h):
        return h[rim].mean() - h[floor].mean()

    assert relief(r.heights) == pytest.approx(fresh_depth, rel=0.15)
    assert relief(blurred) < 0.75 * fresh_depth
    # it blends at the ejecta edge: steps across it like the untouched terrain's
    steps = np.median(border_steps(r.heights, ~outside))
    assert steps < 2 * np.median(np.abs(np.diff(blurred, axis=1)))
    with pytest.raises(ValueError, match="does not fit inside the DEM"):
        replace_crater(d, craters.Crater(800.0, 0.0, 600.0))


def test_replace_crater_in_a_stack_keeps_layers_matching():
    seed = dem.Dem(np.random.default_rng(5).normal(0, 30, (17, 17)), pixel_size_m=400.0)
    e = dem.expand(seed, 3, fractal_dimension=2.3, roughness=0.05, rng=1)
    base = dem.Dem(e.heights, Affine(50.0, 0, 0, 0, -50.0, 0), "EPSG:32633")
    s = dem.enhance({"layers": 4, "size": 65, "seed": 3,
                     "craters": ["c=0.05,k=-2,d_min_m=5,d_max_m=400"]}, dem=base)
    # layer 1 spans +-800 m, layer 2 +-400 m: this crater's reach (+-480 m) fits layer 1 only
    # and overlaps layers 2 and 3
    crater = craters.Crater(100.0, -50.0, 300.0)
    r = replace_crater(s, crater, rng=1)
    assert r.is_consistent()
    assert [np.array_equal(a.heights, b.heights) for a, b in zip(s.layers, r.layers,
                                                                  strict=True)] == \
        [False, False, False, False]
    assert r.layers[1].history[-1]["op"] == "dem.replace_crater"
    cat = r.catalogs[1]
    assert len(cat) == len(s.catalogs[1]) + 1 and cat["kind"][-1] == "replacement"
    assert cat["x_m"][-1] == 100.0 and cat["depth_m"][-1] > 20
    ids = np.concatenate([c["index"] for c in r.catalogs])
    assert len(np.unique(ids)) == len(ids)
    # a crater small enough for the finest layer goes there and changes no finer layer
    small = replace_crater(s, craters.Crater(10.0, 10.0, 20.0), rng=1)
    assert small.is_consistent() and len(small.catalogs[3]) == len(s.catalogs[3]) + 1
    with pytest.raises(ValueError, match="does not fit inside any layer"):
        replace_crater(s, craters.Crater(0.0, 0.0, 5000.0))
    with pytest.raises(ValueError, match="only for a Dem"):
        replace_crater(s, crater, frame=s.frame)
