"""Rocks on demand (latlong.ondemand.rocks, craters.local.draw_rock_cells): the draws,
the rock kernel against numpy, locality and refinement with rocks."""

from __future__ import annotations

import numpy as np
import pytest

from craters import BoulderLayer
from craters.cells import cell_ids, cell_of, cell_solid_angle
from craters.kernels import fbm2
from craters.local import ROCK_FACETS, draw_rock_cells
from latlong import LatLongGrid, Scene, build
from latlong.ondemand import _field_kernels as K
from latlong.ondemand import _rock_kernels as R
from latlong.ondemand import units_of
from latlong.ondemand.field import crater_field

LAYERS = ["c=0.5,k=-2,d_min_m=4,d_max_m=15"]
ROCKS = ["c=0.2,k=-2.5,d_min_m=0.5,d_max_m=12,burial_max=0.4"]


@pytest.fixture(scope="module")
def scene():
    # the 100 m fBm body of test_ondemand with rocks of 0.5-12 m
    return Scene.from_settings({"preset": "fbm-cratered", "seed": 5, "on_demand": True,
                                "craters": LAYERS, "boulders": ROCKS})


def test_rock_cells_draw_the_expected_counts_sizes_and_shapes():
    la = BoulderLayer(0.05, -2.5, 0.5, 4.0, burial_max=0.4)
    i, j = np.meshgrid(np.arange(40) + 3, np.arange(40) + 9)
    ids = cell_ids(14, np.full(i.size, 4), i.ravel(), j.ravel())
    area = cell_solid_angle(14, 4, i.ravel(), j.ravel()) * 3000.0**2
    got = draw_rock_cells(la, 1, seed=7, b=0, level=14, cell_ids=ids, area_m2=area)
    expected = area.sum() * 0.05 * (1.0**-2.5 - 2.0**-2.5)
    assert abs(len(got["diameter_m"]) - expected) < 4 * np.sqrt(expected)
    d = got["diameter_m"]
    assert ((d >= 1.0) & (d < 2.0)).all()
    f, ii, jj = cell_of(got["unit"], 14)
    assert np.array_equal(cell_ids(14, f, ii, jj), got["cell"])
    assert ((got["burial_frac"] >= 1e-3) & (got["burial_frac"] <= 0.4)).all()
    assert ((got["elongation"] >= 1.0) & (got["elongation"] <= 1.4)).all()
    assert np.allclose(got["height_m"] / d, 0.6 * (got["height_m"] / d / 0.6))
    assert got["facets"].shape == (len(d), ROCK_FACETS, 3)
    # the same rocks whatever else is drawn; other draws than the craters'
    some = draw_rock_cells(la, 1, seed=7, b=0, level=14, cell_ids=ids[[17]],
                           area_m2=area[[17]])
    sel = got["cell"] == ids[17]
    for key in ("unit", "diameter_m", "facets", "id", "burial_frac"):
        assert got[key][sel].tobytes() == some[key].tobytes()


def _rock_height_numpy(rc, seeds, p):
    """Height of each rock (rows of ``rc``) over direction ``p``: the module notes'
    ellipsoid and facets, in numpy."""
    c = rc[:, 0:3] @ p
    xe, xn = rc[:, 3:6] @ p, rc[:, 6:9] @ p
    s = np.hypot(xe, xn)
    dist = np.arctan2(s, c) * rc[:, 9]
    with np.errstate(invalid="ignore", divide="ignore"):
        x = np.where(s > 0, dist * xe / s, 0.0)
        y = np.where(s > 0, dist * xn / s, 0.0)
    xi = (x * rc[:, R.CA] + y * rc[:, R.SA]) / rc[:, R.A]
    eta = (y * rc[:, R.CA] - x * rc[:, R.SA]) / rc[:, R.B]
    q2 = xi**2 + eta**2
    f = np.sqrt(np.clip(1.0 - q2, 0.0, None))
    for m in range(R.N_FACETS):
        col = R.F0 + 4 * m
        f = np.minimum(f, rc[:, col + 2] - rc[:, col + 3] * (xi * rc[:, col]
                                                             + eta * rc[:, col + 1]))
    with np.errstate(over="ignore"):  # the hash's uint64 arithmetic wraps
        rough = [fbm2.py_func(s, xx, yy, 0.5 * a, 3, 0.5)
                 for s, xx, yy, a in zip(seeds, x, y, rc[:, R.A], strict=True)]
        f = f + R.ROCK_ROUGHNESS * np.array(rough)
    z = np.maximum(rc[:, R.Z0] + rc[:, R.CZ] * f, 0.0)
    near = np.sum((p - rc[:, 0:3]) ** 2, axis=1) <= rc[:, R.CHORD2]
    return np.where((q2 < 1.0) & near, z, 0.0)


