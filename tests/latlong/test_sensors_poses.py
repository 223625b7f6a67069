"""Trajectories: generated approaches, TOML poses, and labelled camera frames of a
cratered body through ``latlong camera``."""

from __future__ import annotations

import json

import numpy as np
import pytest

import craters
from latlong import Body, LatLongGrid, stamp_craters
from latlong.sensors import RayMesh
from latlong.sensors.poses import approach, read_poses, surface_point


def test_approach_ranges_times_and_aim():
    target = np.array([600.0, 300.0, 400.0])
    p = approach(target, n_frames=5, start_range_m=3000.0, end_range_m=300.0,
                 path_angle_deg=30.0, path_azimuth_deg=90.0, duration_s=8.0)
    ranges = np.linalg.norm(p.position_m - target, axis=1)
    np.testing.assert_allclose(ranges, 3000.0 * 0.1 ** (np.arange(5) / 4), rtol=1e-12)
    np.testing.assert_allclose(p.time_s, [0, 2, 4, 6, 8])
    for k in range(5):  # the optical axis passes through the target
        axis = p[k].rotation[:, 2]
        to_target = (target - p.position_m[k]) / ranges[k]
        assert axis @ to_target == pytest.approx(1.0, abs=1e-12)
    up = target / np.linalg.norm(target)  # 30 deg from the local vertical, towards east
    line = (p.position_m[0] - target) / ranges[0]
    assert np.degrees(np.arccos(line @ up)) == pytest.approx(30.0, abs=1e-9)
    east = np.cross([0, 0, 1.0], up)
    east /= np.linalg.norm(east)
    assert line @ east > 0.49


@pytest.mark.parametrize("target", [[0.0, 0.0, -1500.0], [0.0, 0.0, 0.0], [2e3, -1e3, 50.0]])
def test_approach_over_a_local_frame_with_z_up(target):
    """A DEM mesh (x east, y north, z = height, heights below the datum too): with
    ``vertical=(0, 0, 1)`` the cameras come down from above, whatever the target's
    height; the default (the radial direction) would put them under the ground."""
    p = approach(target, n_frames=3, start_range_m=5000.0, end_range_m=500.0,
                 path_angle_deg=30.0, path_azimuth_deg=90.0, vertical=(0.0, 0.0, 2.0))
    line = (p.position_m - target) / np.linalg.norm(p.position_m - target, axis=1)[:, None]
    np.testing.assert_allclose(line, [[0.5, 0.0, np.sqrt(3) / 2]] * 3, atol=1e-12)  # east
    north = approach(target, n_frames=1, start_range_m=100.0, end_range_m=100.0,
                     path_angle_deg=45.0, vertical=(0, 0, 1))
    np.testing.assert_allclose(north.position_m[0] - target, [0, 50 * np.sqrt(2),
                                                              50 * np.sqrt(2)], atol=1e-9)
    if target[2] < 0:  # the old behaviour: below the surface, looking up
        assert approach(target, n_frames=1, start_range_m=100.0,
                        end_range_m=100.0).position_m[0, 2] < target[2]


@pytest.mark.parametrize(("kwargs", "needle"), [
    ({"n_frames": 0}, "n_frames"), ({"start_range_m": -1.0}, "start_range_m"),
    ({"path_angle_deg": 95.0}, "path_angle_deg"), ({"duration_s": 0.0}, "duration_s"),
    ({"vertical": (0.0, 0.0, 0.0)}, "vertical"), ({"vertical": (1.0, 2.0)}, "vertical")])
def test_approach_bad_input_names_the_parameter(kwargs, needle):
    args = {"n_frames": 3, "start_range_m": 100.0, "end_range_m": 10.0, **kwargs}
    with pytest.raises(ValueError, match=needle):
        approach([1.0, 0, 0], **args)


