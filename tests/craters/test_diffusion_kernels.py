"""The numba kernels of the stamping tables against the numpy expressions they replace,
bit for bit (issue 20)."""

from __future__ import annotations

import numpy as np
import pytest

from craters._diffusion_kernels import _blend_tables, _rim_and_floor, _rim_spectra, _scale_rims
from craters.stamp import N_RIM, rim_perturbations


def test_blend_tables_matches_numpy_bit_for_bit():
    rng = np.random.default_rng(5)
    stack = rng.normal(size=(7, 9, 33)).astype(np.float32)
    n = 50
    a, b = rng.integers(0, 7, n), rng.integers(0, 7, n)
    j0 = rng.integers(0, 8, n)
    fd, ft, depth = rng.random(n), rng.random(n), rng.uniform(1, 1e3, n)
    rows = rng.permutation(n + 5)[:n]  # into given rows of a bigger table
    out = np.full((n + 5, 33), -7.0)
    _blend_tables(stack, a, b, j0, fd, ft, depth, rows, out)
    f, t = fd[:, None], ft[:, None]
    want = np.full((n + 5, 33), -7.0)
    want[rows] = ((1 - f) * ((1 - t) * stack[a, j0] + t * stack[a, j0 + 1])
                  + f * ((1 - t) * stack[b, j0] + t * stack[b, j0 + 1])) * depth[:, None]
    np.testing.assert_array_equal(out, want)


def test_cached_shapes_do_not_depend_on_what_was_made_before():
    """The diffusion cache fills (D, tau) nodes on demand, in batches that depend on the
    calls before: a node's shape must be the same bits whatever batch made it, so a seed
    gives the same surface in any process."""
    from craters import diffusion as df
    from craters.targets import get_target

    moon = get_target("moon")
    fresh_cache = df._Cache(moon, 3.0)
    warmed = df._Cache(moon, 3.0)
    warmed.stack(np.arange(150, 290, 7), np.full(20, 40))  # other nodes, fewer tau
    idx = np.arange(200, 240)
    upto = np.full(40, len(fresh_cache.tau_nodes))
    a, pa = fresh_cache.stack(idx, upto)
    b, pb = warmed.stack(idx, upto)
    np.testing.assert_array_equal(a[pa], b[pb])


def test_rim_and_floor_match_numpy_slices():
    rng = np.random.default_rng(6)
    tabs = rng.normal(size=(40, 64))
    rim, floor = np.empty(40), np.empty(40)
    _rim_and_floor(tabs, 32, 26, rim, floor)
    np.testing.assert_array_equal(rim, tabs[:, :32].max(axis=1))
    np.testing.assert_array_equal(floor, tabs[:, :26].min(axis=1))


def test_rim_kernels_match_the_numpy_expression_bit_for_bit():
    from craters.stamp import _HARMONICS

    n = 300
    rng = np.random.default_rng(7)
    irr = rng.uniform(0.0, 0.1, n)
    irr[:3] = 0.0  # no irregularity: rows of zeros (the peak-0 branch)
    phases = rng.uniform(0.0, 2 * np.pi, size=(n, _HARMONICS.size))
    amps = _HARMONICS.astype(float) ** -1.5
    want_spec = np.zeros((n, N_RIM // 2 + 1), dtype=np.complex128)
    want_spec[:, _HARMONICS] = (N_RIM / 2) * amps * np.exp(1j * phases) * (-1.0) ** _HARMONICS
    spec = np.zeros_like(want_spec)
    _rim_spectra(phases, (N_RIM / 2) * amps, (-1.0) ** _HARMONICS, _HARMONICS, spec)
    np.testing.assert_array_equal(spec, want_spec)
    rho = np.fft.irfft(want_spec, n=N_RIM, axis=1)
    rho[3] = 0.0
    peak = np.abs(rho).max(axis=1, keepdims=True)
    out = np.empty_like(rho)
    _scale_rims(rho, irr, out)
    np.testing.assert_array_equal(out, rho / np.where(peak > 0, peak, 1.0) * irr[:, None])
    # and rim_perturbations draws the same phases as that expression did
    got = rim_perturbations(n, irr, rng=np.random.default_rng(8))
    ph = np.random.default_rng(8).uniform(0.0, 2 * np.pi, size=(n, _HARMONICS.size))
    sp = np.zeros_like(want_spec)
    sp[:, _HARMONICS] = (N_RIM / 2) * amps * np.exp(1j * ph) * (-1.0) ** _HARMONICS
    r = np.fft.irfft(sp, n=N_RIM, axis=1)
    pk = np.abs(r).max(axis=1, keepdims=True)
    np.testing.assert_array_equal(got, r / np.where(pk > 0, pk, 1.0) * irr[:, None])
    assert np.allclose(np.abs(got).max(axis=1), irr)


def test_fresh_profile_in_blocks_equals_one_block(monkeypatch):
    from craters import morphology

    x = np.linspace(0.0, 3.0, 97)
    d = np.geomspace(5.0, 3e5, 1001)  # simple and complex craters
    monkeypatch.setattr(morphology, "_BLOCK", 10**9)  # one block
    whole = morphology.fresh_profile(x, d)
    monkeypatch.setattr(morphology, "_BLOCK", 500)  # 5 rows a block, a ragged last one
    np.testing.assert_array_equal(morphology.fresh_profile(x, d), whole)


@pytest.mark.parametrize("degradation", [0.1, 0.2, 0.4])
def test_worn_profiles_are_smooth_between_the_transform_nodes(degradation):
    # the tables come from the Fourier-Bessel series at their own radii: their curvature
    # (second differences) changes slowly from sample to sample; resampled linearly from
    # the transform's nodes it alternated (third differences ~0.9 of the second: rings in
    # low-sun close-ups)
    from craters.diffusion import profile_tables, tau_from_degradation

    h = profile_tables([1000.0], tau_from_degradation([1000.0], [degradation]))[0]
    assert np.abs(np.diff(h, 3)).max() < 0.25 * np.abs(np.diff(h, 2)).max()
