"""3-D Gabor noise and its fit to a 2-D example (Li 2020 §3.2, Galerne et al. 2012)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from latlong.implicit import (
    GaborNoise,
    GaborPatch,
    LcsnLayer,
    VoxelGrid,
    fit_gabor,
    gabor_image,
    implicit_surface,
    parse_gabor_spec,
    power_spectrum,
    read_example,
)
from latlong.implicit import _kernels as K
from latlong.shapes import ShapeModel

DATA = Path(__file__).parents[1] / "data"


def gabor_reference(points, pos, wave, env, amp, phase, cutoff2):
    out = np.zeros(len(points))
    for q in range(len(pos)):
        x = points - pos[q]
        r2 = (x * x).sum(1)
        val = amp[q] * np.exp(-np.pi * env[q] ** 2 * r2) * np.cos(2 * np.pi * x @ wave[q] +
                                                                  phase[q])
        out += np.where(r2 * env[q] ** 2 < cutoff2, val, 0.0)
    return out


def radial_log_power(image, pixel_m, n_bins=12):
    """log10 of the periodogram summed in logarithmic rings of frequency."""
    power, fx, fy = power_spectrum(image, pixel_m)
    r = np.hypot(*np.meshgrid(fx, fy)) * pixel_m
    edges = np.geomspace(1 / min(image.shape), 0.5, n_bins + 1)
    idx = np.digitize(r.ravel(), edges)
    return np.log10([power.ravel()[idx == i].sum() for i in range(1, n_bins + 1)])


def test_grid_kernel_matches_reference(rng):
    n = 40
    pos = rng.uniform(0, 10, (n, 3))
    wave = rng.normal(size=(n, 3)) * 0.3
    env = rng.uniform(0.2, 0.6, n)
    amp = rng.uniform(0.5, 2.0, n)
    phase = rng.uniform(0, 2 * np.pi, n)
    cutoff2 = math.log(1e3) / math.pi
    grid = VoxelGrid(np.array([-1.0, 0.0, 1.0]), 0.4, (30, 31, 32))
    base = rng.uniform(-2, 2, grid.shape)
    lo, hi = grid.index_boxes(pos, math.sqrt(cutoff2) / env)
    nbins, offsets, items, active = grid.bins(lo, hi)
    out = np.zeros(grid.shape)
    K._gabor_grid_kernel(grid.origin, grid.h, active, grid.bin_size, nbins, offsets, items, lo,
                         hi, pos, wave, env, amp, phase, cutoff2, base, 1.0, out)
    k, j, i = np.meshgrid(*(np.arange(m) for m in grid.shape), indexing="ij")
    pts = grid.origin + np.stack([i, j, k], -1).reshape(-1, 3) * grid.h
    want = gabor_reference(pts, pos, wave, env, amp, phase, cutoff2)
    near = np.abs(base.ravel()) < 1.0
    np.testing.assert_allclose(out.ravel()[near], want[near], rtol=1e-10, atol=1e-12)
    assert (out.ravel()[~near] == 0).all() and np.abs(want[near]).max() > 0.5
    point = np.empty(len(pts))
    K._gabor_points_kernel(pts, pos, wave, env, amp, phase, cutoff2, point)
    np.testing.assert_allclose(point, want, rtol=1e-10, atol=1e-12)


@pytest.mark.parametrize("density", [4.0, 16.0])
def test_amplitude_is_the_rms(density):
    img = gabor_image(GaborNoise.single(0.1, 0.1, 2.5, density=density), (256, 256), 1.0,
                      rng=1)
    assert img.std() == pytest.approx(2.5, rel=0.05)
    assert abs(img.mean()) < 0.1


def test_spectrum_has_the_patch():
    noise = GaborNoise.single(0.125, 0.02, 1.0, orientation_deg=60.0, density=8.0)
    power, fx, fy = power_spectrum(gabor_image(noise, (256, 256), 1.0, rng=2), 1.0)
    i, j = np.unravel_index(np.argmax(power), power.shape)
    f, angle = math.hypot(fx[j], fy[i]), math.degrees(math.atan2(fy[i], fx[j])) % 180
    assert f == pytest.approx(0.125, abs=0.01) and angle == pytest.approx(60, abs=5)
    iso = gabor_image(GaborNoise.single(0.125, 0.02, 1.0, density=8.0), (256, 256), 1.0,
                      rng=2)
    power, fx, fy = power_spectrum(iso, 1.0)
    r = np.hypot(*np.meshgrid(fx, fy))
    ring = power[np.abs(r - 0.125) < 0.02].mean()
    assert ring > 20 * power[np.abs(r - 0.3) < 0.02].mean()  # isotropic: a ring at f


@pytest.mark.parametrize("n_frequencies", [12, 24])
def test_fit_recovers_a_single_patch(n_frequencies):
    truth = GaborNoise.single(1 / 12, 1 / 48, 2.0, orientation_deg=30.0, density=8.0)
    img = gabor_image(truth, (256, 256), 1.0, rng=1)
    fit = fit_gabor(img, 1.0, n_frequencies=n_frequencies)
    top = max(fit.patches, key=lambda p: p.weight)
    assert top.frequency == pytest.approx(1 / 12, rel=0.05)
    assert top.orientation_deg == pytest.approx(30.0, abs=1e-9)
    assert top.bandwidth == pytest.approx(1 / 48, rel=0.01)
    assert top.weight / sum(p.weight for p in fit.patches) > 0.5
    assert fit.amplitude_m == pytest.approx(img.std())


def test_fit_two_orientations_and_pixel_size():
    truth = GaborNoise((GaborPatch(0.1, 0.02, 0.0), GaborPatch(0.04, 0.015, 90.0)), 1.0, 8.0)
    img = gabor_image(truth, (256, 256), 1.0, rng=3)
    fit = fit_gabor(img, 1.0)
    by_angle = {}
    for p in fit.patches:
        if p.orientation_deg is not None:
            key = round(p.orientation_deg) % 180
            by_angle[key] = by_angle.get(key, 0.0) + p.weight
    top2 = sorted(by_angle, key=by_angle.get)[-2:]
    assert sorted(top2) == [0, 90]
    scaled = fit_gabor(img, 20.0)  # 20 m pixels: the same patches, frequencies / 20
    assert [p.frequency * 20 for p in scaled.patches] == pytest.approx(
        [p.frequency for p in fit.patches])


def test_fit_a_real_dem_by_example():
    """LOLA LDEM_4 crop (7.6 km pixels): the fitted noise has the example's rms and its
    spectrum in every logarithmic frequency ring within a factor of 10 (measured: mean
    |log10 ratio| 0.33)."""
    import dem

    d = dem.read(DATA / "ldem4_crop.lbl")
    z, px = d.heights, float(np.mean(d.pixel_size_m))
    fit = fit_gabor(z, px)
    syn = gabor_image(fit, z.shape, px, rng=1)
    assert syn.std() == pytest.approx(z.std(), rel=0.15)
    diff = radial_log_power(syn, px) - radial_log_power(z, px)
    assert np.abs(diff).mean() < 0.5 and np.abs(diff).max() < 1.0, diff.round(2)
    linear = fit_gabor(z, px, weighting="linear")
    lin = radial_log_power(gabor_image(linear, z.shape, px, rng=1), px)
    assert (lin - radial_log_power(z, px))[-2:].max() < -0.5  # linear LS drops the top


def test_noise_on_an_implicit_surface():
    """On a metaball sphere the noise moves the surface by about its rms."""
    import pyvista as pv

    s = pv.Sphere(radius=100.0, theta_resolution=64, phi_resolution=64)
    model = ShapeModel(np.asarray(s.points, float), s.faces.reshape(-1, 4)[:, 1:].astype(int))
    kw = {"voxel_m": 2.0, "packing_voxels": 32, "rng": 4}
    bare = implicit_surface(model, **kw)
    noisy = implicit_surface(model, gabor=GaborNoise.single(1 / 12, 1 / 24, 1.5), **kw)
    moved = pv.PolyData(noisy.vertices).compute_implicit_distance(bare.to_pyvista())
    offset = np.asarray(moved["implicit_distance"])  # signed, from the noise-free surface
    assert offset.std() == pytest.approx(1.5, rel=0.2)
    assert abs(offset.mean()) < 0.3
    assert noisy.metadata["gabor"]["impulses"] > 1000 and noisy.is_watertight()
    with_craters = implicit_surface(model, [LcsnLayer("fig6-kernel3", 20, 40)],
                                    gabor=GaborNoise.single(1 / 12, 1 / 24, 1.5), **kw)
    assert with_craters.is_watertight() and len(with_craters.catalog) > 0


# --------------------------------------------------------------------------- errors
@pytest.mark.parametrize("call,match", [
    (lambda: GaborPatch(-0.1, 0.1), "`frequency`"),
    (lambda: GaborPatch(0.1, 0.0), "`bandwidth`"),
    (lambda: GaborPatch(0.1, 0.1, 400.0), "`orientation_deg`"),
    (lambda: GaborNoise((), 1.0), "`patches`"),
    (lambda: GaborNoise.single(0.1, 0.1, -1.0), "`amplitude_m`"),
    (lambda: GaborNoise.single(0.1, 0.1, 1.0, density=0.0), "`density`"),
    (lambda: power_spectrum(np.zeros((8, 8)), 1.0), "`image`"),
    (lambda: power_spectrum(np.full((32, 32), np.nan), 1.0), "`image`"),
    (lambda: fit_gabor(np.zeros((32, 32)), -1.0), "`pixel_m`"),
    (lambda: fit_gabor(np.random.default_rng(0).random((32, 32)), 1.0, weighting="log"),
     "`weighting`"),
    (lambda: fit_gabor(np.zeros((32, 32)), 1.0), "no variance"),
    (lambda: gabor_image(GaborNoise.single(0.1, 0.1, 1.0), (0, 4), 1.0), "`shape`"),
    (lambda: parse_gabor_spec("frequency=0.1,bandwidth=0.1"), "missing amplitude_m"),
    (lambda: parse_gabor_spec("frequency=0.1,bandwidth=x,amplitude_m=1"),
     "bandwidth must be a number"),
    (lambda: parse_gabor_spec("frequency=0.1,bandwidth=0.1,amplitude_m=1,q=2"), "unknown item"),
])
def test_bad_input(call, match):
    with pytest.raises(ValueError, match=match):
        call()


def test_read_example(tmp_path):
    from PIL import Image

    z = np.random.default_rng(0).normal(size=(40, 50))
    np.save(tmp_path / "z.npy", z)
    img, heights = read_example(tmp_path / "z.npy")
    assert heights and np.array_equal(img, z)
    Image.fromarray((np.clip(z + 3, 0, 6) * 40).astype(np.uint8)).save(tmp_path / "z.png")
    img, heights = read_example(tmp_path / "z.png")
    assert not heights and img.shape == (40, 50) and 0 <= img.min() <= img.max() <= 1
    for name, match, kind in (("missing.npy", "does not exist", FileNotFoundError),
                              ("z.txt", "unknown format", ValueError)):
        (tmp_path / "z.txt").write_text("1 2")
        with pytest.raises(kind, match=match):
            read_example(tmp_path / name)
    np.save(tmp_path / "v.npy", np.zeros(5))
    with pytest.raises(ValueError, match="2-D"):
        read_example(tmp_path / "v.npy")
