"""SPICE-driven sequences (latlong.sensors.spice) against spiceypy's own answers, from
kernels the tests write (tests/latlong/spice_kernels.py)."""

from __future__ import annotations

import numpy as np
import pytest

from craters._shared import ParameterError
from latlong.sensors import quaternion_to_matrix

sp = pytest.importorskip("spiceypy")

from latlong.sensors.spice import spice_camera, spice_sequence  # noqa: E402

from .spice_kernels import CAM_FRAME, START_UTC, write_kernels  # noqa: E402

ARGS = {"target": "MOON", "observer": "TESTCRAFT", "frame": "IAU_MOON",
        "camera_frame": CAM_FRAME}


@pytest.fixture(scope="module")
def kernels(tmp_path_factory):
    return write_kernels(tmp_path_factory.mktemp("spice"))


def angle(a, b) -> float:
    """Angle (rad) between two vectors; by the cross product's norm and the dot product, as
    the arc cosine of a dot product near 1 cannot resolve angles under ~1.5e-8 rad (its
    next value below 1 is that far off: the 1e-9 checks below passed or failed by rounding)."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    return float(np.arctan2(np.linalg.norm(np.cross(a, b)), np.dot(a, b)))


def test_a_sequence_is_what_spiceypy_gives(kernels):
    seq = spice_sequence(kernels, utc=f"{START_UTC},2025-03-01T12:05:00,30", **ARGS)
    assert len(seq.poses) == 11 and seq.utc[0] == "2025-03-01T12:00:00.000000"
    assert seq.utc[-1] == "2025-03-01T12:05:00.000000"
    sp.furnsh(str(kernels))
    try:
        for k, t in enumerate(seq.poses.time_s):
            assert t == sp.str2et(seq.utc[k])
            pos = np.asarray(sp.spkpos("TESTCRAFT", t, "IAU_MOON", "NONE", "MOON")[0]) * 1e3
            assert np.abs(seq.poses.position_m[k] - pos).max() <= 1e-9 * np.linalg.norm(pos)
            rot = np.asarray(sp.pxform(CAM_FRAME, "IAU_MOON", t))
            mine = quaternion_to_matrix(seq.poses.quaternion_wxyz[k])
            # the angle of the rotation between the two (|R - I|_F / sqrt 2 for small
            # angles: arccos of the trace loses 1e-8 to rounding): within 1e-9 rad
            assert np.linalg.norm(mine.T @ rot - np.eye(3)) / np.sqrt(2) <= 1e-9
            sun = np.asarray(sp.spkpos("SUN", t, "IAU_MOON", "NONE", "MOON")[0])
            assert angle(seq.sun_directions[k], sun) <= 1e-9
            # the camera looks at the Moon's centre (the CK was written so)
            assert angle(mine[:, 2], -seq.poses.position_m[k]) <= 1e-6
    finally:
        sp.kclear()
    info = seq.frame_info()
    assert info[3] == {"et_s": float(seq.poses.time_s[3]), "utc": seq.utc[3]}
    # the kernels were unloaded again
    assert sp.ktotal("ALL") == 0


def test_the_planet_is_where_spiceypy_puts_it(kernels):
    seq = spice_sequence(kernels, utc=f"{START_UTC},2025-03-01T12:02:00,60", planet="EARTH",
                         **ARGS)
    assert seq.planet_directions is not None and seq.planet_radii_deg is not None
    sp.furnsh(str(kernels))
    try:
        radius = np.mean(sp.bodvrd("EARTH", "RADII", 3)[1])
        for k, t in enumerate(seq.poses.time_s):
            e = np.asarray(sp.spkpos("EARTH", t, "IAU_MOON", "NONE", "MOON")[0])
            assert angle(seq.planet_directions[k], e) <= 1e-9
            assert seq.planet_radii_deg[k] == pytest.approx(
                np.degrees(np.arcsin(radius / np.linalg.norm(e))), rel=1e-12)
    finally:
        sp.kclear()
    assert 0.9 < seq.planet_radii_deg[0] < 1.0
    planets = seq.planets(0.434)
    assert planets is not None and len(planets) == 3 and planets[1].geometric_albedo == 0.434
    assert spice_sequence(kernels, utc=f"{START_UTC},{START_UTC},1", **ARGS).planets(0.4) \
        is None
    with pytest.raises(ValueError, match="radii of planet 'MARS'"):
        spice_sequence(kernels, utc=f"{START_UTC},{START_UTC},1", planet="MARS", **ARGS)


def test_kernels_listed_one_by_one_and_ephemeris_times(kernels):
    files = [str(kernels.parent / n) for n in ("test.tls", "moon.tpc", "craft.tsc",
                                               "craft.tf", "craft.ti", "craft.bsp", "craft.bc")]
    a = spice_sequence(",".join(files), utc=f"{START_UTC},2025-03-01T12:00:20,10", **ARGS)
    b = spice_sequence(files, et=a.poses.time_s, **ARGS)
    np.testing.assert_array_equal(a.poses.position_m, b.poses.position_m)
    np.testing.assert_array_equal(a.sun_directions, b.sun_directions)


def test_bad_kernels_and_times_give_one_line_naming_them(kernels, tmp_path):
    with pytest.raises(FileNotFoundError, match="SPICE kernel '.*nope.bsp' does not exist"):
        spice_sequence(str(tmp_path / "nope.bsp"), et=[0.0], **ARGS)
    junk = tmp_path / "junk.bsp"
    junk.write_bytes(b"\x00not a kernel" * 20)
    with pytest.raises(ValueError, match="SPICE kernel '.*junk.bsp' is not a SPICE") as err:
        spice_sequence([str(kernels), str(junk)], et=[0.0], **ARGS)
    assert "\n" not in str(err.value)
    broken = tmp_path / "broken.tm"
    broken.write_text("KPL/MK\n\\begindata\nKERNELS_TO_LOAD = ( 'gone.bsp' )\n"
                      "\\begintext\n")
    with pytest.raises(ValueError, match="SPICE kernel '.*broken.tm'.*gone.bsp") as err:
        spice_sequence(broken, et=[0.0], **ARGS)
    assert "\n" not in str(err.value)
    with pytest.raises(ValueError, match="no observer 'TESTCRAFT'.*2030") as err:
        spice_sequence(kernels, utc="2030-01-01,2030-01-01T00:00:10,5", **ARGS)
    assert "\n" not in str(err.value)
    with pytest.raises(ValueError, match="camera frame 'NO_SUCH_FRAME'"):
        spice_sequence(kernels, utc=f"{START_UTC},{START_UTC},1",
                       **{**ARGS, "camera_frame": "NO_SUCH_FRAME"})
    lsk_less = [str(kernels.parent / n) for n in ("moon.tpc", "craft.bsp")]
    with pytest.raises(ValueError, match="leapseconds"):
        spice_sequence(lsk_less, utc=f"{START_UTC},{START_UTC},1", **ARGS)
    for utc in ("2025-03-01", "a,b,-1", "a,b,x"):
        with pytest.raises(ParameterError, match="utc"):
            spice_sequence(kernels, utc=utc, **ARGS)
    with pytest.raises(ParameterError, match="at most"):
        spice_sequence(kernels, utc=f"{START_UTC},2025-03-02T12:00:00,0.01", **ARGS)
    assert sp.ktotal("ALL") == 0


def test_the_camera_command_flies_a_spice_sequence(kernels, run_cli, tmp_path):
    from latlong import Body, LatLongGrid

    model = tmp_path / "moon.npz"
    Body.sphere(LatLongGrid(40), 1737400.0).save(model)
    spice = ["--spice", str(kernels), "--utc", f"{START_UTC},2025-03-01T12:01:00,20",
             "--target", "MOON", "--observer", "TESTCRAFT", "--frame", "IAU_MOON",
             "--instrument-frame", CAM_FRAME]
    out = tmp_path / "frames"
    proc = run_cli("latlong", "camera", str(model), "-o", str(out), "--instrument", "TESTCAM",
                   *spice, "-q")
    assert proc.returncode == 0, proc.stderr
    import json

    doc = json.loads((out / "frames.json").read_text())
    seq = spice_sequence(kernels, utc=f"{START_UTC},2025-03-01T12:01:00,20", **ARGS)
    assert len(doc["frames"]) == 4
    assert doc["intrinsics"] == {"fx": 100.0, "fy": 100.0, "cx": 32.0, "cy": 24.0,
                                 "width": 64, "height": 48}  # from the instrument kernel
    depth = np.load(out / doc["frames"][0]["files"]["depth"]) if str(
        doc["frames"][0]["files"]["depth"]).endswith(".npy") else None
    if depth is None:
        from PIL import Image

        depth = np.asarray(Image.open(out / doc["frames"][0]["files"]["depth"]))
    # the camera looks down at the Moon from 100 km: the surface fills the frame
    assert np.isfinite(depth).all() and np.nanmax(depth) < 2e5
    for k, frame in enumerate(doc["frames"]):
        assert frame["utc"] == seq.utc[k] and frame["et_s"] == frame["time_s"]
        assert frame["time_s"] == seq.poses.time_s[k]
        assert frame["position_m"] == seq.poses.position_m[k].tolist()
        assert angle(frame["sun_direction"], seq.sun_directions[k]) <= 1e-9
    # one-line errors, exit 2: a missing option, a missing kernel, both suns
    for extra, message in (([], "--instrument-frame"),
                           (["--spice", str(tmp_path / "gone.tm")], "gone.tm"),
                           (["--sun-direction", "1,0,0"], "not both")):
        args = spice[:-2] if message == "--instrument-frame" else spice
        if extra[:1] == ["--spice"]:
            args = extra + spice[2:]
            extra = []
        proc = run_cli("latlong", "camera", str(model), "-o", str(tmp_path / "x"),
                       "--fov-deg", "20", "--size", "40x30", *args, *extra, "-q")
        assert proc.returncode == 2 and message in proc.stderr, proc.stderr
        assert proc.stderr.count("\n") == 1 and "Traceback" not in proc.stderr


def test_the_camera_command_takes_the_planet_from_the_kernels(kernels, run_cli, tmp_path):
    import json

    from latlong import Body, LatLongGrid

    model = tmp_path / "moon.npz"
    Body.sphere(LatLongGrid(20), 1737400.0).save(model)
    utc = f"{START_UTC},2025-03-01T12:00:30,30"
    spice = ["--spice", str(kernels), "--utc", utc, "--target", "MOON", "--observer",
             "TESTCRAFT", "--frame", "IAU_MOON", "--instrument-frame", CAM_FRAME]
    out = tmp_path / "frames"
    proc = run_cli("latlong", "camera", str(model), "-o", str(out), "--fov-deg", "20",
                   "--size", "16x12", *spice, "--planet", "EARTH", "-q")
    assert proc.returncode == 0, proc.stderr
    doc = json.loads((out / "frames.json").read_text())
    seq = spice_sequence(kernels, utc=utc, planet="EARTH", **ARGS)
    for k, frame in enumerate(doc["frames"]):
        assert angle(frame["planet"]["direction"], seq.planet_directions[k]) <= 1e-12
        assert frame["planet"]["angular_radius_deg"] == seq.planet_radii_deg[k]
        assert frame["planet"]["geometric_albedo"] == 0.2
        assert 0.0 < frame["planet"]["irradiance_ratio"] < 6.0e-5
    for args, message in ((["--planet", "EARTH", "--fov-deg", "20", "--size", "16x12",
                            "--sun-direction", "1,0,0"], "--spice"),
                          ([*spice, "--planet", "EARTH", "--planet-direction", "0,0,1",
                            "--fov-deg", "20", "--size", "16x12"], "not both")):
        proc = run_cli("latlong", "camera", str(model), "-o", str(tmp_path / "x"), *args,
                       "--position-m", "0,0,3000000", "--quaternion", "0,1,0,0", "-q") \
            if "--spice" not in args else \
            run_cli("latlong", "camera", str(model), "-o", str(tmp_path / "x"), *args, "-q")
        assert proc.returncode == 2 and message in proc.stderr, proc.stderr
        assert proc.stderr.count("\n") == 1 and "Traceback" not in proc.stderr


def test_the_instrument_kernel_gives_the_camera(kernels):
    cam = spice_camera(kernels, "TESTCAM")
    assert (cam.width, cam.height, cam.fx, cam.fy, cam.cx, cam.cy) == (64, 48, 100.0, 100.0,
                                                                        32.0, 24.0)
    wide = spice_camera(kernels, "-9999001", k1=-0.01)
    assert (wide.width, wide.height) == (80, 60) and wide.k1 == -0.01
    assert (wide.cx, wide.cy) == (41.25, 29.5)  # INS-9999001_CCD_CENTER
    # the field of view's half-angles, 10 and 7.5 degrees, reach the image's edges
    assert wide.fx == pytest.approx(40.0 / np.tan(np.radians(10.0)), rel=1e-12)
    assert wide.fy == pytest.approx(30.0 / np.tan(np.radians(7.5)), rel=1e-12)
    with pytest.raises(ValueError, match="instrument 'NOPE'"):
        spice_camera(kernels, "NOPE")
    with pytest.raises(ValueError, match="INS-9999002_PIXEL_SAMPLES"):
        spice_camera(kernels, "-9999002")
    assert sp.ktotal("ALL") == 0
