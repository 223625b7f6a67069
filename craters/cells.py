"""A fixed hierarchy of cells on the sphere: where terrain on demand draws its craters.

Each size bin of a crater population is drawn per cell of one level of this hierarchy
(``counter`` words keyed by the seed and counted by cell, bin and index), so a region
asks only for the cells that reach it and gets exactly the craters the whole body has
there. The cells are those of a gnomonic cube: the six faces of the cube around the unit
sphere (face ``2 a + (0 if s > 0 else 1)`` has outward normal ``s`` along axis ``a``),
each split into ``2**level x 2**level`` squares of its tangent plane, ``u, v`` in
[-1, 1] along the axes ``a + 1`` and ``a + 2`` (mod 3). A point's cell follows from
divisions only and a cell's corners are exact binary fractions, so every machine puts a
point in the same cell; the solid angle of a cell (the Poisson mean of its count) uses
the portable ``atan`` of :mod:`craters.counter`'s kernels.

Cell ids pack ``level`` (6 bits), ``face`` (3 bits), ``i`` and ``j`` (27 bits each) into
a uint64: levels 0 .. 27, cells down to 2**-27 of a face (0.25 mm on a 34 km body).

Examples
--------
>>> face, i, j = cell_of([[1.0, 0.2, -0.3]], 2)
>>> int(face[0]), int(i[0]), int(j[0])
(0, 2, 1)
>>> float(cell_solid_angle(0, 0, 0, 0)) * 6 / (4 * np.pi)
1.0
"""

from __future__ import annotations

import numpy as np

from ._counter_kernels import _cell_of_kernel, _cell_solid_angle_kernel

__all__ = ["MAX_LEVEL", "cell_ids", "cell_of", "cell_parts", "cell_solid_angle",
           "cell_points"]

#: Deepest level of the hierarchy (cell ids hold 27 bits of ``i`` and of ``j``).
MAX_LEVEL = 27


def _level(level) -> int:
    if isinstance(level, bool) or not isinstance(level, int | np.integer) \
            or not 0 <= int(level) <= MAX_LEVEL:
        raise ValueError(f"`level` must be an integer in [0, {MAX_LEVEL}]; got {level!r}")
    return int(level)


def cell_of(points, level: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The cell (face, i, j) of each point (n, 3) (a direction from the centre; any
    length > 0) at ``level``: int64 arrays."""
    level = _level(level)
    p = np.ascontiguousarray(np.asarray(points, dtype=np.float64).reshape(-1, 3))
    if not np.isfinite(p).all() or (np.abs(p).max(axis=1, initial=0.0) == 0.0).any():
        raise ValueError("`points` must be finite, non-zero directions")
    out = np.empty((len(p), 3), dtype=np.int64)
    _cell_of_kernel(p, level, out)
    return out[:, 0], out[:, 1], out[:, 2]


def cell_ids(level: int, face, i, j) -> np.ndarray:
    """uint64 ids of the cells (level, face, i, j) (module notes)."""
    level = _level(level)
    f, ii, jj = (np.asarray(x, dtype=np.int64) for x in (face, i, j))
    n = 1 << level
    if f.size and (f.min() < 0 or f.max() > 5):
        raise ValueError("`face` must be in [0, 5]")
    for name, x in (("i", ii), ("j", jj)):
        if x.size and (x.min() < 0 or x.max() >= n):
            raise ValueError(f"`{name}` must be in [0, {n - 1}] at level {level}")
    return (np.uint64(level) << np.uint64(57) | f.astype(np.uint64) << np.uint64(54)
            | ii.astype(np.uint64) << np.uint64(27) | jj.astype(np.uint64))


def cell_parts(ids) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(level, face, i, j) int64 arrays of cell ids."""
    c = np.asarray(ids, dtype=np.uint64)
    mask = np.uint64((1 << 27) - 1)
    return ((c >> np.uint64(57)).astype(np.int64),
            ((c >> np.uint64(54)) & np.uint64(7)).astype(np.int64),
            ((c >> np.uint64(27)) & mask).astype(np.int64), (c & mask).astype(np.int64))


def cell_solid_angle(level: int, face, i, j) -> np.ndarray:
    """Solid angle of each cell, steradians (the six faces' cells add up to 4 pi): the
    gnomonic rectangle's closed form sum of +-atan(u v / sqrt(1 + u^2 + v^2)) over its
    corners, with the portable atan (the same bytes everywhere)."""
    level = _level(level)
    f, ii, jj = np.broadcast_arrays(*(np.asarray(x, dtype=np.int64) for x in (face, i, j)))
    out = np.empty(f.size, dtype=np.float64)
    _cell_solid_angle_kernel(level, np.ascontiguousarray(ii.ravel()),
                             np.ascontiguousarray(jj.ravel()), out)
    return out.reshape(f.shape)


def cell_points(level: int, face, i, j, fu, fv) -> np.ndarray:
    """Unit vectors (n, 3) of the points at fractions ``fu, fv`` in [0, 1] of each cell's
    tangent-plane square (0: the low corner)."""
    level = _level(level)
    f, ii, jj, a, b = np.broadcast_arrays(*(np.asarray(x) for x in (face, i, j, fu, fv)))
    scale = 2.0 / (1 << level)
    u = -1.0 + (ii + np.asarray(a, np.float64)) * scale
    v = -1.0 + (jj + np.asarray(b, np.float64)) * scale
    axis = f.astype(np.int64) // 2
    sign = np.where(f.astype(np.int64) % 2 == 0, 1.0, -1.0)
    local = np.stack([sign, u, v], axis=-1)  # along the face's axis, a + 1, a + 2
    out = np.take_along_axis(local, (np.arange(3) - axis[..., None]) % 3, axis=-1)
    return out / np.sqrt((out * out).sum(axis=-1, keepdims=True))
