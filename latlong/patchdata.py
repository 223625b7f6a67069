"""The glTF export's patch data, made ring window by ring window (issue 18).

:func:`latlong.export_glb` writes one mesh per leaf of the patch tree: its float32
positions, unit normals and strip indices. Holding the positions and normals of the
whole body costs 24 B a vertex (16 GB at M = 8192); here they exist for a window of
consecutive rings at a time (:mod:`latlong._window_kernels`, the same values bit for
bit). The leaves are visited in order of their first band; each window covers the rings
of the leaves it serves (at least one leaf, about :data:`WINDOW_VERTICES` vertices), and
each leaf's data, made on worker threads, is written at its own offset of the level's
data (``os.pwrite``), so the file is the one the whole-body pass wrote.
"""

from __future__ import annotations

import functools
import os

import numpy as np

from craters._shared import progress_bar

from .meshio.chunks import ordered_chunks

__all__ = ["WINDOW_VERTICES", "leaf_metadata", "write_leaf_data"]

#: Vertices of a ring window (its float32 positions and normals: 24 B each, plus a
#: float32 accumulator of 12 B while the normals are made).
WINDOW_VERTICES = 1 << 22
#: No longitude table: the window kernel computes the cosines and sines itself.
_NO_TABLE = np.empty((0, 2))
#: Bytes of leaf data made per task of the writing pass.
GROUP_BYTES = 1 << 25
#: Leaves per task of the metadata pass.
LEAVES_PER_TASK = 64


def _sorted_leaves(leaves: tuple) -> tuple[np.ndarray, tuple]:
    """(order, the leaf table in that order): leaves by first band, ties in tree order."""
    band_lo, ptr, lo, hi = leaves
    order = np.argsort(band_lo, kind="stable")
    counts = np.diff(ptr)[order]
    ptr_s = np.concatenate([[0], np.cumsum(counts)]).astype(np.int64)
    entry = np.repeat(ptr[:-1][order] - ptr_s[:-1], counts) + np.arange(ptr_s[-1])
    return order, (np.ascontiguousarray(band_lo[order]), ptr_s, np.ascontiguousarray(lo[entry]),
                   np.ascontiguousarray(hi[entry]))


def _windows(ring_offsets: np.ndarray, table: tuple):
    """(first ring, last ring, first leaf, end leaf) of each window over the sorted
    leaves: a leaf on bands b .. b + k - 1 uses rings b .. b + k."""
    band_lo, ptr = table[0], table[1]
    ring_hi = band_lo + np.diff(ptr)
    n = len(band_lo)
    i = 0
    while i < n:
        r0, r1 = int(band_lo[i]), int(ring_hi[i])
        j = i + 1
        while j < n:
            r1n = max(r1, int(ring_hi[j]))
            if ring_offsets[r1n + 1] - ring_offsets[r0] > WINDOW_VERTICES:
                break
            r1 = r1n
            j += 1
        yield r0, r1, i, j
        i = j


def _window_positions(grid, radii, stretch, r0: int, r1: int) -> np.ndarray:
    from ._window_kernels import _window_positions_kernel  # numba loads here
    offs = grid.ring_offsets()
    pos = np.empty((int(offs[r1 + 1] - offs[r0]), 3), dtype=np.float32)
    _window_positions_kernel(grid.magnitude, offs, radii, stretch, r0, r1, pos)
    return pos


def leaf_metadata(grid, radii, stretch, leaves: tuple) -> tuple[np.ndarray, np.ndarray]:
    """(meta, bounds) of every leaf (:func:`~latlong._export_kernels._patch_kernel`'s
    first pass: strip length, vertices, triangles; float32 bounds, centre, radius)."""
    from ._export_kernels import _patch_kernel  # numba loads here
    radii = np.ascontiguousarray(radii, dtype=np.float64)
    stretch = np.array(stretch, dtype=np.float64)
    offs = grid.ring_offsets()
    order, table = _sorted_leaves(leaves)
    n = len(order)
    meta = np.zeros((n, 3), dtype=np.int64)
    bounds = np.zeros((n, 10), dtype=np.float64)
    none = np.zeros(1, dtype=np.int64)
    words = np.zeros(1, dtype=np.uint32)
    for r0, r1, a, b in _windows(offs, table):
        pos = _window_positions(grid, radii, stretch, r0, r1)

        def run(ab, _, pos=pos, base=int(offs[r0])):
            _patch_kernel(grid.magnitude, offs, *table, pos, pos, base, ab[0], ab[1], False,
                          meta, bounds, none, none, none, words.view(np.float32), words)

        chunks = [(c, min(c + LEAVES_PER_TASK, b)) for c in range(a, b, LEAVES_PER_TASK)]
        for _ in ordered_chunks(run, chunks, lambda: None):
            pass
    out_meta = np.empty_like(meta)
    out_bounds = np.empty_like(bounds)
    out_meta[order] = meta
    out_bounds[order] = bounds
    return out_meta, out_bounds


