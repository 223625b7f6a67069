"""``latlong camera`` through the real entry point: files, manifest, one-line errors."""

from __future__ import annotations

import json

import numpy as np
import pytest

from latlong import Body, LatLongGrid
from latlong.sensors import Pose

POSE = Pose.look_at([-3000.0, 200.0, 100.0], [0.0, 0.0, 0.0])
Q = ",".join(repr(float(v)) for v in POSE.quaternion_wxyz)
BASE = ["--fov-deg", "30", "--size", "48x32", "--sun-direction", "-1,0.5,0.2"]


@pytest.fixture(scope="module")
def body_npz(tmp_path_factory):
    path = tmp_path_factory.mktemp("model") / "ball.npz"
    grid = LatLongGrid(24)
    u = grid.unit_vectors()
    Body(grid, 1000.0 + 20.0 * np.sin(5 * u[:, 0]) * np.cos(3 * u[:, 2]),
         radius_m=1000.0).save(path)
    return path


@pytest.fixture(scope="module")
def mesh_ply(tmp_path_factory, body_npz):
    from latlong import load

    path = tmp_path_factory.mktemp("mesh") / "ball_km.ply"
    body = load(body_npz)
    import pyvista as pv

    faces = np.hstack([np.full((body.grid.n_triangles, 1), 3), body.grid.triangles()])
    pv.PolyData(body.vertices() / 1000.0, faces.ravel()).save(path)
    return path


def test_one_pose_writes_the_interface(run_cli, body_npz, tmp_path):
    out = tmp_path / "frames"
    proc = run_cli("latlong", "camera", str(body_npz), "-o", str(out), "--position-m",
                   "-3000,200,100", "--quaternion", Q, *BASE, "-q")
    assert proc.returncode == 0, proc.stderr
    doc = json.loads((out / "frames.json").read_text())
    assert set(doc["intrinsics"]) == {"fx", "fy", "cx", "cy", "width", "height"}
    assert doc["intrinsics"]["width"] == 48 and doc["intrinsics"]["cx"] == 24.0
    (frame,) = doc["frames"]
    assert set(frame) >= {"time_s", "position_m", "quaternion_wxyz", "sun_direction", "files"}
    assert set(frame["files"]) >= {"image", "depth", "range", "normals", "crater_id",
                                   "boulder_id"}
    from PIL import Image

    img = np.asarray(Image.open(out / frame["files"]["image"]))
    depth = np.asarray(Image.open(out / frame["files"]["depth"]))
    rng = np.asarray(Image.open(out / frame["files"]["range"]))
    normals = np.load(out / frame["files"]["normals"])
    assert img.dtype == np.uint16 and img.shape == (32, 48) and img.max() > 0
    assert depth.dtype == np.float32 and rng.dtype == np.float32
    hit = np.isfinite(rng)
    assert hit.mean() > 0.3 and (depth[hit] <= rng[hit]).all()
    assert 1900 < np.nanmin(rng) < 2100
    assert normals.shape == (32, 48, 3) and normals.dtype == np.float32
    assert sorted(p.name for p in tmp_path.iterdir()) == ["frames"]  # no temporary left


def test_poses_csv_mesh_file_and_options(run_cli, mesh_ply, tmp_path):
    rows = ["time_s,x_m,y_m,z_m,qw,qx,qy,qz"]
    for k, x in enumerate((3000.0, 2600.0, 2200.0)):
        p = Pose.look_at([x, 100.0 * k, 50.0], [0, 0, 0])
        rows.append(",".join(repr(float(v)) for v in [0.5 * k, *p.position_m,
                                                      *p.quaternion_wxyz]))
    csv = tmp_path / "poses.csv"
    csv.write_text("\n".join(rows) + "\n")
    out = tmp_path / "run"
    proc = run_cli("latlong", "camera", str(mesh_ply), "--units", "km", "-o", str(out),
                   "--poses", str(csv), "--intrinsics", "60,60,24,16", "--size", "48x32",
                   "--sun-direction", "1,0,0", "--reflectance", "hapke", "--hapke-preset",
                   "c-type", "--bits", "32", "--depth-format", "npy", "--photon-noise",
                   "--all-ground-truth", "--distortion", "-0.1,0.01,0,0,0", "-q")
    assert proc.returncode == 0, proc.stderr
    doc = json.loads((out / "frames.json").read_text())
    assert [f["time_s"] for f in doc["frames"]] == [0.0, 0.5, 1.0]
    last = doc["frames"][2]["files"]
    assert last["image"].endswith(".tif") and last["depth"].endswith(".npy")
    assert np.load(out / last["phase"]).dtype == np.float32
    assert np.load(out / last["depth"]).dtype == np.float32
    assert doc["distortion"]["k1"] == -0.1
    # a folder that is not empty needs --force
    again = run_cli("latlong", "camera", str(mesh_ply), "--units", "km", "-o", str(out),
                    "--poses", str(csv), *BASE)
    assert again.returncode == 2 and "--force" in again.stderr


