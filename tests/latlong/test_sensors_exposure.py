"""Auto-exposure, the sRGB display picture and the OpenEXR ground truth of camera runs
(latlong.sensors.sensor, camera_files)."""

from __future__ import annotations

import json

import numpy as np
import pytest
from PIL import Image

from craters._shared import ParameterError
from latlong import Body, LatLongGrid
from latlong.sensors import Camera, Pose, RayMesh
from latlong.sensors.camera_files import CameraSettings, camera_run
from latlong.sensors.poses import Poses
from latlong.sensors.render import render
from latlong.sensors.sensor import DEFAULT_EXPOSURE_S, Sensor, display_image, expose, exposure_for

R = 1000.0
CAM = Camera.from_fov(40.0, 96, 72)
POSE = Pose.look_at([2600.0, 500.0, 300.0], [0.0, 0.0, 0.0])
SUN = np.array([0.3, 1.0, 0.4]) / np.linalg.norm([0.3, 1.0, 0.4])


@pytest.fixture(scope="module")
def sphere():
    g = LatLongGrid(60)
    return RayMesh(g.unit_vectors() * R, g.triangles())


def lit_percentile(image: np.ndarray, lit: np.ndarray, q: float = 95.0) -> float:
    return float(np.percentile(image[lit].astype(np.float64), q))


def test_auto_exposure_puts_the_lit_percentile_at_the_target(sphere):
    fr = render(sphere, CAM, POSE, SUN)  # the default Sensor: auto-exposure, 16 bits
    lit = fr.reflectance > 0
    assert lit.sum() > 1000 and (~lit).sum() > 1000  # sky and night side are in the frame
    got = lit_percentile(fr.image, lit) / 65535.0
    assert got == pytest.approx(0.75, abs=1.0 / 65535)
    # the exposure is recorded, and is what a fixed exposure of that length records
    fixed = expose(fr.reflectance, Sensor(exposure_s=fr.exposure_s))
    np.testing.assert_array_equal(fixed, fr.image)
    # other targets and percentiles; a fixed exposure is left alone
    s = Sensor(exposure_percentile=99.0, exposure_target=0.5)
    img = expose(fr.reflectance, s)
    assert lit_percentile(img, lit, 99.0) / 65535.0 == pytest.approx(0.5, abs=1.0 / 65535)
    assert exposure_for(fr.reflectance, Sensor(exposure_s=0.002)) == 0.002


def test_auto_exposure_of_a_dark_frame_and_bad_settings():
    assert exposure_for(np.zeros((4, 4))) == DEFAULT_EXPOSURE_S
    assert exposure_for(np.full((2, 2), np.nan)) == DEFAULT_EXPOSURE_S
    # a frame that needs a longer exposure gets it (no clipping to the fixed default)
    dim = np.full((8, 8), 1e-4)
    assert expose(dim)[0, 0] == round(0.75 * 65535)
    for key, bad in (("exposure_percentile", 40.0), ("exposure_percentile", 101.0),
                     ("exposure_target", 0.0), ("exposure_target", 1.5),
                     ("exposure_s", 0.0), ("exposure_s", -1.0)):
        with pytest.raises(ParameterError, match=key):
            Sensor(**{key: bad})


def test_the_display_picture_follows_the_srgb_curve():
    # IEC 61966-2-1: linear 0.0031308 is the knee (12.92 x it = 0.0404: 10 of 255),
    # linear 0.21586 is sRGB 128/255, linear 0.5 is sRGB 0.7354 (188 of 255), 1 is white
    lin = np.array([[0.0, 0.0031308, 0.21586, 0.5, 1.0, 2.0]])
    got = display_image(np.round(lin.clip(0, 1) * 65535).astype(np.uint16))
    assert got.dtype == np.uint8
    assert got.tolist() == [[0, 10, 128, 188, 255, 255]]
    assert display_image(np.array([[0, 255]], dtype=np.uint8)).tolist() == [[0, 255]]
    # a float I/F image: its lit 95th percentile is shown at 0.75 (sRGB 225)
    refl = np.linspace(0.0, 0.3, 101).reshape(1, -1)
    shown = display_image(refl)
    at = int(np.argmin(abs(refl[0] - np.percentile(refl[refl > 0], 95.0))))
    assert abs(int(shown[0, at]) - 225) <= 1 and shown[0, 0] == 0


def test_a_run_writes_display_pictures_exposures_and_openexr(sphere, tmp_path):
    import OpenEXR

    body = Body.sphere(LatLongGrid(60), R)

    poses = Poses.of([POSE, Pose.look_at([2400.0, 900.0, 300.0], [0.0, 0.0, 0.0])])
    runs = {}
    for fmt in ("tif", "exr"):
        settings = CameraSettings(CAM, depth_format=fmt, all_ground_truth=fmt == "tif")
        runs[fmt] = camera_run(body, settings, poses, SUN, tmp_path / fmt, mesh=sphere)
    doc = json.loads((tmp_path / "exr" / "frames.json").read_text())
    assert doc["settings"]["sensor"]["exposure_s"] is None  # auto
    for k, entry in enumerate(doc["frames"]):
        fr = render(sphere, CAM, poses[k], SUN)
        assert entry["exposure_s"] == fr.exposure_s
        files = entry["files"]
        shown = np.asarray(Image.open(tmp_path / "exr" / files["display"]))
        assert shown.dtype == np.uint8 and shown.shape == (CAM.height, CAM.width)
        np.testing.assert_array_equal(shown, display_image(fr.image))
        tif = runs["tif"]["frames"][k]["files"]

        def channels(name, files=files):
            with OpenEXR.File(str(tmp_path / "exr" / files[name])) as f:
                return {c: v.pixels for c, v in f.channels().items()}

        depth = channels("depth")
        assert set(depth) == {"Z"} and depth["Z"].dtype == np.float32
        want = np.asarray(Image.open(tmp_path / "tif" / tif["depth"]))
        np.testing.assert_array_equal(depth["Z"], want)
        np.testing.assert_array_equal(channels("range")["Z"], fr.range_m)
        normals = channels("normals")
        assert set(normals) == {"X", "Y", "Z"}
        np.testing.assert_array_equal(np.stack([normals[c] for c in "XYZ"], axis=-1),
                                      fr.normals)
        albedo = channels("albedo")
        assert set(albedo) == {"Y"}
        np.testing.assert_array_equal(albedo["Y"], fr.albedo)
        np.testing.assert_array_equal(
            albedo["Y"], np.load(tmp_path / "tif" / tif["albedo"]))
        # LommelSeeliger's default normal albedo on the sphere, NaN on the sky
        seen = fr.face >= 0
        assert np.allclose(albedo["Y"][seen], 0.12) and np.isnan(albedo["Y"][~seen]).all()


def test_label_images_as_openexr_keep_minus_one(tmp_path):
    from latlong.sensors.camera_files import write_frame

    g = LatLongGrid(20)
    fr = render(RayMesh(g.unit_vectors() * R, g.triangles()), CAM, POSE, SUN)
    ids = np.full((CAM.height, CAM.width), -1, dtype=np.int32)
    ids[10:20, 5:9] = 7
    fr = type(fr)(**{**{f: getattr(fr, f) for f in fr.__dataclass_fields__},
                     "crater_id": ids})
    files = write_frame(tmp_path, 0, fr, depth_format="exr")
    import OpenEXR

    with OpenEXR.File(str(tmp_path / files["crater_id"])) as f:
        got = f.channels()["id"].pixels
    assert got.dtype == np.uint32
    np.testing.assert_array_equal(got.view(np.int32), ids)
