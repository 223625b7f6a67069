"""Numba kernels of :mod:`latlong.sensors.render` and :mod:`latlong.sensors.sensor`:
surface geometry at the hits, shading, sun-disk samples and sensor noise.

Random numbers are counter-based (``craters.kernels``: splitmix64 keyed by the seed,
a stream and the pixel/sample index), so a frame's bytes never depend on the thread
count (DESIGN §3).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from craters.kernels import GOLDEN, hash_normal, mix64, read_only_inputs, splitmix64

from ._photometry_kernels import _radiance_factor

_TWO_POW_M53 = 1.0 / 9007199254740992.0
_S11 = np.uint64(11)


@njit(cache=True, inline="always")
def _key(seed, stream, index):
    """A 64-bit hash of (seed, stream, index)."""
    return mix64(splitmix64(np.uint64(seed)) ^ (np.uint64(stream) * GOLDEN)
                 ^ mix64(np.uint64(index) + GOLDEN))


@njit(cache=True, inline="always")
def _uniform(h):
    """[0, 1) from the top 53 bits of a hash."""
    return (h >> _S11) * _TWO_POW_M53


@read_only_inputs("pos", "ng_out", "ns_out", "cosines", "facing")
@njit(cache=True, parallel=True)
def _surface_kernel(origin, dirs, t, face, u, v, vertices, faces, vnormals, smooth, sun,
                    pos, ng_out, ns_out, cosines, facing):
    """Per hit: position, geometric and shading normals (both turned towards the camera),
    cos i, cos e, cos g (``cosines`` columns), and whether the facet faces the sun."""
    step = 1 if origin.shape[0] > 1 else 0  # one shared origin or one per ray
    for i in prange(t.shape[0]):
        f = face[i]
        if f < 0:
            for k in range(3):
                pos[i, k] = np.nan
                ng_out[i, k] = np.nan
                ns_out[i, k] = np.nan
                cosines[i, k] = np.nan
            facing[i] = False
            continue
        a, b, c = faces[f, 0], faces[f, 1], faces[f, 2]
        e1x = vertices[b, 0] - vertices[a, 0]
        e1y = vertices[b, 1] - vertices[a, 1]
        e1z = vertices[b, 2] - vertices[a, 2]
        e2x = vertices[c, 0] - vertices[a, 0]
        e2y = vertices[c, 1] - vertices[a, 1]
        e2z = vertices[c, 2] - vertices[a, 2]
        nx = e1y * e2z - e1z * e2y
        ny = e1z * e2x - e1x * e2z
        nz = e1x * e2y - e1y * e2x
        norm = math.sqrt(nx * nx + ny * ny + nz * nz)
        if norm > 0.0:
            nx, ny, nz = nx / norm, ny / norm, nz / norm
        sign = 1.0
        if nx * dirs[i, 0] + ny * dirs[i, 1] + nz * dirs[i, 2] > 0.0:
            sign = -1.0  # the back of the facet is seen
        nx, ny, nz = sign * nx, sign * ny, sign * nz
        if smooth:
            w0 = 1.0 - u[i] - v[i]
            sx = w0 * vnormals[a, 0] + u[i] * vnormals[b, 0] + v[i] * vnormals[c, 0]
            sy = w0 * vnormals[a, 1] + u[i] * vnormals[b, 1] + v[i] * vnormals[c, 1]
            sz = w0 * vnormals[a, 2] + u[i] * vnormals[b, 2] + v[i] * vnormals[c, 2]
            sn = math.sqrt(sx * sx + sy * sy + sz * sz)
            if sn > 0.0:
                sx, sy, sz = sign * sx / sn, sign * sy / sn, sign * sz / sn
            else:
                sx, sy, sz = nx, ny, nz
        else:
            sx, sy, sz = nx, ny, nz
        r = i * step
        for k in range(3):
            pos[i, k] = origin[r, k] + t[i] * dirs[i, k]
        ng_out[i, 0], ng_out[i, 1], ng_out[i, 2] = nx, ny, nz
        ns_out[i, 0], ns_out[i, 1], ns_out[i, 2] = sx, sy, sz
        cosines[i, 0] = sx * sun[0] + sy * sun[1] + sz * sun[2]
        cosines[i, 1] = -(sx * dirs[i, 0] + sy * dirs[i, 1] + sz * dirs[i, 2])
        cosines[i, 2] = -(sun[0] * dirs[i, 0] + sun[1] * dirs[i, 1] + sun[2] * dirs[i, 2])
        facing[i] = nx * sun[0] + ny * sun[1] + nz * sun[2] > 0.0


@read_only_inputs("depth", "rng", "angles", "normals", "sunlit")
@njit(cache=True, parallel=True)
def _ground_truth_kernel(t, face, dirs, axis, cosines, ns, lit, depth, rng, angles, normals,
                         sunlit):
    """The float32 ground-truth images (NaN where the ray missed): depth along ``axis``,
    range, incidence / emission / phase in degrees, shading normals, lit fraction."""
    for i in prange(t.shape[0]):
        if face[i] < 0:
            depth[i] = rng[i] = sunlit[i] = np.nan
            for k in range(3):
                angles[i, k] = np.nan
                normals[i, k] = np.nan
            continue
        rng[i] = t[i]
        depth[i] = t[i] * (dirs[i, 0] * axis[0] + dirs[i, 1] * axis[1] + dirs[i, 2] * axis[2])
        sunlit[i] = lit[i]
        for k in range(3):
            angles[i, k] = math.degrees(math.acos(min(1.0, max(-1.0, cosines[i, k]))))
            normals[i, k] = ns[i, k]


@read_only_inputs("out_o", "out_d", "facing")
@njit(cache=True, parallel=True)
def _shadow_rays_kernel(pos, ng, offset, centre, floor, sun, radius_rad, seed, sample, out_o,
                        out_d, facing):
    """Shadow-ray origins (lifted along the geometric normal by ``offset`` times the point's
    distance from ``centre``, at least ``floor``: the float32 BVH's rounding grows with
    that distance) and directions: the
    sun's centre (``radius_rad`` 0) or sample ``sample`` of a uniform draw over the solar
    disk (a spherical cap of half-angle ``radius_rad``); ``facing``: the facet faces
    that direction."""
    # an orthonormal basis (e1, e2) perpendicular to the sun direction
    ax = 1.0 if abs(sun[0]) < 0.9 else 0.0
    ay = 0.0 if abs(sun[0]) < 0.9 else 1.0
    e1x = ay * sun[2]
    e1y = -ax * sun[2]
    e1z = ax * sun[1] - ay * sun[0]
    n1 = math.sqrt(e1x * e1x + e1y * e1y + e1z * e1z)
    e1x, e1y, e1z = e1x / n1, e1y / n1, e1z / n1
    e2x = sun[1] * e1z - sun[2] * e1y
    e2y = sun[2] * e1x - sun[0] * e1z
    e2z = sun[0] * e1y - sun[1] * e1x
    cos_max = math.cos(radius_rad)
    for i in prange(pos.shape[0]):
        dx, dy, dz = sun[0], sun[1], sun[2]
        if radius_rad > 0.0:
            h = _key(seed, 1 + sample, i)
            u1 = _uniform(h)
            u2 = _uniform(splitmix64(h))
            ct = 1.0 - u1 * (1.0 - cos_max)
            st = math.sqrt(max(0.0, 1.0 - ct * ct))
            ph = 2.0 * math.pi * u2
            cp, sp = math.cos(ph) * st, math.sin(ph) * st
            dx = ct * sun[0] + cp * e1x + sp * e2x
            dy = ct * sun[1] + cp * e1y + sp * e2y
            dz = ct * sun[2] + cp * e1z + sp * e2z
        out_d[i, 0], out_d[i, 1], out_d[i, 2] = dx, dy, dz
        _lift(pos, ng, offset, centre, floor, i, out_o)
        facing[i] = ng[i, 0] * dx + ng[i, 1] * dy + ng[i, 2] * dz > 0.0


@njit(cache=True, inline="always")
def _lift(pos, ng, offset, centre, floor, i, out_o):
    """Origin of a secondary ray from point i: lifted along the geometric normal by
    ``offset`` times its distance from ``centre``, at least ``floor``."""
    rx = pos[i, 0] - centre[0]
    ry = pos[i, 1] - centre[1]
    rz = pos[i, 2] - centre[2]
    eps = max(offset * math.sqrt(rx * rx + ry * ry + rz * rz), floor)
    for k in range(3):
        out_o[i, k] = pos[i, k] + eps * ng[i, k]


@njit(cache=True, parallel=True)
def _shade_kernel(code, params, cosines, sunlit, albedo_w, out):
    """I/F = model(cos i, cos e, cos g) x sunlit fraction x albedo factor."""
    for i in prange(cosines.shape[0]):
        if not sunlit[i] > 0.0:
            out[i] = 0.0
            continue
        out[i] = _radiance_factor(code, params, cosines[i, 0], cosines[i, 1],
                                  cosines[i, 2]) * sunlit[i] * albedo_w[i]


@njit(cache=True, inline="always")
def _poisson(lam, h):
    """A Poisson deviate of mean ``lam`` from the hash ``h``: inversion of the CDF below
    a mean of 64, the normal approximation (rounded, >= 0) above."""
    if lam <= 0.0:
        return 0.0
    if lam < 64.0:
        u = _uniform(h)
        k = 0
        p = math.exp(-lam)
        cdf = p
        while u > cdf and k < 1000:
            k += 1
            p *= lam / k
            cdf += p
        return float(k)
    return max(0.0, math.floor(lam + math.sqrt(lam) * hash_normal(h) + 0.5))


@njit(cache=True, parallel=True)
def _sensor_kernel(electrons, seed, photon_noise, read_noise_e, full_well_e, gain, max_dn,
                   quantize, out):
    """Digital numbers: electrons (with Poisson photon noise and Gaussian read noise,
    counter-based per pixel), clipped to [0, full well], times the gain, and (with
    ``quantize``) rounded and clipped to [0, max_dn]."""
    for i in prange(electrons.shape[0]):
        e = electrons[i]
        if photon_noise:
            e = _poisson(e, _key(seed, 101, i))
        if read_noise_e > 0.0:
            e += read_noise_e * hash_normal(_key(seed, 102, i))
        e = min(max(e, 0.0), full_well_e)
        if quantize:
            out[i] = min(max(math.floor(e * gain + 0.5), 0.0), max_dn)
        else:
            out[i] = e * gain