def test_approach_over_a_dem_mesh_with_vertical(run_cli, tmp_path):
    """A ``dem mesh``-like open surface (x east, y north, z = height) lying below the
    datum: ``--vertical 0,0,1`` brings the generated cameras down from above; without it
    the radial direction of the target points down and the camera would be under it."""
    import dem

    z = -1500.0 + 30.0 * np.sin(np.arange(33)[:, None] / 4.0) * np.cos(np.arange(33) / 5.0)
    mesh = tmp_path / "site.ply"
    dem.mesh.to_mesh(dem.Dem(z, pixel_size_m=20.0), mesh)
    out = tmp_path / "landing"
    args = ["latlong", "camera", str(mesh), "--target-m", "0,0,-1500", "--range-m",
            "400,200", "--frames", "2", "--path-angle-deg", "20", *BASE, "-q"]
    below = run_cli(*args, "-o", str(out))
    assert below.returncode == 2 and "inside" in below.stderr
    proc = run_cli(*args, "--vertical", "0,0,1", "-o", str(out))
    assert proc.returncode == 0, proc.stderr
    doc = json.loads((out / "frames.json").read_text())
    assert [round(f["position_m"][2]) for f in doc["frames"]] == [-1124, -1312]
    from PIL import Image

    assert np.asarray(Image.open(out / doc["frames"][1]["files"]["depth"])).min() > 150


BAD = [
    (["--position-m", "0,0,0", "--quaternion", Q], "inside"),
    (["--position-m", "-3000,200,100", "--quaternion", "1,0.2,0,0"], "--quaternion"),
    (["--position-m", "-3000,200,100", "--quaternion", Q, "--sun-direction", "0,0,0"],
     "--sun-direction"),
    (["--position-m", "-3000,200,100", "--quaternion", Q, "--reflectance", "phong"],
     "--reflectance"),
    (["--position-m", "-3000,200,100"], "--quaternion"),
    (["--position-m", "-3000,200,100", "--quaternion", Q, "--fov-deg", "200"], "--fov-deg"),
    (["--position-m", "-3000,200,100", "--quaternion", "1,0"], "--quaternion"),
]


@pytest.mark.parametrize(("extra", "needle"), BAD)
def test_bad_input_is_one_line_and_writes_nothing(run_cli, body_npz, tmp_path, extra, needle):
    out = tmp_path / "nothing"
    args = [a for a in BASE]
    if "--sun-direction" in extra:
        args = args[:4]
    if "--fov-deg" in extra:
        args = args[2:]
    proc = run_cli("latlong", "camera", str(body_npz), "-o", str(out), *args, *extra)
    assert proc.returncode == 2
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error:") and needle in lines[0], lines
    assert list(tmp_path.iterdir()) == []


def test_unreadable_mesh(run_cli, tmp_path):
    bad = tmp_path / "bad.ply"
    bad.write_text("not a mesh\n")
    out = tmp_path / "out"
    proc = run_cli("latlong", "camera", str(bad), "-o", str(out), "--position-m",
                   "-3000,0,0", "--quaternion", Q, *BASE)
    assert proc.returncode == 2
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and "cannot read model file" in lines[0]
    assert not out.exists()
    bad_csv = tmp_path / "p.csv"
    bad_csv.write_text("t,x,y,z\n0,1,2,3\n")
    proc = run_cli("latlong", "camera", str(bad), "-o", str(out), "--poses", str(bad_csv),
                   *BASE)
    assert proc.returncode == 2 and "time_s,x_m,y_m,z_m,qw,qx,qy,qz" in proc.stderr


