"""Sets of cube-sphere cells for terrain on demand: the cells of points, their
neighbourhoods, sorted distinct ids, and blocks of points with the records (craters,
rocks) that may reach each block. Shared by :mod:`.field` and :mod:`.rocks`."""

from __future__ import annotations

import numpy as np

from craters.cells import cell_parts, cell_points, cell_solid_angle
from craters.local import bin_level, min_cell_angle

from ..parallel.backends import serial_below
from . import _cell_kernels as C
from . import _field_kernels as K

__all__ = ["GrowingRows", "block_level", "block_pairs", "cell_areas", "cells_of", "coarser",
           "in_sorted", "neighbour_set", "neighbours", "reaching", "unique_inverse",
           "unique_sorted"]


def cells_of(units: np.ndarray, level: int) -> np.ndarray:
    """Cell id (uint64) at ``level`` of each direction ``units`` (n, 3)."""
    out = np.empty(len(units), dtype=np.uint64)
    if len(units):
        with serial_below(len(units)):
            C._cells_kernel(np.ascontiguousarray(units, dtype=np.float64), level, out)
    return out


def _run_starts(a: np.ndarray) -> np.ndarray:
    """Indices where a run of equal consecutive values starts (points of a tile or a patch
    come row by row, so their cells repeat in runs: sorting one value per run is some ten
    times less work than sorting them all)."""
    return np.concatenate([[0], np.flatnonzero(a[1:] != a[:-1]) + 1])


def unique_sorted(x: np.ndarray) -> np.ndarray:
    """Sorted distinct values (by sorting: numpy's hashed ``unique`` is some 70 times
    slower on cell ids, whose low bits repeat)."""
    a = np.asarray(x).ravel()
    if not len(a):
        return np.sort(a)
    # timsort (``stable``): cells of points row by row, or of neighbourhoods column by
    # column, come in long sorted runs, which it merges instead of sorting
    a = np.sort(a[_run_starts(a)], kind="stable")
    return a[np.concatenate([[True], a[1:] != a[:-1]])]


