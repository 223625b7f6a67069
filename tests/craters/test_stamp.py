"""Stamping craters into 2-D grids: closed-form checks, terrain integration, order."""

from __future__ import annotations

import hashlib
import subprocess
import sys

import numpy as np
import pytest
from scipy.ndimage import map_coordinates

import craters
from craters import Crater, stamp, stamp_many

PIX = 2.0
N = 1501
C = 750  # centre pixel


@pytest.fixture(scope="module")
def grid_r():
    yy, xx = np.mgrid[0:N, 0:N]
    return xx, yy, np.hypot(xx - C, yy - C) * PIX


def rim_radii(h, cy, cx, pixel, r_max, n_az=360):
    """Radius of the highest point along each azimuth (bilinear sampling, 0.25 m steps)."""
    r = np.arange(0.0, r_max, 0.25)
    az = np.linspace(0, 2 * np.pi, n_az, endpoint=False)
    rr, aa = np.meshgrid(r, az)
    rows = cy + rr * np.sin(aa) / pixel
    cols = cx + rr * np.cos(aa) / pixel
    vals = map_coordinates(h, [rows.ravel(), cols.ravel()], order=1).reshape(rr.shape)
    return r[np.argmax(vals, axis=1)]


def table_profile(r_over_radius, catalog, row=0):
    """The stamping kernels' profile of one crater alone: its table
    (craters.stamping_profiles) through the table lookup (tested against numpy in
    test_kernels.py), 0 beyond the ejecta edge."""
    from craters._stamp_kernels import _table_kernel

    prof = craters.stamping_profiles(catalog)
    x = np.asarray(r_over_radius, dtype=np.float64)
    out = np.empty((1, x.size))
    _table_kernel(np.ascontiguousarray(prof.tables[row:row + 1]), x.ravel(),
                  float(craters.DEFAULT_EJECTA_EDGE), out)
    return out[0].reshape(x.shape)


def test_fresh_1km_on_flat_grid(grid_r):
    _, _, r = grid_r
    h = stamp(np.zeros((N, N)), PIX, Crater(C * PIX, C * PIX, 1000.0), roughness=False)
    rim = h.max()
    depth = rim - h.min()
    assert rim == pytest.approx(36.0, rel=0.02)
    assert depth == pytest.approx(196.0, rel=0.02)
    radii = rim_radii(h, C, C, PIX, 700.0)
    assert np.abs(radii - 500.0).max() <= 4.0
    assert (h[r > 1.525 * 1000.0] == 0.0).all()
    # the kernel is the table's linear interpolation at every pixel, and the table the
    # exact profile to a small fraction of the depth
    one = craters.make_catalog(x_m=[0.0], y_m=[0.0], diameter_m=[1000.0])
    assert np.allclose(h, table_profile(r / 500.0, one), rtol=0, atol=1e-9)
    assert np.abs(h - craters.radial_profile(r / 500.0, 1000.0)).max() < 0.01 * 196.0


def test_degraded_on_tilted_plane(grid_r):
    xx, yy, r = grid_r
    g = np.tan(np.radians(20.0))
    terrain = xx * PIX * g
    h, cat = stamp(terrain, PIX, Crater(C * PIX, C * PIX, 1000.0, degradation=0.3),
                   roughness=False, return_catalog=True)
    assert np.array_equal(h[r > 1525.0], terrain[r > 1525.0])  # far field bit-for-bit
    depth = cat["depth_m"][0]
    steps = max(np.abs(np.diff(h, axis=0)).max(), np.abs(np.diff(h, axis=1)).max())
    assert steps <= 0.1 * depth
    # on ground tilted by 10 deg or more the crater is made in the plane's frame (issue
    # 36; stamped along z it was 6 % longer along the dip at 20 deg): the flat-ground
    # profile of the in-plane distance, along the plane's normal
    one = craters.make_catalog(x_m=[0.0], y_m=[0.0], diameter_m=[1000.0], degradation=[0.3])
    ln = np.hypot(g, 1.0)
    dx, dy, dz = (xx - C) * PIX, (yy - C) * PIX, h - C * PIX * g
    u, w = (dx + g * dz) / ln, (dz - g * dx) / ln
    inside = np.hypot(u, dy) < 0.98 * 500.0
    assert np.allclose(w[inside], table_profile(np.hypot(u, dy)[inside] / 500.0, one),
                       rtol=0, atol=1e-5)  # inside the rim: on the crater's surface
    # outside: the profile at the pixel's foot on the plane, over N_z, added vertically
    x_foot = np.hypot(dx * ln, dy) / 500.0
    out = (x_foot > 1.0) & (r <= 1525.0)
    assert np.allclose(h[out], terrain[out] + ln * table_profile(x_foot[out], one), rtol=0,
                       atol=1e-9)
    assert cat["degradation"][0] == pytest.approx(0.3, abs=0.01)
    assert cat["slope_deg"][0] == pytest.approx(20.0, abs=1e-6)


