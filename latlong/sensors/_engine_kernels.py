"""Numba kernels of :mod:`latlong.sensors.engine`: Embree's ray-packet queries called
from parallel numba loops, and the float64 Möller–Trumbore refinement of every hit.

Embree is called through ``ctypes`` function pointers passed in as arguments (numba
reads their address at run time, so the kernels cache). Each parallel iteration traces a
fixed block of rays, W consecutive rays a call, with its own 32-byte-aligned
``RTCRayHit8`` buffer (Embree 4 ``rtcore_ray.h``'s structure-of-arrays layout: ray = 12
fields, hit = Ng[3], u, v, primID, geomID, instID; :func:`_packet_buffers`). Each lane of
a packet is traced on its own (a packet is a batch, not a shared traversal result), so
every ray's result depends on nothing but that ray: same bytes for any thread count, and
the same answers as single-ray calls (``rtcIntersect1``, ``rtcOccluded1``) gave on every
ray of a 1024^2 frame of a 12 M-triangle body, in less time: its primary rays 0.143-0.146 s
instead of 0.158-0.162 s, its 0.47 M shadow rays 0.127-0.143 s instead of 0.153-0.169 s
(best of 10, interleaved in one process, 2 threads, two runs, 2026-12-08).
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from craters.kernels import read_only_inputs

from ..geometry._ray_kernels import _moller_trumbore

#: Rays per parallel iteration.
BLOCK = 256
#: Rays per Embree call (``rtcIntersect8`` / ``rtcOccluded8``: 8-wide packets, native on
#: AVX2 and AVX-512).
W = 8
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
def _packet_buffers():
    """Fresh ``RTCRayHit8`` and valid-mask buffers, 32-byte aligned: the packet's float32
    and uint32 views and address, the int32 mask and its address (the views keep the
    memory alive). Field f of lane j is word ``f * W + j``: org 0-2, tnear 3, dir 4-6,
    time 7, tfar 8, mask 9, id 10, flags 11, Ng 12-14, u 15, v 16, primID 17, geomID 18,
    instID 19 (Embree 4 ``rtcore_ray.h``; 21 fields: room for instPrimID)."""
    raw = np.empty(21 * W + 8, np.float32)
    off = ((32 - raw.ctypes.data % 32) % 32) // 4
    buf = raw[off:off + 21 * W]
    vraw = np.empty(W + 8, np.int32)
    voff = ((32 - vraw.ctypes.data % 32) % 32) // 4
    valid = vraw[voff:voff + W]
    return buf, buf.view(np.uint32), raw.ctypes.data + 4 * off, valid, \
        vraw.ctypes.data + 4 * voff


@njit(cache=True, inline="always")
def _load_lane(buf, ibuf, j, origins, directions, i, centre, t0, tnear, tfar):
    """Ray i into lane j of the packet: its float32 origin at ``t0`` along it (relative
    to the mesh's centre), direction, [tnear, tfar], and no hit yet."""
    r = _row(origins, i)
    for k in range(3):
        buf[k * W + j] = np.float32(origins[r, k] + t0 * directions[i, k] - centre[k])
        buf[(4 + k) * W + j] = np.float32(directions[i, k])
    buf[3 * W + j] = np.float32(tnear)
    buf[7 * W + j] = np.float32(0.0)
    buf[8 * W + j] = np.float32(tfar)
    ibuf[9 * W + j] = _INVALID
    ibuf[10 * W + j] = np.uint32(0)
    ibuf[11 * W + j] = np.uint32(0)
    ibuf[17 * W + j] = _INVALID
    ibuf[18 * W + j] = _INVALID
    ibuf[19 * W + j] = _INVALID


@njit(cache=True, inline="always")
def _fill_packet(buf, ibuf, valid, t0s, p, n, origins, directions, centre, radius, t_min,
                 t_max, shadow):
    """Rays ``p .. p + W - 1`` (those below n) into the packet's lanes, their start along
    the ray into ``t0s``; returns how many lanes are live. A closest-hit ray starts just
    before the bounding sphere; a shadow ray (``shadow``) at ``t_min`` or before."""
    live = 0
    for j in range(W):
        i = p + j
        valid[j] = 0
        if i >= n:
            continue
        t0 = _start(origins, directions, i, centre, radius)
        tnear = 0.0
        if shadow:
            t0 = min(t0, t_min[i])
            tnear = t_min[i] - t0
        span = t_max[i] - t0
        if not span > tnear:
            continue
        _load_lane(buf, ibuf, j, origins, directions, i, centre, t0, tnear, min(span, 3e38))
        t0s[j] = t0
        valid[j] = -1
        live += 1
    return live


@read_only_inputs("t_out", "face_out", "u_out", "v_out", "blocked")
@njit(cache=True, parallel=True)
def _trace_kernel(query8, scene, origins, directions, t_min, t_max, centre, radius, vertices,
                  faces, shadow, t_out, face_out, u_out, v_out, blocked):
    """Every ray through Embree in packets of W (``query8``: ``rtcIntersect8``, or with
    ``shadow`` ``rtcOccluded8``). Closest hits: ``t_out``, ``face_out``, ``u_out``,
    ``v_out``, refined in float64 on the face (``t_min`` unused). Shadow rays:
    ``blocked`` True where something lies on the ray between ``t_min`` and ``t_max`` (the
    hit outputs and ``vertices``, ``faces`` unused). One kernel for both: one compile."""
    n = directions.shape[0]
    for blk in prange((n + BLOCK - 1) // BLOCK):
        buf, ibuf, ptr, valid, vptr = _packet_buffers()
        t0s = np.empty(W)
        for p in range(blk * BLOCK, min(n, (blk + 1) * BLOCK), W):
            for i in range(p, min(n, p + W)):
                if shadow:
                    blocked[i] = False
                else:
                    face_out[i] = -1
                    t_out[i] = np.inf
                    u_out[i] = 0.0
                    v_out[i] = 0.0
            if _fill_packet(buf, ibuf, valid, t0s, p, n, origins, directions, centre, radius,
                            t_min, t_max, shadow) == 0:
                continue
            query8(vptr, scene, ptr, 0)
            for j in range(W):
                i = p + j
                if valid[j] == 0:
                    continue
                if shadow:
                    blocked[i] = buf[8 * W + j] < 0.0  # Embree 4 sets tfar = -inf
                    continue
                if ibuf[18 * W + j] == _INVALID:
                    continue
                f = np.int64(ibuf[17 * W + j])
                t, u, v, det = _ray_face(origins, directions, vertices, faces, i, f)
                if det == 0.0:  # a ray in the triangle's plane: keep Embree's answer
                    t = t0s[j] + np.float64(buf[8 * W + j])
                    u, v = np.float64(buf[15 * W + j]), np.float64(buf[16 * W + j])
                if t > t_max[i]:
                    continue
                face_out[i] = f
                t_out[i] = t
                u_out[i] = u
                v_out[i] = v


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
