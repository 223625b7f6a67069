"""Bodies far bigger than memory used to allow (issue 18): the build keeps one float64
radius per vertex plus bounded buffers, with the same bytes as the whole-grid code it
replaced."""

from __future__ import annotations

import numpy as np
import pytest

import latlong.body as body_module
import latlong.perlin as perlin
import latlong.surface as surface
from latlong import Body, LatLongGrid, perlin_fbm
from latlong.surface import band_areas


def _fbm_whole_grid(grid, frequency, octaves, persistence, lacunarity, amplitude_m, rng):
    """The fBm as computed before issue 18: every unit vector at once, then the kernel,
    then the amplitude (reference)."""
    from latlong._perlin_kernels import GRAD3, PERM, _fbm3_kernel

    rng = np.random.default_rng(rng)
    rot = perlin.random_rotation(rng)
    offset = rng.uniform(0.0, 256.0, size=3)
    u = grid.unit_vectors_range(0, grid.n_vertices)
    xs, ys, zs = (((u[:, 0] * rot[a, 0] + u[:, 1] * rot[a, 1] + u[:, 2] * rot[a, 2])
                   * frequency + offset[a]).astype(np.float32) for a in range(3))
    out = np.empty(grid.n_vertices)
    _fbm3_kernel(xs, ys, zs, octaves, np.float32(persistence), np.float32(lacunarity), 0,
                 PERM, GRAD3, out)
    out *= amplitude_m
    return out


@pytest.mark.parametrize("chunk", [1, 97, 1000, 1 << 20])
@pytest.mark.parametrize("magnitude", [7, 40])
def test_fbm_in_chunks_equals_the_whole_grid(monkeypatch, chunk, magnitude):
    grid = LatLongGrid(magnitude)
    args = (1.5, 6, 0.5, 1.75, 40.0)
    ref = _fbm_whole_grid(grid, *args, rng=3)
    monkeypatch.setattr(perlin, "_CHUNK", chunk)
    np.testing.assert_array_equal(perlin_fbm(grid, *args, rng=3), ref)
    out = np.full(grid.n_vertices, np.nan)
    assert perlin_fbm(grid, *args, rng=3, out=out) is out
    np.testing.assert_array_equal(out, ref)


@pytest.mark.parametrize("bad", [np.empty(10), np.empty(386, np.float32),
                                 np.empty((386, 2))[:, 0]])
def test_fbm_out_is_checked(bad):
    with pytest.raises(ValueError, match="`out`"):
        perlin_fbm(LatLongGrid(8), 1.5, 4, 0.5, 2.0, 1.0, rng=0, out=bad)


def test_body_takes_an_array_over_without_a_copy():
    grid = LatLongGrid(6)
    radii = np.linspace(1.0, 2.0, grid.n_vertices)
    kept = radii.copy()
    copied = Body(grid, radii)
    assert not np.shares_memory(copied.radii_m, radii) and radii.flags.writeable
    adopted = Body(grid, radii, copy=False)
    assert adopted.radii_m is radii and not radii.flags.writeable
    np.testing.assert_array_equal(adopted.radii_m, kept)
    assert adopted.radius_m == copied.radius_m
    # not float64 / not contiguous: converted (a copy whatever `copy` says)
    other = Body(grid, radii.astype(np.float32), copy=False)
    assert not np.shares_memory(other.radii_m, radii)
    assert not other.radii_m.flags.writeable


def test_replace_shares_unchanged_radii_and_copies_new_ones():
    grid = LatLongGrid(6)
    body = Body.sphere(grid, 3.0)
    assert body.replace(metadata={"a": 1}).radii_m is body.radii_m
    assert body.replace(stretch=(2, 1, 1)).radii_m is body.radii_m
    new = np.full(grid.n_vertices, 4.0)
    assert not np.shares_memory(body.replace(radii_m=new).radii_m, new)
    assert body.replace(radii_m=new, copy=False).radii_m is new
    with pytest.raises(ValueError, match="finite"):
        body.replace(radii_m=np.full(grid.n_vertices, np.nan))


@pytest.mark.parametrize("chunk", [5, 1 << 20])
def test_radii_checks_in_chunks(monkeypatch, chunk):
    monkeypatch.setattr(body_module, "_CHECK_CHUNK", chunk)
    grid = LatLongGrid(6)
    radii = np.full(grid.n_vertices, 2.0)
    radii[[3, 50, 200]] = [-1.0, 0.0, -2.5]
    with pytest.raises(ValueError, match=r"3 vertices have radius <= 0 \(min -2\.5 m\)"):
        Body(grid, radii)
    radii[:] = 2.0
    radii[-1] = np.inf
    with pytest.raises(ValueError, match="must be finite"):
        Body(grid, radii, copy=False)


@pytest.mark.parametrize("magnitude", [1, 5, 40, 41, 150])
def test_mean_radius_from_ring_areas(magnitude):
    """The reference radius of a body made without one: the area-weighted mean, the same
    bits as ``dot(vertex_areas, radii) / sum`` up to 10 000 vertices (M <= 40; numpy's
    dot is one BLAS thread there), within 1e-15 beyond."""
    grid = LatLongGrid(magnitude)
    radii = 100.0 + np.random.default_rng(magnitude).standard_normal(grid.n_vertices)
    w = grid.vertex_areas()
    ref = float(np.dot(w, radii) / w.sum())
    got = Body(grid, radii).radius_m
    if grid.n_vertices <= 10_000:
        assert got == ref
    else:
        assert abs(got - ref) <= 1e-15 * ref
    w_sorted = np.sort(w)  # a different order of the same sum: agrees to rounding
    assert abs(got - float(np.sum(w * radii) / w_sorted.sum())) <= 1e-14 * ref


def test_ring_areas_give_the_vertex_areas():
    grid = LatLongGrid(9)
    np.testing.assert_array_equal(
        grid.vertex_areas(), grid.ring_areas()[np.repeat(np.arange(grid.n_rings),
                                                         grid.ring_sizes())])
    assert abs(grid.vertex_areas().sum() - 4 * np.pi) < 1e-12


@pytest.mark.parametrize("step", [1, 50, 1000])
def test_band_areas_do_not_depend_on_the_step(monkeypatch, step):
    body = Body(LatLongGrid(30), 10.0 + np.random.default_rng(1).random(5402),
                stretch=(1.5, 1.0, 0.8))
    ref = band_areas(body)
    monkeypatch.setattr(surface, "_TRIANGLES_PER_STEP", step)
    np.testing.assert_array_equal(band_areas(body), ref)
