"""Numba kernels of :mod:`latlong.sensors.engine`: Embree's single-ray queries called
from parallel numba loops, and the float64 Möller–Trumbore refinement of every hit.

Embree is called through ``ctypes`` function pointers passed in as arguments (numba
reads their address at run time, so the kernels cache). Each parallel iteration traces a
fixed block of rays with its own 16-byte-aligned ``RTCRayHit`` buffer (Embree 4
``rtcore_ray.h`` layout: ray = 12 words, hit = Ng[3], u, v, primID, geomID, instID), so
every ray's result depends on nothing but that ray: same bytes for any thread count.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from craters.kernels import read_only_inputs

from ..geometry._ray_kernels import _moller_trumbore

#: Rays per parallel iteration.
BLOCK = 256
_INVALID = np.uint32(0xFFFFFFFF)


@njit(cache=True, inline="always")
def _row(origins, i):
    """The origin row of ray i: one shared origin (a (1, 3) array) or one per ray."""
    return i if origins.shape[0] > 1 else 0


@njit(cache=True, inline="always")
def _ray_face(origins, directions, vertices, faces, i, f):
    """:func:`_moller_trumbore` of ray ``i`` against face ``f``."""
    a, b, c = faces[f, 0], faces[f, 1], faces[f, 2]
    r = _row(origins, i)
    return _moller_trumbore(
        origins[r, 0], origins[r, 1], origins[r, 2],
        directions[i, 0], directions[i, 1], directions[i, 2],
        vertices[a, 0], vertices[a, 1], vertices[a, 2],
        vertices[b, 0], vertices[b, 1], vertices[b, 2],
        vertices[c, 0], vertices[c, 1], vertices[c, 2])


@njit(cache=True)
def _refine_kernel(origins, directions, vertices, faces, face, t_out, u_out, v_out):
    """Float64 Möller–Trumbore of each ray against its face (``face[i] >= 0``), in
    place; rays whose face is -1 are left alone (tests compare it with numpy)."""
    for i in range(directions.shape[0]):
        f = face[i]
        if f < 0:
            continue
        t, u, v, det = _ray_face(origins, directions, vertices, faces, i, f)
        if det != 0.0:
            t_out[i], u_out[i], v_out[i] = t, u, v


@njit(cache=True, inline="always")
def _start(origins, directions, i, centre, radius):
    """Distance along ray i to where its float32 origin is taken (just before the
    bounding sphere, so a far camera loses no precision in float32)."""
    r = _row(origins, i)
    tc = ((centre[0] - origins[r, 0]) * directions[i, 0]
          + (centre[1] - origins[r, 1]) * directions[i, 1]
          + (centre[2] - origins[r, 2]) * directions[i, 2])
    return max(0.0, tc - radius)


@njit(cache=True, inline="always")
def _aligned(raw):
    """A 32-word view of ``raw`` that starts on a 16-byte boundary, and its address."""
    p0 = raw.ctypes.data
    off = ((16 - p0 % 16) % 16) // 4
    return raw[off:off + 32], p0 + 4 * off


@njit(cache=True, inline="always")
def _ray_buffer():
    """A fresh ``RTCRayHit`` buffer: its float32 and uint32 views and its address (the
    views keep the memory alive)."""
    buf, ptr = _aligned(np.empty(40, np.float32))
    return buf, buf.view(np.uint32), ptr


@njit(cache=True, inline="always")
def _load_ray(buf, ibuf, origins, directions, i, centre, t0, tnear, tfar):
    r = _row(origins, i)
    for k in range(3):
        buf[k] = np.float32(origins[r, k] + t0 * directions[i, k] - centre[k])
        buf[4 + k] = np.float32(directions[i, k])
    buf[3] = np.float32(tnear)
    buf[7] = np.float32(0.0)
    buf[8] = np.float32(tfar)
    ibuf[9] = _INVALID
    ibuf[10] = np.uint32(0)
    ibuf[11] = np.uint32(0)
    ibuf[17] = _INVALID
    ibuf[18] = _INVALID
    ibuf[19] = _INVALID


@read_only_inputs("t_out", "face_out", "u_out", "v_out")
@njit(cache=True, parallel=True)
def _intersect_kernel(intersect1, scene, origins, directions, t_max, centre, radius,
                      vertices, faces, t_out, face_out, u_out, v_out):
    """Closest hit of every ray (Embree, float32), refined in float64 on its face."""
    n = directions.shape[0]
    for blk in prange((n + BLOCK - 1) // BLOCK):
        buf, ibuf, ptr = _ray_buffer()
        for i in range(blk * BLOCK, min(n, (blk + 1) * BLOCK)):
            t0 = _start(origins, directions, i, centre, radius)
            face_out[i] = -1
            t_out[i] = np.inf
            u_out[i] = 0.0
            v_out[i] = 0.0
            span = t_max[i] - t0
            if not span > 0.0:
                continue
            _load_ray(buf, ibuf, origins, directions, i, centre, t0, 0.0, min(span, 3e38))
            intersect1(scene, ptr, 0)
            if ibuf[18] == _INVALID:
                continue
            f = np.int64(ibuf[17])
            t, u, v, det = _ray_face(origins, directions, vertices, faces, i, f)
            if det == 0.0:  # a ray in the triangle's plane: keep Embree's answer
                t, u, v = t0 + np.float64(buf[8]), np.float64(buf[15]), np.float64(buf[16])
            if t > t_max[i]:
                continue
            face_out[i] = f
            t_out[i] = t
            u_out[i] = u
            v_out[i] = v


@njit(cache=True, parallel=True)
def _occluded_kernel(occluded1, scene, origins, directions, t_min, t_max, centre, radius,
                     out):
    """True where something lies on the ray between ``t_min`` and ``t_max``."""
    n = directions.shape[0]
    for blk in prange((n + BLOCK - 1) // BLOCK):
        buf, ibuf, ptr = _ray_buffer()
        for i in range(blk * BLOCK, min(n, (blk + 1) * BLOCK)):
            t0 = min(_start(origins, directions, i, centre, radius), t_min[i])
            span = t_max[i] - t0
            out[i] = False
            if not span > t_min[i] - t0:
                continue
            _load_ray(buf, ibuf, origins, directions, i, centre, t0, t_min[i] - t0,
                      min(span, 3e38))
            occluded1(scene, ptr, 0)
            out[i] = buf[8] < 0.0  # Embree 4 sets tfar = -inf on occlusion


@njit(cache=True, parallel=True)
def _unit_kernel(directions, out):
    """Unit copies of the directions; the index of the first zero or non-finite one
    (-1 when all are good)."""
    n = directions.shape[0]
    bad = n
    for i in prange(n):
        x, y, z = directions[i, 0], directions[i, 1], directions[i, 2]
        norm = np.sqrt(x * x + y * y + z * z)
        if not (norm > 0.0 and norm < np.inf):
            bad = min(bad, i)
            norm = 1.0
        out[i, 0], out[i, 1], out[i, 2] = x / norm, y / norm, z / norm
    return bad if bad < n else -1


@read_only_inputs("out")
@njit(cache=True)
def _shift_kernel(vertices, centre, out):
    """``out[:n] = float32(vertices - centre)``; returns the largest squared distance of a
    vertex from ``centre`` (float64), in one pass over the vertices."""
    r2 = 0.0
    for i in range(vertices.shape[0]):
        x = vertices[i, 0] - centre[0]
        y = vertices[i, 1] - centre[1]
        z = vertices[i, 2] - centre[2]
        out[i, 0] = np.float32(x)
        out[i, 1] = np.float32(y)
        out[i, 2] = np.float32(z)
        d = x * x + y * y + z * z
        if d > r2:
            r2 = d
    return r2