def test_surface_point_on_a_sphere():
    grid = LatLongGrid(40)
    body = Body.sphere(grid, 1000.0)
    mesh = RayMesh(body.vertices(), grid.triangles())
    p = surface_point(mesh, 20.0, 45.0)
    d = p / np.linalg.norm(p)
    np.testing.assert_allclose(d, [np.cos(np.radians(20)) * np.cos(np.radians(45)),
                                   np.cos(np.radians(20)) * np.sin(np.radians(45)),
                                   np.sin(np.radians(20))], atol=1e-12)
    assert 995.0 < np.linalg.norm(p) <= 1000.0  # on a facet, inside the vertices' sphere


def test_toml_poses_read_and_bad_keys(tmp_path):
    good = tmp_path / "p.toml"
    good.write_text("[[frame]]\ntime_s = 1.5\nposition_m = [3000.0, 0, 0]\n"
                    "quaternion_wxyz = [1.0, 0, 0, 0]\n")
    p = read_poses(good)
    assert len(p) == 1 and p.time_s[0] == 1.5 and p.position_m[0, 0] == 3000.0
    bad = tmp_path / "b.toml"
    bad.write_text("[[frame]]\ntime_s = 1\nposition = [1, 2, 3]\nquaternion_wxyz = [1, 0, 0, 0]\n")
    with pytest.raises(ValueError, match="frame 1"):
        read_poses(bad)


@pytest.fixture(scope="module")
def cratered_npz(tmp_path_factory):
    radius = 1000.0
    body = Body.sphere(LatLongGrid(120), radius)
    area = 4 * np.pi * radius**2
    cat = craters.power_law_population(radius=radius, c=300 / (area * (60.0**-2 - 300.0**-2)),
                                       k=-2.0, d_min=60.0, d_max=300.0, rng=3)
    body = stamp_craters(body, cat, rng=3)
    path = tmp_path_factory.mktemp("cratered") / "c.npz"
    body.save(path)
    return path


def test_camera_descent_writes_labels_and_rim_ellipses(run_cli, cratered_npz, tmp_path):
    out = tmp_path / "descent"
    proc = run_cli("latlong", "camera", str(cratered_npz), "-o", str(out), "--target-lat-lon",
                   "10,20", "--range-m", "2500,1200", "--frames", "3", "--path-angle-deg",
                   "20", "--fov-deg", "40", "--size", "96x80", "--sun-direction", "1,0.3,0.5",
                   "-q")
    assert proc.returncode == 0, proc.stderr
    doc = json.loads((out / "frames.json").read_text())
    assert len(doc["frames"]) == 3
    from PIL import Image

    seen = 0
    for fr in doc["frames"]:
        lab = np.asarray(Image.open(out / fr["files"]["crater_id"]))
        assert lab.dtype == np.int32 and lab.shape == (80, 96)
        ids = set(np.unique(lab[lab >= 0]).tolist())
        assert ids, "a descent over a cratered body sees craters"
        assert {e["crater_id"] for e in fr["rim_ellipses"]} <= ids
        seen += len(fr["rim_ellipses"])
        b = np.asarray(Image.open(out / fr["files"]["boulder_id"]))
        assert (b == -1).all()  # no boulders on this body
    assert seen > 0
    # the frames come closer: ranges fall geometrically
    r = [np.linalg.norm(np.array(f["position_m"])) for f in doc["frames"]]
    assert r[0] > r[1] > r[2]


def test_camera_pose_options_conflict(run_cli, cratered_npz, tmp_path):
    proc = run_cli("latlong", "camera", str(cratered_npz), "-o", str(tmp_path / "o"),
                   "--target-lat-lon", "10,20", "--fov-deg", "40", "--size", "96x80",
                   "--sun-direction", "1,0,0")
    assert proc.returncode == 2 and "--range-m" in proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1
    proc = run_cli("latlong", "camera", str(cratered_npz), "-o", str(tmp_path / "o"),
                   "--target-lat-lon", "10,20", "--range-m", "10,5", "--fov-deg", "40",
                   "--size", "96x80", "--sun-direction", "1,0,0", "--position-m", "1,2,3")
    assert proc.returncode == 2 and "one of" in proc.stderr
    assert not (tmp_path / "o").exists()