def test_gentle_slopes_keep_the_vertical_stamp(grid_r):
    """Below TILT_MIN_DEG (10 deg) the crater is the flat-ground profile added to the
    plane (the frames differ by < 1.5 % in distance)."""
    xx, _, r = grid_r
    terrain = xx * PIX * np.tan(np.radians(8.0))
    h = stamp(terrain, PIX, Crater(C * PIX, C * PIX, 1000.0, degradation=0.3),
              roughness=False)
    one = craters.make_catalog(x_m=[0.0], y_m=[0.0], diameter_m=[1000.0], degradation=[0.3])
    assert np.allclose(h, terrain + table_profile(r / 500.0, one), rtol=0, atol=1e-6)


def test_steep_slope_erodes_more():
    yy, xx = np.mgrid[0:301, 0:301]
    out = []
    for slope_deg in (10.0, 35.0):
        terrain = xx * 1.0 * np.tan(np.radians(slope_deg))
        _, cat = stamp(terrain, 1.0, Crater(150.0, 150.0, 60.0, degradation=0.1),
                       roughness=False, return_catalog=True)
        out.append(cat[0])
    assert out[0]["degradation"] == pytest.approx(0.1, abs=0.01)
    assert out[1]["degradation"] > 0.5 and out[1]["depth_m"] < out[0]["depth_m"]
    # slope erosion d' = d + (1 - d) s, s = (35 - 20) / (45 - 20)
    assert out[1]["degradation"] == pytest.approx(0.1 + 0.9 * 0.6, abs=0.01)
    _, cat = stamp(xx * np.tan(np.radians(35.0)), 1.0, Crater(150.0, 150.0, 60.0, 0.1),
                   roughness=False, return_catalog=True, slope_erosion=False)
    assert cat["degradation"][0] == pytest.approx(0.1, abs=0.01)


def test_rough_terrain_no_steps_and_far_field(rng):
    n = 401
    base = np.cumsum(np.cumsum(rng.standard_normal((n, n)), 0), 1) * 0.01
    h = stamp(base, 1.0, Crater(200.0, 200.0, 120.0, degradation=0.2), rng=3)
    yy, xx = np.mgrid[0:n, 0:n]
    r = np.hypot(xx - 200, yy - 200)
    reach = 120 * 1.5 * 1.02 + 1
    assert np.array_equal(h[r > reach], base[r > reach])
    changed = h != base
    assert changed[r < 60].all()


def test_age_order_young_on_top():
    # overlapping, each on the other's gentle outer flank (< 10 deg: stamped along z, so
    # a symmetric second difference shows the profile; on a wall it is tilted, issue 36)
    cat = craters.make_catalog(x_m=[100.0, 150.0], y_m=[100.0, 100.0],
                               diameter_m=[80.0, 60.0], age_gyr=[1.0, 2.0])

    def bowl_intact(h, cx, diameter):
        # symmetric second differences cancel the fitted plane: a crater stamped last
        # shows exactly its profile's curvature around its centre
        k = 10
        got = h[100, cx + k] + h[100, cx - k] - 2 * h[100, cx]
        one = craters.make_catalog(x_m=[0.0], y_m=[0.0], diameter_m=[diameter])
        p = table_profile(np.array([0.0, k / (diameter / 2)]), one)
        return abs(got - 2 * (p[1] - p[0])) < 1e-9

    h = stamp_many(np.zeros((201, 201)), 1.0, cat, roughness=False, slope_erosion=False)
    assert bowl_intact(h, 100, 80.0) and not bowl_intact(h, 150, 60.0)
    swapped = cat.copy()
    swapped["age_gyr"] = [2.0, 1.0]
    h2 = stamp_many(np.zeros((201, 201)), 1.0, swapped, roughness=False, slope_erosion=False)
    assert bowl_intact(h2, 150, 60.0) and not bowl_intact(h2, 100, 80.0)


def test_stamped_catalog_and_determinism():
    cat = craters.power_law_population(c=0.05, k=-2.0, d_min=6.0, d_max=60.0,
                                       x_range=(0, 400), y_range=(0, 400), rng=5)
    h1, s1 = stamp_many(np.zeros((401, 401)), 1.0, cat, rng=8, return_catalog=True)
    h2 = stamp_many(np.zeros((401, 401)), 1.0, cat, rng=8)
    h3 = stamp_many(np.zeros((401, 401)), 1.0, cat, rng=9)
    assert np.array_equal(h1, h2) and not np.array_equal(h1, h3)
    assert len(s1) == len(cat)
    assert (np.diff(s1["age_gyr"]) <= 0).all()
    assert np.allclose(s1["rim_radius_m"], s1["diameter_m"] / 2)
    assert set(s1.dtype.names) >= {"depth_m", "rim_height_m", "slope_deg", "seed"}


