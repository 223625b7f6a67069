"""Light bounced between surfaces (latlong.sensors.render, ``bounces`` 1 and 2): the
kernels against numpy, and a spherical bowl against its closed form (every point of a
sphere's inside sees every other with the same form factor, 1 / (4 pi R^2) per unit
area, so each further bounce is the last one times albedo x the bowl's area / 4 pi R^2:
the uniform scattered light of Ingersoll, Svitek & Murray 1992's spherical bowls)."""

from __future__ import annotations

import numpy as np
import pytest

from latlong import LatLongGrid
from latlong.sensors import Camera, Lambert, LommelSeeliger, Pose, RayMesh, radiance_factor
from latlong.sensors._bounce_kernels import _bounce_light_kernel, _bounce_rays_kernel
from latlong.sensors.render import render

R = 100.0
RIM_Z = 0.3  # the bowl: the sphere below z = 0.3 R, seen from inside
ALBEDO = 0.3
SUN = np.array([0.8, 0.0, 0.6]) / np.linalg.norm([0.8, 0.0, 0.6])
CAM = Camera.from_fov(60.0, 64, 64)
POSE = Pose.look_at([0.0, 0.0, 250.0], [0.0, 0.0, -50.0], up=(0.0, 1.0, 0.0))


@pytest.fixture(scope="module")
def bowl():
    g = LatLongGrid(60)
    u, f = g.unit_vectors(), g.triangles()
    keep = u[:, 2] < RIM_Z
    faces = f[keep[f].all(axis=1)][:, ::-1]  # turned: normals towards the centre
    remap = np.full(len(u), -1)
    remap[keep] = np.arange(keep.sum())
    return RayMesh(u[keep] * R, remap[faces])


def closed_form(mesh) -> float:
    """A Lambertian bowl's once-bounced I/F, the same at every point:
    albedo / (4 pi R^2) x the integral of the direct I/F over the bowl (lit where the
    sun ray from a point leaves the sphere through the opening)."""
    v, f = mesh.vertices, mesh.faces
    a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    centre = (a + b + c) / 3
    area = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1)
    inward = -centre / np.linalg.norm(centre, axis=1, keepdims=True)
    cos_i = inward @ SUN
    exit_z = (centre - 2.0 * (centre @ SUN)[:, None] * SUN)[:, 2]  # the ray's second hit
    direct = ALBEDO * np.clip(cos_i, 0.0, None) * (exit_z >= RIM_Z * R)
    return ALBEDO / (4.0 * np.pi * R * R) * float((direct * area).sum())


def test_a_bowl_receives_its_closed_form_bounce(bowl):
    kw = {"reflectance": Lambert(ALBEDO)}
    direct = render(bowl, CAM, POSE, SUN, **kw)
    bounced = render(bowl, CAM, POSE, SUN, bounces=1, bounce_samples=256, seed=3, **kw)
    seen = direct.face >= 0
    shadow = seen & (direct.reflectance == 0.0)
    assert seen.sum() > 1500 and shadow.sum() > 500 and (seen & ~shadow).sum() > 300
    added = (bounced.reflectance - direct.reflectance)[seen]
    want = closed_form(bowl)
    # the mean over ~1800 pixels within 3 % (the mesh's facets against the sphere), and
    # each pixel's 256-ray estimate within its Monte Carlo spread
    assert abs(added.mean() / want - 1.0) < 0.03
    assert np.percentile(np.abs(added / want - 1.0), 95) < 0.35
    # shadowed floors are no longer black; the same bytes again; 0 bounces = direct
    assert (bounced.reflectance[shadow] > 0.5 * want).all()
    again = render(bowl, CAM, POSE, SUN, bounces=1, bounce_samples=256, seed=3, **kw)
    np.testing.assert_array_equal(again.reflectance, bounced.reflectance)
    np.testing.assert_array_equal(render(bowl, CAM, POSE, SUN, bounces=0, **kw).image,
                                  direct.image)


