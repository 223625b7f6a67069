"""Numba kernel for exact Poisson faulting on the lat/long grid in O(F*M + N)."""

from __future__ import annotations

import numpy as np
from numba import njit, prange

# Margin on v.n beyond which a whole ring is certainly on one side of a fault, so the
# per-vertex sign test (the definition) cannot disagree with the shortcut.
_MARGIN = 1e-12


@njit(cache=True, inline="always")
def _dot(unit, k, nx, ny, nz):
    return unit[k, 0] * nx + unit[k, 1] * ny + unit[k, 2] * nz


@njit(cache=True, parallel=True)
def _apply_faults_kernel(ring_offsets, ring_cos, ring_sin, unit, normals, lon0, horiz,
                         heights, out):
    """Add ``sum_f heights[f] * [unit_i . normals[f] > 0]`` to ``out``.

    Ring by ring (in parallel; every ring owns its own slice, so the result does not
    depend on the thread count): a fault covers one contiguous arc of longitude on a
    ring, ``cos(lon - lon0) > -n_z tan(lat) / A``; its ends come from the closed form
    and are then settled by the exact sign test on the neighbouring vertices, so the
    result equals the brute-force sign test. Arcs are accumulated in a difference array
    and summed once per ring.
    """
    n_rings = ring_offsets.shape[0] - 1
    n_faults = normals.shape[0]
    two_pi = 2.0 * np.pi
    for r in prange(n_rings):
        o = ring_offsets[r]
        n = ring_offsets[r + 1] - o
        if n == 1:  # a pole: test directly
            acc = 0.0
            for f in range(n_faults):
                if _dot(unit, o, normals[f, 0], normals[f, 1], normals[f, 2]) > 0.0:
                    acc += heights[f]
            out[o] += acc
            continue
        diff = np.zeros(n + 1, dtype=np.float64)
        whole = 0.0
        sin_lat = ring_cos[r]  # z of the ring = cos(colatitude)
        cos_lat = ring_sin[r]
        for f in range(n_faults):
            nx = normals[f, 0]
            ny = normals[f, 1]
            nz = normals[f, 2]
            h = heights[f]
            a = cos_lat * horiz[f]  # amplitude of the longitude term
            b = sin_lat * nz  # constant term
            if b - a > _MARGIN:
                whole += h
                continue
            if a + b < -_MARGIN:
                continue
            if a <= 0.0:
                c = 0.0  # degenerate: decide every vertex by the exact test below
            else:
                c = -b / a
            if c > 1.0:
                c = 1.0
            elif c < -1.0:
                c = -1.0
            half = np.arccos(c)
            scale = n / two_pi
            jlo = int(np.ceil((lon0[f] - half) * scale))
            jhi = int(np.floor((lon0[f] + half) * scale))
            if a <= 0.0:
                jlo = 0
                jhi = n - 1
            # settle the ends with the exact sign test (a few steps at most): grow the
            # arc while the vertex just outside is raised (never past a whole ring), then
            # trim ends that are not raised
            while jhi - jlo + 1 < n and _dot(unit, o + (jlo - 1) % n, nx, ny, nz) > 0.0:
                jlo -= 1
            while jhi - jlo + 1 < n and _dot(unit, o + (jhi + 1) % n, nx, ny, nz) > 0.0:
                jhi += 1
            while jlo <= jhi and _dot(unit, o + jlo % n, nx, ny, nz) <= 0.0:
                jlo += 1
            while jhi >= jlo and _dot(unit, o + jhi % n, nx, ny, nz) <= 0.0:
                jhi -= 1
            count = jhi - jlo + 1
            if count <= 0:
                continue
            if count >= n:
                whole += h
                continue
            s = jlo % n
            e = s + count
            diff[s] += h
            if e <= n:
                diff[e] -= h
            else:
                diff[n] -= h
                diff[0] += h
                diff[e - n] -= h
        acc = whole
        for j in range(n):
            acc += diff[j]
            out[o + j] += acc
