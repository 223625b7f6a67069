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
from latlong.sensors._bounce_kernels import (
    B3_TAPS,
    NORMAL_POWER_LOG2,
    PLANE_SIN2,
    _atrous_pass_kernel,
    _bounce_light_kernel,
    _bounce_rays_kernel,
    _secondary_kernel,
    atrous_steps,
)
from latlong.sensors.light import filter_bounced
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
    kw = {"reflectance": Lambert(ALBEDO), "bounce_filter_px": 0}  # each pixel's own rays
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
    kw = {"reflectance": Lambert(ALBEDO), "bounce_samples": 256, "bounce_filter_px": 0,
          "seed": 3}
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
    ids = np.arange(n)
    o, d = np.empty((n, 3)), np.empty((n, 3))
    above = np.empty(n, dtype=np.bool_)
    _bounce_rays_kernel(pos, ng, ns, ids, 2e-6, np.zeros(3), 1e-9, 7, 0, o, d, above)
    assert np.allclose(np.linalg.norm(d, axis=1), 1.0, atol=1e-12) and above.all()
    cos = (d * ns).sum(axis=1)
    # cosine-weighted: cos theta has density 2 c on [0, 1]: mean 2/3, mean square 1/2
    assert abs(cos.mean() - 2.0 / 3.0) < 3e-3 and abs((cos**2).mean() - 0.5) < 3e-3
    # origins lifted along the geometric normal by 2e-6 of the distance from the centre
    np.testing.assert_allclose(o, pos + 2e-6 * 50.0 * ng, rtol=0, atol=1e-12)
    # another sample index is another draw; the same index the same
    d2 = np.empty_like(d)
    _bounce_rays_kernel(pos, ng, ns, ids, 2e-6, np.zeros(3), 1e-9, 7, 1, o, d2, above)
    assert not np.allclose(d, d2)
    d3 = np.empty_like(d)
    _bounce_rays_kernel(pos, ng, ns, ids, 2e-6, np.zeros(3), 1e-9, 7, 0, o, d3, above)
    np.testing.assert_array_equal(d, d3)
    # a point's rays are keyed by its id, not by its place in the arrays
    sub = np.arange(0, n, 7)
    d4 = np.empty((len(sub), 3))
    _bounce_rays_kernel(pos[sub], ng[sub], ns[sub], ids[sub], 2e-6, np.zeros(3), 1e-9, 7, 0,
                        o[sub], d4, above[sub])
    np.testing.assert_array_equal(d4, d[sub])


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


def test_secondary_kernel_is_the_numpy_steps_it_replaced(bowl):
    rng = np.random.default_rng(7)
    n = 4000
    o = rng.normal(scale=30.0, size=(n, 3))
    d = rng.normal(size=(n, 3)) * rng.uniform(0.5, 2.0, (n, 1))  # not unit: as given
    hits = bowl.intersect(o, d)
    above = rng.random(n) > 0.2
    sun = SUN
    face, q, nq = np.empty(n, np.int64), np.empty((n, 3)), np.empty((n, 3))
    facing = np.empty(n, np.bool_)
    _secondary_kernel(o, d, hits.t_m, hits.face, above, bowl.face_normals, sun, face, q, nq,
                      facing)
    want_face = np.where(above, hits.face, -1)
    want_nq = np.zeros((n, 3))
    want_nq[want_face >= 0] = bowl.face_normals[want_face[want_face >= 0]]
    assert (hits.face >= 0).sum() > 1000 and (want_face >= 0).sum() < (hits.face >= 0).sum()
    np.testing.assert_array_equal(face, want_face)
    np.testing.assert_array_equal(q, hits.points(o, d))  # NaN where nothing is hit
    np.testing.assert_array_equal(nq, want_nq)
    dots = (want_nq[:, 0] * sun[0] + want_nq[:, 1] * sun[1]) + want_nq[:, 2] * sun[2]
    np.testing.assert_array_equal(facing, (want_face >= 0) & (dots > 0.0))
    assert facing.any() and not facing.all()


