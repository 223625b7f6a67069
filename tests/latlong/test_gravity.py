"""Gravity of constant-density polyhedra (polyhedral-gravity) and slopes against it."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from scipy.special import elliprd

from latlong import Body, LatLongGrid, gravity, mesh_slopes, read_shape_model, slopes_and_areas
from latlong._gravity_kernels import _local_linear_kernel
from latlong.gravity import GRAVITATIONAL_CONSTANT as G
from latlong.gravity import polyhedron_gravity

pytest.importorskip("polyhedral_gravity")
DATA = Path(__file__).parents[1] / "data"
RHO = 2670.0


def prism_potential(lo, hi, p):
    """Closed-form potential of a homogeneous rectangular prism (Nagy et al. 2000,
    J. Geodesy 74, 552, eq. 7), geodetic sign (positive)."""
    total = 0.0
    for i, x in enumerate((lo[0] - p[0], hi[0] - p[0])):
        for j, y in enumerate((lo[1] - p[1], hi[1] - p[1])):
            for k, z in enumerate((lo[2] - p[2], hi[2] - p[2])):
                r = math.sqrt(x * x + y * y + z * z)
                term = (x * y * math.log(z + r) + y * z * math.log(x + r)
                        + z * x * math.log(y + r) - 0.5 * x * x * math.atan(y * z / (x * r))
                        - 0.5 * y * y * math.atan(z * x / (y * r))
                        - 0.5 * z * z * math.atan(x * y / (z * r)))
                total += (-1) ** (i + j + k + 1) * term
    return G * RHO * total


def box_mesh(lo, hi):
    v = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1])
                  for z in (lo[2], hi[2])], float)
    q = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    f = np.array([t for a, b, c, d in q for t in ((a, b, c), (a, c, d))], np.int64)
    return v, f


def test_prism_matches_its_closed_form():
    lo, hi = (-100.0, -60.0, -30.0), (140.0, 50.0, 45.0)
    v, f = box_mesh(lo, hi)
    assert np.einsum("ij,ij->", v[f[:, 0]], np.cross(v[f[:, 1]], v[f[:, 2]])) > 0  # outward
    pts = np.array([[300.0, 20.0, -10.0], [17.0, 230.0, 91.0], [-250.0, -170.0, 160.0],
                    [1.0e4, -3.0e3, 2.0e3]])
    pot, acc = polyhedron_gravity(v, f, RHO, pts)
    for n, (p, u, a) in enumerate(zip(pts, pot, acc, strict=True)):
        assert u == pytest.approx(prism_potential(lo, hi, p), rel=1e-10)
        if n == 3:  # far away the formula's terms cancel ~1e6-fold: no gradient check
            continue
        def diff(h, p=p):  # the formula's logs lose digits far away: wide differences
            return np.array([(prism_potential(lo, hi, p + h * e)
                              - prism_potential(lo, hi, p - h * e)) / (2 * h)
                             for e in np.eye(3)])

        grad = (4 * diff(0.25) - diff(0.5)) / 3  # Richardson: O(h^4)
        np.testing.assert_allclose(a, grad, rtol=1e-6, atol=1e-6 * np.linalg.norm(grad))


def ellipsoid_surface_acceleration(axes, pts):
    """Homogeneous ellipsoid, interior (and surface) attraction -2 pi G rho A_i x_i with
    A_i = a1 a2 a3 (2/3) R_D(a_j^2, a_k^2, a_i^2) (Chandrasekhar 1969, ch. 3; Carlson's
    symmetric integral)."""
    a2 = np.asarray(axes, float) ** 2
    pre = np.prod(axes) * 2.0 / 3.0
    coef = [pre * elliprd(a2[(i + 1) % 3], a2[(i + 2) % 3], a2[i]) for i in range(3)]
    return -2 * math.pi * G * RHO * np.asarray(coef) * pts


@pytest.mark.parametrize("stretch", [(1.0, 1.0, 1.0), (1.5, 1.0, 0.8)])
def test_sphere_and_ellipsoid_converge_to_the_closed_form(stretch):
    """The polyhedron inscribed in the smooth body differs from it by O(h^2): the error
    falls ~4x from M = 32 to 64 (M = 1000 gives ~5e-7, see the issue-16 note)."""
    errors = []
    for m in (32, 64):
        body = Body.sphere(LatLongGrid(m), 1000.0, stretch=stretch)
        v, f = body.vertices(), body.grid.triangles()
        idx = np.linspace(0, len(v) - 1, 25).astype(int)
        pts = v[idx] * (1 + 1e-7)
        _, acc = polyhedron_gravity(v, f, RHO, pts)
        want = ellipsoid_surface_acceleration(1000.0 * np.asarray(stretch), pts)
        errors.append(np.max(np.linalg.norm(acc - want, axis=1)
                             / np.linalg.norm(want, axis=1)))
    assert errors[1] < 1e-3
    assert 3.0 < errors[0] / errors[1] < 5.0


def test_far_point_sees_a_point_mass():
    eros = read_shape_model(DATA / "eros001708.tab", units="km")
    c = eros.volume_centroid
    mass = RHO * eros.volume_m3
    for direction in [*np.eye(3), np.array([0.6, -0.48, 0.64])]:
        p = c + 1.7e6 * direction  # 100 x the longest half-axis: quadrupole ~ 1e-4
        pot, acc = polyhedron_gravity(eros.vertices, eros.faces, RHO, p[None])
        r = np.linalg.norm(p - c)
        assert pot[0] == pytest.approx(G * mass / r, rel=1e-4)
        want = -G * mass * (p - c) / r**3
        assert np.linalg.norm(acc[0] - want) < 3e-4 * np.linalg.norm(want)


def test_body_interpolation_against_the_direct_evaluation():
    # magnitude 30 against its 15 (the direct evaluation is n^2: 36/18 took 28 s of CI's
    # 15 minutes, 30/15 7.5 s; 30/15: RMS 0.080 deg, max 0.76; 36/18: 0.058, 0.63)
    body = Body.sphere(LatLongGrid(30), 1000.0, stretch=(1.6, 1.0, 0.7))
    exact = gravity(body, RHO, 5.27, lod_magnitude=30)
    coarse = gravity(body, RHO, 5.27, lod_magnitude=15)
    assert exact.evaluated_points == body.grid.n_vertices
    cos = np.einsum("ij,ij->i", exact.effective_m_s2, coarse.effective_m_s2) / (
        np.linalg.norm(exact.effective_m_s2, axis=1)
        * np.linalg.norm(coarse.effective_m_s2, axis=1))
    angle = np.degrees(np.arccos(np.clip(cos, -1, 1)))
    assert np.sqrt(np.mean(angle**2)) < 0.1 and angle.max() < 1.0


def test_rotation_adds_the_centrifugal_term():
    body = Body.sphere(LatLongGrid(16), 1000.0)
    still = gravity(body, RHO)
    spin = gravity(body, RHO, 2.0, spin_axis=(0, 0, 3))
    omega = 2 * math.pi / 7200.0
    x = body.vertices() - np.array(spin.acceleration_m_s2 * 0)  # centroid ~ origin
    np.testing.assert_allclose(spin.acceleration_m_s2, still.acceleration_m_s2)
    want = still.acceleration_m_s2 + omega**2 * x * [1, 1, 0]
    np.testing.assert_allclose(spin.effective_m_s2, want, atol=1e-12)
    assert spin.spin_axis == (0.0, 0.0, 1.0) and spin.period_h == 2.0


def test_gravitational_slopes_of_a_sphere_are_flat():
    body = Body.sphere(LatLongGrid(40), 1000.0)
    s, _ = slopes_and_areas(body, 5.0, gravity=gravity(body, RHO))
    assert s.max() < 1.0


def test_mesh_subset_and_decimated_paths_and_determinism():
    eros = read_shape_model(DATA / "eros001708.tab", units="km")
    exact = gravity(eros, RHO, 5.27)
    assert exact.evaluated_points == len(eros.vertices)
    approx = gravity(eros, RHO, 5.27, max_pairs=8e5)  # decimated source
    assert approx.source_facets < len(eros.faces)
    a, area = mesh_slopes(eros, gravity=exact)
    b, _ = mesh_slopes(eros, gravity=approx)
    assert np.sqrt(np.average((a - b) ** 2, weights=area)) < 1.2  # measured 0.92
    again = gravity(eros, RHO, 5.27, max_pairs=8e5)
    assert again.effective_m_s2.tobytes() == approx.effective_m_s2.tobytes()
    # every facet, a subset of the vertices, the local linear fit for the others
    body = Body(LatLongGrid(20), 1000.0 + 30 * np.sin(3 * LatLongGrid(20).longitudes()),
                stretch=(1.6, 1.0, 0.8))
    mesh = body.to_pyvista()
    from latlong.shapes import ShapeModel

    model = ShapeModel(np.asarray(mesh.points), np.asarray(mesh.faces).reshape(-1, 4)[:, 1:])
    full = gravity(model, RHO, 5.27)
    sub = gravity(model, RHO, 5.27, max_pairs=1e7)
    assert sub.source_facets == len(model.faces) and sub.evaluated_points < len(model.vertices)
    a, area = mesh_slopes(model, gravity=full)
    b, _ = mesh_slopes(model, gravity=sub)
    assert np.sqrt(np.average((a - b) ** 2, weights=area)) < 0.3  # measured 0.17


def reference_local_linear(points, normals, src, vals, nb):
    out = np.empty((len(points), vals.shape[1]))
    for i, (p, n) in enumerate(zip(points, normals, strict=True)):
        axis = np.eye(3)[np.argmin(np.abs(n))]
        t = axis - (axis @ n) * n
        t /= np.linalg.norm(t)
        s = np.cross(n, t)
        d = src[nb[i]] - p
        d2 = (d**2).sum(axis=1)
        w = 1.0 / (d2 + d2.max())
        basis = np.stack([np.ones(len(d)), d @ t, d @ s], axis=1)
        a = (basis * w[:, None]).T @ basis
        out[i] = np.linalg.solve(a, (basis * w[:, None]).T @ vals[nb[i]])[0]
    return out


def test_local_linear_kernel_matches_numpy(rng):
    src = rng.normal(size=(200, 3))
    src /= np.linalg.norm(src, axis=1, keepdims=True)
    pts = rng.normal(size=(50, 3))
    pts /= np.linalg.norm(pts, axis=1, keepdims=True)
    vals = np.concatenate([src @ [[1.0, 2.0], [0.5, -1.0], [3.0, 0.0]],
                           rng.normal(size=(200, 1))], axis=1)
    nb = np.argsort(((pts[:, None] - src[None]) ** 2).sum(axis=2), axis=1)[:, :10]
    out = np.empty((50, 3))
    _local_linear_kernel(pts, pts.copy(), src, vals, np.ascontiguousarray(nb), out)
    np.testing.assert_allclose(out, reference_local_linear(pts, pts, src, vals, nb),
                               rtol=1e-9, atol=1e-9)


def test_bad_inputs():
    body = Body.sphere(LatLongGrid(4), 10.0)
    with pytest.raises(ValueError, match="density_kg_m3"):
        gravity(body, -1.0)
    with pytest.raises(ValueError, match="period_h"):
        gravity(body, 1000.0, 0.0)
    with pytest.raises(ValueError, match="spin_axis"):
        gravity(body, 1000.0, 5.0, spin_axis=(0, 0, 0))
    with pytest.raises(TypeError, match="Body or ShapeModel"):
        gravity("body", 1000.0)
