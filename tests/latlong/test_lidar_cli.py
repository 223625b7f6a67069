"""``latlong lidar`` through the real entry point: outputs, manifest, errors, determinism."""

from __future__ import annotations

import hashlib
import json

import laspy
import numpy as np
import pytest

import craters
import latlong
from latlong.sensors.camera import Pose
from latlong.sensors.lidar import LidarSettings
from latlong.sensors.lidar_files import lidar_run, write_las
from latlong.sensors.poses import Poses
from latlong.sensors.scene_geometry import scene_geometry


def _look_at(position_m, target_m):
    return Pose.look_at(position_m, target_m).quaternion_wxyz

POS = "700,0,0"
Q = ",".join(f"{v:.17g}" for v in _look_at([700.0, 0, 0], [0.0, 0, 0]))


@pytest.fixture(scope="module")
def body_file(tmp_path_factory):
    body = latlong.Body.sphere(latlong.LatLongGrid(24), 400.0)
    cat = craters.make_catalog(lat_deg=[0.0], lon_deg=[0.0], diameter_m=[100.0])
    path = tmp_path_factory.mktemp("lidar") / "b.npz"
    latlong.stamp_craters(body, cat, rng=1).save(path)
    return path


def digest(folder):
    return {p.name: hashlib.sha256(p.read_bytes()).hexdigest() for p in sorted(folder.iterdir())}


def test_lidar_command_writes_las_ranges_and_manifest(run_cli, body_file, tmp_path):
    poses = tmp_path / "poses.csv"
    q2 = _look_at([650.0, 100, 0], [0.0, 0, 0])
    poses.write_text("time_s,x_m,y_m,z_m,qw,qx,qy,qz\n"
                     f"0.0,700,0,0,{Q}\n"
                     f"1.5,650,100,0,{','.join(f'{v:.17g}' for v in q2)}\n")
    out = tmp_path / "run"
    r = run_cli("latlong", "lidar", str(body_file), "-o", str(out), "--poses", str(poses),
                "--pattern", "scan", "--beams", "40x30", "--fov-deg", "40",
                "--divergence-mrad", "2", "--rays-per-beam", "4", "--range-noise-m", "0.02",
                "--seed", "9", "-q")
    assert r.returncode == 0, r.stderr
    man = json.loads((out / "lidar.json").read_text())
    assert man["format"] == "craterform.lidar/1" and man["seed"] == 9
    assert man["intrinsics"]["width"] == 40 and man["intrinsics"]["cx"] == 20.0
    assert [f["time_s"] for f in man["frames"]] == [0.0, 1.5]
    fr = man["frames"][1]
    assert fr["position_m"] == [650.0, 100.0, 0.0]
    las = laspy.read(out / fr["files"]["points"])
    assert las.header.version == "1.4" and las.header.point_format.id == 6
    assert len(las.points) == fr["n_returns"] > 500
    # the WKT bit (point formats 6-10 need it) and the CRS VLR PDAL and QGIS read:
    # body-fixed Cartesian on the sphere of the model's mean radius
    import pyproj

    assert las.header.global_encoding.wkt
    crs = las.header.parse_crs()
    assert crs == pyproj.CRS.from_wkt(man["crs_wkt"]) and crs.is_geocentric
    assert crs.ellipsoid.semi_major_metre == pytest.approx(400.0, rel=1e-3)
    rng_img = np.load(out / fr["files"]["range"])
    assert rng_img.shape == (30, 40) and rng_img.dtype == np.float32
    # LAS points: body frame, on the 400 m sphere's surface, time = frame time + offsets
    r_xyz = np.linalg.norm(np.stack([las.x, las.y, las.z], 1), axis=1)
    assert np.abs(r_xyz - 400.0).max() < 40.0
    assert las.gps_time.min() >= 1.5 and las.gps_time.max() < 1.5 + 1200 / 1e5 + 1e-9
    assert set(np.unique(las.crater_id)) <= {-1, 0} and (las.crater_id == 0).any()
    assert (las.boulder_id == -1).all()


