"""The regolith's albedo mottling (latlong.sensors.regolith_albedo) against numpy, its
normalisation, locality, and the albedo a descent frame carries (issue 36)."""

from __future__ import annotations

import numpy as np
import pytest

from craters.kernels import mix64
from latlong.sensors import regolith_albedo
from latlong.sensors._albedo_kernels import _KX, _KY, _KZ, _OCTAVE, _mottle_kernel
from latlong.sensors.albedo import MOTTLE_GAIN, MOTTLE_RMS


def _mix(z):
    """splitmix64's finaliser over a uint64 array (wrapping arithmetic)."""
    return np.array([mix64(np.uint64(v)) for v in z], dtype=np.uint64)


def _lattice(seed, ix, iy, iz):
    with np.errstate(over="ignore"):
        k = (ix.astype(np.uint64) * _KX) ^ (iy.astype(np.uint64) * _KY) \
            ^ (iz.astype(np.uint64) * _KZ)
        h = _mix(np.uint64(seed) ^ _mix(k))
    return (h >> np.uint64(11)).astype(np.float64) * (2.0 / 2.0**53) - 1.0


def mottle_reference(points, seed, wavelength, octaves, gain):
    """The module's fBm of value noise, in numpy."""
    fade = lambda t: t**3 * (t * (t * 6 - 15) + 10)  # noqa: E731
    total = np.zeros(len(points))
    amp, inv = 1.0 - gain, 1.0 / wavelength
    for o in range(octaves):
        with np.errstate(over="ignore"):
            s = np.uint64(seed) + np.uint64(o) * _OCTAVE
        p = points * inv
        i0 = np.floor(p).astype(np.int64)
        f = p - np.floor(p)
        u = fade(f)
        val = np.zeros(len(points))
        for k in range(8):
            d = np.array([k & 1, (k >> 1) & 1, k >> 2])
            w = np.prod(np.where(d == 1, u, 1.0 - u), axis=1)
            val += w * _lattice(s, i0[:, 0] + d[0], i0[:, 1] + d[1], i0[:, 2] + d[2])
        total += amp * val
        amp *= gain
        inv *= 2.0
    return total


def test_the_kernel_matches_numpy(rng):
    pts = np.concatenate([rng.uniform(-2e6, 2e6, (150, 3)), rng.uniform(-3, 3, (50, 3))])
    out = np.empty(len(pts))
    _mottle_kernel(pts, np.uint64(12345), 7.0, 4, MOTTLE_GAIN, out)
    np.testing.assert_allclose(out, mottle_reference(pts, 12345, 7.0, 4, MOTTLE_GAIN),
                               rtol=0, atol=1e-14)


def test_contrast_is_the_rms_of_the_log_albedo(rng):
    pts = rng.uniform(-1e6, 1e6, (200_000, 3))
    f = regolith_albedo(pts, seed=3, contrast=0.1, pixel_m=20.0 / 2**25)
    assert abs(np.log(f).std() / 0.1 - 1.0) < 0.03  # MOTTLE_RMS measured on 10^6 points
    assert abs(np.log(f).mean()) < 0.01
    assert MOTTLE_RMS == pytest.approx(0.168)


def test_a_point_is_the_same_alone_or_with_others_and_finer_pictures_add_detail(rng):
    pts = rng.uniform(-1e3, 1e3, (500, 3)) + [0.0, 0.0, 1.737e6]
    both = regolith_albedo(pts, seed=9, pixel_m=0.01)
    alone = np.array([regolith_albedo(p[None], seed=9, pixel_m=0.01)[0] for p in pts[:20]])
    assert np.array_equal(both[:20], alone)
    coarse = np.log(regolith_albedo(pts, seed=9, pixel_m=1.0))
    fine = np.log(both)
    # the coarse picture's octaves are the fine one's first octaves: what the fine one
    # adds is its finer octaves, uncorrelated with them
    assert np.corrcoef(coarse, fine)[0, 1] > 0.6 and np.std(fine) > np.std(coarse)
    assert np.array_equal(regolith_albedo(pts, seed=9, contrast=0.0, pixel_m=0.01),
                          np.ones(len(pts)))
    assert not np.array_equal(both, regolith_albedo(pts, seed=10, pixel_m=0.01))


