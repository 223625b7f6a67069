"""The 6M^2+2 lat/long grid: counts, closed outward 2-manifold, spacing, nesting."""

from __future__ import annotations

import numpy as np
import pytest

from latlong import LatLongGrid
from latlong._grid_kernels import _ray_triangle

MAGNITUDES = [*range(1, 65), 200]
EDGE_RATIO_LIMIT = 2.5
NESTING_TOL = 1e-9


def reference_triangles(m: int) -> np.ndarray:
    """Pure-numpy reference of the zipper triangulation (sorting the ring advances)."""
    g = LatLongGrid(m)
    sizes, offs = g.ring_sizes(), g.ring_offsets()
    out = []
    for band in range(2 * m):
        south = band >= m
        ra, rb = (band + 1, band) if south else (band, band + 1)
        na, nb, oa, ob = sizes[ra], sizes[rb], offs[ra], offs[rb]
        if na == 1:
            j = np.arange(nb)
            tri = np.stack([np.full(nb, oa), ob + j, ob + (j + 1) % nb], axis=1)
        else:
            # advances of ring a at longitudes (i+1)/na, of ring b at (j+1)/nb; a first on ties
            ka = (np.arange(na) + 1) * nb
            kb = (np.arange(nb) + 1) * na
            keys = np.concatenate([ka, kb])
            is_a = np.concatenate([np.ones(na, bool), np.zeros(nb, bool)])
            order = np.lexsort((~is_a, keys))
            is_a = is_a[order]
            i = np.concatenate([[0], np.cumsum(is_a)[:-1]])
            j = np.concatenate([[0], np.cumsum(~is_a)[:-1]])
            a0, a1 = oa + i % na, oa + (i + 1) % na
            b0, b1 = ob + j % nb, ob + (j + 1) % nb
            tri = np.where(is_a[:, None], np.stack([a0, b0, a1], 1), np.stack([a0, b0, b1], 1))
        if south:
            tri = tri[:, [0, 2, 1]]
        out.append(tri)
    return np.concatenate(out)


@pytest.mark.parametrize("m", MAGNITUDES)
def test_counts(m):
    g = LatLongGrid(m)
    assert g.n_vertices == 6 * m * m + 2
    assert g.ring_sizes().sum() == g.n_vertices
    assert g.ring_sizes()[m] == 6 * m  # the equator
    t = g.triangles()
    assert t.shape == (2 * g.n_vertices - 4, 3) == (g.n_triangles, 3)
    assert t.min() == 0 and t.max() == g.n_vertices - 1


@pytest.mark.parametrize("m", MAGNITUDES)
def test_closed_outward_two_manifold(m):
    g = LatLongGrid(m)
    t = g.triangles()
    n = g.n_vertices
    # every directed edge exactly once and its reverse exactly once: closed, consistently
    # oriented, no edge shared by more than two triangles
    directed = np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]])
    key = directed[:, 0] * n + directed[:, 1]
    assert np.unique(key).size == key.size
    rev = directed[:, 1] * n + directed[:, 0]
    assert np.array_equal(np.sort(key), np.sort(rev))
    # no degenerate triangles; Euler characteristic 2 (genus 0)
    assert (t[:, 0] != t[:, 1]).all() and (t[:, 1] != t[:, 2]).all() and (t[:, 0] != t[:, 2]).all()
    n_edges = key.size // 2
    assert n - n_edges + len(t) == 2
    # manifold vertices: each vertex's incident triangles form one fan (#edges == #tris)
    tri_per_vertex = np.bincount(t.ravel(), minlength=n)
    edges_per_vertex = np.bincount(g.edges().ravel(), minlength=n)
    assert np.array_equal(tri_per_vertex, edges_per_vertex)
    # outward: every triangle's normal points away from the centre, volume > 0
    u = g.unit_vectors()
    a, b, c = u[t[:, 0]], u[t[:, 1]], u[t[:, 2]]
    normal = np.cross(b - a, c - a)
    assert (np.einsum("ij,ij->i", normal, a + b + c) > 0).all()
    volume = np.einsum("ij,ij->", a, np.cross(b, c)) / 6
    assert volume > 0


@pytest.mark.parametrize("m", [1, 2, 3, 7, 16])
def test_vertex_links_are_single_cycles(m):
    g = LatLongGrid(m)
    t = g.triangles()
    for v in range(g.n_vertices):
        fan = t[(t == v).any(axis=1)]
        # each opposite edge (in the triangle's order after v) links the ring of neighbours
        nxt = {}
        for tri in fan:
            k = int(np.flatnonzero(tri == v)[0])
            nxt[int(tri[(k + 1) % 3])] = int(tri[(k + 2) % 3])
        start = next(iter(nxt))
        seen, cur = 1, nxt[start]
        while cur != start:
            cur = nxt[cur]
            seen += 1
        assert seen == len(fan) == len(nxt)


@pytest.mark.parametrize("m", MAGNITUDES)
def test_edge_length_ratio(m):
    g = LatLongGrid(m)
    u = g.unit_vectors()
    e = g.edges()
    length = np.linalg.norm(u[e[:, 0]] - u[e[:, 1]], axis=1)
    assert length.max() / length.min() <= EDGE_RATIO_LIMIT


