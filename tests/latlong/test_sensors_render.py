"""Rendering (latlong.sensors.render / sensor): a sphere against its closed forms, cast
shadows, a crater's shadow against its profile, the sensor, determinism."""

from __future__ import annotations

import hashlib
import math
import os
import subprocess
import sys

import numpy as np
import pytest

import craters
from craters._shared import ParameterError
from latlong import LatLongGrid
from latlong.sensors import Camera, Lambert, LommelSeeliger, Pose, RayMesh, radiance_factor
from latlong.sensors.render import Sun, camera_inside, render
from latlong.sensors.scene_geometry import scene_mesh
from latlong.sensors.sensor import Sensor, expose

R = 1000.0


@pytest.fixture(scope="module")
def sphere():
    g = LatLongGrid(150)
    return RayMesh(g.unit_vectors() * R, g.triangles())


def analytic_sphere(camera, pose, sun_dir):
    """Closed-form ray/sphere distances, cos i, cos e per pixel (NaN off the sphere)."""
    o, d = camera.rays(pose)
    d = d.reshape(-1, 3)
    od = d @ o
    disc = od**2 - (o @ o - R * R)
    t = np.where(disc > 0, -od - np.sqrt(np.maximum(disc, 0.0)), np.nan)
    n = (o + t[:, None] * d) / R
    return t, n @ sun_dir, -(n * d).sum(axis=1), -(d @ sun_dir)


CAM = Camera.from_fov(45.0, 160, 120)
POSE = Pose.look_at([2600.0, 500.0, 300.0], [0.0, 0.0, 0.0])
SUN = np.array([0.3, 1.0, 0.4]) / np.linalg.norm([0.3, 1.0, 0.4])


@pytest.mark.parametrize("model", [Lambert(0.2), LommelSeeliger(0.15)])
def test_sphere_shading_is_the_closed_form(sphere, model):
    fr = render(sphere, CAM, POSE, SUN, reflectance=model)
    # the image is the model's closed form at the shading normals the frame reports
    # (the angle-weighted vertex normals blended, as Mitsuba's; float32 in the frame)
    p = fr.position_m.reshape(-1, 3)
    n = fr.normals.reshape(-1, 3).astype(np.float64)
    o = POSE.position_m
    d = (p - o) / np.linalg.norm(p - o, axis=1, keepdims=True)
    mu0, mu = n @ SUN, -(n * d).sum(axis=1)
    lit = fr.sunlit.ravel() > 0
    ref = radiance_factor(model, mu0[lit], mu[lit], -(d[lit] @ SUN))
    np.testing.assert_allclose(fr.reflectance.ravel()[lit], ref, rtol=2e-6, atol=2e-8)
    # angle-weighted normals of this sphere mesh are radial within 0.022 degrees
    u = sphere.vertices / R
    dev = np.degrees(np.arccos(np.clip((sphere.vertex_normals * u).sum(axis=1), -1, 1)))
    assert dev.max() < 0.025
    # against the analytic sphere: the facets lie inside it by the sag, which moves the
    # point along the ray; away from the terminator and limb that is < 1e-3 at M = 150
    t, mu0_a, mu_a, cg = analytic_sphere(CAM, POSE, SUN)
    an = radiance_factor(model, mu0_a, mu_a, cg)
    ok = lit & (mu0_a > math.cos(math.radians(80))) & (mu_a > math.cos(math.radians(80)))
    rel = np.abs(fr.reflectance.ravel()[ok] / an[ok] - 1)
    assert ok.sum() > 5000 and rel.max() < 1e-3
    assert np.median(rel) < 2e-5


