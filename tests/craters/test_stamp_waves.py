"""Parallel waves of craters on a raster (issue 20): the schedule against a brute-force
box-overlap check, and ``stamp_many`` byte-identical to the serial age-ordered stamp for
any thread count."""

from __future__ import annotations

import hashlib
import importlib
import os
import subprocess
import sys
from pathlib import Path

import numba
import numpy as np
import pytest

import craters
from craters._stamp_kernels import PARALLEL_MIN
from craters._wave_kernels import WAVE_MARGIN, _wave_schedule_kernel

stamp_module = importlib.import_module("craters.stamp")  # craters.stamp is its function

PIXEL = 2.0
SHAPE = (300, 360)


def _spans(c, reach, n):
    """Numpy reference of the schedule's span along one axis: the crater's box (centre
    ``c``, ``reach`` pixels) and the pixels next to its centre clamped onto the raster,
    plus WAVE_MARGIN, clipped to [0, n - 1]."""
    cc = np.clip(c, 0.0, n - 1.0)
    lo = np.maximum(np.floor(np.minimum(c, cc) - reach) - WAVE_MARGIN, 0).astype(np.int64)
    hi = np.minimum(np.ceil(np.maximum(c, cc) + reach) + WAVE_MARGIN, n - 1).astype(np.int64)
    return lo, hi


def _crater_boxes(c, reach, n):
    """Numpy reference of ``_crater_box`` along one axis: the pixels a crater reads or
    writes (empty, lo > hi, for a crater off the raster)."""
    return (np.maximum(np.floor(c - reach), 0).astype(np.int64),
            np.minimum(np.ceil(c + reach), n - 1).astype(np.int64))


def _overlap(lo, hi):
    """(n, n) True where the intervals [lo, hi] of two craters intersect."""
    return (lo[:, None] <= hi[None, :]) & (lo[None, :] <= hi[:, None])


def _random_craters(n, shape, rng):
    """Centres (pixels; some off the raster) and reaches (pixels; a few huge)."""
    ny, nx = shape
    cy = rng.uniform(-40.0, ny + 40.0, n)
    cx = rng.uniform(-40.0, nx + 40.0, n)
    reach = 1.0 + 60.0 * rng.pareto(1.5, n).clip(0.0, 5.0) * rng.uniform(0.0, 0.3, n)
    reach[:3] = [400.0, 150.0, 90.0]
    cy[:3] = [-200.0, ny / 2, ny + 30.0]  # one far off the raster that still reaches it
    return cy, cx, reach