@pytest.mark.parametrize("m", MAGNITUDES)
def test_nesting(m):
    coarse, fine = LatLongGrid(m), LatLongGrid(2 * m)
    idx = fine.nested_indices(coarse)
    # the even rings / even vertices of the 2M grid
    assert np.array_equal(fine.vertex_rings()[idx], 2 * coarse.vertex_rings())
    assert np.array_equal(fine.vertex_positions()[idx], 2 * coarse.vertex_positions())
    assert np.abs(fine.unit_vectors()[idx] - coarse.unit_vectors()).max() <= NESTING_TOL
    assert np.abs(fine.latitudes()[idx] - coarse.latitudes()).max() <= NESTING_TOL


def test_nesting_other_factors():
    g3, g1 = LatLongGrid(9), LatLongGrid(3)
    idx = g3.nested_indices(3)
    assert np.abs(g3.unit_vectors()[idx] - g1.unit_vectors()).max() <= NESTING_TOL
    with pytest.raises(ValueError, match="must divide"):
        LatLongGrid(10).nested_indices(3)


@pytest.mark.parametrize("m", [1, 2, 3, 5, 8, 13, 40])
def test_triangles_kernel_matches_numpy_reference(m):
    assert np.array_equal(LatLongGrid(m).triangles(), reference_triangles(m))


def test_band_triangles_chunks_concatenate():
    g = LatLongGrid(9)
    parts = [g.band_triangles(lo, hi) for lo, hi in [(0, 1), (1, 7), (7, 9), (9, 18)]]
    assert np.array_equal(np.concatenate(parts), g.triangles())
    with pytest.raises(ValueError, match="band_lo"):
        g.band_triangles(5, 3)


def test_coordinates_and_areas():
    g = LatLongGrid(12)
    u = g.unit_vectors()
    assert np.allclose(np.linalg.norm(u, axis=1), 1.0)
    assert np.array_equal(u[0], [0, 0, 1]) and np.array_equal(u[-1], [0, 0, -1])
    assert np.isclose(g.vertex_areas().sum(), 4 * np.pi, rtol=1e-12)
    lon = g.longitudes()
    assert lon.min() >= 0 and lon.max() < 2 * np.pi
    # ring r sits at colatitude pi r / 2M
    assert np.allclose(np.pi / 2 - g.latitudes(), g.ring_colatitudes()[g.vertex_rings()])


def test_neighbours_match_triangles():
    g = LatLongGrid(5)
    t = g.triangles()
    for v in [0, 1, 7, 40, g.n_vertices - 1]:
        expect = np.unique(t[(t == v).any(axis=1)])
        assert np.array_equal(g.neighbours(v), expect[expect != v])
    assert len(g.neighbours(0)) == 6
    with pytest.raises(ValueError, match="`i`"):
        g.neighbours(g.n_vertices)


def reference_interpolate(g: LatLongGrid, values, colat, lon):
    """Pure-numpy reference of the ring-bilinear interpolation."""
    m = g.magnitude
    q = colat / (np.pi / (2 * m))
    r0 = np.clip(np.floor(q).astype(int), 0, 2 * m - 1)
    t = np.clip(q - r0, 0, 1)
    out = np.zeros_like(colat)
    for k, wgt in ((0, 1 - t), (1, t)):
        r = r0 + k
        n = g.ring_sizes()[r]
        s = np.mod(lon / (2 * np.pi) * n, n)
        j0 = np.minimum(np.floor(s).astype(int), n - 1)
        w = s - j0
        j1 = np.where(j0 + 1 == n, 0, j0 + 1)
        o = g.ring_offsets()[r]
        v = np.where(n == 1, values[o], (1 - w) * values[o + j0 % n] + w * values[o + j1 % n])
        out += wgt * v
    return out


def test_interpolate(rng):
    g = LatLongGrid(7)
    values = rng.standard_normal(g.n_vertices)
    # exact at the vertices
    assert np.allclose(g.interpolate(values, np.pi / 2 - g.latitudes(), g.longitudes()), values,
                       atol=1e-12)
    colat = rng.uniform(0, np.pi, 500)
    lon = rng.uniform(-7, 7, 500)
    assert np.allclose(g.interpolate(values, colat, lon),
                       reference_interpolate(g, values, colat, lon), atol=1e-12)
    # z is reproduced to second order
    fine = LatLongGrid(64)
    z = fine.unit_vectors()[:, 2]
    got = fine.interpolate(z, colat, lon)
    assert np.abs(got - np.cos(colat)).max() < 1e-3


@pytest.mark.parametrize("bad", [0, -3, 1.5, "4", True, 10**7])
def test_bad_magnitude(bad):
    with pytest.raises((TypeError, ValueError), match="magnitude"):
        LatLongGrid(bad)


def test_readonly_arrays():
    g = LatLongGrid(3)
    for a in (g.unit_vectors(), g.triangles(), g.ring_sizes(), g.latitudes()):
        with pytest.raises(ValueError):
            a[0] = 0


def test_ray_triangle_matches_a_linear_solve(rng):
    """Moller-Trumbore against numpy: origin + t d = a + u (b - a) + v (c - a)."""
    for _ in range(200):
        a, b, c = rng.normal(size=(3, 3)) + np.array([0.0, 0.0, 2.0])
        d = rng.normal(size=3)
        u, v, t = _ray_triangle(d[0], d[1], d[2], a, b, c)
        want = np.linalg.solve(np.stack([d, a - b, a - c], axis=1), a)
        np.testing.assert_allclose([t, u, v], want, rtol=1e-8, atol=1e-8)
    # parallel to the triangle's plane: no crossing
    a, b, c = np.array([0.0, 0, 1]), np.array([1.0, 0, 1]), np.array([0.0, 1, 1])
    assert _ray_triangle(1.0, 1.0, 0.0, a, b, c)[2] == -1.0
