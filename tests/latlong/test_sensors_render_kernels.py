"""The render kernels against pure-numpy references."""

from __future__ import annotations

import numpy as np

from latlong.sensors._render_kernels import (
    _ground_truth_kernel,
    _shadow_rays_kernel,
    _surface_kernel,
)


def _rng_unit(rng, n):
    v = rng.normal(size=(n, 3))
    return v / np.linalg.norm(v, axis=1, keepdims=True)


def test_shadow_rays_match_numpy():
    rng = np.random.default_rng(1)
    pos = rng.normal(size=(50, 3)) * 300.0
    ng = _rng_unit(rng, 50)
    sun = np.array([0.6, 0.0, 0.8])
    centre = np.array([10.0, -5.0, 3.0])
    o, d = np.empty_like(pos), np.empty_like(pos)
    facing = np.empty(50, dtype=np.bool_)
    _shadow_rays_kernel(pos, ng, 2e-6, centre, 1e-4, sun, 0.0, 7, 0, o, d, facing)
    eps = np.maximum(2e-6 * np.linalg.norm(pos - centre, axis=1), 1e-4)
    np.testing.assert_allclose(o, pos + eps[:, None] * ng, rtol=0, atol=1e-12)
    np.testing.assert_array_equal(d, np.broadcast_to(sun, d.shape))
    np.testing.assert_array_equal(facing, ng @ sun > 0)
    # soft: every sample inside the solar disk's cap, unit length, a pure function of
    # (seed, sample, index)
    radius = np.radians(0.27)
    _shadow_rays_kernel(pos, ng, 2e-6, centre, 1e-4, sun, radius, 7, 3, o, d, facing)
    np.testing.assert_allclose(np.linalg.norm(d, axis=1), 1.0, atol=1e-12)
    assert (d @ sun >= np.cos(radius) - 1e-12).all() and (d @ sun < 1.0).all()
    d2 = np.empty_like(d)
    _shadow_rays_kernel(pos[::-1].copy(), ng[::-1].copy(), 2e-6, centre, 1e-4, sun, radius,
                        7, 3, o, d2, facing)
    assert not np.allclose(d2[::-1], d)  # keyed by index: reversed rows draw other samples
    _shadow_rays_kernel(pos, ng, 2e-6, centre, 1e-4, sun, radius, 7, 3, o, d2, facing)
    np.testing.assert_array_equal(d2, d)
    np.testing.assert_array_equal(facing, (ng * d).sum(axis=1) > 0)


def test_surface_kernel_matches_numpy():
    rng = np.random.default_rng(2)
    verts = rng.normal(size=(30, 3)) * 50.0
    faces = rng.integers(0, 30, size=(40, 3)).astype(np.uint32)  # a RayMesh's faces' type
    faces = faces[(faces[:, 0] != faces[:, 1]) & (faces[:, 1] != faces[:, 2])
                  & (faces[:, 0] != faces[:, 2])]
    vn = _rng_unit(rng, 30)
    n = 64
    origin = np.array([[0.0, 0.0, 500.0]])
    dirs = _rng_unit(rng, n)
    face = rng.integers(-1, len(faces), size=n)
    t = rng.uniform(100, 400, size=n)
    u, v = rng.uniform(0, 0.5, size=n), rng.uniform(0, 0.5, size=n)
    sun = np.array([0.0, 0.6, 0.8])
    pos, ngo, nso, cos = (np.empty((n, 3)) for _ in range(4))
    facing = np.empty(n, dtype=np.bool_)
    _surface_kernel(origin, dirs, t, face, u, v, verts, faces, vn, True, sun, pos, ngo, nso,
                    cos, facing)
    hit = face >= 0
    tri = faces[face[hit]]
    a, b, c = verts[tri[:, 0]], verts[tri[:, 1]], verts[tri[:, 2]]
    g = np.cross(b - a, c - a)
    g /= np.linalg.norm(g, axis=1, keepdims=True)
    sign = np.where((g * dirs[hit]).sum(axis=1) > 0, -1.0, 1.0)[:, None]
    g *= sign
    w = np.stack([1 - u[hit] - v[hit], u[hit], v[hit]], 1)
    s = (w[:, :, None] * vn[tri]).sum(axis=1)
    s = sign * s / np.linalg.norm(s, axis=1, keepdims=True)
    np.testing.assert_allclose(pos[hit], origin + t[hit, None] * dirs[hit], atol=1e-9)
    np.testing.assert_allclose(ngo[hit], g, atol=1e-12)
    np.testing.assert_allclose(nso[hit], s, atol=1e-12)
    np.testing.assert_allclose(cos[hit, 0], s @ sun, atol=1e-12)
    np.testing.assert_allclose(cos[hit, 1], -(s * dirs[hit]).sum(axis=1), atol=1e-12)
    np.testing.assert_allclose(cos[hit, 2], -(dirs[hit] @ sun), atol=1e-12)
    np.testing.assert_array_equal(facing[hit], g @ sun > 0)
    assert np.isnan(pos[~hit]).all() and not facing[~hit].any()


def test_ground_truth_kernel_matches_numpy():
    rng = np.random.default_rng(3)
    n = 40
    t = rng.uniform(10, 20, size=n)
    face = rng.integers(-1, 5, size=n)
    dirs = _rng_unit(rng, n)
    axis = np.array([0.0, 0.0, 1.0])
    cos = rng.uniform(-1.2, 1.2, size=(n, 3))
    ns = _rng_unit(rng, n)
    lit = rng.uniform(0, 1, size=n)
    depth, rng_m, sunlit = (np.empty(n, dtype=np.float32) for _ in range(3))
    angles, normals = (np.empty((n, 3), dtype=np.float32) for _ in range(2))
    _ground_truth_kernel(t, face, dirs, axis, cos, ns, lit, depth, rng_m, angles, normals,
                         sunlit)
    hit = face >= 0
    np.testing.assert_allclose(rng_m[hit], t[hit], rtol=1e-7)
    np.testing.assert_allclose(depth[hit], t[hit] * dirs[hit, 2], rtol=1e-6, atol=1e-5)
    np.testing.assert_allclose(angles[hit], np.degrees(np.arccos(np.clip(cos[hit], -1, 1))),
                               rtol=1e-6, atol=1e-4)
    np.testing.assert_allclose(normals[hit], ns[hit], rtol=1e-7)
    np.testing.assert_allclose(sunlit[hit], lit[hit], rtol=1e-7)
    assert np.isnan(depth[~hit]).all() and np.isnan(angles[~hit]).all()