def test_bright_ejecta_brightens_fresh_craters_only(cratered_npz):
    """--bright-ejecta: around a fresh crater the albedo factor is 1 + contrast at the rim
    and follows (r/R)^-3 outside; craters at or above the fresh degradation leave it 1."""
    from latlong import load
    from latlong.sensors import ejecta_albedo, scene_geometry

    geo = scene_geometry(load(cratered_npz))
    cat = geo.craters
    a = ejecta_albedo(geo, contrast=0.5, fresh_degradation=1.0)
    assert a.min() >= 1.0 and a.max() <= 1.5 + 1e-12
    i = int(np.argmin(cat["degradation"]))
    c = np.array([cat["centre_x_m"][i], cat["centre_y_m"][i], cat["centre_z_m"][i]])
    r = np.linalg.norm(geo.vertices - c, axis=1) / cat["rim_radius_m"][i]
    w = 1.0 - cat["degradation"][i]
    inside = r <= 1.0
    assert (a[inside] >= 1.0 + 0.5 * w - 1e-12).all()
    ring = (r > 1.5) & (r < 2.5)
    assert (a[ring] >= 1.0 + 0.5 * w * r[ring] ** -3 - 1e-12).all()
    mature = ejecta_albedo(geo, contrast=0.5, fresh_degradation=float(cat["degradation"].min()))
    assert (mature == 1.0).all()  # every crater at or above the threshold
    with pytest.raises(ValueError, match="contrast"):
        ejecta_albedo(geo, contrast=-1.0)


def test_map_catalog_on_a_dem_mesh_is_placed_on_the_surface():
    """A dem catalog (x_m, y_m in the mesh's local frame) labels a dem mesh: centres on the
    surface below them, +z normals, rows kept (ids = rows), NaN where off the mesh."""
    from latlong.sensors import crater_labels, scene_geometry
    from latlong.sensors.scene_geometry import SceneGeometry

    n = 21
    xs = np.linspace(-100.0, 100.0, n)
    gx, gy = np.meshgrid(xs, xs)
    verts = np.stack([gx.ravel(), gy.ravel(), 5.0 + 0.01 * gx.ravel()], 1)
    idx = np.arange(n * n).reshape(n, n)
    a, b, c, d = idx[:-1, :-1].ravel(), idx[:-1, 1:].ravel(), idx[1:, :-1].ravel(), \
        idx[1:, 1:].ravel()
    faces = np.concatenate([np.stack([a, b, d], 1), np.stack([a, d, c], 1)])
    geo = SceneGeometry(verts, faces, np.full(len(faces), -1, np.int32))
    cat = craters.make_catalog(x_m=[500.0, 10.0], y_m=[0.0, 20.0], diameter_m=[20.0, 30.0])
    placed = scene_geometry(geo, craters=cat).craters
    assert len(placed) == 2 and np.isnan(placed["centre_z_m"][0])
    assert placed["centre_z_m"][1] == pytest.approx(5.1, abs=1e-9)
    assert placed["normal_z"][1] == 1.0
    pts = [[10.0, 20.0, 5.1], [10.0, 40.0, 5.1], [500.0, 0.0, 5.0]]
    assert crater_labels(pts, placed).tolist() == [1, -1, -1]


def test_fitted_rims_equal_rim_curves_on_the_ids_seen(cratered_npz):
    from latlong import load
    from latlong.sensors import rim_curves, scene_geometry
    from latlong.sensors.labels import FittedRims

    geo = scene_geometry(load(cratered_npz))
    rims = FittedRims(geo.craters, geo)
    rims([3, 1, 4])
    got = rims([1, 5, 9, 2])  # 1 from the first call, the others new
    want = rim_curves(geo.craters, geo, ids=[1, 2, 3, 4, 5, 9])
    for a, b in zip(got, want, strict=True):
        np.testing.assert_array_equal(a, b)
