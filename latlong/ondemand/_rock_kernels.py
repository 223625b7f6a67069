"""Numba kernels of rocks on demand (:mod:`latlong.ondemand.rocks`). A point's value is
computed by one thread from its own data, a maximum over the rocks that reach it (no
order, no sums): the same whatever other points are asked with it. Reference in numpy:
``tests/latlong/test_ondemand_rocks.py``."""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from craters.kernels import fbm2, read_only_inputs

from ._field_kernels import _far, _local

# rock record columns after the crater record's first twelve (centre, east, north, RHO,
# RAD = the footprint's largest radius, COS_FAR = cos of its angle)
CA, SA = 12, 13      # cos, sin of the long axis' azimuth (from east)
A, B = 14, 15        # footprint semi-axes (m)
CZ = 16              # half the rock's height (m)
Z0 = 17              # height of the ellipsoid's centre above the ground (m)
F0 = 18              # facets: (cos phi, sin phi, offset, slope) each
N_FACETS = 6
#: Roughness of a rock's surface (fBm of 3 octaves from half its long semi-axis, gain
#: 0.5), in units of its half-height: facets that are not planes.
ROCK_ROUGHNESS = 0.12
CHORD2 = F0 + 4 * N_FACETS   # squared chord of the footprint's angle
N_ROCK_COLS = CHORD2 + 1


@njit(cache=True, inline="always")
def _rock_height(rc, seeds, k, p0, p1, p2):
    """Height (m) of rock k above the ground at direction p: the ellipsoid of half-height
    CZ centred Z0 above the ground, cut by its facet planes, roughened by its own fBm
    (``seeds[k]``); 0 outside."""
    if _far(rc, k, CHORD2, p0, p1, p2):
        return 0.0
    _, _, x, y, _, _ = _local(rc, k, p0, p1, p2)
    xi = (x * rc[k, CA] + y * rc[k, SA]) / rc[k, A]
    eta = (y * rc[k, CA] - x * rc[k, SA]) / rc[k, B]
    q2 = xi * xi + eta * eta
    if not q2 < 1.0:
        return 0.0
    f = np.sqrt(1.0 - q2)
    for m in range(N_FACETS):
        c = F0 + 4 * m
        g = rc[k, c + 2] - rc[k, c + 3] * (xi * rc[k, c] + eta * rc[k, c + 1])
        if g < f:
            f = g
    f += ROCK_ROUGHNESS * fbm2(seeds[k], x, y, 0.5 * rc[k, A], 3, 0.5)
    z = rc[k, Z0] + rc[k, CZ] * f
    return z if z > 0.0 else 0.0


@read_only_inputs("out", "which")
@njit(cache=True, parallel=True)
def _rocks_kernel(points, block_of, blk_start, blk_list, rc, seeds, out, which):
    """Adds to each point the tallest rock over it (of its block's rocks) and writes that
    rock's row in ``which`` (-1 where no rock stands: the ground truth of the labels)."""
    for i in prange(points.shape[0]):
        blk = block_of[i]
        top = 0.0
        best = -1
        for t in range(blk_start[blk], blk_start[blk + 1]):
            k = blk_list[t]
            h = _rock_height(rc, seeds, k, points[i, 0], points[i, 1], points[i, 2])
            if h > top:
                top = h
                best = k
        out[i] += top
        which[i] = best


@read_only_inputs("out")
@njit(cache=True, parallel=True)
def _face_rocks_kernel(which, faces, out):
    """Each face's rock: the rock (``which``, per vertex, -1 none) that at least two of
    its corners stand on, else -1 (tests: against numpy)."""
    for f in prange(faces.shape[0]):
        a = which[faces[f, 0]]
        b = which[faces[f, 1]]
        c = which[faces[f, 2]]
        r = b if b == c else -1
        if a == c:
            r = a
        if a == b:
            r = a
        out[f] = r
