"""Numba kernels of the interreflection (:mod:`latlong.sensors.light`). References in
numpy: ``tests/latlong/test_sensors_bounce.py``."""

from __future__ import annotations

import math

from numba import njit, prange

from craters.kernels import read_only_inputs, splitmix64

from ._photometry_kernels import _radiance_factor
from ._render_kernels import _key, _lift, _uniform

# the counter stream of the bounce directions (the sun-disk samples use 1 + sample)
BOUNCE_STREAM = 1 << 40
#: added to the sample index for the rays on from the first bounce's hits
SECOND_BOUNCE = 1 << 32


@njit(cache=True, parallel=True)
def _bounce_rays_kernel(pos, ng, ns, offset, centre, floor, seed, sample, out_o, out_d,
                        above):
    """Cosine-weighted directions about the shading normal ``ns`` (sample ``sample`` of
    each point, counter-based on (seed, sample, point)), origins lifted along the
    geometric normal as the shadow rays' are; ``above``: the direction leaves the facet
    (a direction below it carries no light)."""
    for i in prange(pos.shape[0]):
        h = _key(seed, BOUNCE_STREAM + sample, i)
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