def test_sphere_depth_range_and_terminator(sphere):
    fr = render(sphere, CAM, POSE, SUN)
    t, mu0_a, mu_a, _ = analytic_sphere(CAM, POSE, SUN)
    o, d = CAM.rays(POSE)
    hits = sphere.intersect(o, d.reshape(-1, 3))
    both = np.isfinite(t) & hits.hit
    # the float32 images are the float64 ranges rounded
    np.testing.assert_array_equal(fr.range_m.ravel()[hits.hit],
                                  hits.t_m[hits.hit].astype(np.float32))
    axis = d.reshape(-1, 3) @ POSE.rotation[:, 2]
    np.testing.assert_allclose(fr.depth_m.ravel()[both], (hits.t_m * axis)[both], rtol=1e-7)
    # the mesh lies inside the sphere by at most its sag; seen at emission e the range is
    # longer by sag / cos e (limb pixels excepted)
    edge = np.linalg.norm(np.diff(sphere.vertices[sphere.faces[:50]], axis=1), axis=2).max()
    sag = edge**2 / (3 * 2 * R) * 1.5
    ok = both & (mu_a > 0.2)
    dt = hits.t_m[ok] - t[ok]
    assert dt.min() > -1e-9 and (dt * mu_a[ok]).max() < sag
    # terminator: the lit state differs from the closed form only within a facet's
    # angular size of it
    lit = fr.sunlit.ravel() > 0
    differ = both & (lit != (mu0_a > 0))
    facet_rad = edge / R
    assert np.abs(mu0_a[differ]).max() < 2 * facet_rad
    assert (both & lit).sum() > 3000 and (both & ~lit).sum() > 1000


def test_cast_shadow_of_a_second_body():
    """A small sphere between the sun and a big one casts the closed-form shadow."""
    g = LatLongGrid(60)
    u, f = g.unit_vectors(), g.triangles()
    c2, r2 = np.array([0.0, 0.0, 1400.0]), 150.0
    mesh = RayMesh(np.concatenate([u * R, u * r2 + c2]), np.concatenate([f, f + len(u)]))
    cam = Camera.from_fov(30.0, 120, 120)
    pose = Pose.look_at([3000.0, 0.0, 2500.0], [0.0, 0.0, 1000.0])
    fr = render(mesh, cam, pose, [0.0, 0.0, 1.0])
    p = fr.position_m.reshape(-1, 3)
    on_big = np.abs(np.linalg.norm(p, axis=1) - R) < 5.0
    in_shadow = np.hypot(p[:, 0], p[:, 1]) < r2 * 0.95
    clear = np.hypot(p[:, 0], p[:, 1]) > r2 * 1.05
    lit = fr.sunlit.ravel() > 0
    assert (on_big & in_shadow).sum() > 50
    assert not lit[on_big & in_shadow].any()
    assert lit[on_big & clear & (p[:, 2] > 200)].all()


def crater_mesh(diameter_m, n):
    """A fresh crater (craters.radial_profile) on a square n x n vertex grid."""
    rad = diameter_m / 2
    xs = np.linspace(-1.6 * rad, 1.6 * rad, n)
    x, y = np.meshgrid(xs, xs)
    z = craters.radial_profile(np.hypot(x, y).ravel() / rad, diameter_m)
    idx = np.arange(n * n).reshape(n, n)
    a, b, c, d = idx[:-1, :-1].ravel(), idx[:-1, 1:].ravel(), idx[1:, :-1].ravel(), \
        idx[1:, 1:].ravel()
    faces = np.concatenate([np.column_stack([a, b, d]), np.column_stack([a, d, c])])
    return RayMesh(np.column_stack([x.ravel(), y.ravel(), z]), faces)


def profile_shadow_area(diameter_m, elevation_deg, dx=0.5):
    """Shadowed area inside the rim from the profile alone: sweep each line towards the
    sun with the running shadow height S(x) = max(h(x), S(x + dx) - dx tan(elevation))."""
    rad = diameter_m / 2
    tan_e = math.tan(math.radians(elevation_deg))
    xl = np.arange(-1.6 * rad, 1.6 * rad + dx, dx)
    area = 0.0
    for y in np.arange(-rad + 2 * dx, rad, 4 * dx):
        h = craters.radial_profile(np.hypot(xl, y) / rad, diameter_m)
        drop = dx * tan_e
        s = h.copy()
        for k in range(len(xl) - 2, -1, -1):
            s[k] = max(h[k], s[k + 1] - drop)
        area += ((np.hypot(xl, y) < rad) & (s > h + 1e-9)).sum() * dx * 4 * dx
    return area


