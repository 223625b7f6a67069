"""Planetshine (latlong.sensors.planetshine, ``render(..., planet=)``): the Lambert
sphere's phase law and irradiance ratio against a numerical integral over the planet's
surface, and a plane on the night side lit by the full Earth alone."""

from __future__ import annotations

import math

import numpy as np
import pytest

from latlong.sensors import Camera, Lambert, Planet, Pose, RayMesh
from latlong.sensors.planetshine import lambert_sphere_phase
from latlong.sensors.render import render


def fibonacci_sphere(n: int) -> np.ndarray:
    k = np.arange(n) + 0.5
    z = 1.0 - 2.0 * k / n
    phi = math.pi * (3.0 - math.sqrt(5.0)) * k
    r = np.sqrt(1.0 - z * z)
    return np.column_stack([r * np.cos(phi), r * np.sin(phi), z])


def planet_irradiance(albedo: float, radius: float, distance: float, alpha: float) -> float:
    """Irradiance (sun's = 1) at ``distance`` from a Lambert sphere of ``albedo`` seen at
    phase ``alpha``: sum over its surface of (albedo / pi) cos i cos e dA / r^2."""
    n = fibonacci_sphere(400_000)
    sun = np.array([1.0, 0.0, 0.0])
    observer = distance * np.array([math.cos(alpha), math.sin(alpha), 0.0])
    p = radius * n
    to_obs = observer - p
    r = np.linalg.norm(to_obs, axis=1)
    cos_i = np.clip(n @ sun, 0.0, None)
    cos_e = np.clip((n * to_obs).sum(axis=1) / r, 0.0, None)
    # the observer's facet faces the planet: one more cosine, ~1 for a small disk
    cos_o = (to_obs @ observer) / (r * distance)
    da = 4.0 * math.pi * radius**2 / len(n)
    return float((albedo / math.pi * cos_i * cos_e * cos_o / r**2).sum() * da)


def test_phase_law_is_the_lambert_spheres():
    assert lambert_sphere_phase(0.0) == pytest.approx(1.0, abs=1e-15)
    assert lambert_sphere_phase(math.pi / 2) == pytest.approx(1.0 / math.pi, abs=1e-15)
    assert lambert_sphere_phase(math.pi) == pytest.approx(0.0, abs=1e-15)
    full = planet_irradiance(0.3, 1.0, 1e4, 0.0)
    for alpha in np.radians([30.0, 60.0, 90.0, 120.0, 150.0]):
        got = planet_irradiance(0.3, 1.0, 1e4, alpha) / full
        assert got == pytest.approx(float(lambert_sphere_phase(alpha)), abs=2e-3)


@pytest.mark.parametrize("alpha_deg", [0.0, 70.0, 135.0])
def test_irradiance_ratio_integrates_the_planets_surface(alpha_deg):
    """p = 2/3 of a Lambert sphere's albedo; the ratio is its light over the sun's, far
    from the planet (at 60 radii, the Moon's distance from the Earth, the integral is
    1.2 % above the ratio when full, 2 % below at 90 degrees, 7 % below at 135)."""
    radius, distance, albedo = 1.0, 1e4, 0.6
    a = math.radians(alpha_deg)
    # the planet seen from the surface at `direction`; the sun such that the phase is a
    direction = -np.array([math.cos(a), math.sin(a), 0.0])
    planet = Planet(direction, math.degrees(math.asin(radius / distance)), 2.0 * albedo / 3.0)
    assert planet.phase_deg([1.0, 0.0, 0.0]) == pytest.approx(alpha_deg, abs=1e-9)
    want = planet_irradiance(albedo, radius, distance, a)
    assert planet.irradiance_ratio([1.0, 0.0, 0.0]) == pytest.approx(want, rel=3e-3)


def test_earth_lights_the_moons_night_side():
    earth = Planet([0.0, 0.0, 1.0])  # overhead; full Earth: the sun behind the Moon
    sun = np.array([0.1, 0.0, -1.0])
    ratio = earth.irradiance_ratio(sun)
    assert ratio == pytest.approx(0.2 * math.sin(math.radians(0.95)) ** 2
                                  * float(lambert_sphere_phase(math.radians(
                                      earth.phase_deg(sun)))), rel=1e-12)
    assert 5.0e-5 < ratio < 6.0e-5  # ~1/18 000 of sunlight
    v = np.array([[-500.0, -500.0, 0.0], [500.0, -500.0, 0.0], [500.0, 500.0, 0.0],
                  [-500.0, 500.0, 0.0]])
    plane = RayMesh(v, np.array([[0, 1, 2], [0, 2, 3]]))
    cam = Camera.from_fov(40.0, 32, 32)
    pose = Pose.look_at([0.0, 0.0, 300.0], [0.0, 0.0, 0.0], up=(0.0, 1.0, 0.0))
    kw = {"reflectance": Lambert(0.3), "normals": "face"}
    dark = render(plane, cam, pose, sun, **kw)
    lit = render(plane, cam, pose, sun, planet=earth, **kw)
    assert (dark.reflectance == 0).all() and (lit.face >= 0).all()
    np.testing.assert_allclose(lit.reflectance, ratio * 0.3, rtol=1e-12)
    # the auto-exposure finds the faint light: the frame is not black
    assert np.percentile(lit.image, 95) > 0.5 * 65535
    # a planet below the horizon sends nothing
    np.testing.assert_array_equal(
        render(plane, cam, pose, sun, planet=Planet([0.0, 0.3, -1.0]), **kw).reflectance, 0.0)


def test_bad_planets_are_named():
    for kw, name in (({"direction": [0, 0, 0]}, "planet_direction"),
                     ({"direction": [1, 0]}, "planet_direction"),
                     ({"direction": [1, 0, 0], "angular_radius_deg": 0.0},
                      "planet_angular_radius_deg"),
                     ({"direction": [1, 0, 0], "angular_radius_deg": 90.0},
                      "planet_angular_radius_deg"),
                     ({"direction": [1, 0, 0], "geometric_albedo": 1.5},
                      "planet_geometric_albedo")):
        with pytest.raises(ValueError, match=name):
            Planet(**kw)
    # huge components do not overflow the norm into a zero direction
    np.testing.assert_allclose(Planet([1e308, 0.0, 1e308]).direction,
                               [2**-0.5, 0.0, 2**-0.5], rtol=1e-15)
    v = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]])
    with pytest.raises(TypeError, match="planet"):
        render(RayMesh(v, np.array([[0, 1, 2]])), Camera.from_fov(40.0, 8, 8),
               Pose.look_at([0, 0, 5.0], [0, 0, 0.0], up=(0.0, 1.0, 0.0)), [0, 0, 1.0],
               planet=[0, 0, 1.0])