def pass_reference(num, den, seen, pos, nrm, step):
    """:func:`_atrous_pass_kernel` in numpy: the 5 x 5 taps one offset at a time (rows,
    then columns: the kernel's order of the sums)."""
    h, w, _ = num.shape
    acc = np.zeros(num.shape)
    d_acc = np.zeros((h, w))
    total = np.zeros((h, w))
    for a in range(5):
        for c in range(5):
            di, dj = (a - 2) * step, (c - 2) * step
            i0, i1, j0, j1 = max(0, -di), min(h, h - di), max(0, -dj), min(w, w - dj)
            if i0 >= i1 or j0 >= j1:
                continue
            p = (slice(i0, i1), slice(j0, j1))
            q = (slice(i0 + di, i1 + di), slice(j0 + dj, j1 + dj))
            cos = (nrm[p] * nrm[q]).sum(axis=-1)
            ok = seen[q] & (cos > 0.0)
            cos = np.where(ok, cos, 0.0) ** (2**NORMAL_POWER_LOG2)
            d = pos[q] - pos[p]
            d2 = (d * d).sum(axis=-1)
            e = (nrm[p] * d).sum(axis=-1)
            t = np.where(d2 > 0.0, 1.0 - e * e / (np.where(d2 > 0.0, d2, 1.0) * PLANE_SIN2), 1.0)
            ok &= t > 0.0
            wt = np.where(ok, B3_TAPS[a] * B3_TAPS[c] * cos * t * t, 0.0)
            total[p] += wt
            d_acc[p] += wt * den[q]
            acc[p] += wt[..., None] * num[q]
    keep = seen & (total > 0)
    safe = np.where(keep, total, 1.0)
    return (np.where(keep[..., None], acc / safe[..., None], num),
            np.where(keep, d_acc / safe, den))


def filter_reference(light, seen, pos, nrm, rays, radius):
    """:func:`filter_bounced` in numpy on an image: the a-trous passes of rays x light and
    rays, their ratio at the end."""
    num, den = light * rays[..., None], rays.copy()
    for step in atrous_steps(radius):
        num, den = pass_reference(num, den, seen, pos, nrm, step)
    return num / den[..., None]


def filtered(light, seen, pos, nrm, rays, radius):
    """:func:`filter_bounced` as an image (unseen pixels 0)."""
    out = np.zeros(light.shape)
    out[seen] = filter_bounced(light[seen], seen, pos, nrm, radius, rays[seen])
    return out