def test_fresh_crater_shadow_at_low_sun():
    """Acceptance: at 10 degrees sun the shadowed floor matches the profile within 5 %."""
    diameter, elev = 1000.0, 10.0
    mesh = crater_mesh(diameter, 241)
    sun = [math.cos(math.radians(elev)), 0.0, math.sin(math.radians(elev))]
    height = 20_000.0
    cam = Camera.from_fov(2 * math.degrees(math.atan(0.55 * diameter / height)), 200, 200)
    pose = Pose.look_at([0, 0, height], [0, 0, 0], up=[0, 1, 0])
    fr = render(mesh, cam, pose, sun)
    p = fr.position_m.reshape(-1, 3)
    inside = np.hypot(p[:, 0], p[:, 1]) < diameter / 2
    footprint = (fr.depth_m.ravel().astype(float) / cam.fx) ** 2  # horizontal m^2
    rendered = footprint[inside & (fr.sunlit.ravel() == 0)].sum()
    expected = profile_shadow_area(diameter, elev)
    assert abs(rendered / expected - 1) < 0.05
    # the sun-side half of the floor is dark, the far wall bright
    floor = np.hypot(p[:, 0], p[:, 1]) < 0.45 * diameter  # not the lit rim crest
    assert fr.sunlit.ravel()[floor & (p[:, 0] > 0.1 * diameter)
                             & (np.abs(p[:, 1]) < 0.2 * diameter)].max() == 0
    assert fr.reflectance.ravel()[inside & (p[:, 0] < -0.4 * diameter)].min() > 0


def test_soft_shadows_make_a_penumbra():
    mesh = crater_mesh(400.0, 121)
    cam = Camera.from_fov(3.0, 64, 64)
    pose = Pose.look_at([0, 0, 8000.0], [0, 0, 0], up=[0, 1, 0])
    sun = Sun([math.cos(math.radians(12)), 0.0, math.sin(math.radians(12))],
              angular_radius_deg=2.0)
    hard = render(mesh, cam, pose, sun)
    soft = render(mesh, cam, pose, sun, soft_shadow_samples=32, seed=3)
    again = render(mesh, cam, pose, sun, soft_shadow_samples=32, seed=3)
    np.testing.assert_array_equal(soft.sunlit, again.sunlit)
    part = (soft.sunlit > 0) & (soft.sunlit < 1)
    assert part.sum() > 20
    assert set(np.unique(hard.sunlit[np.isfinite(hard.sunlit)])) <= {0.0, 1.0}
    assert abs(float(np.nansum(soft.sunlit)) / float(np.nansum(hard.sunlit)) - 1) < 0.1


def test_sensor_quantisation_noise_and_psf():
    refl = np.full((200, 200), 0.1)
    s = Sensor(exposure_s=0.01, flux_e_per_s=1e6, full_well_e=1e4, bits=16)  # 1000 e-
    clean = expose(refl, s)
    assert (clean == round(1000 * 65535 / 1e4)).all() and clean.dtype == np.uint16
    noisy = expose(refl, Sensor(exposure_s=0.01, flux_e_per_s=1e6, full_well_e=1e4,
                                photon_noise=True, read_noise_e=5.0), seed=7)
    e = noisy.astype(float) * 1e4 / 65535
    assert abs(e.mean() - 1000) < 2 and abs(e.var() / (1000 + 25) - 1) < 0.05
    np.testing.assert_array_equal(noisy, expose(refl, Sensor(
        exposure_s=0.01, flux_e_per_s=1e6, full_well_e=1e4, photon_noise=True,
        read_noise_e=5.0), seed=7))
    assert not np.array_equal(noisy, expose(refl, Sensor(
        exposure_s=0.01, flux_e_per_s=1e6, full_well_e=1e4, photon_noise=True,
        read_noise_e=5.0), seed=8))
    # small means: Poisson by inversion
    low = expose(np.full((300, 300), 1e-3), Sensor(flux_e_per_s=300.0, exposure_s=10.0,
                                                  photon_noise=True, bits=32))
    counts = low.astype(float) * 3000.0
    assert abs(counts.mean() - 3.0) < 0.05 and abs(counts.var() - 3.0) < 0.1
    assert np.allclose(counts, np.round(counts), atol=1e-3)
    # the PSF keeps the light and spreads a point
    dot = np.zeros((41, 41))
    dot[20, 20] = 1.0
    blurred = expose(dot, Sensor(psf_sigma_px=2.0, bits=32))
    assert abs(float(blurred.sum()) - 1.0) < 1e-5 and blurred[20, 24] > 0
    assert expose(np.array([[1.0]]), Sensor(bits=8)).dtype == np.uint8
    with pytest.raises(ParameterError, match="bits"):
        Sensor(bits=12)


