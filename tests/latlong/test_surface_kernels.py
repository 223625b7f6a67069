"""The surface sampler's numba kernels against pure-numpy references: the same bits.

Crater and boulder positions, counts and the SCC area all come from these numbers, so the
kernels must reproduce the numpy expressions they replaced exactly, not approximately.
"""

import numpy as np
import pytest

from latlong import Body, LatLongGrid, surface
from latlong._surface_kernels import band_triangle_areas, band_triangle_areas_serial


def _numpy_areas(body, band_lo, band_hi):
    """Reference: the triangle areas as computed before the kernel (numpy)."""
    t = body.grid.band_triangles(band_lo, band_hi)
    v0 = int(t.min())
    p = body.vertices(v0, int(t.max()) + 1)[t - v0]
    return t, 0.5 * np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1)


def _numpy_sample(body, areas, n, rng):
    """Reference: sample_surface_points as written in numpy before the kernel (the same
    draws and final conversion; the per-band search in numpy)."""
    total, a, b, band, resid = surface._draws(areas, n, rng)  # the unchanged random part
    p = np.empty((n, 3))
    order = np.argsort(band, kind="stable")
    starts = np.searchsorted(band[order], np.arange(len(areas) + 1))
    for bnd in np.flatnonzero(np.diff(starts)):
        sel = order[starts[bnd]:starts[bnd + 1]]
        t, area = _numpy_areas(body, int(bnd), int(bnd) + 1)
        k = np.minimum(np.searchsorted(np.cumsum(area), resid[sel], side="right"), len(t) - 1)
        tri = t[k]
        v = body.vertices(int(tri.min()), int(tri.max()) + 1)
        v0, v1, v2 = (v[tri[:, c] - tri.min()] for c in range(3))
        p[sel] = v0 + a[sel, None] * (v1 - v0) + b[sel, None] * (v2 - v0)
    lat, lon = surface._grid_lat_lon(body, p)
    return lat, lon, total


def _rough_body(m, stretch, seed=0):
    g = LatLongGrid(m)
    radii = 1000.0 + np.random.default_rng(seed).normal(0.0, 40.0, g.n_vertices)
    return Body(g, radii, radius_m=1000.0, stretch=stretch)


@pytest.mark.parametrize("m, stretch", [(1, (1.0, 1.0, 1.0)), (2, (1.0, 1.0, 1.0)),
                                        (7, (1.0, 1.0, 1.0)), (40, (1.3, 0.9, 0.7)),
                                        (121, (1.0, 2.0, 1.0))])
@pytest.mark.parametrize("kernel", [band_triangle_areas, band_triangle_areas_serial])
def test_triangle_areas_are_numpys_bits(m, stretch, kernel):
    body = _rough_body(m, stretch)
    g = body.grid
    _, ref = _numpy_areas(body, 0, 2 * m)
    for lo, hi in [(0, 2 * m), (0, 1), (m - 1, m + 1), (2 * m - 1, 2 * m)]:
        bo = g.band_offsets()
        out = np.full(int(bo[hi] - bo[lo]), np.nan)
        kernel(m, g.ring_offsets(), bo, body.radii_m, np.asarray(body.stretch, float),
               lo, hi, out)
        np.testing.assert_array_equal(out, ref[bo[lo]:bo[hi]])


def test_triangle_areas_sum_to_the_sphere():
    # closed form: the polyhedron inscribed in a sphere has slightly less than 4 pi r^2
    a = surface.band_areas(Body.sphere(LatLongGrid(200), 3.0))
    assert 0.9999 * 4 * np.pi * 9 < a.sum() < 4 * np.pi * 9


@pytest.mark.parametrize("m, stretch, n", [(1, (1.0, 1.0, 1.0), 50), (9, (1.0, 1.0, 1.0), 3000),
                                           (50, (1.5, 1.0, 0.6), 20000),
                                           (200, (1.0, 1.0, 1.0), 5)])
def test_sampler_is_the_numpy_sampler(m, stretch, n):
    body = _rough_body(m, stretch, seed=m)
    areas = surface.band_areas(body)
    ref_areas = np.add.reduceat(_numpy_areas(body, 0, 2 * m)[1], body.grid.band_offsets()[:-1])
    np.testing.assert_array_equal(areas, ref_areas)
    got = surface.sample_surface_points(body, areas, n, np.random.default_rng(7))
    ref = _numpy_sample(body, areas, n, np.random.default_rng(7))
    for g_, r_ in zip(got[:2], ref[:2], strict=True):
        np.testing.assert_array_equal(g_, r_)
    assert got[2] == ref[2]


def test_sampler_points_lie_on_the_surface_uniformly():
    body = Body.sphere(LatLongGrid(30), 100.0)
    lat, lon, _ = surface.surface_positions(body, 200_000, rng=2)
    # uniform on a sphere: sin(lat) uniform on [-1, 1]; longitude uniform on [0, 360)
    hist, _ = np.histogram(np.sin(np.radians(lat)), bins=10, range=(-1, 1))
    assert np.all(np.abs(hist / 20_000 - 1) < 0.03)
    hist, _ = np.histogram(lon, bins=12, range=(0, 360))
    assert np.all(np.abs(hist / (200_000 / 12) - 1) < 0.03)
