"""Boulders on DEMs: kernels against numpy references, placement, stamping, stacks, CLI."""

from __future__ import annotations

import json

import numpy as np
import pytest
from affine import Affine
from scipy.interpolate import RegularGridInterpolator

import craters
import dem
from craters.boulders import boulder_world_meshes
from dem._boulder_kernels import _bilinear_kernel, _raster_max_kernel


def test_bilinear_kernel_matches_scipy():
    rng = np.random.default_rng(0)
    z = rng.normal(size=(13, 17))
    cols = rng.uniform(-1, 17, 500)
    rows = rng.uniform(-1, 13, 500)
    out = np.empty(500)
    _bilinear_kernel(z, cols, rows, out)
    inside = (cols >= 0) & (cols <= 16) & (rows >= 0) & (rows <= 12)
    ref = RegularGridInterpolator((np.arange(13), np.arange(17)), z)(
        np.stack([rows[inside], cols[inside]], 1))
    assert np.allclose(out[inside], ref, rtol=1e-12, atol=1e-12)
    assert np.isnan(out[~inside]).all()


def reference_raster_max(z, verts, faces):
    """Pure numpy: for every triangle, the barycentric height at the pixel centres of its
    bounding box; each pixel keeps the maximum."""
    out = z.copy()
    rows, cols = z.shape
    for v in verts:
        tri = v[faces]  # (F, 3, 3)
        for (x0, y0, z0), (x1, y1, z1), (x2, y2, z2) in tri:
            det = (x1 - x0) * (y2 - y0) - (x2 - x0) * (y1 - y0)
            if det == 0:
                continue
            c_lo, c_hi = max(int(np.ceil(min(x0, x1, x2))), 0), min(int(np.floor(max(
                x0, x1, x2))), cols - 1)
            r_lo, r_hi = max(int(np.ceil(min(y0, y1, y2))), 0), min(int(np.floor(max(
                y0, y1, y2))), rows - 1)
            if c_lo > c_hi or r_lo > r_hi:
                continue
            rr, cc = np.mgrid[r_lo:r_hi + 1, c_lo:c_hi + 1]
            w1 = ((cc - x0) * (y2 - y0) - (x2 - x0) * (rr - y0)) / det
            w2 = ((x1 - x0) * (rr - y0) - (cc - x0) * (y1 - y0)) / det
            w0 = 1 - w1 - w2
            inside = (w0 >= -1e-12) & (w1 >= -1e-12) & (w2 >= -1e-12)
            h = w0 * z0 + w1 * z1 + w2 * z2
            win = out[r_lo:r_hi + 1, c_lo:c_hi + 1]
            out[r_lo:r_hi + 1, c_lo:c_hi + 1] = np.where(inside & (h > win), h, win)
    return out


def test_raster_max_kernel_matches_numpy_reference():
    v, faces = craters.boulder_meshes([3, 4], craters.BoulderShape(n_levels=2))
    f = faces[1]
    verts = v[:, :42] * 9.0 + np.array([[[10.0, 8.0, 1.0]], [[14.0, 12.0, 0.5]]])
    z = np.random.default_rng(1).normal(0, 0.3, (24, 26))
    got = z.copy()
    _raster_max_kernel(got, np.ascontiguousarray(verts), f.astype(np.int64))
    want = reference_raster_max(z, verts, f)
    assert np.array_equal(got, want)
    assert (got > z).sum() > 50


@pytest.fixture(scope="module")
def slope_dem():
    """A north-up projected DEM: tilted plane (12 % to the east) with bumps, 0.25 m."""
    n = 161
    rng = np.random.default_rng(2)
    y, x = np.mgrid[0:n, 0:n] * 0.25
    z = 0.12 * x + 0.3 * np.sin(x / 3.0) * np.cos(y / 4.0) + rng.normal(0, 0.01, (n, n))
    return dem.Dem(z, Affine(0.25, 0, 500000.0, 0, -0.25, 4000000.0), "EPSG:32633")