@pytest.mark.parametrize("kw, match", [
    ({"points_m": np.zeros((3, 2))}, "points_m"),
    ({"points_m": [[np.nan, 0, 0]]}, "points_m"),
    ({"seed": -1}, "seed"),
    ({"contrast": 3.0}, "contrast"),
    ({"pixel_m": 0.0}, "pixel_m"),
    ({"wavelength_max_m": -1.0}, "wavelength_max_m"),
])
def test_bad_inputs(kw, match):
    args = {"points_m": np.zeros((2, 3)), "seed": 1, "pixel_m": 0.1, **kw}
    with pytest.raises(ValueError, match=match):
        regolith_albedo(**args)


def test_descent_frames_carry_mottling_and_bright_ejecta():
    from latlong import Scene
    from latlong.ondemand.descent import descent

    def frame(craters, **kw):
        scene = Scene.from_settings({"preset": "fbm-cratered", "seed": 5, "on_demand": True,
                                     "craters": [craters]})
        return next(descent(scene, 10.0, 40.0, [20.0], width_px=64, sun_elevation_deg=60.0,
                            **kw)).frame.reflectance

    worn = "c=0.5,k=-2,d_min_m=4,d_max_m=15"  # ages up to 3.5 Gyr: nearly all worn flat
    a = frame(worn, bright_ejecta=0.0, mottling=0.0)
    b = frame(worn, bright_ejecta=0.0)
    lit = (a > 0) & (b > 0)
    # the mottling's octaves from 2 m down to two of the frame's 17 cm pixels, in an 11 m
    # footprint: measured 0.049 RMS of the log (0.05 with every octave)
    assert 0.03 < np.log(b[lit] / a[lit]).std() < 0.12
    assert np.array_equal(frame(worn, mottling=0.0), a)  # worn craters: no bright ejecta
    fresh = worn + ",age_max_gyr=0.0001"
    c, d = frame(fresh, bright_ejecta=0.0), frame(fresh)
    lit = (c > 0) & (d > 0)
    r = np.log(d[lit] / c[lit])
    # fresh ejecta everywhere at this density, up to 1 + 0.5 at the rims (measured 1.49)
    assert (r > 0).mean() > 0.5 and 1.3 < np.exp(r.max()) <= 1.5 + 1e-9


def ejecta_reference(verts, centres, radii, gains, reach):
    """Each vertex's largest 1 + gain g(d / R) over the craters, through a k-d tree."""
    from scipy.spatial import cKDTree

    out = np.ones(len(verts))
    tree = cKDTree(verts)
    for c, near in enumerate(tree.query_ball_point(centres, reach * radii)):
        near = np.asarray(near, dtype=np.int64)
        if not len(near):
            continue
        rho = np.linalg.norm(verts[near] - centres[c], axis=1) / radii[c]
        g = np.where(rho <= 1.0, 1.0, np.maximum(rho, 1.0) ** -3)
        out[near] = np.maximum(out[near], 1.0 + gains[c] * g)
    return out


def test_bright_ejecta_match_the_kd_tree_reference(rng):
    import craters
    from latlong.sensors import SceneGeometry, ejecta_albedo

    verts = rng.uniform(-500.0, 500.0, (20_000, 3)) * [1.0, 1.0, 0.05] + [0, 0, 1.737e6]
    n = 300
    centres = rng.uniform(-600.0, 600.0, (n, 3)) * [1.0, 1.0, 0.0] + [0, 0, 1.737e6]
    d = np.exp(rng.uniform(np.log(2.0), np.log(150.0), n))
    deg = rng.uniform(0.0, 0.5, n)
    cat = craters.make_catalog(x_m=np.zeros(n), y_m=np.zeros(n), diameter_m=d,
                               degradation=deg, centre_x_m=centres[:, 0],
                               centre_y_m=centres[:, 1], centre_z_m=centres[:, 2])
    geo = SceneGeometry(verts, np.array([[0, 1, 2]]), np.array([-1], np.int32), cat)
    got = ejecta_albedo(geo, contrast=0.7, fresh_degradation=0.3, reach_radii=3.0)
    w = np.clip(1.0 - deg / 0.3, 0.0, None)
    keep = w > 0
    want = ejecta_reference(verts, centres[keep], 0.5 * d[keep], 0.7 * w[keep], 3.0)
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-12)
    assert (got > 1.0).mean() > 0.2  # the test sees bright ejecta
    import numba

    threads = numba.get_num_threads()
    try:  # the same bytes with one thread (each thread's craters merged by the maximum)
        numba.set_num_threads(1)
        one = ejecta_albedo(geo, contrast=0.7, fresh_degradation=0.3, reach_radii=3.0)
    finally:
        numba.set_num_threads(threads)
    assert np.array_equal(one, got)


