"""Numba kernels of the interreflection (:mod:`latlong.sensors.light`). References in
numpy: ``tests/latlong/test_sensors_bounce.py``."""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from craters.kernels import read_only_inputs, splitmix64

from ._photometry_kernels import _radiance_factor
from ._render_kernels import _key, _lift, _uniform

# the counter stream of the bounce directions (the sun-disk samples use 1 + sample)
BOUNCE_STREAM = 1 << 40
#: added to the sample index for the rays on from the first bounce's hits
SECOND_BOUNCE = 1 << 32


@njit(cache=True, parallel=True)
def _bounce_rays_kernel(pos, ng, ns, ids, offset, centre, floor, seed, sample, out_o, out_d,
                        above):
    """Cosine-weighted directions about the shading normal ``ns`` (sample ``sample`` of
    each point, counter-based on (seed, sample, the point's id ``ids[i]``)), origins
    lifted along the geometric normal as the shadow rays' are; ``above``: the direction
    leaves the facet (a direction below it carries no light)."""
    for i in prange(pos.shape[0]):
        h = _key(seed, BOUNCE_STREAM + sample, ids[i])
        u1 = _uniform(h)
        u2 = _uniform(splitmix64(h))
        r = math.sqrt(u1)
        ph = 2.0 * math.pi * u2
        lx, ly, lz = r * math.cos(ph), r * math.sin(ph), math.sqrt(max(0.0, 1.0 - u1))
        nx, ny, nz = ns[i, 0], ns[i, 1], ns[i, 2]
        # an orthonormal basis (t, b, n) (Frisvad 2012, with Duff et al. 2017's sign)
        sgn = 1.0 if nz >= 0.0 else -1.0
        a = -1.0 / (sgn + nz)
        bb = nx * ny * a
        tx, ty, tz = 1.0 + sgn * nx * nx * a, sgn * bb, -sgn * nx
        bx, by, bz = bb, sgn + ny * ny * a, -ny
        dx = lx * tx + ly * bx + lz * nx
        dy = lx * ty + ly * by + lz * ny
        dz = lx * tz + ly * bz + lz * nz
        out_d[i, 0], out_d[i, 1], out_d[i, 2] = dx, dy, dz
        _lift(pos, ng, offset, centre, floor, i, out_o)
        above[i] = ng[i, 0] * dx + ng[i, 1] * dy + ng[i, 2] * dz > 0.0


@read_only_inputs("face", "q", "nq", "facing")
@njit(cache=True, parallel=True)
def _secondary_kernel(origins, dirs, t, hit_face, above, face_normals, sun, face, q, nq,
                      facing):
    """What the bounce rays hit, in one pass (the numpy steps it replaced, with the same
    values): ``face`` the face hit (``hit_face``) where the ray leaves its facet
    (``above``), else -1; ``q`` the hit point o + t u, u the unit direction as
    :meth:`.engine.RayMesh.intersect` makes it (NaN where nothing is hit); ``nq`` the
    face's normal (0 without a face); ``facing`` the face turns towards the ``sun``."""
    for i in prange(dirs.shape[0]):
        x, y, z = dirs[i, 0], dirs[i, 1], dirs[i, 2]
        norm = np.sqrt(x * x + y * y + z * z)
        f = hit_face[i]
        if f >= 0:
            q[i, 0] = origins[i, 0] + t[i] * (x / norm)
            q[i, 1] = origins[i, 1] + t[i] * (y / norm)
            q[i, 2] = origins[i, 2] + t[i] * (z / norm)
        else:
            q[i, 0] = q[i, 1] = q[i, 2] = np.nan
        if not above[i]:
            f = -1
        face[i] = f
        if f < 0:
            nq[i, 0] = nq[i, 1] = nq[i, 2] = 0.0
            facing[i] = False
            continue
        n0, n1, n2 = face_normals[f, 0], face_normals[f, 1], face_normals[f, 2]
        nq[i, 0], nq[i, 1], nq[i, 2] = n0, n1, n2
        facing[i] = (n0 * sun[0] + n1 * sun[1]) + n2 * sun[2] > 0.0


@read_only_inputs("out")
@njit(cache=True, parallel=True)
def _bounce_light_kernel(code, params, dirs, face, face_normals, albedo_w, sun, lit, out):
    """I/F of each secondary hit seen back along its ray: the model at (cos i to the sun,
    cos e back along the ray, cos g between them) times its albedo factor and lit
    fraction (0 for a miss, a facet turned away from the ray or from the sun)."""
    for k in prange(dirs.shape[0]):
        f = face[k]
        if f < 0 or not lit[k] > 0.0:
            out[k] = 0.0
            continue
        n0, n1, n2 = face_normals[f, 0], face_normals[f, 1], face_normals[f, 2]
        d0, d1, d2 = dirs[k, 0], dirs[k, 1], dirs[k, 2]
        dn = math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
        cos_e = -(n0 * d0 + n1 * d1 + n2 * d2) / dn
        cos_i = n0 * sun[0] + n1 * sun[1] + n2 * sun[2]
        if not (cos_e > 0.0 and cos_i > 0.0):
            out[k] = 0.0
            continue
        cos_g = -(d0 * sun[0] + d1 * sun[1] + d2 * sun[2]) / dn
        out[k] = _radiance_factor(code, params, cos_i, cos_e, cos_g) * albedo_w[k] * lit[k]