@pytest.fixture(scope="module")
def stamped(slope_dem):
    cat = dem.boulder_population(slope_dem, "c=0.02,k=-3,d_min_m=0.6,d_max_m=6,burial_max=0.5",
                                 rng=4)
    before = slope_dem.heights.copy()
    out, placed = dem.stamp_boulders(slope_dem, cat, return_catalog=True)
    assert np.array_equal(slope_dem.heights, before)  # input untouched
    return cat, out, placed


def to_pixels(a, x, y):
    """Local-frame points -> fractional (col, row) through the inverse pixel affine."""
    inv = ~a
    x, y = np.asarray(x), np.asarray(y)
    return inv.a * x + inv.b * y + inv.c, inv.d * x + inv.e * y + inv.f


def local_ground(d, x, y):
    """Bilinear height of the original DEM at local-frame points (independent path)."""
    frame = dem.local_frame(d)
    a = dem.frame.pixel_affine(d, frame)
    col, row = to_pixels(a, x, y)
    rows, cols = d.shape
    return RegularGridInterpolator((np.arange(rows), np.arange(cols)), d.heights,
                                   bounds_error=False)(np.stack([row, col], -1))


def test_placement_burial_and_nothing_floats(slope_dem, stamped):
    cat, out, placed = stamped
    assert len(placed) > 100
    size = placed["diameter_m"]
    nv = 642
    verts, _ = boulder_world_meshes(placed)
    verts = verts.reshape(len(placed), nv, 3)
    nrm = np.stack([placed["normal_x"], placed["normal_y"], placed["normal_z"]], 1)
    ground = local_ground(slope_dem, verts[..., 0], verts[..., 1])
    depth = (ground - verts[..., 2]) * nrm[:, 2:3]
    deepest = depth.max(axis=1)
    assert np.all(np.abs(deepest - placed["burial_m"]) <= 0.05 * size)
    assert (deepest > 0).all()
    assert np.allclose(placed["burial_m"], placed["burial_frac"] * placed["height_m"])
    assert np.allclose(placed["top_m"], verts[..., 2].max(axis=1))
    # the ground tilts 12 % to the east: the boulders lean with it
    assert np.allclose(np.median(-placed["normal_x"] / placed["normal_z"]), 0.12, atol=0.03)
    assert abs(np.median(placed["normal_y"])) < 0.03


