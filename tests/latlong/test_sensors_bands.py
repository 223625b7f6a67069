"""Multi-band cameras (``render(..., bands=)``, ``--bands``): each band is the frame its
model alone would give, one exposure for all, one multi-band TIFF a frame."""

from __future__ import annotations

import json

import numpy as np
import pytest

from latlong import Body, LatLongGrid
from latlong.sensors import (
    Camera,
    Hapke,
    LunarLambert,
    Planet,
    Pose,
    RayMesh,
    Sensor,
    exposure_for,
    render,
)
from latlong.sensors.photometry import with_albedo
from latlong.sensors.stars import with_stars

SUN = np.array([0.3, 0.2, 1.0])
CAM = Camera.from_fov(50.0, 48, 40)
POSE = Pose.look_at([0.0, 0.0, 260.0], [0.0, 0.0, 0.0], up=(0.0, 1.0, 0.0))


@pytest.fixture(scope="module")
def bumpy():
    """A rough sphere of 100 m: shadows, bounced light and sky in one frame."""
    g = LatLongGrid(40)
    u = g.unit_vectors()
    r = 100.0 * (1.0 + 0.05 * np.sin(7 * u[:, 0]) * np.cos(5 * u[:, 1]))
    return RayMesh(u * r[:, None], g.triangles())


def test_each_band_is_its_models_frame(bumpy):
    red, blue = LunarLambert(0.14), LunarLambert(0.09)
    kw = {"bounces": 1, "bounce_samples": 4, "planet": Planet([0.0, 1.0, 0.2]), "seed": 5,
          "sensor": Sensor(photon_noise=True, read_noise_e=5.0, psf_sigma_px=0.7)}
    both = render(bumpy, CAM, POSE, SUN, bands={"red": red, "blue": blue}, **kw)
    assert both.bands == ("red", "blue") and both.image.shape == (40, 48, 2)
    for b, model in enumerate((red, blue)):
        one = render(bumpy, CAM, POSE, SUN, reflectance=model, **kw)
        np.testing.assert_array_equal(both.reflectance[:, :, b], one.reflectance)
        np.testing.assert_array_equal(both.albedo[:, :, b], one.albedo)
    # one shutter: the exposure of all bands together, the red band the brighter
    assert both.exposure_s == exposure_for(both.reflectance, kw["sensor"])
    lit = both.reflectance[:, :, 1] > 0
    dn = both.image.astype(np.float64)
    assert dn[:, :, 0][lit].sum() / dn[:, :, 1][lit].sum() == pytest.approx(0.14 / 0.09,
                                                                            rel=0.03)
    np.testing.assert_array_equal(both.depth_m, one.depth_m)
    # the same model twice: the same light, other noise
    twin = render(bumpy, CAM, POSE, SUN, bands={"a": red, "b": red}, **kw)
    np.testing.assert_array_equal(twin.reflectance[:, :, 0], twin.reflectance[:, :, 1])
    assert (twin.image[:, :, 0] != twin.image[:, :, 1]).mean() > 0.3
    # stars in every band of the sky
    starry = with_stars(both, Sensor(), seed=1)
    sky = both.face < 0
    assert sky.any() and (starry.reflectance[~sky] == both.reflectance[~sky]).all()


def test_bad_bands_are_named(bumpy):
    with pytest.raises(ValueError, match="bands.*not both"):
        render(bumpy, CAM, POSE, SUN, reflectance=LunarLambert(), bands={"r": LunarLambert()})
    for bands in ({}, {"r g": LunarLambert()}, ["r"]):
        with pytest.raises(ValueError, match="bands"):
            render(bumpy, CAM, POSE, SUN, bands=bands)
    assert with_albedo(Hapke(), 0.2) == Hapke(w=0.2)
    with pytest.raises(ValueError, match="w"):
        with_albedo(Hapke(), 1.5)


@pytest.mark.filterwarnings("ignore::rasterio.errors.NotGeoreferencedWarning")
def test_the_camera_command_writes_a_multi_band_tiff(run_cli, tmp_path):
    import rasterio
    from PIL import Image

    model = tmp_path / "rock.npz"
    Body.sphere(LatLongGrid(30), 100.0).save(model)
    out = tmp_path / "rgb"
    args = ["latlong", "camera", str(model), "--position-m", "0,0,300", "--quaternion",
            "0,1,0,0", "--fov-deg", "50", "--size", "40x30", "--sun-direction", "0.3,0.2,1",
            "--reflectance", "lunar-lambert"]
    proc = run_cli(*args, "-o", str(out), "--bands", "R=0.14,G=0.12,B=0.095",
                   "--depth-format", "exr", "-q")
    assert proc.returncode == 0, proc.stderr
    doc = json.loads((out / "frames.json").read_text())
    assert doc["settings"]["bands"] == {"R": 0.14, "G": 0.12, "B": 0.095}
    files = doc["frames"][0]["files"]
    with rasterio.open(out / files["image"]) as tif:
        assert (tif.count, tif.dtypes[0], tif.descriptions) == (3, "uint16", ("R", "G", "B"))
        dn = tif.read()
    lit = dn[2] > 0
    np.testing.assert_allclose((dn[0][lit] / dn[2][lit]).mean(), 0.14 / 0.095, rtol=0.02)
    assert np.asarray(Image.open(out / files["display"])).shape == (30, 40, 3)
    for spec, message in (("R=x", "albedo of band 'R'"), ("R=0.1,R=0.2", "twice"),
                          ("R", "NAME=ALBEDO"), ("R=20", "albedo")):
        proc = run_cli(*args, "-o", str(tmp_path / "bad"), "--bands", spec, "-q")
        assert proc.returncode == 2 and message in proc.stderr, proc.stderr
        assert proc.stderr.count("\n") == 1 and not (tmp_path / "bad").exists()
