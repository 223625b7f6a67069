"""Exact ring-arc faulting against brute force, fault statistics, two-phase faulting."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from latlong import (
    FAULTING_PRESETS,
    FaultingParams,
    LatLongGrid,
    apply_faults,
    area_mean,
    poisson_faulting,
    random_faults,
    two_phase_faulting,
)

SUM_TOL = 1e-9  # relative to sum |h|: only the summation order differs from brute force


def brute_force(grid, normals, heights):
    """Reference: the sign test itself, h_i = sum_f heights[f] [u_i . n_f > 0]."""
    u = grid.unit_vectors()
    out = np.zeros(grid.n_vertices)
    for n, h in zip(np.asarray(normals, float), np.asarray(heights, float), strict=True):
        d = u[:, 0] * n[0] + u[:, 1] * n[1] + u[:, 2] * n[2]  # same rounding as the kernel
        out += h * (d > 0)
    return out


def raised_sets_equal(grid, normals):
    """Each fault alone (height 1) raises exactly the brute-force set of vertices."""
    for n in normals:
        fast = apply_faults(grid, [n], [1.0])
        slow = brute_force(grid, [n], [1.0])
        if not np.array_equal(fast, slow):
            return False
    return True


@pytest.mark.parametrize("m", [1, 2, 5, 17, 60])
def test_matches_brute_force(m, rng):
    g = LatLongGrid(m)
    normals, heights = random_faults(300, 2.0, rng=rng)
    fast = apply_faults(g, normals, heights)
    slow = brute_force(g, normals, heights)
    assert np.abs(fast - slow).max() <= SUM_TOL * np.abs(heights).sum()
    assert raised_sets_equal(g, normals[:40])


def test_degenerate_normals():
    g = LatLongGrid(12)
    special = [
        [0, 0, 1], [0, 0, -1],  # the poles: whole hemispheres by rings
        [1, 0, 0], [0, 1, 0], [-1, 0, 0], [1, 1, 0],  # great circles through vertices
        [0, 0, 1e-300], [1e-300, 0, 1], [1, 0, 1e-17],
        [np.cos(0.3), np.sin(0.3), 0.0],
        [1, 0, np.tan(np.pi / 24)],  # the plane touches ring vertices
    ]
    assert raised_sets_equal(g, special)


@settings(max_examples=60, deadline=None)
@given(st.lists(st.floats(-1, 1, allow_subnormal=False), min_size=3, max_size=3).filter(
    lambda v: np.dot(v, v) > 1e-12), st.integers(1, 20))
def test_single_fault_property(normal, m):
    assert raised_sets_equal(LatLongGrid(m), [normal])


def test_pole_and_hemisphere_counts():
    g = LatLongGrid(10)
    h = apply_faults(g, [[0, 0, 1]], [1.0])
    # exactly the northern rings (the equator has z = 0, not > 0)
    assert h.sum() == g.ring_offsets()[10]
    assert h[0] == 1 and h[-1] == 0


def test_bad_inputs():
    g = LatLongGrid(3)
    with pytest.raises(ValueError, match="normals"):
        apply_faults(g, [[1, 0]], [1.0])
    with pytest.raises(ValueError, match="heights"):
        apply_faults(g, [[1, 0, 0]], [1.0, 2.0])
    with pytest.raises(ValueError, match="finite"):
        apply_faults(g, [[np.nan, 0, 0]], [1.0])
    with pytest.raises(ValueError, match="non-zero"):
        apply_faults(g, [[0, 0, 0]], [1.0])
    with pytest.raises(TypeError, match="grid"):
        apply_faults("grid", [[1, 0, 0]], [1.0])
    assert not apply_faults(g, np.zeros((0, 3)), np.zeros(0)).any()


def test_random_faults_distribution():
    normals, heights = random_faults(20000, 3.0, rng=1)
    assert np.allclose(np.linalg.norm(normals, axis=1), 1)
    assert np.abs(heights).max() <= 3.0
    assert abs(heights.std() - 1.0) < 0.03  # max / 3, truncated at 3 sigma
    assert np.abs(normals.mean(axis=0)).max() < 0.03  # isotropic
    with pytest.raises(ValueError, match="n_faults"):
        random_faults(-1, 1.0)
    with pytest.raises(ValueError, match="max_fault_m"):
        random_faults(5, np.nan)


def test_poisson_faulting_zero_mean_and_antisymmetric():
    g = LatLongGrid(12)
    h = poisson_faulting(g, 500, 1.0, rng=7)
    assert abs(area_mean(g, h)) < 1e-12
    # every fault raises one hemisphere: after removing the mean, h(-u) = -h(u)
    rings, pos = g.vertex_rings(), g.vertex_positions()
    sizes = g.ring_sizes()[rings]
    antipode = g.index(2 * g.magnitude - rings, pos + sizes // 2)
    inner = (rings > 0) & (rings < 2 * g.magnitude)
    assert np.allclose(h[inner], -h[antipode[inner]], atol=1e-9)
    assert np.isclose(h[0], -h[-1], atol=1e-9)


def test_two_phase_deterministic_and_seed_dependent():
    g = LatLongGrid(16)
    p = FaultingParams(200, 2.0, 15.0, 2, 300, 0.1)
    a = two_phase_faulting(g, 50.0, p, rng=3)
    b = two_phase_faulting(g, 50.0, p, rng=3)
    c = two_phase_faulting(g, 50.0, p, rng=4)
    assert np.array_equal(a, b)
    assert not np.allclose(a, c)


def test_two_phase_smoothing_reduces_phase_one_roughness():
    g = LatLongGrid(48)
    rough = FaultingParams(800, 5.0, 0.0, 0, 0, 0.0)
    smoothed = FaultingParams(800, 5.0, 30.0, 3, 0, 0.0)
    a = two_phase_faulting(g, 100.0, rough, rng=5)
    b = two_phase_faulting(g, 100.0, smoothed, rng=5)
    # same phase-1 faults; smoothing removes the short-wavelength (edge-to-edge) relief
    e = g.edges()
    assert np.abs(np.diff(b[e], axis=1)).mean() < 0.3 * np.abs(np.diff(a[e], axis=1)).mean()


def test_presets_and_params_validation():
    assert FAULTING_PRESETS["paper"].n_faults_2 == 20000
    assert FAULTING_PRESETS["fig4"].max_fault_2_m == 0.5
    with pytest.raises(ValueError, match="smooth_passes"):
        FaultingParams(smooth_passes=-1)
    with pytest.raises(ValueError, match="max_fault_1_m"):
        FaultingParams(max_fault_1_m=float("inf"))
    with pytest.raises(ValueError, match="stretch"):
        FaultingParams(stretch=(1.0, 0.0, 1.0))
    assert FAULTING_PRESETS["paper"].stretch == (2.0, 1.0, 1.0)