def test_cube_keys_kernel_matches_numpy(rng):
    from latlong.geometry.meshes import bounds
    from latlong.sensors._albedo_kernels import _cube_keys_kernel

    verts = rng.normal(scale=300.0, size=(20000, 3)) + [1.7e6, -2e5, 3e4]
    lo, hi = bounds(verts)
    np.testing.assert_array_equal(lo, verts.min(axis=0))
    np.testing.assert_array_equal(hi, verts.max(axis=0))
    for cell in (0.37, 7.0, 1e3):
        ijk = np.floor((verts - lo) / cell).astype(np.int64)
        dims = np.floor((hi - lo) / cell).astype(np.int64) + 1
        np.testing.assert_array_equal(dims, ijk.max(axis=0) + 1)  # what albedo.py relies on
        keys = np.empty(len(verts), dtype=np.int64)
        _cube_keys_kernel(verts, lo, cell, dims, keys)
        np.testing.assert_array_equal(keys, ijk[:, 0] + dims[0] * (ijk[:, 1] + dims[1] * ijk[:, 2]))


def bump_reference(points, normals, seeds, wavelengths, amps):
    """:func:`_bump_kernel` in numpy: the gradient of the octaves' value noise (one octave
    of :func:`mottle_reference` each) by central differences, its part across each
    normal, n - grad_t, normalised."""
    grad = np.zeros_like(points)
    for s, lam, a in zip(seeds, wavelengths, amps, strict=True):
        step = 1e-6 * lam
        for axis in range(3):
            d = np.zeros(3)
            d[axis] = step
            # one octave of amplitude 1 - 0 = 1 (gain 0)
            grad[:, axis] += a * (mottle_reference(points + d, s, lam, 1, 0.0)
                                  - mottle_reference(points - d, s, lam, 1, 0.0)) / (2 * step)
    across = grad - (grad * normals).sum(axis=1, keepdims=True) * normals
    m = normals - across
    return m / np.linalg.norm(m, axis=1, keepdims=True)


def test_the_relief_kernel_matches_numpy(rng):
    from latlong.sensors._albedo_kernels import _bump_kernel

    pts = np.concatenate([rng.uniform(-3e3, 3e3, (150, 3)), rng.uniform(-3, 3, (50, 3))])
    nrm = rng.normal(size=pts.shape)
    nrm /= np.linalg.norm(nrm, axis=1, keepdims=True)
    seeds = np.array([777, 2**63 + 5], dtype=np.uint64)
    lams, amps = np.array([2.0, 1.0]), np.array([0.3, 0.1])
    out = np.empty_like(pts)
    _bump_kernel(pts, nrm, seeds, lams, amps, out)
    np.testing.assert_allclose(out, bump_reference(pts, nrm, seeds, lams, amps),
                               rtol=0, atol=1e-6)