@pytest.mark.parametrize("cell", [1, 7, 24, 1000])
def test_schedule_separates_every_overlapping_pair(cell):
    """Numpy O(n^2) reference: the kernel's waves are the greedy schedule over the cells
    (a crater's wave is one more than the latest earlier crater sharing a cell with it),
    no two craters whose boxes overlap share a wave, and each crater comes after every
    earlier crater it overlaps."""
    rng = np.random.default_rng(3)
    n = 500
    cy, cx, reach = _random_craters(n, SHAPE, rng)
    wave = np.empty(n, dtype=np.int64)
    n_waves = _wave_schedule_kernel(SHAPE[0], SHAPE[1], cy, cx, reach, cell, wave)
    assert n_waves == wave.max() + 1
    assert set(np.unique(wave)) == set(range(n_waves))
    i0, i1 = _spans(cy, reach, SHAPE[0])
    j0, j1 = _spans(cx, reach, SHAPE[1])
    shares_cell = _overlap(i0 // cell, i1 // cell) & _overlap(j0 // cell, j1 // cell)
    expect = np.zeros(n, dtype=np.int64)
    for c in range(n):
        earlier = np.nonzero(shares_cell[c, :c])[0]
        expect[c] = expect[earlier].max() + 1 if earlier.size else 0
    np.testing.assert_array_equal(wave, expect)
    # the pixels each crater reads or writes (the plane fit's fallback sample next to a
    # centre off the raster included, in the spans): overlapping craters are in order
    b0, b1 = _crater_boxes(cy, reach, SHAPE[0])
    c0, c1 = _crater_boxes(cx, reach, SHAPE[1])
    touch = (_overlap(b0, b1) & _overlap(c0, c1)) | (_overlap(i0, i1) & _overlap(j0, j1))
    i, j = np.nonzero(np.triu(touch, 1))
    assert i.size > n  # the check has pairs to check
    assert (wave[j] > wave[i]).all()


def test_schedule_cells_from_the_median_box():
    rng = np.random.default_rng(4)
    cy, cx, reach = _random_craters(300, SHAPE, rng)
    wave, n_waves, cell = stamp_module._wave_schedule(SHAPE, cy, cx, reach)
    assert cell == int(max((2 * np.median(reach) + 2 * WAVE_MARGIN + 1) / 4, 4))
    ref = np.empty(len(cy), dtype=np.int64)
    assert _wave_schedule_kernel(SHAPE[0], SHAPE[1], cy, cx, reach, cell, ref) == n_waves
    np.testing.assert_array_equal(wave, ref)
    assert n_waves < len(cy) // 4  # waves hold many craters


def _terrain_and_catalog():
    """Folded terrain (slopes 0 to 60 degrees: craters eroded and erased) and ~700
    craters of 3-60 m over and beyond the raster's edges, with three of 300 m whose boxes
    exceed PARALLEL_MIN (one partly off the raster)."""
    ny, nx = SHAPE
    rng = np.random.default_rng(21)
    yy, xx = np.mgrid[0:ny, 0:nx] * PIXEL
    heights = 138.0 * np.sin(xx / 80.0) * (yy < 300.0) + rng.normal(0.0, 0.2, SHAPE)
    w, h = nx * PIXEL, ny * PIXEL
    cat = craters.power_law_population(c=700 / ((w + 60) * (h + 60) * (3.0**-2 - 60.0**-2)),
                                       k=-2.0, d_min=3.0, d_max=60.0, x_range=(-30.0, w + 30),
                                       y_range=(-30.0, h + 30), rng=5)
    big = craters.make_catalog(x_m=[150.0, 500.0, 700.0], y_m=[300.0, -60.0, 450.0],
                               diameter_m=[300.0, 300.0, 320.0], age_gyr=[3.0, 1.2, 0.3],
                               degradation=[np.nan] * 3)
    cat = craters.make_catalog(**{k: np.concatenate([cat[k], big[k]]) for k in
                                  ("x_m", "y_m", "diameter_m", "age_gyr", "degradation")})
    return heights, cat


def _digest(heights, stamped):
    d = hashlib.sha256(heights.tobytes())
    for name in stamped.dtype.names:
        d.update(np.ascontiguousarray(stamped[name]).tobytes())
    return d.hexdigest()


def _stamp(roughness=True, progress=False):
    heights, cat = _terrain_and_catalog()
    return craters.stamp_many(heights, PIXEL, cat, roughness=roughness, rng=9,
                              progress=progress, return_catalog=True)


def test_the_scene_covers_the_cases():
    heights, cat = _terrain_and_catalog()
    h, stamped = _stamp()
    assert len(cat) >= 4 * stamp_module.WAVE_MIN
    assert len(stamped) < len(cat)  # erased on steep ground
    assert ((stamped["slope_deg"] > 20.0) & (stamped["depth_m"] > 0)).any()  # eroded
    reach = (craters.DEFAULT_EJECTA_EDGE * 0.5 * cat["diameter_m"] * 1.02) / PIXEL + 1.0
    boxes = [np.maximum(np.diff(_crater_boxes(cat[k] / PIXEL, reach, n), axis=0)[0] + 1, 0)
             for k, n in (("y_m", SHAPE[0]), ("x_m", SHAPE[1]))]
    assert ((boxes[0] * boxes[1]) >= PARALLEL_MIN).sum() >= 2
    off = (cat["x_m"] < 0) | (cat["y_m"] < 0) | (cat["x_m"] > SHAPE[1] * PIXEL)
    assert off.sum() > 10
    assert not np.array_equal(h, heights)


@pytest.mark.parametrize("roughness", [True, False])
def test_waves_equal_the_serial_stamp(monkeypatch, roughness):
    """1 thread (the serial kernel) and 2 threads (waves, once allowed for this little
    work; with a progress bar: several kernel calls) give the same heights and catalog,
    bit for bit."""
    old = numba.get_num_threads()
    calls = []
    real = stamp_module._stamp_waves_kernel
    monkeypatch.setattr(stamp_module, "_stamp_waves_kernel",
                        lambda *a: calls.append(1) or real(*a))
    try:
        numba.set_num_threads(1)
        serial = _digest(*_stamp(roughness))
        assert not calls
        if numba.config.NUMBA_NUM_THREADS < 2:
            pytest.skip("one thread: no waves to compare")
        numba.set_num_threads(2)
        assert _digest(*_stamp(roughness)) == serial
        assert not calls  # too little work for waves
        monkeypatch.setattr(stamp_module, "WAVE_MIN_PIXELS", 0)
        assert _digest(*_stamp(roughness)) == serial
        assert len(calls) == 1
        assert _digest(*_stamp(roughness, progress=True)) == serial
        assert len(calls) > 5  # the waves in chunks, for the bar
        # the serial kernel on two threads (its own row-parallel writes)
        monkeypatch.setattr(stamp_module, "WAVE_MIN", 10**9)
        assert _digest(*_stamp(roughness)) == serial
    finally:
        numba.set_num_threads(old)


def test_same_bytes_for_1_2_4_threads():
    """Separate processes with NUMBA_NUM_THREADS = 1, 2 and 4 (numba allows more threads
    than cores when the variable asks for them)."""
    here = str(Path(__file__).parent)
    code = (f"import sys; sys.path.insert(0, {here!r}); import numba; "
            "import test_stamp_waves as t; t.stamp_module.WAVE_MIN_PIXELS = 0; "
            "print(numba.get_num_threads(), t._digest(*t._stamp()))")
    out = {}
    for threads in ("1", "2", "4"):
        env = {**os.environ, "NUMBA_NUM_THREADS": threads}
        proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                              env=env, check=True)
        n, digest = proc.stdout.split()
        assert n == threads
        out[threads] = digest
    assert len(set(out.values())) == 1, out