def test_same_bytes_whatever_the_thread_count(run_cli, body_file, tmp_path):
    """Same seed -> same bytes (LAS, ranges, manifest) with 1 and 2 numba threads."""
    sums = []
    for threads in ("1", "2"):
        out = tmp_path / f"t{threads}"
        r = run_cli("latlong", "lidar", str(body_file), "-o", str(out), "--position-m", POS,
                    "--quaternion", Q, "--beams", "64x48", "--fov-deg", "60",
                    "--divergence-mrad", "3", "--rays-per-beam", "8", "--multiple-returns",
                    "--range-noise-m", "0.05", "--seed", "4", "-q",
                    env={"NUMBA_NUM_THREADS": threads})
        assert r.returncode == 0, r.stderr
        sums.append(digest(out))
    assert sums[0] == sums[1] and len(sums[0]) == 3


@pytest.mark.parametrize("args, flag", [
    (["--position-m", POS, "--quaternion", "1,0,0,0.1"], "--quaternion"),
    (["--position-m", "100,0,0", "--quaternion", Q], "--position-m"),
    (["--position-m", POS], "--quaternion"),
    (["--position-m", POS, "--quaternion", Q, "--beams", "0x4"], "--beams"),
    (["--position-m", POS, "--quaternion", Q, "--rays-per-beam", "4"], "--rays-per-beam"),
    (["--position-m", POS, "--quaternion", Q, "--pattern", "zigzag"], "--pattern"),
    (["--position-m", "1,2", "--quaternion", Q], "--position-m"),
])
def test_bad_input_one_line_exit_2_nothing_written(run_cli, body_file, tmp_path, args, flag):
    out = tmp_path / "run"
    r = run_cli("latlong", "lidar", str(body_file), "-o", str(out), *args)
    assert r.returncode == 2
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error:") and flag in lines[0]
    assert sorted(p.name for p in tmp_path.iterdir()) == []


def test_unreadable_model_and_bad_poses(run_cli, tmp_path):
    bad = tmp_path / "bad.ply"
    bad.write_text("not a mesh\n")
    r = run_cli("latlong", "lidar", str(bad), "-o", str(tmp_path / "o"), "--position-m", POS,
                "--quaternion", Q)
    assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1
    assert "cannot read model file" in r.stderr
    poses = tmp_path / "p.csv"
    poses.write_text("t,x,y,z\n0,1,2,3\n")
    r = run_cli("latlong", "lidar", str(bad), "-o", str(tmp_path / "o"), "--poses", str(poses))
    assert r.returncode == 2 and "--poses" in r.stderr and "header" in r.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.ply", "p.csv"]


def test_existing_folder_needs_force_and_symlinks_are_refused(body_file, tmp_path):
    geo = scene_geometry(latlong.load_surface(body_file))
    s = LidarSettings(beams=(8, 8))
    poses = Poses.one([700.0, 0, 0], _look_at([700.0, 0, 0], [0.0, 0, 0]))
    out = tmp_path / "run"
    out.mkdir()
    (out / "keep.txt").write_text("x")
    with pytest.raises(ValueError, match="--force"):
        lidar_run(geo, s, poses, out, rng=1)
    lidar_run(geo, s, poses, out, rng=1, force=True)
    assert sorted(p.name for p in out.iterdir()) == ["keep.txt", "lidar.json", "lidar_0000.las",
                                                     "range_0000.npy"]
    link = tmp_path / "link"
    link.symlink_to(tmp_path / "elsewhere", target_is_directory=True)
    with pytest.raises(ValueError, match="symbolic link"):
        lidar_run(geo, s, poses, link, rng=1)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["link", "run"]


def test_las_round_trip_keeps_a_tenth_of_a_millimetre(body_file, tmp_path):
    from latlong.sensors.engine import RayMesh
    from latlong.sensors.lidar import lidar_frame

    geo = scene_geometry(latlong.load_surface(body_file))
    q = _look_at([700.0, 0, 0], [0.0, 0, 0])
    fr = lidar_frame(RayMesh(geo.vertices, geo.faces), LidarSettings(beams=(16, 16),
                     fov_deg=50.0), [700.0, 0, 0], q, time_s=3.25, ground_truth=geo)
    las = laspy.read(write_las(fr, tmp_path / "f.las", point_source_id=7))
    xyz = np.stack([las.x, las.y, las.z], 1)
    assert np.abs(xyz - fr.position_m).max() <= 0.5e-4 + 1e-9
    np.testing.assert_array_equal(las.intensity, fr.intensity)
    assert (las.gps_time == 3.25).all() and (las.point_source_id == 7).all()
    np.testing.assert_array_equal(las.crater_id, fr.crater_id)


