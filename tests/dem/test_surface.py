"""DEM sites as surfaces (dem.DemSurface): the camera and the LIDAR of latlong.sensors see a
layer stack through the same calls as a body; ``dem camera`` / ``dem lidar``."""

from __future__ import annotations

import json

import numpy as np
import pytest
from affine import Affine
from PIL import Image

import craters
import dem
import latlong
from latlong.geometry.surface import Surface
from latlong.sensors import (
    Camera,
    CameraSettings,
    LidarSettings,
    Pose,
    Poses,
    camera_run,
    lidar_frame,
    lidar_run,
    render,
    scene_geometry,
)


@pytest.fixture(scope="module")
def stack():
    """Three 33 x 33 layers (100, 50, 25 m pixels) with craters and boulders."""
    seed = dem.Dem(np.random.default_rng(2).normal(0, 30, (9, 9)), pixel_size_m=400.0)
    e = dem.expand(seed, 2, fractal_dimension=2.3, roughness=0.05, rng=1)  # 33^2, 100 m
    base = dem.Dem(e.heights, Affine(100.0, 0, 1000.0, 0, -100.0, 9000.0), "EPSG:32633")
    x, y = base.xy(16, 16)
    return dem.enhance({"layers": 3, "size": 33, "seed": 1, "target": [float(x), float(y)],
                        "craters": ["c=0.05,k=-2,d_min_m=20,d_max_m=800"],
                        "boulders": ["c=0.05,k=-2,d_min_m=50,d_max_m=120"]}, dem=base)


@pytest.fixture(scope="module")
def body():
    """A 500 m sphere with three craters facing +x."""
    cat = craters.make_catalog(lat_deg=[0.0, 12.0, -10.0], lon_deg=[0.0, 8.0, -12.0],
                               diameter_m=[160.0, 90.0, 70.0])
    return latlong.stamp_craters(latlong.Body.sphere(latlong.LatLongGrid(48), 500.0), cat,
                                 rng=1)


def _ground_z(site: dem.DemSurface, x: float, y: float) -> float:
    """Height of the site's mesh straight below (x, y), metres."""
    from latlong.sensors import RayMesh

    mesh = RayMesh(*site.mesh())
    return float(1e4 - mesh.intersect([[x, y, 1e4]], [[0.0, 0.0, -1.0]]).t_m[0])


def test_a_site_implements_the_surface_protocol(stack, tmp_path):
    site = dem.DemSurface(stack)
    assert isinstance(site, Surface)
    v, f = site.mesh()
    v_ref, f_ref, _ = dem.mesh.mesh_arrays(stack)
    np.testing.assert_array_equal(v, v_ref)
    np.testing.assert_array_equal(f, f_ref)
    n = site.vertex_normals()
    assert n.shape == v.shape and (n[:, 2] > 0.5).all()
    np.testing.assert_allclose(np.linalg.norm(n, axis=1), 1.0)
    assert site.local_frames(v[:2]).tolist() == [np.eye(3).tolist()] * 2
    # the catalogs of every layer, coarsest first; the boulders' mesh ids are their index
    assert len(site.craters) == sum(len(c) for c in stack.catalogs if c is not None) > 10
    assert {"x_m", "y_m", "diameter_m"} <= set(site.craters.dtype.names)
    assert len(site.boulders) == sum(len(b) for b in stack.boulders if b is not None) > 0
    assert site.metadata["pixel_sizes_m"] == stack.pixel_sizes_m()
    json.dumps(site.metadata)
    src = site.mesh_source()
    assert src.n_faces > len(f)  # the boulders after the terrain
    assert site.save(tmp_path / "a.ply").read_bytes() == \
        dem.to_mesh(stack, tmp_path / "b.ply").read_bytes()
    with pytest.raises(ValueError, match="weighting"):
        site.vertex_normals("cotangent")


def test_the_camera_renders_a_stack_and_a_body_through_the_same_call(stack, body, tmp_path):
    """One function, two surfaces: the frames are lit, their depths match the poses'
    distances to the ground, and the crater labels are there."""
    site = dem.DemSurface(stack)
    ground = _ground_z(site, 0.0, 0.0)
    views = {  # surface, pose, distance from the camera to the ground at the image centre
        "site": (site, Pose.look_at([0.0, 0.0, ground + 1500.0], [0.0, 0.0, ground],
                                    up=(0.0, 1.0, 0.0)), 1500.0),
        "body": (body, Pose.look_at([1500.0, 0.0, 0.0], [0.0, 0.0, 0.0]),
                 1500.0 - body.radii_m[np.argmax(body.grid.unit_vectors()[:, 0])]),
    }
    settings = CameraSettings(Camera.from_fov(40.0, 64, 48))
    for name, (surface, pose, distance) in views.items():
        doc = camera_run(surface, settings, Poses.of([pose]), [1.0, 0.4, 0.6], tmp_path / name)
        (frame,) = doc["frames"]
        image = np.asarray(Image.open(tmp_path / name / frame["files"]["image"]))
        depth = np.asarray(Image.open(tmp_path / name / frame["files"]["depth"]))
        crater_id = np.asarray(Image.open(tmp_path / name / frame["files"]["crater_id"]))
        assert (image > 0).mean() > 0.3, name
        assert abs(depth[24, 32] - distance) < 0.02 * distance, name
        assert np.nanmin(depth) > 0.8 * distance and np.nanmax(depth) < 1.6 * distance
        assert (crater_id >= 0).sum() > 20 and len(frame["rim_ellipses"]) >= 1, name
        # the per-frame call sees the same surface the same way
        one = render(surface, settings.camera, pose, [1.0, 0.4, 0.6])
        np.testing.assert_array_equal(one.depth_m, depth)
        np.testing.assert_array_equal(one.crater_id, crater_id)


