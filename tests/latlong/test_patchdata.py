"""The glTF export's ring windows (latlong.patchdata, latlong._window_kernels): the same
positions, normals and files as the whole-body arrays, bit for bit (issue 18)."""

from __future__ import annotations

import hashlib

import numpy as np
import pytest

import latlong
import latlong.patchdata as patchdata
from latlong import Body, LatLongGrid
from latlong._export_kernels import _glb_positions_kernel
from latlong._grid_kernels import lon_table
from latlong._window_kernels import _window_normals_kernel, _window_positions_kernel
from latlong.geometry.normals import lat_long_vertex_normals, vertex_normals


def _body(m, stretch=(1.0, 1.0, 1.0), seed=0):
    g = LatLongGrid(m)
    rng = np.random.default_rng(seed)
    radii = 1000.0 * (1.0 + 0.05 * rng.standard_normal(g.n_vertices))
    return Body(g, radii, stretch=stretch)


@pytest.mark.parametrize("stretch", [(1.0, 1.0, 1.0), (1.7, 1.0, 0.6)])
@pytest.mark.parametrize("m", [1, 2, 9])
def test_window_positions_and_normals_equal_the_whole_body(m, stretch):
    body = _body(m, stretch, seed=m)
    g = body.grid
    offs = g.ring_offsets()
    st = np.array(stretch)
    whole = np.empty((g.n_vertices, 3), np.float32)
    _glb_positions_kernel(m, offs, body.radii_m, st, lon_table(m, offs), whole)
    normals = {w: lat_long_vertex_normals(g, body.radii_m, stretch, weighting=w)
               for w in ("area", "angle")}
    assert normals["area"].tobytes() == g.vertex_normals(body.radii_m, stretch).tobytes()
    # the streamed angle-weighted normals (the glTF's) are the numpy reference's
    ref = vertex_normals(*body.mesh(), "angle")
    assert np.abs(normals["angle"] - ref).max() < 2e-6
    for r0 in range(2 * m + 1):
        for r1 in range(r0, 2 * m + 1):
            a, b = offs[r0], offs[r1 + 1]
            pos = np.empty((b - a, 3), np.float32)
            _window_positions_kernel(m, offs, body.radii_m, st, r0, r1, pos)
            assert pos.tobytes() == whole[a:b].tobytes(), (r0, r1)
            for w, angle in (("area", False), ("angle", True)):
                nrm = np.empty((b - a, 3), np.float32)
                _window_normals_kernel(m, offs, body.radii_m, st, np.empty((0, 2)), r0, r1, nrm,
                                       angle)
                assert nrm.tobytes() == normals[w][a:b].tobytes(), (r0, r1, w)


def _sha(path):
    return hashlib.sha256(path.read_bytes()).hexdigest()


@pytest.mark.parametrize("m, stretch, lod, k", [(7, (1.3, 1.0, 0.8), 0, 4),
                                                (48, (1.0, 1.0, 1.0), 2, 8)])
def test_glb_is_the_same_for_any_window_size(tmp_path, monkeypatch, m, stretch, lod, k):
    body = _body(m, stretch, seed=3)
    out = {}
    for window in (1 << 30, 200, 1):  # one window; many; one leaf at a time
        monkeypatch.setattr(patchdata, "WINDOW_VERTICES", window)
        (tmp_path / f"w{window}").mkdir()
        path = tmp_path / f"w{window}" / "body.glb"  # the manifest names the .glb
        latlong.export_glb(body, path, patch_k=k, lod=lod)
        out[window] = (_sha(path), _sha(path.with_suffix(".json")))
    assert len(set(out.values())) == 1


def test_windows_cover_every_leaf_once_in_band_order():
    g = LatLongGrid(64)
    from latlong.strips import patch_tree

    leaves = list(patch_tree(g, 8).leaves())
    band_lo = np.array([p.band_lo for p in leaves])
    ptr = np.concatenate([[0], np.cumsum([p.band_hi - p.band_lo for p in leaves])])
    table = (band_lo, ptr, np.zeros(ptr[-1], np.int64), np.zeros(ptr[-1], np.int64))
    order, srt = patchdata._sorted_leaves(table)
    assert np.all(np.diff(srt[0]) >= 0)
    seen = []
    offs = g.ring_offsets()
    for r0, r1, a, b in patchdata._windows(offs, srt):
        seen.extend(range(a, b))
        rings_hi = srt[0][a:b] + np.diff(srt[1])[a:b]
        assert r0 <= srt[0][a:b].min() and rings_hi.max() <= r1
        assert b - a == 1 or offs[r1 + 1] - offs[r0] <= patchdata.WINDOW_VERTICES
    assert seen == list(range(len(leaves)))


def test_every_prange_of_the_window_normals_is_a_parallel_loop():
    """numba runs a ``prange`` it cannot make a parallel loop as a plain loop, silently:
    the band loop of :func:`_window_normals_kernel` (its bound a conditional expression)
    ran on one thread, the glTF export's largest cost (2.40 s on 1 thread, 2.28 s on 2 at
    M = 1400; 1.20 s on 2 once parallel). Compiled afresh (diagnostics are not cached)."""
    import inspect

    from numba import njit

    from craters._calls import read_only

    kernel = _window_normals_kernel
    fresh = njit(parallel=True)(kernel.py_func)
    m = 3
    g = LatLongGrid(m)
    out = np.empty((g.n_vertices, 3), np.float32)
    # read-only, as the kernel's wrapper passes them (craters._calls.read_only_inputs)
    inputs = [read_only(a) for a in (np.full(g.n_vertices, 10.0), np.ones(3), np.empty((0, 2)))]
    args = (m, g.ring_offsets(), *inputs, 0, 2 * m, out)
    fresh(*args, True)
    diagnostics = next(iter(fresh.overloads.values())).metadata["parfor_diagnostics"]
    loops = {parfor.loc.line for parfor in diagnostics.initial_parfors}
    lines, first = inspect.getsourcelines(kernel.py_func)
    pranges = {first + i for i, line in enumerate(lines) if "in prange(" in line}
    assert pranges and pranges <= loops, f"serial prange lines: {sorted(pranges - loops)}"