def test_las_1_2_for_older_readers(body_file, tmp_path):
    """LAS 1.2, point format 1 (loaders.gl 4.5 reads <= 1.3 only: checked by hand, its
    first point equal to laspy's): the same points, labels and CRS VLR, no WKT bit."""
    import dataclasses

    from latlong.sensors.engine import RayMesh
    from latlong.sensors.lidar import lidar_frame

    geo = scene_geometry(latlong.load_surface(body_file))
    q = _look_at([700.0, 0, 0], [0.0, 0, 0])
    fr = lidar_frame(RayMesh(geo.vertices, geo.faces), LidarSettings(beams=(16, 16),
                     fov_deg=50.0), [700.0, 0, 0], q, time_s=3.25, ground_truth=geo)
    las = laspy.read(write_las(fr, tmp_path / "f.las", version="1.2", crs_wkt="GEOCCS["
                               '"b",DATUM["b",SPHEROID["b",400,0]],PRIMEM["R",0],UNIT["metre",1]]'))
    assert las.header.version == "1.2" and las.header.point_format.id == 1
    assert not las.header.global_encoding.wkt and las.header.parse_crs().is_geocentric
    xyz = np.stack([las.x, las.y, las.z], 1)
    assert np.abs(xyz - fr.position_m).max() <= 0.5e-4 + 1e-9
    np.testing.assert_array_equal(las.crater_id, fr.crater_id)
    assert (las.gps_time == 3.25).all()
    many = dataclasses.replace(fr, number_of_returns=np.full(len(fr.number_of_returns), 9,
                                                             dtype=fr.number_of_returns.dtype))
    with pytest.raises(ValueError, match="las_version.*7 returns"):
        write_las(many, tmp_path / "g.las", version="1.2")
    assert not (tmp_path / "g.las").exists()
    with pytest.raises(ValueError, match="version"):
        write_las(fr, tmp_path / "h.las", version="2.0")


@pytest.mark.parametrize("version", ["1.4", "1.2"])
def test_laz_holds_the_las_points_header_and_crs(run_cli, body_file, tmp_path, version):
    """``--laz``: LASzip-compressed point files (lazrs) with the LAS file's points, labels,
    header and CRS VLR, smaller, the same bytes on every run."""
    runs = {}
    for name, extra in (("las", []), ("laz", ["--laz"]), ("laz2", ["--laz"])):
        out = tmp_path / name
        r = run_cli("latlong", "lidar", str(body_file), "-o", str(out), "--position", POS,
                    "--quaternion", Q, "--beams", "64x48", "--fov-deg", "40", "--seed", "3",
                    "--las-version", version, "-q", *extra)
        assert r.returncode == 0, r.stderr
        runs[name] = out
    man = json.loads((runs["laz"] / "lidar.json").read_text())
    name = man["frames"][0]["files"]["points"]
    assert name == "lidar_0000.laz" and man["settings"]["laz"] is True
    assert digest(runs["laz"]) == digest(runs["laz2"])
    las, laz = laspy.read(runs["las"] / "lidar_0000.las"), laspy.read(runs["laz"] / name)
    assert laz.header.are_points_compressed and not las.header.are_points_compressed
    assert laz.header.version == las.header.version == version
    for dim in ("X", "Y", "Z", "intensity", "gps_time", "return_number", "crater_id"):
        np.testing.assert_array_equal(laz[dim], las[dim])
    assert laz.header.parse_crs() == las.header.parse_crs() is not None
    sizes = [(runs[k] / n).stat().st_size for k, n in (("laz", name), ("las", "lidar_0000.las"))]
    assert sizes[0] < 0.8 * sizes[1], sizes
