"""The ray engine (latlong.sensors.engine): Embree hits refined in float64."""

from __future__ import annotations

import hashlib

import numpy as np
import pytest

from craters._shared import ParameterError, ParameterTypeError
from latlong import LatLongGrid
from latlong.sensors import RayMesh
from latlong.sensors._engine_kernels import _refine_kernel

R = 1000.0


def numpy_moller_trumbore(o, d, a, b, c):
    """Reference: Möller & Trumbore (1997) for many rays against one triangle each."""
    e1, e2 = b - a, c - a
    p = np.cross(d, e2)
    det = np.einsum("ij,ij->i", e1, p)
    s = o - a
    u = np.einsum("ij,ij->i", s, p) / det
    q = np.cross(s, e1)
    v = np.einsum("ij,ij->i", d, q) / det
    t = np.einsum("ij,ij->i", e2, q) / det
    return t, u, v


def brute_force_first_hit(o, d, verts, faces):
    """Reference: every ray against every triangle (numpy), the nearest hit."""
    a, b, c = (verts[faces[:, k]] for k in range(3))
    t_best = np.full(len(o), np.inf)
    f_best = np.full(len(o), -1)
    for i in range(len(o)):
        oo = np.broadcast_to(o[i], a.shape)
        dd = np.broadcast_to(d[i], a.shape)
        t, u, v = numpy_moller_trumbore(oo, dd, a, b, c)
        ok = (u >= -1e-12) & (v >= -1e-12) & (u + v <= 1 + 1e-12) & (t > 0)
        if ok.any():
            j = np.flatnonzero(ok)[np.argmin(t[ok])]
            t_best[i], f_best[i] = t[j], j
    return t_best, f_best


def sphere_mesh(magnitude, radius=R, offset=(0.0, 0.0, 0.0)):
    g = LatLongGrid(magnitude)
    return g.unit_vectors() * radius + np.asarray(offset), g.triangles()


def random_rays(rng, n, distance, radius=R, spread=1.2, centre=(0.0, 0.0, 0.0)):
    """Rays from random points at ``distance`` aimed at points of the ball of ``spread``
    radii about the centre."""
    o = rng.normal(size=(n, 3))
    o *= distance / np.linalg.norm(o, axis=1, keepdims=True)
    target = rng.normal(size=(n, 3))
    target *= (spread * radius * rng.random(n) ** (1 / 3)
               / np.linalg.norm(target, axis=1))[:, None]
    return o + centre, target - o