def test_stamp_is_the_heightfield_maximum_of_the_meshes(slope_dem, stamped):
    """The stamped raster equals max(ground, the boulder meshes' tops) at pixel centres,
    recomputed from the catalog's meshes in the local frame (checks the frames)."""
    cat, out, placed = stamped
    verts, faces = boulder_world_meshes(placed)
    frame = dem.local_frame(slope_dem)
    a = dem.frame.pixel_affine(slope_dem, frame)
    col, row = to_pixels(a, verts[:, 0], verts[:, 1])
    pix = np.stack([col, row, verts[:, 2]], 1).reshape(len(placed), -1, 3)
    f = faces[: len(faces) // len(placed)]
    want = reference_raster_max(slope_dem.heights, pix, f)
    assert (want != slope_dem.heights).sum() > 500
    assert np.allclose(out.heights, want, rtol=0, atol=1e-9)
    # everywhere: heights only rise, and only under boulders
    diff = out.heights - slope_dem.heights
    assert diff.min() >= 0
    assert (diff > 0).sum() > 0
    hist = out.history[-1]
    assert hist["op"] == "dem.stamp_boulders"
    p = hist["parameters"]
    assert p["boulders"] == len(placed)
    assert p["given"] == len(cat) == p["boulders"] + p["unresolved"] + p["off_grid_or_unknown"]


def test_small_off_grid_and_unknown_boulders_are_left_out(slope_dem):
    cat = craters.make_catalog(x_m=[0.0, 0.0, 19.9, 5.0], y_m=[0.0, 0.0, 0.0, 5.0],
                               diameter_m=[0.3, 2.0, 2.0, 2.0], burial_frac=[0.2] * 4,
                               azimuth_deg=[0.0] * 4,
                               seed=np.array([1, 2, 3, 4], dtype=np.uint64))
    out, placed = dem.stamp_boulders(slope_dem, cat, return_catalog=True)
    assert list(placed["seed"]) == [2, 4]  # 0.3 m < 2 px; 19.9 m is at the edge
    z = slope_dem.heights.copy()
    z[60:70, 95:105] = np.nan  # under the boulder at (5, 5)
    holey = slope_dem.replace(heights=z)
    out2, placed2 = dem.stamp_boulders(holey, cat, return_catalog=True)
    assert list(placed2["seed"]) == [2]
    assert np.array_equal(np.isnan(out2.heights), np.isnan(z))
    p = out2.history[-1]["parameters"]
    assert (p["unresolved"], p["off_grid_or_unknown"]) == (1, 2)
    with pytest.raises(ValueError, match="burial_frac"):
        dem.stamp_boulders(slope_dem, craters.make_catalog(x_m=[0.0], y_m=[0.0],
                                                           diameter_m=[1.0]))
    with pytest.raises(ValueError, match="min_px"):
        dem.stamp_boulders(slope_dem, cat, min_px=-1)
    with pytest.raises(TypeError, match="dem"):
        dem.stamp_boulders(z, cat)


def test_population_law_and_determinism(slope_dem):
    layer = craters.BoulderLayer(c=0.05, k=-2.8, d_min_m=0.5, d_max_m=10)
    a = dem.boulder_population(slope_dem, layer, rng=7)
    b = dem.boulder_population(slope_dem, layer, rng=7)
    assert a.tobytes() == b.tobytes()
    area = (160 * 0.25) ** 2
    mean = area * layer.c * (layer.d_min_m**layer.k - layer.d_max_m**layer.k)
    assert abs(len(a) - mean) < 4 * np.sqrt(mean)
    k_fit = craters.fit_power_law_exponent(a["diameter_m"], 0.5, 10)
    assert abs(k_fit / layer.k - 1) < 0.05
    frame = dem.local_frame(slope_dem)
    assert a["x_m"].min() >= -20.01 and a["x_m"].max() <= 20.01
    oa = dem.stamp_boulders(slope_dem, a, frame=frame)
    ob = dem.stamp_boulders(slope_dem, b, frame=frame)
    assert oa.heights.tobytes() == ob.heights.tobytes()


@pytest.fixture(scope="module")
def rocky_stack():
    seed = dem.Dem(np.random.default_rng(3).normal(0, 2, (17, 17)), pixel_size_m=16.0)
    e = dem.expand(seed, 2, fractal_dimension=2.3, roughness=0.05, rng=1)
    base = dem.Dem(e.heights, Affine(4.0, 0, 400000.0, 0, -4.0, 3000000.0), "EPSG:32633")
    return dem.enhance({"layers": 5, "size": 65, "seed": 3,
                        "craters": ["c=0.05,k=-2,d_min_m=1,d_max_m=60"],
                        "boulders": ["c=0.02,k=-3,d_min_m=0.3,d_max_m=12"]}, dem=base)


def test_enhance_with_boulders(rocky_stack, tmp_path):
    s = rocky_stack
    assert s.is_consistent()
    b = s.info["boulders"]
    assert b["drawn"] == sum(b["stamped"]) + sum(b["off_grid"]) + b["rejected"]
    assert sum(b["stamped"]) > 50
    ids = np.concatenate([c["index"] for c in s.boulders])
    assert len(np.unique(ids)) == len(ids)
    sizes = s.pixel_sizes_m()
    for k, cat in enumerate(s.boulders):
        assert (cat["diameter_m"] >= 2.0 * sizes[k] - 1e-9).all()  # resolved by its layer
    s.write(tmp_path / "st")
    back = dem.read_stack(tmp_path / "st")
    man = json.loads((tmp_path / "st" / "manifest.json").read_text())
    for k in range(len(s)):
        assert man["layers"][k]["boulders"]["stamped"] == len(s.boulders[k])
        assert np.allclose(back.boulders[k]["centre_z_m"], s.boulders[k]["centre_z_m"])
        assert np.array_equal(back.boulders[k]["seed"], s.boulders[k]["seed"])


def boulders_shown(stack, k):
    """For each boulder of layer k: the pixel centres it covers and its top surface there
    (the exact heightfield of its mesh, numpy reference)."""
    cat = stack.boulders[k]
    a = dem.frame.pixel_affine(stack.layers[k], stack.frame)
    verts, faces = boulder_world_meshes(cat)
    col, row = to_pixels(a, verts[:, 0], verts[:, 1])
    pix = np.stack([col, row, verts[:, 2]], 1).reshape(len(cat), -1, 3)
    f = faces[: len(faces) // len(cat)]
    empty = np.full(stack.layers[k].shape, -np.inf)
    for one in pix:
        shown = reference_raster_max(empty, one[None], f)
        covered = np.isfinite(shown)
        yield covered, shown[covered]


def test_every_boulder_shows_in_its_layer(rocky_stack):
    """Each boulder covers some pixel centre of its layer and the layer is at least its
    top surface there. Exactly so in a stack without craters (later layers only add RMD
    detail at odd pixels and boulders, both through a maximum) and in the finest layer of
    the cratered stack; in its coarser layers the smaller craters of finer layers, stamped
    later, are superposed on everything, boulders included (the synchronisation carries
    them up), so there a boulder can be dented by a younger crater."""
    seed = dem.Dem(np.random.default_rng(3).normal(0, 2, (17, 17)), pixel_size_m=16.0)
    e = dem.expand(seed, 2, fractal_dimension=2.3, roughness=0.05, rng=1)
    base = dem.Dem(e.heights, Affine(4.0, 0, 400000.0, 0, -4.0, 3000000.0), "EPSG:32633")
    bare = dem.enhance({"layers": 5, "size": 65, "seed": 3,
                        "boulders": ["c=0.02,k=-3,d_min_m=0.3,d_max_m=12"]}, dem=base)
    checked = 0
    for stack, layers in ((bare, range(5)), (rocky_stack, [4])):
        for k in layers:
            z = stack.layers[k].heights
            for covered, top in boulders_shown(stack, k):
                assert covered.any()
                assert (z[covered] >= top - 1e-9).all()
                checked += 1
    assert checked > 60


def test_mesh_with_boulders(rocky_stack, tmp_path):
    import pyvista as pv

    s = rocky_stack
    n_rocks = sum(len(c) for c in s.boulders)
    plain = dem.to_mesh(s, tmp_path / "plain.vtp", boulders=False)
    rocky = dem.to_mesh(s, tmp_path / "rocky.vtp")
    mp, mr = pv.read(plain), pv.read(rocky)
    assert mr.n_points == mp.n_points + 642 * n_rocks
    assert mr.n_cells == mp.n_cells + 1280 * n_rocks
    ids = mr.point_data["boulder_id"]
    assert (ids[:mp.n_points] == -1).all()
    verts, _ = boulder_world_meshes(np.concatenate([c for c in s.boulders if len(c)]))
    assert np.allclose(mr.points[mp.n_points:], verts, atol=1e-3)
    ply = dem.to_mesh(s, tmp_path / "rocky.ply")
    raw = ply.read_bytes()
    head = raw[:raw.index(b"end_header")]
    assert b"property int boulder_id" in head
    import trimesh

    t = trimesh.load(ply, process=False)
    assert len(t.vertices) == mr.n_points and t.is_winding_consistent


def test_cli_enhance_boulders_same_bytes_any_thread_count(run_cli, tmp_path, rocky_stack,
                                                          one_line_error):
    src = tmp_path / "base.tif"
    dem.write(rocky_stack.layers[0], src)
    digests = {}
    for tag, env in (("a", {}), ("t1", {"NUMBA_NUM_THREADS": "1"})):
        out = tmp_path / tag
        proc = run_cli("dem", "enhance", str(src), "-o", str(out), "--layers", "4",
                       "--size", "33", "--boulders", "c=0.02,k=-3,d_min_m=0.5,d_max_m=8",
                       "--seed", "2", "-q", env=env)
        assert proc.returncode == 0, proc.stderr
        digests[tag] = {p.name: p.read_bytes() for p in sorted(out.iterdir())}
        mesh = run_cli("dem", "mesh", str(out / "manifest.json"), "-o", str(out / "m.ply"), "-q",
                       env=env)
        assert mesh.returncode == 0, mesh.stderr
        digests[tag]["m.ply"] = (out / "m.ply").read_bytes()
    assert digests["a"] == digests["t1"]
    assert any(n.startswith("boulders_") for n in digests["a"])
    bad = run_cli("dem", "enhance", str(src), "-o", str(tmp_path / "x"),
                  "--boulders", "c=0.02,k=3,d_min_m=0.5,d_max_m=8", cwd=tmp_path)
    one_line_error(bad, "--boulders", "`k`")
    bad = run_cli("dem", "enhance", str(src), "-o", str(tmp_path / "x"),
                  "--boulders", "c=0.02,k=-3,d_min_m=0.5,d_max_m=8", "--min-boulder-px", "0.5",
                  cwd=tmp_path)
    one_line_error(bad, "--min-boulder-px", "[1,")
    assert not (tmp_path / "x").exists()


def reference_window_gradients(z, p, r0, r1, c0, c1):
    """Pure numpy: numpy.gradient with unknown pixels as 0, averaged over each window
    through summed-area tables."""
    g_row, g_col = np.gradient(np.where(np.isnan(z), 0.0, z), p)
    out = np.empty((len(r0), 2))
    for k, g in enumerate((g_col, g_row)):
        sat = np.zeros((z.shape[0] + 1, z.shape[1] + 1))
        sat[1:, 1:] = g.cumsum(0).cumsum(1)
        out[:, k] = (sat[r1, c1] - sat[r0, c1] - sat[r1, c0] + sat[r0, c0]) / (
            (r1 - r0) * (c1 - c0))
    return out


def test_window_gradient_kernel_matches_numpy_reference():
    from dem._boulder_kernels import _window_gradient_kernel

    rng = np.random.default_rng(5)
    z = rng.normal(0, 1, (23, 31)).cumsum(0)
    z[4, 7] = z[0, 30] = z[22, 3] = np.nan
    r0 = np.array([0, 3, 10, 21, 0, 5], np.int64)
    r1 = np.array([23, 6, 11, 23, 1, 9], np.int64)
    c0 = np.array([0, 5, 29, 0, 30, 2], np.int64)
    c1 = np.array([31, 10, 31, 4, 31, 3], np.int64)
    got = np.empty((len(r0), 2))
    _window_gradient_kernel(z, ~np.isnan(z), 0.7, r0, r1, c0, c1, got)
    want = reference_window_gradients(z, 0.7, r0, r1, c0, c1)
    assert np.allclose(got, want, rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize("amp", [0.3, 1.0])
def test_extremely_rough_ground_settles_or_is_left_out(amp):
    """White-noise ground (slopes up to ~80 degrees between 0.25 m pixels): each placed
    boulder reaches its burial exactly and its catalog depth is the one it has; those
    whose points leave the raster while settling are left out and counted."""
    z = np.random.default_rng(5).normal(0, amp, (201, 201))
    d0 = dem.Dem(z, Affine(0.25, 0, 500000.0, 0, -0.25, 4000000.0), "EPSG:32633")
    cat = dem.boulder_population(d0, "c=0.05,k=-2.5,d_min_m=0.5,d_max_m=8,burial_max=0.5", rng=2)
    out, placed = dem.stamp_boulders(d0, cat, return_catalog=True)
    verts, _ = boulder_world_meshes(placed)
    verts = verts.reshape(len(placed), -1, 3)
    nrm = np.stack([placed["normal_x"], placed["normal_y"], placed["normal_z"]], 1)
    ground = local_ground(d0, verts[..., 0], verts[..., 1])
    deepest = ((ground - verts[..., 2]) * nrm[:, 2:3]).max(axis=1)
    size = placed["diameter_m"]
    assert np.all(np.abs(deepest - placed["burial_m"]) <= 1e-6 * size)
    assert np.all(np.abs(deepest - placed["bottom_depth_m"]) <= 1e-9 * size)
    assert (deepest > 0).all()
    p = out.history[-1]["parameters"]
    assert p["given"] == len(cat) == p["boulders"] + p["unresolved"] + p["off_grid_or_unknown"]
    assert p["boulders"] == len(placed) > 500