def test_same_bytes_for_any_thread_count(run_cli, body_npz, tmp_path):
    digests = []
    for threads in ("1", "2"):
        out = tmp_path / threads
        proc = run_cli("latlong", "camera", str(body_npz), "-o", str(out), "--position-m",
                       "-3000,200,100", "--quaternion", Q, *BASE, "--photon-noise",
                       "--read-noise-e", "4", "--sun-angular-radius-deg", "0.5",
                       "--soft-shadow-samples", "4", "-q", env={"NUMBA_NUM_THREADS": threads})
        assert proc.returncode == 0, proc.stderr
        digests.append({p.name: p.read_bytes() for p in sorted(out.iterdir())})
    assert digests[0] == digests[1]


def _options(parser, name):
    import argparse

    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return sub.choices[name], sub.choices[name].get_default("func").options


def test_the_sensor_options_are_the_library_declarations():
    """Each setting's default lives once, in the library: the records' declarations
    (CameraSettings, LidarSettings), the detector's fields, the pose functions' defaults;
    ``dem camera`` / ``dem lidar`` differ only by MODEL, ``--units`` and the vertical."""
    import dataclasses
    import inspect

    from dem.cli import build_parser as dem_parser
    from latlong.cli import build_parser
    from latlong.sensors import CameraSettings, LidarSettings, Sensor
    from latlong.sensors.poses import approach

    camera, cam = _options(build_parser(), "camera")
    _, lid = _options(build_parser(), "lidar")
    for f in dataclasses.fields(LidarSettings):
        assert lid[f.name].default == f.default, f.name
    for f in dataclasses.fields(CameraSettings)[3:]:
        assert cam[f.name] == dataclasses.replace(f.metadata["setting"], key=cam[f.name].key,
                                                  kind=cam[f.name].kind,
                                                  group=cam[f.name].group,
                                                  parse=cam[f.name].parse), f.name
    for f in dataclasses.fields(Sensor):
        assert cam[f.name].default == f.default, f.name
    signature = inspect.signature(approach).parameters
    for key, param in (("frames", "n_frames"), ("path_angle_deg", "path_angle_deg"),
                       ("path_azimuth_deg", "path_azimuth_deg"), ("vertical", "vertical")):
        assert cam[key].default == lid[key].default == signature[param].default, key
    assert "(0.5 = 50 % brighter" in " ".join(camera.format_help().split())  # % escaped
    for name, ours in (("camera", cam), ("lidar", lid)):
        _, site = _options(dem_parser(), name)
        assert set(ours) - set(site) == {"units"} and set(site) <= set(ours)
        assert site["vertical"].default == (0.0, 0.0, 1.0)
        assert site["model"].help != ours["model"].help
        same = [k for k in site if dataclasses.replace(site[k], parse=None)
                == dataclasses.replace(ours[k], parse=None)]  # parsers: one closure a table
        assert set(site) - set(same) == {"model", "vertical"}, name


def test_a_library_error_is_shown_under_its_flag(run_cli, body_npz, tmp_path):
    """Errors about library parameters (Camera's fx, Sensor's bits, approach's n_frames)
    are named by the option that sets them, through the kit's declarations."""
    one = ["--position-m", "-3000,200,100", "--quaternion", Q]
    for extra, needle in ((["--size", "48x32", "--sun-direction", "1,0,0", "--intrinsics",
                            "-60,60,24,16", *one], "error: --intrinsics must be"),
                          ([*BASE, "--bits", "12", *one], "error: --bits must be 8, 16 or 32"),
                          ([*BASE, "--target-m", "1000,0,0", "--range-m", "400,200",
                            "--frames", "0"], "error: --frames must be an integer"),
                          ([*BASE, "--units", "mm", *one], "error: --units must be one of m, km")):
        proc = run_cli("latlong", "camera", str(body_npz), "-o", str(tmp_path / "x"), *extra)
        assert proc.returncode == 2 and proc.stderr.startswith(needle), proc.stderr
    assert list(tmp_path.iterdir()) == []
