"""The minimal ray engine (latlong.sensors.engine) against a pure-numpy brute force."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

from latlong.sensors.engine import RayMesh


def moller_trumbore(vertices, faces, origins, directions):
    """Pure-numpy brute force: the nearest hit of every ray over every triangle
    (Möller & Trumbore 1997), (t (k,), face (k,), u, v); inf / -1 on a miss."""
    a, b, c = (vertices[faces[:, i]] for i in range(3))
    e1, e2 = b - a, c - a
    p = np.cross(directions[:, None], e2[None])
    det = np.einsum("kfi,fi->kf", p, e1)
    with np.errstate(divide="ignore", invalid="ignore"):
        inv = 1.0 / det
        s = origins[:, None] - a[None]
        u = np.einsum("kfi,kfi->kf", s, p) * inv
        q = np.cross(s, e1[None])
        v = np.einsum("ki,kfi->kf", directions, q) * inv
        t = np.einsum("fi,kfi->kf", e2, q) * inv
    ok = (det != 0) & (u >= 0) & (v >= 0) & (u + v <= 1) & (t > 0)
    t = np.where(ok, t, np.inf)
    face = np.argmin(t, axis=1)
    rows = np.arange(len(t))
    best = t[rows, face]
    miss = ~np.isfinite(best)
    return best, np.where(miss, -1, face), u[rows, face], v[rows, face]


@pytest.fixture(scope="module")
def scene():
    m = trimesh.creation.icosphere(subdivisions=3, radius=1000.0)
    # far from the origin, where float32 positions alone are good to ~2 mm
    return np.asarray(m.vertices) + [3.0e4, -2.0e4, 1.0e4], np.asarray(m.faces)


def test_intersect_matches_brute_force(scene):
    v, f = scene
    rng = np.random.default_rng(7)
    centre = v.mean(axis=0)
    o = centre + rng.normal(size=(600, 3)) * 3000.0
    aim = centre + rng.normal(size=(600, 3)) * 700.0
    d = (aim - o) / np.linalg.norm(aim - o, axis=1, keepdims=True)
    o = np.where(np.linalg.norm(o - centre, axis=1, keepdims=True) < 1200, centre + 5e3, o)
    hits = RayMesh(v, f).intersect(o, d)
    t, face, u, vv = moller_trumbore(v, f, o, d)
    assert ((hits.face >= 0) == (face >= 0)).all()
    assert 100 < (face >= 0).sum() < 600
    hit = face >= 0
    np.testing.assert_allclose(hits.t_m[hit], t[hit], rtol=0, atol=1e-9)
    same = hits.face == face
    assert same[hit].mean() > 0.99  # others: a ray through a shared edge
    np.testing.assert_allclose(hits.u[same & hit], u[same & hit], atol=1e-9)
    np.testing.assert_allclose(hits.v[same & hit], vv[same & hit], atol=1e-9)
    assert np.isinf(hits.t_m[~hit]).all() and (hits.face[~hit] == -1).all()


def test_t_max_and_occluded(scene):
    v, f = scene
    centre = v.mean(axis=0)
    o = np.array([centre + [5000.0, 0, 0], centre + [5000.0, 0, 0]])
    d = np.array([[-1.0, 0, 0], [1.0, 0, 0]])
    mesh = RayMesh(v, f)
    hits = mesh.intersect(o, d)
    assert hits.t_m[0] == pytest.approx(4000.0, abs=1e-9) and hits.face[1] == -1
    assert mesh.intersect(o, d, t_max=3999.0).face.tolist() == [-1, -1]
    assert mesh.occluded(o, d, 4001.0).tolist() == [True, False]
    assert mesh.occluded(o, d, 3999.0).tolist() == [False, False]


def test_bad_meshes_are_refused():
    with pytest.raises(ValueError, match="faces"):
        RayMesh(np.zeros((3, 3)), [[0, 1, 5]])
    with pytest.raises(ValueError, match="vertices"):
        RayMesh(np.zeros((0, 3)), [[0, 1, 2]])
