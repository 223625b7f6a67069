"""Stars behind the body (latlong.sensors.stars): catalogue positions and brightness, and
frames where no surface is seen."""

from __future__ import annotations

import numpy as np
import pytest

from latlong import LatLongGrid
from latlong.sensors import Camera, Pose, RayMesh
from latlong.sensors.render import render
from latlong.sensors.sensor import Sensor
from latlong.sensors.stars import SUN_V_MAG, bright_stars, star_reflectance, with_stars

# Orion's belt, J2000: Alnitak, Alnilam, Mintaka (SIMBAD positions to 0.001 deg)
BELT = {"Alnitak": (85.18958, -1.94257), "Alnilam": (84.05339, -1.20192),
        "Mintaka": (83.00167, -0.29909)}


def towards(ra_deg: float, dec_deg: float) -> np.ndarray:
    ra, dec = np.radians(ra_deg), np.radians(dec_deg)
    return np.array([np.cos(dec) * np.cos(ra), np.cos(dec) * np.sin(ra), np.sin(dec)])


CAM = Camera.from_fov(8.0, 200, 160)
POSE = Pose.look_at([0.0, 0.0, 0.0], towards(84.05333, -1.20194), up=(0.0, 0.0, 1.0))


def test_the_catalogue_holds_the_bright_stars():
    dirs, vmag = bright_stars()
    assert len(vmag) == 5080 and vmag.min() == -1.46 and vmag.max() <= 6.0
    sirius = np.argmin(vmag)
    assert np.allclose(dirs[sirius], towards(101.28708, -16.71611), atol=1e-6)
    assert np.allclose(np.linalg.norm(dirs, axis=1), 1.0)


def test_stars_land_where_they_project_with_their_magnitude():
    img = star_reflectance(CAM, POSE)
    omega = 1.0 / (CAM.fx * CAM.fy)
    dirs, vmag = bright_stars()
    for name, (ra, dec) in BELT.items():
        near = dirs @ towards(ra, dec) > np.cos(np.radians(0.002))  # Alnitak is two stars
        assert 1 <= near.sum() <= 2 and vmag[near].min() < 2.3, name
        (px,), _ = CAM.project(dirs[near][np.argmin(vmag[near])][None, :] * 1e12, POSE)
        u, w = px - 0.5
        i, j = int(np.floor(u)), int(np.floor(w))
        patch = img[j:j + 2, i:i + 2]
        # the four pixels around it hold the stars' I/F: pi 10^(-0.4 (V - V_sun)) / Omega
        # (cos^3 of their fraction of a degree off the axis ~ 1)
        want = np.pi * np.sum(10 ** (-0.4 * (vmag[near] - SUN_V_MAG))) / omega
        assert patch.sum() == pytest.approx(want, rel=0.01), name
        if near.sum() > 1:
            continue
        # its centroid is its projection
        yy, xx = np.mgrid[j:j + 2, i:i + 2]
        assert (patch * xx).sum() / patch.sum() == pytest.approx(u, abs=1e-9)
        assert (patch * yy).sum() / patch.sum() == pytest.approx(w, abs=1e-9)
    assert np.count_nonzero(img) < 400  # points, not a glow


def test_a_sky_frame_is_exposed_on_its_stars_and_a_body_hides_them():
    g = LatLongGrid(20)
    # a 1 km sphere 50 km away along the view, covering the frame's middle
    centre = towards(84.05333, -1.20194) * 5e4
    mesh = RayMesh(g.unit_vectors() * 1000.0 + centre, g.triangles())
    frame = render(mesh, CAM, POSE, towards(84.05333, -1.20194) * -1.0)  # lit from behind
    starry = with_stars(frame, Sensor())
    sky = frame.face < 0
    assert (~sky).sum() > 500
    assert starry.reflectance[~sky].sum() == frame.reflectance[~sky].sum()
    assert np.count_nonzero(starry.reflectance[sky]) > 8
    # with the body lit, the sky's stars are faint against it (exposure from the body)
    far = render(mesh, CAM, Pose.look_at([0.0, 0.0, 0.0], -centre, up=(0.0, 0.0, 1.0)),
                 [1.0, 0.0, 0.0])
    only_sky = with_stars(far, Sensor())
    lit = only_sky.reflectance > 0
    assert (far.face < 0).all() and lit.sum() > 4
    top = np.percentile(only_sky.image[lit].astype(float), 95) / 65535
    assert top == pytest.approx(0.75, abs=2 / 65535)