def test_a_second_bounce_adds_albedo_times_the_bowls_share_of_the_sphere(bowl):
    kw = {"reflectance": Lambert(ALBEDO), "bounce_samples": 256, "seed": 3}
    once = render(bowl, CAM, POSE, SUN, bounces=1, **kw)
    twice = render(bowl, CAM, POSE, SUN, bounces=2, **kw)
    seen = once.face >= 0
    v, f = bowl.vertices, bowl.faces
    area = 0.5 * np.linalg.norm(np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]]),
                                axis=1).sum()
    want = ALBEDO * area / (4.0 * np.pi * R * R) * closed_form(bowl)  # ~0.19 of bounce 1
    added = (twice.reflectance - once.reflectance)[seen]
    assert abs(added.mean() / want - 1.0) < 0.04
    assert (added >= 0).all()  # the first bounce's rays are the same rays
    np.testing.assert_array_equal(render(bowl, CAM, POSE, SUN, bounces=2, **kw).reflectance,
                                  twice.reflectance)
    with pytest.raises(ValueError, match="bounces"):
        render(bowl, CAM, POSE, SUN, bounces=3)


def test_bounce_directions_are_cosine_weighted_about_the_normal():
    rng = np.random.default_rng(1)
    n = 200_000
    ns = rng.normal(size=(n, 3))
    ns /= np.linalg.norm(ns, axis=1, keepdims=True)
    ng = ns.copy()
    pos = ns * 50.0
    o, d = np.empty((n, 3)), np.empty((n, 3))
    above = np.empty(n, dtype=np.bool_)
    _bounce_rays_kernel(pos, ng, ns, 2e-6, np.zeros(3), 1e-9, 7, 0, o, d, above)
    assert np.allclose(np.linalg.norm(d, axis=1), 1.0, atol=1e-12) and above.all()
    cos = (d * ns).sum(axis=1)
    # cosine-weighted: cos theta has density 2 c on [0, 1]: mean 2/3, mean square 1/2
    assert abs(cos.mean() - 2.0 / 3.0) < 3e-3 and abs((cos**2).mean() - 0.5) < 3e-3
    # origins lifted along the geometric normal by 2e-6 of the distance from the centre
    np.testing.assert_allclose(o, pos + 2e-6 * 50.0 * ng, rtol=0, atol=1e-12)
    # another sample index is another draw; the same index the same
    d2 = np.empty_like(d)
    _bounce_rays_kernel(pos, ng, ns, 2e-6, np.zeros(3), 1e-9, 7, 1, o, d2, above)
    assert not np.allclose(d, d2)
    d3 = np.empty_like(d)
    _bounce_rays_kernel(pos, ng, ns, 2e-6, np.zeros(3), 1e-9, 7, 0, o, d3, above)
    np.testing.assert_array_equal(d, d3)


def test_bounce_light_kernel_is_the_model_seen_back_along_the_ray():
    rng = np.random.default_rng(2)
    k, m = 5000, 40
    normals = rng.normal(size=(m, 3))
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    dirs = rng.normal(size=(k, 3)) * 3.0
    face = rng.integers(-1, m, k)
    albedo = rng.uniform(0.5, 1.5, k)
    lit = rng.choice([0.0, 0.5, 1.0], k)
    model = LommelSeeliger(0.2)
    out = np.empty(k)
    _bounce_light_kernel(model.code, model.vector(), dirs, face, normals, albedo, SUN, lit,
                         out)
    u = dirs / np.linalg.norm(dirs, axis=1, keepdims=True)
    nf = normals[np.maximum(face, 0)]
    cos_i, cos_e, cos_g = nf @ SUN, -(nf * u).sum(axis=1), -(u @ SUN)
    ok = (face >= 0) & (lit > 0) & (cos_i > 0) & (cos_e > 0)
    want = np.where(ok, radiance_factor(model, np.where(ok, cos_i, 1), np.where(ok, cos_e, 1),
                                        cos_g) * albedo * lit, 0.0)
    np.testing.assert_allclose(out, want, rtol=1e-12, atol=0)
    assert ok.sum() > 500 and (~ok).sum() > 500