def test_the_rock_kernel_matches_numpy(scene):
    field = crater_field(scene)
    units = units_of(*np.meshgrid(np.linspace(10, 10.2, 40), np.linspace(20, 20.2, 40)))
    got = field.rocks.rocks(units, 0.5)
    rc = got["rc"]
    assert len(rc) > 20
    out = np.zeros(len(units))
    which = np.zeros(len(units), dtype=np.int64)
    every = np.arange(len(rc), dtype=np.int64)
    R._rocks_kernel(units, np.zeros(len(units), np.int64), np.array([0, len(rc)]), every,
                    rc, got["seed"], out, which)
    heights = np.array([_rock_height_numpy(rc, got["seed"], p) for p in units])
    ref = heights.max(axis=1)
    assert np.allclose(out, ref, rtol=0, atol=1e-12)
    # the tallest rock of each point (the labels' ground truth), -1 where none stands
    assert np.array_equal(which, np.where(ref > 0, heights.argmax(axis=1), -1))
    assert (out > 0).mean() > 0.01
    # no rock stands higher than its unburied height (and its roughness)
    top = got["height_m"] * (1 - got["burial_frac"] + 0.5 * R.ROCK_ROUGHNESS)
    assert (ref <= top.max() + 1e-12).all()


def test_a_height_with_rocks_is_the_same_alone_in_a_batch_and_in_the_whole_body(scene):
    grid = LatLongGrid(60)
    field = crater_field(scene)
    res = grid.spacing(field.base.radius_m)
    units = grid.unit_vectors()
    every = field.radii(units, 3.0 * res)
    assert len(field.rocks.last["diameter_m"]) > 10
    pick = np.random.default_rng(2).choice(len(units), 40, replace=False)
    assert field.radii(units[pick], 3.0 * res).tobytes() == every[pick].tobytes()
    i = pick[0]
    assert field.radii(units[i:i + 1], 3.0 * res).tobytes() == every[i:i + 1].tobytes()
    body = build(Scene.from_settings({"preset": "fbm-cratered", "seed": 5, "on_demand": True,
                                      "magnitude": 60, "craters": LAYERS, "boulders": ROCKS}))
    assert body.radii_m.tobytes() == every.tobytes()


def test_a_finer_resolution_changes_heights_only_where_added_craters_and_rocks_reach(scene):
    field = crater_field(scene)
    units = units_of(*np.meshgrid(np.linspace(30, 36, 80), np.linspace(40, 46, 80)))
    coarse = field.radii(units, 2.0)
    fine = field.radii(units, 1.0)
    cr, fc, rocks = field.last["craters"], field.last["fc"], field.rocks.last
    reach = np.zeros(len(units), bool)
    for k in np.flatnonzero((cr.diameter_m >= 1.0) & (cr.diameter_m < 2.0)):
        reach |= units @ fc[k, 0:3] >= fc[k, K.COS_FAR]
    added = (rocks["diameter_m"] >= 1.0) & (rocks["diameter_m"] < 2.0)
    assert added.sum() > 5
    for k in np.flatnonzero(added):
        reach |= units @ rocks["rc"][k, 0:3] >= rocks["rc"][k, K.COS_FAR]
    changed = fine != coarse
    assert changed.any()
    assert not (changed & ~reach).any()


def test_descent_frames_label_the_rocks_of_their_own_terrain(scene, tmp_path):
    from craters.catalog import read_catalog
    from latlong.ondemand.descent import descent, write_descent

    frames = list(descent(scene, 10.0, 40.0, [40.0, 15.0], width_px=64))
    stretch = np.sqrt(scene.boulders.shape.elongation)
    for f in frames:
        ids = f.frame.boulder_id
        hit = ids >= 0
        assert 0.001 < hit.mean() < 0.5 and ids.max() < len(f.rocks)
        assert set(np.unique(ids[hit])) <= set(range(len(f.rocks)))
        # each labelled pixel lies on the footprint of the rock it names (its long
        # semi-axis, plus the two ground pixels a face on the rock may reach beyond it)
        cat = f.rocks[ids[hit]]
        u = units_of(cat["lat_deg"], cat["lon_deg"])
        p = f.frame.position_m[hit]
        cos = np.einsum("ij,ij->i", p, u) / np.linalg.norm(p, axis=1)
        arc = np.linalg.norm(p, axis=1) * np.arccos(np.clip(cos, -1.0, 1.0))
        assert (arc <= 0.5 * cat["diameter_m"] * stretch + 2 * f.ground_pixel_m).all()
    assert write_descent(frames, tmp_path / "d", seed=5, site_lat_lon_deg=(10.0, 40.0)) == 2
    back = read_catalog(tmp_path / "d" / "rocks_0001.csv")
    assert len(back) == len(frames[1].rocks)
    assert np.allclose(back["diameter_m"], frames[1].rocks["diameter_m"])


def test_face_rocks_kernel_matches_numpy(rng):
    which = rng.integers(-1, 4, 5000)  # few rocks: ties of two and three corners are common
    faces = rng.integers(0, len(which), (20000, 3))
    a, b, c = which[faces].T
    want = np.where(b == c, b, -1)
    want = np.where(a == c, a, want)
    want = np.where(a == b, a, want)
    got = np.empty(len(faces), dtype=np.int64)
    R._face_rocks_kernel(which, faces, got)
    np.testing.assert_array_equal(got, want)
    assert (got == -1).any() and (got >= 0).any()
