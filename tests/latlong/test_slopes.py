"""Slopes and radius spectra on bodies and meshes."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from scipy.special import sph_harm_y

from latlong import (
    Body,
    LatLongGrid,
    facet_slopes,
    mesh_slopes,
    radius_spectrum,
    read_shape_model,
    slope_summary,
    slopes,
    slopes_and_areas,
    vertex_normals,
)
from latlong.shapes import ShapeModel
from latlong.slopes import direction_cap_sums

DATA = Path(__file__).parents[1] / "data"
ELLIPSOID_RMS_DEG = 0.5


def ellipsoid_angle(body):
    """Analytic angle between the stretched sphere's normal (S^-2 p) and the radial p."""
    p = body.vertices()
    n = p / np.asarray(body.stretch) ** 2
    return np.degrees(np.arctan2(np.linalg.norm(np.cross(n, p), axis=1),
                                 np.einsum("ij,ij->i", n, p)))


def test_ellipsoid_slopes_match_the_analytic_angle():
    body = Body.sphere(LatLongGrid(400), 100.0, stretch=(2.0, 1.0, 1.0))
    s = slopes(body, 3.0)
    rms = float(np.sqrt(np.mean((s - ellipsoid_angle(body)) ** 2)))
    assert rms <= ELLIPSOID_RMS_DEG
    assert rms < 0.05  # measured 0.006


def reference_cap_average(body, radius_deg, weighted):
    """Brute force: every vertex against every other vertex (small grids only)."""
    normals, area = vertex_normals(body)
    u = body.grid.unit_vectors()
    w = normals * (area[:, None] if weighted else 1.0)
    inside = u @ u.T >= math.cos(math.radians(radius_deg)) - 1e-12
    avg = inside @ w
    p = body.vertices()
    return np.degrees(np.arctan2(np.linalg.norm(np.cross(avg, p), axis=1),
                                 np.einsum("ij,ij->i", avg, p)))


@pytest.mark.parametrize("weighted", [True, False])
@pytest.mark.parametrize("radius_deg", [0.0, 7.3, 20.5, 88.7])
def test_cap_average_matches_brute_force(rng, weighted, radius_deg):
    g = LatLongGrid(14)
    body = Body(g, 10.0 + rng.uniform(0, 1.0, g.n_vertices), stretch=(1.3, 1.0, 0.8))
    got = slopes(body, radius_deg, weighted=weighted)
    if radius_deg == 0:
        normals, _ = vertex_normals(body)
        p = body.vertices()
        want = np.degrees(np.arctan2(np.linalg.norm(np.cross(normals, p), axis=1),
                                     np.einsum("ij,ij->i", normals, p)))
    else:
        want = reference_cap_average(body, radius_deg, weighted)
    # vertices exactly on a cap boundary may be counted differently: almost all agree
    assert np.mean(np.abs(got - want) < 1e-9) > 0.97


def test_sphere_is_flat_and_facets():
    # a hard 3 degree cap takes the vertices near its edge unevenly, which tilts the mean
    # by a fraction of the vertex spacing: 0.76 deg at M = 40 (2.25 deg spacing), 0.08
    # deg at M = 200
    assert slopes(Body.sphere(LatLongGrid(200), 5.0)).max() < 0.1
    body = Body.sphere(LatLongGrid(40), 5.0)
    assert slopes(body).max() < 1.0
    s, a = facet_slopes(body)
    assert len(s) == body.grid.n_triangles and s.max() < 5.0
    assert a.sum() == pytest.approx(4 * np.pi * 25, rel=0.01)


def test_mesh_slopes_agree_with_body_slopes():
    body = Body.sphere(LatLongGrid(40), 50.0, stretch=(1.5, 1.0, 1.0))
    mesh = body.to_pyvista()
    model = ShapeModel(np.asarray(mesh.points), np.asarray(mesh.faces).reshape(-1, 4)[:, 1:])
    a, area_a = slopes_and_areas(body, 5.0)
    b, area_b = mesh_slopes(model, 5.0, center="origin")
    assert np.allclose(area_a, area_b)
    assert np.sqrt(np.mean((a - b) ** 2)) < 0.5  # caps from grid vs actual directions


def test_real_model_slopes():
    eros = read_shape_model(DATA / "eros001708.tab", units="km")
    s, area = mesh_slopes(eros)
    summary = slope_summary(s, area)
    assert 25 < summary["median_deg"] < 60  # an elongated body: shape-dominated
    assert summary["area_fraction"].sum() == pytest.approx(1.0)