def test_refine_kernel_matches_numpy(rng):
    verts, faces = sphere_mesh(6)
    o, d = random_rays(rng, 500, 3 * R)
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    face = rng.integers(0, len(faces), 500)
    face[::7] = -1
    t = np.full(500, -5.0)
    u = np.zeros(500)
    v = np.zeros(500)
    _refine_kernel(o, d, verts, faces, face, t, u, v)
    ok = face >= 0
    f = face[ok]
    tr, ur, vr = numpy_moller_trumbore(o[ok], d[ok], verts[faces[f, 0]], verts[faces[f, 1]],
                                       verts[faces[f, 2]])
    np.testing.assert_allclose(t[ok], tr, rtol=1e-12, atol=1e-9)
    np.testing.assert_allclose(u[ok], ur, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(v[ok], vr, rtol=1e-12, atol=1e-12)
    assert (t[~ok] == -5.0).all()


@pytest.mark.parametrize("distance", [3 * R, 1e4 * R])
def test_first_hit_matches_brute_force(rng, distance):
    verts, faces = sphere_mesh(8)
    mesh = RayMesh(verts, faces)
    o, d = random_rays(rng, 300, distance)
    hits = mesh.intersect(o, d)
    d_unit = d / np.linalg.norm(d, axis=1, keepdims=True)
    t_ref, f_ref = brute_force_first_hit(o, d_unit, verts, faces)
    assert (hits.hit == (f_ref >= 0)).all()
    h = hits.hit
    # a far camera: float64 refinement keeps 1e-12 relative (1e7 m -> 10 micrometres)
    np.testing.assert_allclose(hits.t_m[h], t_ref[h], rtol=1e-12, atol=1e-9)
    same = hits.face[h] == f_ref[h]
    assert same.mean() > 0.99  # others: a shared edge, the same distance
    assert (~hits.hit).sum() > 20 and h.sum() > 100


def test_hits_lie_on_their_exact_triangle(rng):
    """Distances are those of the mesh's own float64 triangles (to ~1e-9 m), and the
    mesh is the analytic sphere to within its sag."""
    verts, faces = sphere_mesh(40)
    mesh = RayMesh(verts, faces)
    o, d = random_rays(rng, 20_000, 5 * R, spread=0.9)
    hits = mesh.intersect(o, d)
    assert hits.hit.all()
    p = hits.points(o, d)
    f = hits.face
    a, b, c = (verts[faces[f, k]] for k in range(3))
    n = mesh.face_normals[f]
    assert np.abs(np.einsum("ij,ij->i", p - a, n)).max() < 1e-9
    w = np.stack([1 - hits.u - hits.v, hits.u, hits.v], 1)
    assert w.min() > -1e-6 and w.max() < 1 + 1e-6
    np.testing.assert_allclose((w[:, :1] * a + w[:, 1:2] * b + w[:, 2:] * c), p, atol=1e-9)
    # analytic sphere: the facets lie inside it by at most the sag
    radius = np.linalg.norm(p, axis=1)
    edge = np.linalg.norm(b - a, axis=1).max()
    sag = R - np.sqrt(R**2 - (edge / np.sqrt(3)) ** 2)
    assert radius.max() <= R * (1 + 1e-12) and radius.min() >= R - sag


def test_matches_trimesh_ray_triangle(rng):
    """trimesh's pure-numpy ray/triangle code (no Embree) as an independent reference."""
    trimesh = pytest.importorskip("trimesh")
    pytest.importorskip("rtree")  # trimesh's broad phase
    from trimesh.ray.ray_triangle import RayMeshIntersector

    verts, faces = sphere_mesh(12)
    verts = verts * np.array([1.0, 0.7, 0.5])  # an ellipsoid
    mesh = RayMesh(verts, faces)
    o, d = random_rays(rng, 400, 4 * R, spread=0.8)
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    hits = mesh.intersect(o, d)
    tm = trimesh.Trimesh(verts, faces, process=False)
    tri, ray, loc = RayMeshIntersector(tm).intersects_id(o, d, multiple_hits=True,
                                                           return_locations=True)
    t_ref = np.full(len(o), np.inf)
    np.minimum.at(t_ref, ray, np.linalg.norm(loc - o[ray], axis=1))
    assert (np.isfinite(t_ref) == hits.hit).all()
    np.testing.assert_allclose(hits.t_m[hits.hit], t_ref[hits.hit], rtol=1e-9)


def test_precision_far_from_the_origin(rng):
    """A DEM in projected metres (x ~ 5e5 m): float32 alone would round to 3 cm."""
    off = (5.0e5, 4.2e6, 1.0e3)
    verts, faces = sphere_mesh(8, 100.0, off)
    mesh = RayMesh(verts, faces)
    o, d = random_rays(rng, 200, 500.0, 100.0, centre=np.asarray(off))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    hits = mesh.intersect(o, d)
    t_ref, f_ref = brute_force_first_hit(o, d, verts, faces)
    assert (hits.hit == (f_ref >= 0)).all()
    np.testing.assert_allclose(hits.t_m[hits.hit], t_ref[hits.hit], rtol=0, atol=1e-8)


def test_occluded_agrees_with_intersect(rng):
    verts, faces = sphere_mesh(10)
    mesh = RayMesh(verts, faces)
    o, d = random_rays(rng, 2000, 3 * R)
    hits = mesh.intersect(o, d)
    t_max = rng.uniform(0, 4 * R, len(o))
    occ = mesh.occluded(o, d, t_max)
    decided = np.abs(hits.t_m - t_max) > 1e-3
    assert (occ == (hits.t_m < t_max))[decided].all()
    assert occ.any() and (~occ).any()
    # t_min skips what lies before it; t_max limits intersect too
    assert not mesh.occluded(o, d, np.inf, t_min=10 * R).any()
    limited = mesh.intersect(o, d, t_max=t_max)
    assert (limited.hit == (hits.t_m <= t_max)).all()


def test_both_sides_are_hit_and_origin_broadcasts():
    verts, faces = sphere_mesh(6)
    mesh = RayMesh(verts, faces)
    d = np.eye(3)
    inside = mesh.intersect(np.zeros(3), d)  # from the centre: the back faces
    assert inside.hit.all()
    assert np.all(np.abs(inside.t_m - R) < 0.2 * R)
    dots = np.einsum("ij,ij->i", mesh.face_normals[inside.face], d)
    assert (dots > 0).all()


def test_validation():
    verts, faces = sphere_mesh(2)
    with pytest.raises(ParameterError, match="faces"):
        RayMesh(verts, faces + len(verts))
    with pytest.raises(ParameterTypeError, match="faces"):
        RayMesh(verts, faces.astype(float))
    with pytest.raises(ParameterError, match="vertices"):
        RayMesh(verts[:, :2], faces)
    with pytest.raises(ParameterError, match="vertices"):
        RayMesh(np.full_like(verts, np.nan), faces)
    with pytest.raises(ParameterError, match="build_quality"):
        RayMesh(verts, faces, build_quality="best")
    mesh = RayMesh(verts, faces, build_quality="low")
    with pytest.raises(ParameterError, match="directions"):
        mesh.intersect(np.zeros((2, 3)), np.zeros((2, 3)))
    with pytest.raises(ParameterError, match="origins"):
        mesh.intersect(np.zeros((3, 3)), np.ones((2, 3)))
    with pytest.raises(ParameterError, match="t_max"):
        mesh.occluded(np.zeros((2, 3)), np.ones((2, 3)), [1.0, -1.0])
    assert "vertices" in repr(mesh)


_THREADS_SCRIPT = """
import hashlib, numpy as np
from latlong import LatLongGrid
from latlong.sensors import RayMesh
g = LatLongGrid(30)
mesh = RayMesh(g.unit_vectors() * 1000.0, g.triangles())
rng = np.random.default_rng(5)
o = rng.normal(size=(50000, 3)); o *= 3000 / np.linalg.norm(o, axis=1, keepdims=True)
d = rng.uniform(-1100, 1100, size=o.shape) - o
h = mesh.intersect(o, d)
occ = mesh.occluded(o, d, rng.uniform(0, 4000, len(o)))
print(hashlib.sha256(b"".join(a.tobytes() for a in (h.t_m, h.face, h.u, h.v, occ))).hexdigest())
"""


def test_same_bytes_for_any_thread_count():
    import subprocess
    import sys

    out = set()
    for threads in ("1", "2"):
        import os

        env = dict(os.environ, NUMBA_NUM_THREADS=threads)
        proc = subprocess.run([sys.executable, "-c", _THREADS_SCRIPT], capture_output=True,
                              text=True, env=env, check=True)
        out.add(proc.stdout.strip())
    assert len(out) == 1, out
    assert len(hashlib.sha256().hexdigest()) == len(out.pop())


def test_shift_kernel_matches_numpy():
    from latlong.sensors._engine_kernels import _shift_kernel

    rng = np.random.default_rng(5)
    v = rng.normal(size=(1000, 3)) * 1e5 + 3e6
    centre = 0.5 * (v.min(axis=0) + v.max(axis=0))
    out = np.zeros((1001, 3), dtype=np.float32)
    r2 = _shift_kernel(v, centre, out)
    ref = np.zeros_like(out)
    np.subtract(v, centre, out=ref[:-1], casting="unsafe")
    np.testing.assert_array_equal(out, ref)
    assert r2 == ((v - centre) ** 2).sum(axis=1).max()
