"""The sensors see every kind of surface through the same calls (a lat/long body, a cratered
mesh surface, a mesh file), labelled by the surface's own catalogs."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import craters
import latlong
from latlong.mesh import mesh_surface
from latlong.sensors import (
    Camera,
    LidarSettings,
    Pose,
    RayMesh,
    lidar_frame,
    ray_scene,
    render,
    scene_geometry,
)

DATA = Path(__file__).resolve().parents[1] / "data"
CAM = Camera.from_fov(30.0, 40, 30)


@pytest.fixture(scope="module")
def body():
    cat = craters.make_catalog(lat_deg=[0.0, 5.0], lon_deg=[0.0, 10.0], diameter_m=[120.0, 60.0])
    return latlong.stamp_craters(latlong.Body.sphere(latlong.LatLongGrid(32), 400.0), cat, rng=2)


def test_a_body_a_mesh_surface_and_a_mesh_file_through_one_call(body, tmp_path):
    itokawa = mesh_surface(DATA / "itokawa_8.obj", 25.0, units="km")
    surfaces = {"body": body, "mesh surface": itokawa,
                "mesh file": latlong.load_surface(body.export(tmp_path / "b.ply"))}
    for name, surface in surfaces.items():
        far = 3.0 * float(np.abs(scene_geometry(surface).vertices).max())
        pose = Pose.look_at([far, 0.0, 0.0], [0.0, 0.0, 0.0])
        frame = render(surface, CAM, pose, [1.0, 0.3, 0.2])
        hit = frame.face >= 0
        assert hit.mean() > 0.05 and (frame.reflectance[hit] > 0).mean() > 0.5, name
        assert np.nanmin(frame.range_m) > far / 3.0, name
        # the same frame from the shared ray mesh and the geometry that labels it
        geometry, mesh = ray_scene(surface)
        again = render(mesh, CAM, pose, [1.0, 0.3, 0.2], ground_truth=geometry)
        np.testing.assert_array_equal(again.image, frame.image)
        np.testing.assert_array_equal(again.crater_id, frame.crater_id)
    # the body's catalog labels its frames and its LIDAR returns; a mesh file has none
    pose = Pose.look_at([1200.0, 0.0, 0.0], [0.0, 0.0, 0.0])
    assert (render(body, CAM, pose, [1.0, 0.0, 0.0]).crater_id == 0).sum() > 10
    fr = lidar_frame(body, LidarSettings(beams=(24, 18), fov_deg=30.0), pose.position_m,
                     pose.quaternion_wxyz)
    assert set(np.unique(fr.crater_id)) >= {-1, 0}
    plain = render(surfaces["mesh file"], CAM, pose, [1.0, 0.0, 0.0])
    assert (plain.crater_id == -1).all() and plain.boulder_id is not None


def test_what_is_not_a_surface_is_refused(body):
    with pytest.raises(TypeError, match="surface"):
        render("b.npz", CAM, Pose.look_at([900.0, 0, 0], [0, 0, 0]), [1.0, 0, 0])
    geometry, mesh = ray_scene(body)
    other = RayMesh([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]])
    with pytest.raises(ValueError, match="ground_truth"):
        render(other, CAM, Pose.look_at([900.0, 0, 0], [0, 0, 0]), [1.0, 0, 0],
               ground_truth=geometry)
    assert len(mesh.faces) == len(geometry.faces)