#: The geometric weights of :func:`_atrous_pass_kernel` (:func:`.light.filter_bounced`):
#: a neighbour counts by (n_p . n_q)^(2^NORMAL_POWER_LOG2) = (n_p . n_q)^32 and by
#: (1 - sin^2 / PLANE_SIN2)^2, 0 beyond, sin the elevation of the neighbour above the
#: point's tangent plane seen from the point (0 for one plane; ~10 deg cuts it off).
NORMAL_POWER_LOG2 = 5
PLANE_SIN2 = 0.03
#: The cubic B-spline's taps (1, 4, 6, 4, 1) / 16 of each a-trous pass (Dammertz et al.
#: 2010): a pass with taps ``step`` pixels apart has variance step^2 px^2 per axis.
B3_TAPS = np.array([1.0, 4.0, 6.0, 4.0, 1.0]) / 16.0


def atrous_steps(radius: int) -> list[int]:
    """The a-trous passes' tap spacings for a smoothing ``radius`` in pixels: 1, 2, 4 ...
    up to the largest power of two <= radius / 2 (at least one pass): their variances add
    to ~(radius / 2)^2 (8 px: 1 + 4 + 16 = 21, sigma 4.6 px), the Gaussian of sigma
    radius / 2 that they stand for, reaching 2 (1 + 2 + 4 ...) px."""
    steps = [1]
    while 2 * steps[-1] <= radius / 2:
        steps.append(2 * steps[-1])
    return steps


@njit(cache=True, inline="always")
def _geometric_weight(pos, nrm, i, j, ii, jj):
    """The weight of neighbour (ii, jj) for pixel (i, j) on one surface (module notes):
    0 when its normal turns away or it lies off the pixel's tangent plane."""
    nx, ny, nz = nrm[i, j, 0], nrm[i, j, 1], nrm[i, j, 2]
    c = nx * nrm[ii, jj, 0] + ny * nrm[ii, jj, 1] + nz * nrm[ii, jj, 2]
    if not c > 0.0:
        return 0.0
    dx = pos[ii, jj, 0] - pos[i, j, 0]
    dy = pos[ii, jj, 1] - pos[i, j, 1]
    dz = pos[ii, jj, 2] - pos[i, j, 2]
    d2 = dx * dx + dy * dy + dz * dz
    t = 1.0
    if d2 > 0.0:
        e = nx * dx + ny * dy + nz * dz
        t = 1.0 - e * e / (d2 * PLANE_SIN2)
        if not t > 0.0:
            return 0.0
    for _ in range(NORMAL_POWER_LOG2):
        c = c * c
    return c * (t * t)


@read_only_inputs("out_num", "out_den")
@njit(cache=True, parallel=True)
def _atrous_pass_kernel(num, den, seen, pos, nrm, taps, step, out_num, out_den):
    """One pass of the edge-avoiding a-trous filter (Dammertz, Sewtz, Hanika & Lensch
    2010, "Edge-avoiding a-trous wavelet transform for fast global illumination
    filtering", HPG): each seen pixel's ``num`` (h, w, bands) and ``den`` (h, w) become
    their means over the 5 x 5 seen pixels ``step`` apart around it, weighted by the
    B-spline ``taps`` (5,) times the geometric weights (:func:`_geometric_weight`).
    ``num`` = rays x light and ``den`` = rays carried through every pass make
    ``num / den`` a mean that counts each estimate by its rays (normalised convolution,
    Knutsson & Westin 1993). Unseen pixels are copied. Each pixel's sums in a fixed
    order (rows, then columns): the same bytes on any thread count."""
    h, w, nb = num.shape
    for i in prange(h):
        acc = np.zeros(nb)
        for j in range(w):
            if not seen[i, j]:
                for b in range(nb):
                    out_num[i, j, b] = num[i, j, b]
                out_den[i, j] = den[i, j]
                continue
            for b in range(nb):
                acc[b] = 0.0
            total = 0.0
            d_acc = 0.0
            for a in range(5):
                ii = i + (a - 2) * step
                if ii < 0 or ii >= h:
                    continue
                for c in range(5):
                    jj = j + (c - 2) * step
                    if jj < 0 or jj >= w or not seen[ii, jj]:
                        continue
                    g = _geometric_weight(pos, nrm, i, j, ii, jj)
                    if g == 0.0:
                        continue
                    wt = taps[a] * taps[c] * g
                    total += wt
                    d_acc += wt * den[ii, jj]
                    for b in range(nb):
                        acc[b] += wt * num[ii, jj, b]
            if not total > 0.0:  # a zero normal: not even the pixel itself counts
                for b in range(nb):
                    out_num[i, j, b] = num[i, j, b]
                out_den[i, j] = den[i, j]
                continue
            for b in range(nb):
                out_num[i, j, b] = acc[b] / total
            out_den[i, j] = d_acc / total