def test_relief_tilts_the_normals_by_the_rms_its_octaves_ask(rng):
    from latlong.sensors import regolith_normals
    from latlong.sensors.albedo import relief_octaves

    pts = rng.uniform(-1e5, 1e5, (200_000, 3))
    nrm = rng.normal(size=pts.shape)
    nrm /= np.linalg.norm(nrm, axis=1, keepdims=True)
    for pixel, tilt in ((0.3, 2.5), (0.5, 10.0)):
        out = regolith_normals(pts, nrm, seed=4, pixel_m=pixel, tilt_1m_deg=tilt)
        assert np.allclose(np.linalg.norm(out, axis=1), 1.0)
        cos = np.clip((out * nrm).sum(axis=1), -1.0, 1.0)
        rms_tan = np.sqrt(np.mean(np.tan(np.arccos(cos)) ** 2))
        want = np.sqrt((relief_octaves(pixel, tilt, 1.0)[1] ** 2).sum())
        assert rms_tan == pytest.approx(want, rel=0.02)
    # a function of position: a point alone gives its bytes in the batch; 0 changes nothing
    one = regolith_normals(pts[7:8], nrm[7:8], seed=4, pixel_m=0.3, tilt_1m_deg=2.5)
    assert one.tobytes() == regolith_normals(pts, nrm, seed=4, pixel_m=0.3,
                                             tilt_1m_deg=2.5)[7:8].tobytes()
    assert np.array_equal(regolith_normals(pts, nrm, seed=4, pixel_m=0.3, tilt_1m_deg=0.0), nrm)


def test_relief_octaves_are_shared_by_nearby_pixel_sizes():
    """Octaves on a fixed ladder of wavelengths: frames 12 % apart in pixel share theirs
    (the same texture at the same places), weights whose squares sum to 1, and the RMS
    tilt follows pixel^(H - 1) (2.5 deg at 1 m)."""
    from latlong.sensors.albedo import relief_octaves

    a, ta, ka = relief_octaves(0.5, 2.5, 0.76)
    b, tb, kb = relief_octaves(0.56, 2.5, 0.76)
    assert set(ka) & set(kb) and np.all(np.log2(a) == np.round(np.log2(a)))
    for p in (0.01, 0.3, 1.0, 1.7, 50.0):
        lams, tilts, _ = relief_octaves(p, 2.5, 0.76)
        rms = np.sqrt((tilts ** 2).sum())
        assert rms == pytest.approx(np.tan(np.radians(2.5)) * p ** -0.24, rel=0.1)


@pytest.mark.parametrize(("args", "message"), [
    ({"tilt_1m_deg": 50.0}, "tilt_1m_deg"), ({"tilt_1m_deg": -1.0}, "tilt_1m_deg"),
    ({"pixel_m": 0.0}, "pixel_m"), ({"hurst": 1.5}, "hurst"),
    ({"normals": [[0.0, 0.0, 1.0]]}, "normals"), ({"points_m": [[np.nan, 0, 0]] * 2}, "points_m"),
])
def test_relief_errors_name_the_parameter(args, message):
    from latlong.sensors import regolith_normals

    kw = {"points_m": [[0.0, 0.0, 1e3]] * 2, "normals": [[0.0, 0.0, 1.0]] * 2, "seed": 1,
          "pixel_m": 1.0, "tilt_1m_deg": 3.0, **args}
    with pytest.raises(ValueError, match=message):
        regolith_normals(**kw)


def test_descent_relief_is_shading_only():
    """The relief below the pixels changes the picture, not the geometry: the same depth,
    other reflectances, more of the image's power in its finest octave."""
    from latlong import Scene
    from latlong.ondemand.descent import descent

    scene = Scene.from_settings({"preset": "fbm-cratered", "seed": 5, "on_demand": True})

    def frame(**kw):
        return next(descent(scene, 10.0, 40.0, [20.0], width_px=64, sun_elevation_deg=30.0,
                            bright_ejecta=0.0, mottling=0.0, **kw)).frame

    flat, rough = frame(microrelief_deg=0.0), frame(microrelief_deg=8.0)
    assert np.array_equal(flat.depth_m, rough.depth_m, equal_nan=True)
    lit = (flat.reflectance > 0) & (rough.reflectance > 0)
    assert not np.array_equal(flat.reflectance[lit], rough.reflectance[lit])

    def top_octave(img):
        p = np.abs(np.fft.fft2(img - img.mean())) ** 2
        f = np.hypot(*np.meshgrid(np.fft.fftfreq(img.shape[0]), np.fft.fftfreq(img.shape[1])))
        return p[f > 0.25].sum() / p[f > 0].sum()

    # 8 deg at 17 cm pixels: measured 0.0316 -> 0.0678 (the default, 2.5 deg, is
    # set against LROC NAC pictures at 0.5 m: latlong.ondemand.descent's notes)
    assert top_octave(rough.reflectance) > 1.5 * top_octave(flat.reflectance)