def test_vertex_albedo_and_face_normals(sphere):
    base = render(sphere, CAM, POSE, SUN, reflectance=Lambert(0.2))
    twice = render(sphere, CAM, POSE, SUN, reflectance=Lambert(0.2),
                   vertex_albedo=np.full(len(sphere.vertices), 2.0))
    np.testing.assert_allclose(twice.reflectance, 2 * base.reflectance)
    flat = render(sphere, CAM, POSE, SUN, reflectance=Lambert(0.2), normals="face")
    hit = base.face >= 0
    assert not np.allclose(flat.reflectance[hit], base.reflectance[hit])
    with pytest.raises(ParameterError, match="normals"):
        render(sphere, CAM, POSE, SUN, normals="phong")
    with pytest.raises(ParameterError, match="vertex_albedo"):
        render(sphere, CAM, POSE, SUN, vertex_albedo=[1.0, 2.0])


def test_inputs_and_helpers(sphere):
    assert camera_inside(sphere, [0.0, 0.0, 0.0])
    assert not camera_inside(sphere, [3000.0, 0.0, 0.0])
    with pytest.raises(ParameterError, match="sun_direction"):
        Sun([0.0, 0.0, 0.0])
    assert abs(Sun.at_distance([1, 0, 0], 1.0).angular_radius_deg - 0.2666) < 1e-3
    with pytest.raises(TypeError, match="model"):
        scene_mesh("model.ply")
    g = LatLongGrid(4)
    assert isinstance(scene_mesh((g.unit_vectors(), g.triangles())), RayMesh)
    with pytest.raises(TypeError, match="camera"):
        render(sphere, None, POSE, SUN)


_FRAME_SCRIPT = """
import hashlib, numpy as np
from latlong import LatLongGrid
from latlong.sensors import Camera, Pose, RayMesh, HAPKE_PRESETS
from latlong.sensors.render import Sun, render
from latlong.sensors.sensor import Sensor
g = LatLongGrid(40)
u = g.unit_vectors()
radii = 1000 + 30 * np.sin(7 * u[:, :1]) * np.cos(5 * u[:, 1:2])
mesh = RayMesh(u * radii, g.triangles())
fr = render(mesh, Camera.from_fov(40, 96, 80), Pose.look_at([2800, 300, 200], [0, 0, 0]),
            Sun([1, 0.4, 0.2], 1.0), reflectance=HAPKE_PRESETS["moon"], soft_shadow_samples=8,
            sensor=Sensor(photon_noise=True, read_noise_e=3.0, psf_sigma_px=0.7), seed=11)
print(hashlib.sha256(b"".join(np.ascontiguousarray(a).tobytes() for a in (
    fr.image, fr.reflectance, fr.depth_m, fr.range_m, fr.normals, fr.face,
    fr.sunlit))).hexdigest())
"""


def test_same_bytes_for_any_thread_count():
    out = set()
    for threads in ("1", "2"):
        env = dict(os.environ, NUMBA_NUM_THREADS=threads)
        proc = subprocess.run([sys.executable, "-c", _FRAME_SCRIPT], capture_output=True,
                              text=True, env=env, check=True)
        out.add(proc.stdout.strip())
    assert len(out) == 1 and len(out.pop()) == len(hashlib.sha256().hexdigest())
