"""Parallel waves of craters (issue 20): the schedule against a brute-force overlap
check, and the stamped body byte-identical to the serial age-ordered stamp for any
thread count."""

from __future__ import annotations

import hashlib
import os
import subprocess
import sys
from pathlib import Path

import numba
import numpy as np
import pytest

import craters
import latlong.cratering as cratering
from latlong import Body, LatLongGrid, stamp_craters
from latlong._wave_kernels import _wave_schedule_kernel


def _angle(colat1, lon1, colat2, lon2):
    u1 = np.stack([np.sin(colat1) * np.cos(lon1), np.sin(colat1) * np.sin(lon1),
                   np.cos(colat1)], -1)
    u2 = np.stack([np.sin(colat2) * np.cos(lon2), np.sin(colat2) * np.sin(lon2),
                   np.cos(colat2)], -1)
    return np.arccos(np.clip((u1 * u2).sum(-1), -1.0, 1.0))


@pytest.mark.parametrize("n_theta", [4, 16, 64])
def test_schedule_separates_every_overlapping_pair(n_theta):
    """Numpy reference: for every pair i < j whose caps overlap, wave[j] > wave[i]; the
    waves are the greedy schedule's, never later than one plus the latest earlier
    overlapping crater's wave (cells only ever add conflicts)."""
    rng = np.random.default_rng(7)
    n = 400
    z = rng.uniform(-1, 1, n)
    colat, lon = np.arccos(z), rng.uniform(0, 2 * np.pi, n)
    colat[:5] = [0.01, np.pi - 0.02, 0.5, 1.0, 3.1]  # near the poles too
    ang = rng.uniform(0.005, 0.25, n) ** 1.5
    wave = np.empty(n, dtype=np.int64)
    n_waves = _wave_schedule_kernel(colat, lon, ang, n_theta, wave)
    assert n_waves == wave.max() + 1
    sep = _angle(colat[:, None], lon[:, None], colat[None, :], lon[None, :])
    overlap = sep < ang[:, None] + ang[None, :]
    i, j = np.nonzero(np.triu(overlap, 1))
    assert (wave[j] > wave[i]).all()
    # a crater overlapping nothing earlier may still wait (shared cells), but a wave is
    # never empty
    assert set(np.unique(wave)) == set(range(n_waves))


def _body_and_catalog():
    radius = 2000.0
    body = Body.sphere(LatLongGrid(120), radius)
    area = 4 * np.pi * radius**2
    cat = craters.power_law_population(radius=radius, c=1500 / (area * (15.0**-2 - 600.0**-2)),
                                       k=-2.0, d_min=15.0, d_max=600.0, rng=5)
    return body, cat


def _digest(body):
    h = hashlib.sha256(body.radii_m.tobytes())
    for name in body.craters.dtype.names:
        h.update(np.ascontiguousarray(body.craters[name]).tobytes())
    return h.hexdigest()


def test_waves_equal_the_serial_stamp(monkeypatch):
    body, cat = _body_and_catalog()
    target = craters.small_body(2000.0)
    old = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        serial = _digest(stamp_craters(body, cat, rng=3, target=target))
        if numba.config.NUMBA_NUM_THREADS < 2:
            pytest.skip("one thread: no waves to compare")
        numba.set_num_threads(2)
        calls = []
        real = cratering._stamp_waves_kernel
        monkeypatch.setattr(cratering, "_stamp_waves_kernel",
                            lambda *a: calls.append(1) or real(*a))
        assert _digest(stamp_craters(body, cat, rng=3, target=target)) == serial
        assert calls  # the waves ran
        # a schedule that is too tight is detected and the stamp redone serially
        monkeypatch.setattr(cratering, "WAVE_RADIUS_SHARE", 4.0)
        assert _digest(stamp_craters(body, cat, rng=3, target=target)) == serial
    finally:
        numba.set_num_threads(old)


def test_same_bytes_for_1_2_4_threads():
    here = str(Path(__file__).parent)
    code = (f"import sys; sys.path.insert(0, {here!r}); import craters; "
            "import test_crater_waves as t; from latlong import stamp_craters; "
            "b, c = t._body_and_catalog(); "
            "print(t._digest(stamp_craters(b, c, rng=3, target=craters.small_body(2000.0))))")
    out = set()
    for threads in ("1", "2", "4"):
        env = {**os.environ, "NUMBA_NUM_THREADS": threads}
        proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                              env=env, check=True)
        out.add(proc.stdout.strip())
    assert len(out) == 1


def test_fill_rim_cells_gives_the_rim_offsets_of_the_whole_fill():
    """Filling only the cells the rim samples read gives the same rim offsets, bit for
    bit, as filling every hole (and the same value in every cell it fills)."""
    from craters.kernels import rim_offsets
    from latlong._crater_kernels import _fill_holes, _fill_rim_cells

    rng = np.random.default_rng(11)
    g, nh, sp, radius = 21, 10, 1.0, 6.0
    grid = rng.normal(size=(g, g))
    known = rng.uniform(size=(g, g)) < 0.35
    grid[~known] = 0.0
    rim = craters.rim_perturbations(1, 0.05, rng=2)[0]
    full = _fill_holes(grid, known)
    part = _fill_rim_cells(grid, known, float(nh), float(nh), sp, radius, rim)
    filled = (part != grid) | known
    assert (~known & filled).sum() > 10
    np.testing.assert_array_equal(part[filled], full[filled])
    a, b = np.empty(len(rim)), np.empty(len(rim))
    rim_offsets(full, float(nh), float(nh), sp, radius, rim, 0.0, 0.0, 0.0, a)
    rim_offsets(part, float(nh), float(nh), sp, radius, rim, 0.0, 0.0, 0.0, b)
    np.testing.assert_array_equal(a, b)


def test_balanced_waves_keep_each_crater_in_its_wave_once():
    """LPT sharing of each wave among threads: a permutation that keeps every wave's
    craters together, and the heaviest thread's load no worse than round-robin dealing."""
    from latlong._wave_kernels import _balance_waves_kernel

    rng = np.random.default_rng(4)
    n, n_threads = 400, 3
    wave = np.sort(rng.integers(0, 25, n))
    cost = rng.pareto(1.5, n) + 1.0
    order = np.lexsort((-cost, wave))
    starts = np.searchsorted(wave[order], np.arange(wave.max() + 2))
    out = np.empty(n, np.int64)
    bounds = np.empty((len(starts) - 1, n_threads + 1), np.int64)
    _balance_waves_kernel(order, starts, cost, n_threads, out, bounds)
    assert np.array_equal(np.sort(out), np.arange(n))
    lpt = rr = 0.0
    for w in range(len(starts) - 1):
        assert bounds[w, 0] == starts[w] and bounds[w, -1] == starts[w + 1]
        assert set(out[starts[w]:starts[w + 1]]) == set(order[starts[w]:starts[w + 1]])
        loads = [cost[out[bounds[w, t]:bounds[w, t + 1]]].sum() for t in range(n_threads)]
        lpt += max(loads)
        dealt = order[starts[w]:starts[w + 1]]
        rr += max(cost[dealt[t::n_threads]].sum() for t in range(n_threads))
    assert lpt <= rr
    assert lpt < 0.95 * rr  # heavy-tailed costs: dealing in turn leaves real imbalance
