"""fbm3 reproduces noise.pnoise3; perlin_fbm on the mesh."""

from __future__ import annotations

import numpy as np
import pytest

from latlong import FBM_PRESETS, LatLongGrid, fbm3, perlin_fbm
from latlong._perlin_kernels import GRAD3, PERM, _fbm3_fast_kernel, _fbm3_kernel

try:
    import noise
except ImportError:  # an sdist that needs a C compiler: the reference is optional
    noise = None
needs_noise = pytest.mark.skipif(
    noise is None, reason="the comparison with the reference Perlin noise needs the "
    "`noise` package (pip install \".[reference]\", needs a C compiler): without it "
    "fbm3 is not checked against noise.pnoise3")

PNOISE_TOL = 1e-5


def pnoise3(points, octaves, persistence, lacunarity, base):
    return np.array([noise.pnoise3(float(x), float(y), float(z), octaves=octaves,
                                   persistence=persistence, lacunarity=lacunarity, base=base)
                     for x, y, z in points])


PARAMS = [(1, 0.5, 2.0, 0), (10, 0.5, 1.75, 0), (10, 0.5, 1.5, 1), (10, 0.3, 2.5, 0),
          (4, 0.8, 3.0, 1), (7, 0.5, 1.0, 0)]


@pytest.mark.parametrize("scale", [1.0, 30.0, 2500.0])  # 2500: the general kernel
@pytest.mark.parametrize("params", PARAMS)
@needs_noise
def test_matches_pnoise3(params, scale, rng):
    pts = rng.uniform(-scale, scale, (1500, 3))
    ref = pnoise3(pts, *params)
    ours = fbm3(pts[:, 0], pts[:, 1], pts[:, 2], *params)
    assert np.abs(ours - ref).max() <= PNOISE_TOL


def test_fast_kernel_equals_general_kernel(rng):
    pts = rng.uniform(-900, 900, (20000, 3)).astype(np.float32)
    a = np.empty(len(pts))
    b = np.empty(len(pts))
    args = (10, np.float32(0.5), np.float32(2.0), 0, PERM, GRAD3)
    _fbm3_fast_kernel(pts[:, 0].copy(), pts[:, 1].copy(), pts[:, 2].copy(), *args, a)
    _fbm3_kernel(pts[:, 0].copy(), pts[:, 1].copy(), pts[:, 2].copy(), *args, b)
    assert np.array_equal(a, b)


def test_broadcast_and_scalar():
    assert fbm3(0.1, 0.2, 0.3).shape == ()
    x = np.linspace(0, 1, 5)
    assert fbm3(x, 0.5, [[0.0], [1.0]]).shape == (2, 5)


@pytest.mark.parametrize("kw,match", [
    ({"octaves": 0}, "octaves"), ({"persistence": -1}, "persistence"),
    ({"lacunarity": 0.5}, "lacunarity"), ({"base": 256}, "base"),
    ({"octaves": 30, "lacunarity": 3.0}, "lacunarity"),
])
def test_bad_parameters(kw, match):
    with pytest.raises(ValueError, match=match):
        fbm3(0.1, 0.2, 0.3, **kw)


def test_nonfinite_points():
    with pytest.raises(ValueError, match="finite"):
        fbm3([0.1, np.nan], 0.0, 0.0)


def test_perlin_fbm_deterministic_and_scaled():
    g = LatLongGrid(20)
    p = FBM_PRESETS["fig5b"]
    a = perlin_fbm(g, p.frequency, p.octaves, p.persistence, p.lacunarity, 7.0, rng=11)
    b = perlin_fbm(g, p.frequency, p.octaves, p.persistence, p.lacunarity, 7.0, rng=11)
    c = perlin_fbm(g, p.frequency, p.octaves, p.persistence, p.lacunarity, 7.0, rng=12)
    assert np.array_equal(a, b)
    assert not np.allclose(a, c)
    assert np.abs(a).max() <= 7.0
    assert a.std() > 0.5


def test_perlin_fbm_is_fbm3_on_the_rotated_sphere():
    g = LatLongGrid(6)
    seed = 5
    h = perlin_fbm(g, 2.0, 3, 0.5, 2.0, 1.0, rng=seed)
    r = np.random.default_rng(seed)
    from latlong.perlin import random_rotation

    rot = random_rotation(r)
    off = r.uniform(0, 256, 3)
    p = g.unit_vectors() @ rot.T * 2.0 + off
    assert np.allclose(h, fbm3(p[:, 0], p[:, 1], p[:, 2], 3, 0.5, 2.0), atol=1e-6)


def test_presets_are_the_papers():
    got = [(p.frequency, p.persistence, p.lacunarity, p.octaves) for p in FBM_PRESETS.values()]
    assert got == [(1.5, 0.5, 1.75, 10), (2.5, 0.5, 1.5, 10), (4.0, 0.3, 2.5, 10)]
