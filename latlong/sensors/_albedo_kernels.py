"""Numba kernel of the regolith's albedo texture (:func:`latlong.sensors.albedo.
regolith_albedo`): 3-D value noise hashed from the integer lattice of body-fixed
coordinates (counter-based: no table, so nothing repeats; a point's value depends only on
its position and the seed). Reference in numpy: ``tests/latlong/test_albedo.py``."""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from craters.kernels import lattice_coord, mix64, read_only_inputs

_KX = np.uint64(0x9E3779B97F4A7C15)
_KY = np.uint64(0xC2B2AE3D27D4EB4F)
_KZ = np.uint64(0x165667B19E3779F9)
_OCTAVE = np.uint64(0x632BE59BD9B4E019)


@njit(cache=True)
def _lattice(seed, ix, iy, iz):
    """A value in [-1, 1) at lattice point (ix, iy, iz)."""
    k = (np.uint64(ix) * _KX) ^ (np.uint64(iy) * _KY) ^ (np.uint64(iz) * _KZ)
    return (mix64(seed ^ mix64(k)) >> np.uint64(11)) * (2.0 / 9007199254740992.0) - 1.0


@njit(cache=True)
def _value3(seed, x, y, z):
    """Trilinear value noise with quintic fades at (x, y, z) lattice units (the value of
    :func:`_value3_grad`; its unused gradient is compiled away)."""
    return _value3_grad(seed, x, y, z)[0]


@read_only_inputs("out")
@njit(cache=True, parallel=True)
def _mottle_kernel(points, seed, wavelength_m, octaves, gain, out):
    """fBm of ``octaves`` octaves of :func:`_value3` from ``wavelength_m`` halving each
    octave, amplitudes ``gain``^k times (1 - gain) (the infinite series' sum is 1: a
    picture with fewer octaves, the finer ones below its pixels, shows the same coarser
    octaves) at each row of ``points`` (metres), into ``out``."""
    for i in prange(points.shape[0]):
        total = 0.0
        amp = 1.0 - gain
        inv = 1.0 / wavelength_m
        for o in range(octaves):
            s = seed + np.uint64(o) * _OCTAVE
            total += amp * _value3(s, points[i, 0] * inv, points[i, 1] * inv,
                                   points[i, 2] * inv)
            amp *= gain
            inv *= 2.0
        out[i] = total


@njit(cache=True, inline="always")
def _value3_grad(seed, x, y, z):
    """:func:`_value3` at (x, y, z) and its gradient (per lattice unit): the trilinear
    blend differentiated through the quintic fades (30 f^2 (f - 1)^2)."""
    ix, fx, u = lattice_coord(x)
    iy, fy, v = lattice_coord(y)
    iz, fz, w = lattice_coord(z)
    du = 30.0 * fx * fx * (fx - 1.0) * (fx - 1.0)
    dv = 30.0 * fy * fy * (fy - 1.0) * (fy - 1.0)
    dw = 30.0 * fz * fz * (fz - 1.0) * (fz - 1.0)
    c000 = _lattice(seed, ix, iy, iz)
    c100 = _lattice(seed, ix + 1, iy, iz)
    c010 = _lattice(seed, ix, iy + 1, iz)
    c110 = _lattice(seed, ix + 1, iy + 1, iz)
    c001 = _lattice(seed, ix, iy, iz + 1)
    c101 = _lattice(seed, ix + 1, iy, iz + 1)
    c011 = _lattice(seed, ix, iy + 1, iz + 1)
    c111 = _lattice(seed, ix + 1, iy + 1, iz + 1)
    x00 = c100 - c000
    x10 = c110 - c010
    x01 = c101 - c001
    x11 = c111 - c011
    a00 = c000 + u * x00
    a10 = c010 + u * x10
    a01 = c001 + u * x01
    a11 = c011 + u * x11
    b0 = a00 + v * (a10 - a00)
    b1 = a01 + v * (a11 - a01)
    gx = du * ((1.0 - w) * (x00 + v * (x10 - x00)) + w * (x01 + v * (x11 - x01)))
    gy = dv * ((1.0 - w) * (a10 - a00) + w * (a11 - a01))
    gz = dw * (b1 - b0)
    return b0 + w * (b1 - b0), gx, gy, gz