def test_a_lidar_frame_of_a_site(stack, tmp_path):
    site = dem.DemSurface(stack)
    rock = site.boulders[0]
    top = np.array([rock["centre_x_m"], rock["centre_y_m"], rock["centre_z_m"]])
    down = Pose.look_at(top + [0.0, 0.0, 800.0], top, up=(0.0, 1.0, 0.0)).quaternion_wxyz
    fr = lidar_frame(site, LidarSettings(beams=(48, 36), fov_deg=40.0), top + [0, 0, 800.0],
                     down)
    assert len(fr) > 0.9 * 48 * 36
    ground = _ground_z(site, top[0], top[1])
    assert np.nanmax(fr.range_image) < 1.3 * (top[2] + 800.0 - ground)
    assert (fr.crater_id >= 0).any()
    # the beam straight down the boulder's centre returns its id (the stack's index)
    centre = fr.beam == 18 * 48 + 24
    assert fr.boulder_id[centre].tolist() == [int(rock["index"])]
    # a run over the same site, read back from the stack's folder
    stack.write(tmp_path / "site")
    man = lidar_run(dem.DemSurface.read(tmp_path / "site"), LidarSettings(beams=(16, 12)),
                    Poses.one(top + [0, 0, 800.0], down), tmp_path / "run", rng=3)
    assert man["model"] == str(tmp_path / "site") and man["frames"][0]["n_returns"] > 100


def test_one_dem_is_a_site_and_catalogs_drape_on_it(lola_crop):
    from rasterio.windows import Window

    small = lola_crop.crop(Window(100, 100, 17, 17))
    site = dem.DemSurface(small)
    assert site.craters is None and site.boulders is None
    v, _ = site.mesh()
    cat = craters.make_catalog(x_m=[0.0, 1e9], y_m=[0.0, 0.0], diameter_m=[5000.0, 10.0])
    geo = scene_geometry(site, craters=cat)
    centre = np.argmin(np.hypot(v[:, 0], v[:, 1]))  # the centre pixel: the origin
    assert np.hypot(*v[centre, :2]) < 1e-6
    assert geo.craters["centre_z_m"][0] == pytest.approx(v[centre, 2])
    assert np.isnan(geo.craters["centre_z_m"][1]) and geo.craters["normal_z"].tolist() == [1, 1]


def test_dem_camera_and_lidar_commands(run_cli, stack, tmp_path):
    folder = tmp_path / "site"
    stack.write(folder)
    ground = _ground_z(dem.DemSurface(stack), 0.0, 0.0)
    out = tmp_path / "frames"
    proc = run_cli("dem", "camera", str(folder / "manifest.json"), "-o", str(out),
                   "--target-m", f"0,0,{ground}", "--range-m", "2000,1000", "--frames", "2",
                   "--fov-deg", "40", "--size", "40x30", "--sun-direction", "1,0.2,0.5", "-q")
    assert proc.returncode == 0, proc.stderr
    doc = json.loads((out / "frames.json").read_text())
    assert [round(f["position_m"][2] - ground) for f in doc["frames"]] == [2000, 1000]
    assert any(f["rim_ellipses"] for f in doc["frames"])
    tif = tmp_path / "layer.tif"
    dem.write(stack.layers[2], tif)
    proc = run_cli("dem", "lidar", str(tif), "-o", str(tmp_path / "lidar"), "--target-m",
                   "0,0,0", "--range-m", "900,900", "--frames", "1", "--beams", "8x8",
                   "--seed", "1", "-q")
    assert proc.returncode == 0, proc.stderr
    doc = json.loads((tmp_path / "lidar" / "lidar.json").read_text())
    assert doc["seed"] == 1
    # a site's points are in its local frame: an engineering CRS naming the DEM's CRS
    import laspy
    import pyproj

    las = laspy.read(tmp_path / "lidar" / doc["frames"][0]["files"]["points"])
    crs = las.header.parse_crs()
    assert las.header.global_encoding.wkt and crs == pyproj.CRS.from_wkt(doc["crs_wkt"])
    assert crs.type_name == "Engineering CRS" and "metres east, north, up" in crs.name
    bad = run_cli("dem", "camera", str(tif), "-o", str(tmp_path / "x"), "--target-m",
                  "0,0,0", "--range-m", "900,900", "--size", "8x8", "--sun-direction",
                  "0,0,1", "--fov-deg", "30", "--soft-shadow-samples", "5000")
    assert bad.returncode == 2 and bad.stderr.startswith("error: --soft-shadow-samples")
    assert not (tmp_path / "x").exists()