def write_leaf_data(grid, radii, stretch, leaves: tuple, at: np.ndarray, nbytes: np.ndarray,
                    fh, *, progress: bool = False, desc: str = "patches") -> None:
    """Write every leaf's data (positions, normals, indices: ``nbytes[i]`` bytes at the
    level offset ``at[i, 0]``; ``at[i] = -1`` for leaves without a patch) into ``fh`` from
    its current position; leaves ``fh`` positioned after the level's data."""
    from ._export_kernels import _patch_kernel  # numba loads here
    from ._window_kernels import _window_normals_kernel  # numba loads here
    radii = np.ascontiguousarray(radii, dtype=np.float64)
    stretch = np.array(stretch, dtype=np.float64)
    offs = grid.ring_offsets()
    order, table = _sorted_leaves(leaves)
    n = len(order)
    at_s = at[order]
    nb_s = np.ascontiguousarray(nbytes[order], dtype=np.int64)
    pos_at = np.zeros(n, dtype=np.int64)
    nrm_at = np.zeros(n, dtype=np.int64)
    ind_at = np.zeros(n, dtype=np.int64)
    meta = np.zeros((1, 3), dtype=np.int64)
    bounds = np.zeros((1, 10), dtype=np.float64)
    fh.flush()
    start = fh.tell()
    fd = fh.fileno()
    end = start + int(nbytes.sum())
    bar = progress_bar(total=int(nbytes.sum()) >> 20, enabled=progress, desc=f"{desc} (MB)")
    written = 0
    try:
        for r0, r1, a, b in _windows(offs, table):
            pos = _window_positions(grid, radii, stretch, r0, r1)
            nrm = np.empty_like(pos)
            # angle-weighted: the camera's shading normals, and Mitsuba's and Blender's
            _window_normals_kernel(grid.magnitude, offs, radii, stretch, _NO_TABLE, r0, r1,
                                   nrm, True)
            groups = _groups(nb_s, a, b)
            big = max(int(nb_s[g0:g1].sum()) for g0, g1 in groups)

            def make(group, buf, pos=pos, nrm=nrm, base=int(offs[r0])):
                g0, g1 = group
                local = np.concatenate([[0], np.cumsum(nb_s[g0:g1])]).astype(np.int64)
                has = at_s[g0:g1, 0] >= 0
                pos_at[g0:g1] = local[:-1] // 4
                nrm_at[g0:g1] = np.where(has, local[:-1] + at_s[g0:g1, 1] - at_s[g0:g1, 0],
                                         0) // 4
                ind_at[g0:g1] = np.where(has, local[:-1] + at_s[g0:g1, 2] - at_s[g0:g1, 0],
                                         0) // 4
                words = buf[:int(local[-1]) // 4]
                _patch_kernel(grid.magnitude, offs, *table, pos, nrm, base, g0, g1, True, meta,
                              bounds, pos_at, nrm_at, ind_at, words.view(np.float32), words)
                return words.view(np.uint8), g0, local

            for data, g0, local in ordered_chunks(make, groups,
                                                  functools.partial(np.empty, max(big, 4) // 4,
                                                                    np.uint32)):
                for k in range(len(local) - 1):
                    size = int(local[k + 1] - local[k])
                    if size:
                        _pwrite_all(fd, data[int(local[k]):int(local[k + 1])],
                                    start + int(at_s[g0 + k, 0]))
                shown = written >> 20
                written += int(local[-1])
                bar.update((written >> 20) - shown)
    finally:
        bar.close()
    fh.seek(end)


def _groups(nb_s: np.ndarray, a: int, b: int) -> list[tuple[int, int]]:
    """Consecutive leaves ``a .. b - 1`` in runs of about GROUP_BYTES (at least one)."""
    ends = np.cumsum(nb_s[a:b])
    groups = []
    first = 0
    while first < b - a:
        last = int(np.searchsorted(ends, ends[first] - nb_s[a + first] + GROUP_BYTES,
                                   side="right"))
        last = min(max(last, first + 1), b - a)
        groups.append((a + first, a + last))
        first = last
    return groups


def _pwrite_all(fd: int, data, offset: int) -> None:
    view = memoryview(data)
    while len(view):
        done = os.pwrite(fd, view, offset)
        view = view[done:]
        offset += done