@read_only_inputs("out")
@njit(cache=True, parallel=True)
def _bump_kernel(points, normals, seeds, wavelengths_m, amps_m, out):
    """Each unit normal of ``normals`` tilted by the gradient of the height field
    sum_k amps_m[k] :func:`_value3`(seeds[k], points / wavelengths_m[k]) (metres):
    n - grad_t h, normalised (grad_t: the part of the gradient across n), into ``out``."""
    for i in prange(points.shape[0]):
        g0 = 0.0
        g1 = 0.0
        g2 = 0.0
        for o in range(wavelengths_m.shape[0]):
            inv = 1.0 / wavelengths_m[o]
            _, dx, dy, dz = _value3_grad(seeds[o], points[i, 0] * inv, points[i, 1] * inv,
                                         points[i, 2] * inv)
            g0 += amps_m[o] * inv * dx
            g1 += amps_m[o] * inv * dy
            g2 += amps_m[o] * inv * dz
        n0 = normals[i, 0]
        n1 = normals[i, 1]
        n2 = normals[i, 2]
        along = (g0 * n0 + g1 * n1 + g2 * n2)
        m0 = n0 - (g0 - along * n0)
        m1 = n1 - (g1 - along * n1)
        m2 = n2 - (g2 - along * n2)
        norm = np.sqrt(m0 * m0 + m1 * m1 + m2 * m2)
        out[i, 0] = m0 / norm
        out[i, 1] = m1 / norm
        out[i, 2] = m2 / norm


@read_only_inputs("out")
@njit(cache=True, parallel=True)
def _cube_keys_kernel(verts, lo, cell, dims, out):
    """The key ``i + dims0 (j + dims1 k)`` of each vertex's cube of :func:`_ejecta_kernel`'s
    grid, (i, j, k) = floor((vertex - lo) / cell) (tests: against numpy)."""
    for v in prange(verts.shape[0]):
        i = np.int64(np.floor((verts[v, 0] - lo[0]) / cell))
        j = np.int64(np.floor((verts[v, 1] - lo[1]) / cell))
        k = np.int64(np.floor((verts[v, 2] - lo[2]) / cell))
        out[v] = i + dims[0] * (j + dims[1] * k)


@read_only_inputs("out")
@njit(cache=True, parallel=True)
def _ejecta_kernel(verts, order, keys, lo, cell, dims, centres, radii, gains, reach, n_threads,
                   out):
    """Brighten ``out`` (one factor per row of ``verts``, in place) by every crater c:
    ``max(out, 1 + gains[c] * g)``, g = 1 within ``radii[c]`` of ``centres[c]``, (d / R)^-3
    out to ``reach`` radii, nothing beyond. Vertices are found through a uniform grid of
    cubes ``cell`` metres wide from ``lo``, ``dims`` cubes along each axis: ``keys`` the
    sorted cube keys (i + dims0 (j + dims1 k)) of the vertices ``order``. Thread t of
    ``n_threads`` takes every n-th crater into its own copy of ``out``; the copies are
    merged by their maximum, which does not depend on who took which crater."""
    copies = np.empty((n_threads, out.shape[0]))
    for t in prange(n_threads):
        mine = copies[t]
        mine[:] = out
        for c in range(t, centres.shape[0], n_threads):
            _brighten(verts, order, keys, lo, cell, dims, centres[c], radii[c], gains[c],
                      reach, mine)
    for t in range(n_threads):
        for v in range(out.shape[0]):
            if copies[t, v] > out[v]:
                out[v] = copies[t, v]


@njit(cache=True)
def _brighten(verts, order, keys, lo, cell, dims, centre, radius, gain, reach, out):
    """One crater of :func:`_ejecta_kernel` into ``out``."""
    big = reach * radius
    a = np.empty(3, np.int64)
    b = np.empty(3, np.int64)
    for ax in range(3):
        a[ax] = max(np.int64(np.floor((centre[ax] - big - lo[ax]) / cell)), 0)
        b[ax] = min(np.int64(np.floor((centre[ax] + big - lo[ax]) / cell)), dims[ax] - 1)
    for k in range(a[2], b[2] + 1):
        for j in range(a[1], b[1] + 1):
            for i in range(a[0], b[0] + 1):
                key = i + dims[0] * (j + dims[1] * k)
                s = np.searchsorted(keys, key)
                e = np.searchsorted(keys, key, side="right")
                for p in range(s, e):
                    v = order[p]
                    dx = verts[v, 0] - centre[0]
                    dy = verts[v, 1] - centre[1]
                    dz = verts[v, 2] - centre[2]
                    d = np.sqrt(dx * dx + dy * dy + dz * dz)
                    if d > big:
                        continue
                    rho = d / radius
                    g = 1.0 if rho <= 1.0 else 1.0 / (rho * rho * rho)
                    f = 1.0 + gain * g
                    if f > out[v]:
                        out[v] = f