def test_slope_summary():
    s = np.array([1.0, 5.0, 11.0, 25.0, 40.0])
    w = np.array([1.0, 1.0, 1.0, 1.0, 4.0])
    out = slope_summary(s, w)
    assert out["percent_above"][10] == pytest.approx(75.0)
    assert out["percent_above"][30] == pytest.approx(50.0)
    assert out["median_deg"] == 25.0
    assert out["edges_deg"][1] == 3.0 and out["above_percent"][0] == pytest.approx(100.0)
    with pytest.raises(ValueError, match="same length"):
        slope_summary([1.0], [1.0, 2.0])


@pytest.mark.parametrize("lm", [(1, 0), (3, 2), (10, 7), (40, 30)])
def test_radius_spectrum_recovers_a_harmonic(lm):
    g = LatLongGrid(100)
    theta, phi = np.pi / 2 - g.latitudes(), g.longitudes()
    deg, m = lm
    y = np.real(sph_harm_y(deg, m, theta, phi)) * (np.sqrt(2) if m else 1.0)  # unit power
    body = Body(g, 50.0 + 0.5 * y, radius_m=50.0)
    degrees, power = radius_spectrum(body, 60)
    assert power[deg] == pytest.approx(0.25, rel=2e-3)  # ring-zone quadrature error
    others = np.delete(power, [0, deg])
    assert others.max() < 1e-3 * 0.25 + 1e-3  # quadrature leakage of the mean
    assert power[0] == pytest.approx(4 * np.pi * 50.0**2, rel=1e-4)


def test_bad_inputs():
    with pytest.raises(TypeError, match="Body"):
        slopes("body")
    with pytest.raises(ValueError, match="radius_deg"):
        slopes(Body.sphere(LatLongGrid(3), 1.0), -1.0)


def reference_direction_cap_sums(dirs, values, chord):
    """Pure numpy: every point against every other point (small sets only)."""
    d2 = ((dirs[:, None, :] - dirs[None, :, :]) ** 2).sum(axis=2)
    return (d2 <= chord * chord) @ values


@pytest.mark.parametrize("chord", [1e-7, 0.05, 0.3, 1.2, 2.0])
def test_direction_cap_sums_match_brute_force(rng, chord):
    dirs = rng.normal(size=(700, 3))
    dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
    dirs[:40] = dirs[40:80]  # coincident directions
    values = rng.normal(size=(700, 3))
    got = direction_cap_sums(dirs, values, chord)
    np.testing.assert_allclose(got, reference_direction_cap_sums(dirs, values, chord),
                               rtol=1e-12, atol=1e-12)


def test_direction_cap_sums_thread_independent(rng):
    import numba

    dirs = rng.normal(size=(3000, 3))
    dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
    values = rng.normal(size=(3000, 3))
    before = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        one = direction_cap_sums(dirs, values, 0.1)
        numba.set_num_threads(numba.config.NUMBA_NUM_THREADS)
        many = direction_cap_sums(dirs, values, 0.1)
    finally:
        numba.set_num_threads(before)
    assert one.tobytes() == many.tobytes()


def known_spectrum_body(m, l_top, seed):
    """A body whose relief has exactly S_l = 4 l^-2 m^2 for 1 <= l <= l_top."""
    g = LatLongGrid(m)
    theta, phi = np.pi / 2 - g.latitudes(), g.longitudes()
    rng = np.random.default_rng(seed)
    r = np.full(g.n_vertices, 1000.0)
    for deg in range(1, l_top + 1):
        c = rng.normal(size=2 * deg + 1)
        c *= np.sqrt(4.0 * deg ** -2.0 / np.sum(c**2))
        for k, mm in enumerate(range(-deg, deg + 1)):
            y = sph_harm_y(deg, abs(mm), theta, phi)
            r += c[k] * (np.sqrt(2) * (np.real(y) if mm > 0 else np.imag(y)) if mm
                         else np.real(y))
    return Body(g, r, radius_m=1000.0)


def test_radius_spectrum_recovers_a_known_spectrum():
    # issue 16: transforming r (not r - R) leaked the mean into every degree (measured
    # 4400 % at l = 40 on this test's M = 100, l <= 40 version; now 0.03 %)
    body = known_spectrum_body(40, 20, seed=3)
    degrees, power = radius_spectrum(body, 26)
    want = 4.0 * degrees[1:21].astype(float) ** -2.0
    assert np.abs(power[1:21] / want - 1).max() < 0.02
    assert power[21:].sum() < 1e-3 * want.sum()
    assert power[0] == pytest.approx(4 * np.pi * 1000.0**2, rel=1e-6)