def two_planes(h=40, w=48, step_m=5.0):
    """A ground plane seen from above (1 m pixels) whose right half lies ``step_m`` lower
    (a cliff: the same normal on both sides)."""
    y, x = np.mgrid[0:h, 0:w].astype(float)
    z = np.where(x >= w // 2, -step_m, 0.0)
    pos = np.stack([x, y, z], axis=-1)
    nrm = np.zeros((h, w, 3))
    nrm[..., 2] = 1.0
    return pos, nrm


def test_atrous_steps_stand_for_a_gaussian_of_half_the_radius():
    assert atrous_steps(1) == atrous_steps(3) == [1]
    assert atrous_steps(4) == [1, 2]
    assert atrous_steps(8) == [1, 2, 4]
    assert atrous_steps(64) == [1, 2, 4, 8, 16, 32]
    for radius in (2, 4, 8, 16, 32, 64):  # variances add: sigma within 16 % of radius / 2
        sigma = np.sqrt(sum(s * s for s in atrous_steps(radius)))
        assert abs(sigma / (radius / 2) - 1.0) < 0.16, radius
    # the cubic B-spline's variance is 1 px^2 per axis at step 1
    x = np.arange(-2, 3)
    assert B3_TAPS.sum() == 1.0 and np.isclose((B3_TAPS * x * x).sum(), 1.0)


def test_atrous_pass_kernel_matches_numpy():
    rng = np.random.default_rng(4)
    h, w, nb = 23, 31, 2
    pos, nrm = two_planes(h, w)
    pos += rng.normal(scale=0.2, size=pos.shape)
    nrm = nrm + rng.normal(scale=0.3, size=nrm.shape)
    nrm /= np.linalg.norm(nrm, axis=-1, keepdims=True)
    nrm[3, 4] = -nrm[3, 4]  # a normal turned away: no weight either way
    nrm[5, 6] = 0.0  # a zero normal: not even its own weight, kept as it was
    seen = rng.random((h, w)) > 0.15
    num = rng.uniform(0.0, 1.0, (h, w, nb))
    den = rng.choice([2.0, 8.0], (h, w))
    for step in (1, 2, 4, 8):
        out_num, out_den = np.empty_like(num), np.empty_like(den)
        _atrous_pass_kernel(num, den, seen, pos, nrm, B3_TAPS, step, out_num, out_den)
        want_num, want_den = pass_reference(num, den, seen, pos, nrm, step)
        np.testing.assert_allclose(out_num, want_num, rtol=1e-12, atol=0)
        np.testing.assert_allclose(out_den, want_den, rtol=1e-12, atol=0)
        np.testing.assert_array_equal(out_num[~seen], num[~seen])  # unseen as they were
        assert out_num[5, 6, 0] == num[5, 6, 0] or not seen[5, 6]
    rays = den
    light = num / rays[..., None]
    np.testing.assert_allclose(filtered(light, seen, pos, nrm, rays, 8)[seen],
                               filter_reference(light, seen, pos, nrm, rays, 8)[seen],
                               rtol=1e-12, atol=0)


def test_bounce_filter_averages_the_noise_within_a_surface_not_across_a_cliff():
    import numba
    rng = np.random.default_rng(5)
    pos, nrm = two_planes()
    h, w = pos.shape[:2]
    level = np.where(pos[..., 2] < 0.0, 0.2, 1.0)  # each side its own bounced light
    light = (level * (1.0 + 0.3 * rng.standard_normal((h, w))))[..., None]
    seen = np.ones((h, w), dtype=np.bool_)
    ones = np.ones((h, w))
    out = filtered(light, seen, pos, nrm, ones, 4)
    inner = (slice(6, -6), slice(6, w // 2 - 6))
    # the noise falls by about the window's effective size (sigma ~2 px: 4 pi sigma^2 ~ 60)
    assert out[inner].std() < 0.2 * light[inner].std()
    assert abs(out[inner].mean() / light[inner].mean() - 1.0) < 0.02
    # next to the cliff each side keeps its own level: the lower plane lies 5 m off the
    # upper one's tangent plane (sin^2 ~ 1: no weight)
    np.testing.assert_allclose(out[6:-6, w // 2 - 1, 0].mean(), 1.0, atol=0.05)
    np.testing.assert_allclose(out[6:-6, w // 2, 0].mean(), 0.2, atol=0.01)
    # an estimate of more rays counts more: a pixel of 8 rays among pixels of 1 pulls the
    # mean towards itself 8 times as hard as one of 1 ray would
    rays = ones.copy()
    spike = np.zeros((h, w, 1))
    spike[20, 10] = 1.0
    one_ray = filtered(spike, seen, pos, nrm, rays, 4)
    rays[20, 10] = 8.0
    eight = filtered(spike, seen, pos, nrm, rays, 4)
    assert eight[20, 12, 0] > 4.0 * one_ray[20, 12, 0]
    # one thread or two: the same bytes
    threads = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        one = filtered(light, seen, pos, nrm, ones, 4)
    finally:
        numba.set_num_threads(threads)
    np.testing.assert_array_equal(one, out)


def test_a_filtered_bounce_keeps_the_bowls_closed_form_with_a_few_rays(bowl):
    kw = {"reflectance": Lambert(ALBEDO), "seed": 3}
    direct = render(bowl, CAM, POSE, SUN, **kw)
    raw = render(bowl, CAM, POSE, SUN, bounces=1, bounce_samples=16, bounce_filter_px=0, **kw)
    smooth = render(bowl, CAM, POSE, SUN, bounces=1, bounce_samples=16, bounce_filter_px=4,
                    **kw)
    seen = direct.face >= 0
    shadow = seen & (direct.reflectance == 0.0)
    lit = seen & ~shadow
    want = closed_form(bowl)
    added = {name: (fr.reflectance - direct.reflectance) / want
             for name, fr in (("raw", raw), ("smooth", smooth))}
    for name, a in added.items():  # both estimates keep the closed form on average
        assert abs(a[seen].mean() - 1.0) < 0.03, name
    # shadowed pixels trace all 16 rays: ~100 % spread (95th percentile) alone, ~4x less
    # smoothed over ~50 pixels
    spread = {name: np.percentile(np.abs(a[shadow] - 1.0), 95) for name, a in added.items()}
    assert spread["smooth"] < 0.3 * spread["raw"], spread
    # sunlit pixels trace a quarter of them when smoothed: what is left of their noise is a
    # few per cent of their direct light (7 % with each pixel's own 16 rays)
    noise = np.abs(smooth.reflectance - direct.reflectance - want)[lit] / direct.reflectance[lit]
    assert np.percentile(noise, 95) < 0.05
    # the direct light is not touched
    np.testing.assert_array_equal(render(bowl, CAM, POSE, SUN, bounces=0, bounce_filter_px=4,
                                         **kw).reflectance, direct.reflectance)