def unique_inverse(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(sorted distinct values, index of each element's value)."""
    x = np.asarray(x).ravel()
    if not len(x):
        return np.sort(x), np.zeros(0, dtype=np.int64)
    starts = _run_starts(x)
    runs = x[starts]
    order = np.argsort(runs, kind="stable")
    a = runs[order]
    first = np.concatenate([[True], a[1:] != a[:-1]])
    run_inverse = np.empty(len(runs), dtype=np.int64)
    run_inverse[order] = np.cumsum(first) - 1
    lengths = np.diff(np.append(starts, len(x)))
    return a[first], np.repeat(run_inverse, lengths)


def in_sorted(x: np.ndarray, sorted_unique: np.ndarray) -> np.ndarray:
    """Whether each element of ``x`` is in ``sorted_unique``."""
    if not len(sorted_unique):
        return np.zeros(len(x), bool)
    pos = np.minimum(np.searchsorted(sorted_unique, x), len(sorted_unique) - 1)
    return sorted_unique[pos] == x


def coarser(cells: np.ndarray, level: int, to_level: int) -> np.ndarray:
    """The distinct cells of ``to_level`` holding cells of ``level`` (>= it): a cell's
    ``i, j`` at a coarser level are its own shifted right (the cube's cells nest: the
    scaled coordinates differ by powers of two, exactly)."""
    shift = np.uint64(level - to_level)
    mask = np.uint64((1 << 27) - 1)
    face = (cells >> np.uint64(54)) & np.uint64(7)
    i = ((cells >> np.uint64(27)) & mask) >> shift
    j = (cells & mask) >> shift
    return unique_sorted((np.uint64(to_level) << np.uint64(57)) | (face << np.uint64(54))
                     | (i << np.uint64(27)) | j)


def neighbours(cells: np.ndarray, keep_shape: bool = False) -> np.ndarray:
    """The 9 cells around each cell (itself included), (n, 9) or flat."""
    out = np.empty((len(cells), 9), dtype=np.uint64)
    if len(cells):
        with serial_below(len(cells)):
            C._neighbourhood_kernel(np.ascontiguousarray(cells, dtype=np.uint64), out)
    return out if keep_shape else out.ravel()


def neighbour_set(cells: np.ndarray) -> np.ndarray:
    """Sorted distinct cells around ``cells`` (themselves included): the union of their
    :func:`neighbours`, from the distinct cells first (many craters share a cell, so this
    sorts some ten times fewer ids than the neighbourhoods of all of them)."""
    around = neighbours(unique_sorted(cells), keep_shape=True)
    return unique_sorted(around.T.ravel())  # by column: nine sorted runs


def block_level(n: int, units: np.ndarray) -> int:
    """A level of blocks holding some tens of points each (any level gives the same
    values: blocks only narrow the craters each point tests)."""
    if n < 2:
        return 20
    sample = units[::max(1, n // 65536)]  # the level is a choice of speed, not of value
    m = sample.mean(axis=0)
    norm = float(np.linalg.norm(m))
    span = np.pi if norm < 0.5 else float(np.arccos(np.clip((sample @ (m / norm)).min(), -1,
                                                            1)))
    width = max(2.0 * span / np.sqrt(n / 32.0), 1e-9)
    return bin_level(width, 24)


def block_pairs(records: np.ndarray, angles: np.ndarray, active: np.ndarray, level: int,
                occ: np.ndarray, rank: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(start, list): for each occupied block (sorted cell ids ``occ`` at ``level``) the
    ``active`` records (rows of ``records``: centre, east, north; :mod:`._field_kernels`)
    whose reach (``angles``, radians) may touch it, ordered by ``rank``; block ``b``'s are
    ``list[start[b]:start[b + 1]]``."""
    margin = np.cos(2.0 * 2.0 ** (1 - level))  # a block's angular radius, bounded
    ob, oc = C._cap_blocks_kernel(records, np.ascontiguousarray(angles, dtype=np.float64),
                                  np.ascontiguousarray(active, dtype=np.int64), level, occ,
                                  margin)
    srt = np.lexsort((rank[oc], ob))
    return (np.searchsorted(ob[srt], np.arange(len(occ) + 1)).astype(np.int64),
            np.ascontiguousarray(oc[srt]))


def reaching(records: np.ndarray, level: int, occ: np.ndarray) -> np.ndarray:
    """Whether each record's reach (its widest ejecta edge: :mod:`._field_kernels`) may
    touch one of the occupied blocks (sorted cell ids ``occ`` at ``level``): a superset
    of the records that reach a point in them, so a record it rejects changes no value
    (:func:`block_pairs` may still list it: its block radius is a looser bound)."""
    out = np.zeros(len(records), dtype=bool)
    if len(records) and len(occ):
        with serial_below(len(records)):
            C._reach_kernel(np.ascontiguousarray(records[:, K.C0:K.C2 + 1]),
                            np.ascontiguousarray(records[:, K.FAR]), level, occ, out)
    return out


def cell_areas(base, level: int, cells: np.ndarray) -> np.ndarray:
    """Area (m^2) of each cell of ``level`` on the surface of ``base``
    (:class:`.base.BaseField`): its solid angle times the area per steradian at its
    centre."""
    _, face, i, j = cell_parts(cells)
    centres = cell_points(level, face, i, j, 0.5, 0.5)
    step = 0.25 * min_cell_angle(level)
    return cell_solid_angle(level, face, i, j) * base.area_factor(centres, step)


class GrowingRows:
    """Rows kept so far plus a scratch tail, in one buffer that doubles when full: the
    records of the craters a query needs grow bin by bin, and concatenating them anew
    for every bin copied the whole table some 40 times a tile."""

    def __init__(self, width: int, dtype=np.float64):
        self._buf = np.zeros((64, width) if width else 64, dtype=dtype)
        self.n = 0

    def _fit(self, n: int) -> None:
        if n > len(self._buf):
            grown = np.zeros((max(n, 2 * len(self._buf)),) + self._buf.shape[1:],
                             dtype=self._buf.dtype)
            grown[:self.n] = self._buf[:self.n]
            self._buf = grown

    def kept(self) -> np.ndarray:
        """The rows kept (a view)."""
        return self._buf[:self.n]

    def with_tail(self, rows: np.ndarray) -> np.ndarray:
        """The rows kept followed by ``rows`` (a view; the tail is scratch until
        :meth:`keep`)."""
        self._fit(self.n + len(rows))
        self._buf[self.n:self.n + len(rows)] = rows
        return self._buf[:self.n + len(rows)]

    def keep(self, rows: np.ndarray) -> None:
        """Append ``rows`` to the rows kept."""
        self.with_tail(rows)
        self.n += len(rows)