def test_thread_count_does_not_change_the_result():
    code = (
        "import numpy as np, hashlib, craters\n"
        "cat = craters.power_law_population(c=0.05, k=-2.0, d_min=6.0, d_max=80.0,"
        " x_range=(0, 300), y_range=(0, 300), rng=5)\n"
        "h = craters.stamp_many(np.zeros((301, 301)), 1.0, cat, rng=1)\n"
        "print(hashlib.sha256(h.tobytes()).hexdigest())\n")
    digests = set()
    for threads in ("1", "2"):
        env = {"NUMBA_NUM_THREADS": threads, "PATH": ""}
        out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                             env=env, check=True)
        digests.add(out.stdout.strip())
    assert len(digests) == 1
    assert len(hashlib.sha256(b"").hexdigest()) == len(digests.pop())


def test_roughness_and_irregular_rim():
    n = 601
    smooth = stamp(np.zeros((n, n)), 1.0, Crater(300.0, 300.0, 300.0), roughness=False)
    rough = stamp(np.zeros((n, n)), 1.0, Crater(300.0, 300.0, 300.0, irregularity=0.05),
                  rng=2)
    diff = rough - smooth
    assert np.abs(diff).max() > 1.0
    radii = rim_radii(rough, 300, 300, 1.0, 250.0)
    assert radii.std() > 1.0 and np.abs(radii - 150.0).max() <= 0.05 * 150 + 3
    yy, xx = np.mgrid[0:n, 0:n]
    r = np.hypot(xx - 300, yy - 300)
    assert (rough[r > 450 * 1.05 + 1] == 0).all()


def test_craters_on_ground_steeper_than_full_deg_are_erased():
    yy, xx = np.mgrid[0:201, 0:201]
    terrain = xx * np.tan(np.radians(50.0))
    h, cat = stamp(terrain, 1.0, Crater(100.0, 100.0, 30.0), return_catalog=True)
    assert np.array_equal(h, terrain) and len(cat) == 0
    h, cat = stamp(terrain, 1.0, Crater(100.0, 100.0, 30.0), return_catalog=True,
                   slope_erosion=False)
    assert not np.array_equal(h, terrain) and len(cat) == 1


def test_crater_partly_outside_the_grid():
    h = stamp(np.zeros((50, 50)), 1.0, Crater(0.0, 0.0, 40.0))
    assert np.isfinite(h).all() and h.min() < 0
    h = stamp(np.zeros((50, 50)), 1.0, Crater(-500.0, -500.0, 40.0))
    assert (h == 0).all()


def test_input_not_modified():
    base = np.zeros((60, 60))
    stamp(base, 1.0, Crater(30.0, 30.0, 20.0))
    assert (base == 0).all()


@pytest.mark.parametrize("args,match", [
    ((np.zeros((0, 5)), 1.0), "heights"),
    ((np.zeros(5), 1.0), "heights"),
    ((np.full((5, 5), np.nan), 1.0), "heights"),
    ((np.zeros((5, 5)), 0.0), "pixel_size_m"),
    ((np.zeros((5, 5)), -1.0), "pixel_size_m"),
])
def test_bad_grids(args, match):
    with pytest.raises(ValueError, match=match):
        stamp(*args, Crater(1.0, 1.0, 2.0))


@pytest.mark.parametrize("kw,match", [({"diameter_m": -1.0}, "diameter_m"),
                                      ({"diameter_m": np.nan}, "diameter_m"),
                                      ({"degradation": 2.0}, "degradation"),
                                      ({"x_m": np.inf}, "x_m")])
def test_bad_craters(kw, match):
    with pytest.raises(ValueError, match=match):
        Crater(**({"x_m": 1.0, "y_m": 1.0, "diameter_m": 2.0} | kw))


def test_bad_catalogs():
    sphere = craters.make_catalog(lat_deg=[0.0], lon_deg=[0.0], diameter_m=[5.0])
    with pytest.raises(ValueError, match="x_m"):
        stamp_many(np.zeros((5, 5)), 1.0, sphere)
    with pytest.raises(TypeError, match="structured"):
        stamp_many(np.zeros((5, 5)), 1.0, np.zeros(3))


def test_rim_perturbations_match_the_harmonic_sum():
    from craters.stamp import _HARMONICS

    got = craters.rim_perturbations(7, 0.03, rng=4)
    phases = np.random.default_rng(4).uniform(0, 2 * np.pi, (7, _HARMONICS.size))
    theta = -np.pi + 2 * np.pi * np.arange(64) / 64
    ref = np.einsum("k,nkt->nt", _HARMONICS.astype(float) ** -1.5,
                    np.cos(_HARMONICS[None, :, None] * theta[None, None, :] + phases[:, :, None]))
    ref *= 0.03 / np.abs(ref).max(axis=1, keepdims=True)
    assert np.allclose(got, ref, rtol=0, atol=1e-15)
    assert np.allclose(np.abs(got).max(axis=1), 0.03)
