"""Numba port of the ``noise`` package's improved Perlin noise (``pnoise3``).

A line-by-line port of ``noise3`` and ``py_noise3`` in Casey Duncan's ``_perlin.c``
(noise 1.2.2): single precision throughout, the same permutation table, the package's
own 16-entry gradient table (entries 12-15 differ from Perlin 2002), the same ``fmodf``
tiling with ``repeat = 1024 * freq`` and the same octave normalisation ``total / sum of
amplitudes``. Every float32 operation is written in the C order of evaluation so that
the results agree with the C code to the last bit in practice (tests: <= 1e-5).
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

# fmt: off
_PERM_256 = np.array([
    151, 160, 137, 91, 90, 15, 131, 13, 201, 95, 96, 53, 194, 233, 7, 225, 140, 36,
    103, 30, 69, 142, 8, 99, 37, 240, 21, 10, 23, 190, 6, 148, 247, 120, 234, 75, 0,
    26, 197, 62, 94, 252, 219, 203, 117, 35, 11, 32, 57, 177, 33, 88, 237, 149, 56,
    87, 174, 20, 125, 136, 171, 168, 68, 175, 74, 165, 71, 134, 139, 48, 27, 166, 77,
    146, 158, 231, 83, 111, 229, 122, 60, 211, 133, 230, 220, 105, 92, 41, 55, 46, 245,
    40, 244, 102, 143, 54, 65, 25, 63, 161, 1, 216, 80, 73, 209, 76, 132, 187, 208, 89,
    18, 169, 200, 196, 135, 130, 116, 188, 159, 86, 164, 100, 109, 198, 173, 186, 3, 64,
    52, 217, 226, 250, 124, 123, 5, 202, 38, 147, 118, 126, 255, 82, 85, 212, 207, 206,
    59, 227, 47, 16, 58, 17, 182, 189, 28, 42, 223, 183, 170, 213, 119, 248, 152, 2, 44,
    154, 163, 70, 221, 153, 101, 155, 167, 43, 172, 9, 129, 22, 39, 253, 19, 98, 108,
    110, 79, 113, 224, 232, 178, 185, 112, 104, 218, 246, 97, 228, 251, 34, 242, 193,
    238, 210, 144, 12, 191, 179, 162, 241, 81, 51, 145, 235, 249, 14, 239, 107, 49, 192,
    214, 31, 181, 199, 106, 157, 184, 84, 204, 176, 115, 121, 50, 45, 127, 4, 150, 254,
    138, 236, 205, 93, 222, 114, 67, 29, 24, 72, 243, 141, 128, 195, 78, 66, 215, 61,
    156, 180], dtype=np.int32)
# fmt: on
# The C table holds two copies (512 entries); indices reach 510 + base, so the C code
# is only defined for base 0 and 1. A periodic table of 1024 entries equals it there and
# extends it deterministically to base <= 255.
PERM = np.tile(_PERM_256, 4)

# flattened (16 x 3) gradient table, row h = gradient h
GRAD3 = np.array([
    [1, 1, 0], [-1, 1, 0], [1, -1, 0], [-1, -1, 0],
    [1, 0, 1], [-1, 0, 1], [1, 0, -1], [-1, 0, -1],
    [0, 1, 1], [0, -1, 1], [0, 1, -1], [0, -1, -1],
    [1, 0, -1], [-1, 0, -1], [0, -1, 1], [0, 1, 1]], dtype=np.float32).ravel()


@njit(cache=True, inline="always")
def _lerp(t, a, b):
    return a + t * (b - a)


@njit(cache=True, inline="always")
def _grad3(grad, h, x, y, z):
    # unsigned index: no negative-index wrap-around test in the generated code
    h = np.uint64((h & 15) * 3)
    return x * grad[h] + y * grad[h + np.uint64(1)] + z * grad[h + np.uint64(2)]


@njit(cache=True, inline="always")
def _fmodf(x, y):
    # C fmodf: exact, and the identity when |x| < y (the common case, kept cheap); in
    # general computed in double (exact) and rounded back (exact)
    if -y < x < y:
        return x
    return np.float32(np.fmod(np.float64(x), np.float64(y)))


@njit(cache=True, inline="always")
def _ifloor(v):
    # floorf for finite float32 within the int range, without a libm call
    i = int(v)
    return i - 1 if v < i else i


@njit(cache=True, inline="always")
def _noise3(x, y, z, repeatx, repeaty, repeatz, base, perm, grad):
    """``noise3`` of _perlin.c; x, y, z are float32, repeats and base ints."""
    i = _ifloor(_fmodf(x, np.float32(repeatx)))
    j = _ifloor(_fmodf(y, np.float32(repeaty)))
    k = _ifloor(_fmodf(z, np.float32(repeatz)))
    return _noise3_cell(x, y, z, i, j, k, repeatx, repeaty, repeatz, base, perm, grad)


@njit(cache=True, inline="always")
def _noise3_cell(x, y, z, i, j, k, repeatx, repeaty, repeatz, base, perm, grad):
    """The rest of ``noise3`` once the lattice cell (i, j, k) is known."""
    one = np.float32(1.0)
    # (int)fmodf(i + 1, repeat): i lies in [-repeat, repeat - 1], so this is i + 1
    # except that i + 1 == repeat wraps to 0 (integer arithmetic, exact)
    ii = i + 1 if i + 1 < repeatx else 0
    jj = j + 1 if j + 1 < repeaty else 0
    kk = k + 1 if k + 1 < repeatz else 0
    # all table indices are non-negative: use unsigned ones (no wrap-around tests)
    i = np.uint64((i & 255) + base)
    j = np.uint64((j & 255) + base)
    k = np.uint64((k & 255) + base)
    ii = np.uint64((ii & 255) + base)
    jj = np.uint64((jj & 255) + base)
    kk = np.uint64((kk & 255) + base)

    x = x - np.float32(_ifloor(x))
    y = y - np.float32(_ifloor(y))
    z = z - np.float32(_ifloor(z))
    six = np.float32(6.0)
    fifteen = np.float32(15.0)
    ten = np.float32(10.0)
    fx = x * x * x * (x * (x * six - fifteen) + ten)
    fy = y * y * y * (y * (y * six - fifteen) + ten)
    fz = z * z * z * (z * (z * six - fifteen) + ten)

    a = np.uint64(perm[i])
    aa = np.uint64(perm[a + j])
    ab = np.uint64(perm[a + jj])
    b = np.uint64(perm[ii])
    ba = np.uint64(perm[b + j])
    bb = np.uint64(perm[b + jj])
    x1 = x - one
    y1 = y - one
    z1 = z - one
    return _lerp(fz,
                 _lerp(fy,
                       _lerp(fx, _grad3(grad, perm[aa + k], x, y, z),
                             _grad3(grad, perm[ba + k], x1, y, z)),
                       _lerp(fx, _grad3(grad, perm[ab + k], x, y1, z),
                             _grad3(grad, perm[bb + k], x1, y1, z))),
                 _lerp(fy,
                       _lerp(fx, _grad3(grad, perm[aa + kk], x, y, z1),
                             _grad3(grad, perm[ba + kk], x1, y, z1)),
                       _lerp(fx, _grad3(grad, perm[ab + kk], x, y1, z1),
                             _grad3(grad, perm[bb + kk], x1, y1, z1))))


@njit(cache=True)
def _fbm3_point(x, y, z, octaves, persistence, lacunarity, base, perm, grad):
    """``py_noise3`` of _perlin.c (repeat 1024 on every axis)."""
    freq = np.float32(1.0)
    amp = np.float32(1.0)
    vmax = np.float32(0.0)
    total = np.float32(0.0)
    rep = np.float32(1024.0)
    for _ in range(octaves):
        r = int(rep * freq)
        rf = np.float32(r)
        xf = x * freq
        yf = y * freq
        zf = z * freq
        i = _ifloor(_fmodf(xf, rf))
        j = _ifloor(_fmodf(yf, rf))
        k = _ifloor(_fmodf(zf, rf))
        total += _noise3_cell(xf, yf, zf, i, j, k, r, r, r, base, perm, grad) * amp
        vmax += amp
        freq *= lacunarity
        amp *= persistence
    return total / vmax


@njit(cache=True, parallel=True)
def _fbm3_kernel(x, y, z, octaves, persistence, lacunarity, base, perm, grad, out):
    """fBm at float32 points ``x, y, z`` into float64 ``out`` (general, any coordinates)."""
    for p in prange(x.shape[0]):
        out[p] = _fbm3_point(x[p], y[p], z[p], octaves, persistence, lacunarity, base,
                             perm, grad)


#: Coordinates up to this magnitude take the fast kernel: with lacunarity >= 1 every
#: octave then has |x * freq| < int(1024 * freq), where C's fmodf is the identity.
FAST_LIMIT = 1000.0
_BLOCK = 512


@njit(cache=True, parallel=True, boundscheck=False)
def _fbm3_fast_kernel(x, y, z, octaves, persistence, lacunarity, base, perm, grad, out):
    """Same values as :func:`_fbm3_kernel` for |coordinates| <= FAST_LIMIT, lacunarity >= 1.

    Octave-major over blocks of points with a branch-free body, which LLVM vectorises
    (gathers for the table look-ups); the float32 operations are those of noise3, in
    the same order, so the results are bit-identical.
    """
    n = x.shape[0]
    nb = (n + _BLOCK - 1) // _BLOCK
    one = np.float32(1.0)
    six = np.float32(6.0)
    fifteen = np.float32(15.0)
    ten = np.float32(10.0)
    for blk in prange(nb):
        s = blk * _BLOCK
        e = min(s + _BLOCK, n)
        tot = np.zeros(_BLOCK, dtype=np.float32)
        freq = np.float32(1.0)
        amp = np.float32(1.0)
        vmax = np.float32(0.0)
        for _ in range(octaves):
            r = np.int32(np.float32(1024.0) * freq)
            for p in range(s, e):
                xf = x[p] * freq
                yf = y[p] * freq
                zf = z[p] * freq
                i0 = np.int32(xf)
                i0 = i0 - np.int32(1) if xf < np.float32(i0) else i0
                j0 = np.int32(yf)
                j0 = j0 - np.int32(1) if yf < np.float32(j0) else j0
                k0 = np.int32(zf)
                k0 = k0 - np.int32(1) if zf < np.float32(k0) else k0
                i1 = i0 + np.int32(1) if i0 + np.int32(1) < r else np.int32(0)
                j1 = j0 + np.int32(1) if j0 + np.int32(1) < r else np.int32(0)
                k1 = k0 + np.int32(1) if k0 + np.int32(1) < r else np.int32(0)
                fx0 = xf - np.float32(i0)
                fy0 = yf - np.float32(j0)
                fz0 = zf - np.float32(k0)
                i = (i0 & 255) + base
                j = (j0 & 255) + base
                k = (k0 & 255) + base
                i1 = (i1 & 255) + base
                j1 = (j1 & 255) + base
                k1 = (k1 & 255) + base
                u = fx0 * fx0 * fx0 * (fx0 * (fx0 * six - fifteen) + ten)
                v = fy0 * fy0 * fy0 * (fy0 * (fy0 * six - fifteen) + ten)
                w = fz0 * fz0 * fz0 * (fz0 * (fz0 * six - fifteen) + ten)
                a = perm[i]
                aa = perm[a + j]
                ab = perm[a + j1]
                b = perm[i1]
                ba = perm[b + j]
                bb = perm[b + j1]
                fx1 = fx0 - one
                fy1 = fy0 - one
                fz1 = fz0 - one
                h = (perm[aa + k] & 15) * 3
                g000 = fx0 * grad[h] + fy0 * grad[h + 1] + fz0 * grad[h + 2]
                h = (perm[ba + k] & 15) * 3
                g100 = fx1 * grad[h] + fy0 * grad[h + 1] + fz0 * grad[h + 2]
                h = (perm[ab + k] & 15) * 3
                g010 = fx0 * grad[h] + fy1 * grad[h + 1] + fz0 * grad[h + 2]
                h = (perm[bb + k] & 15) * 3
                g110 = fx1 * grad[h] + fy1 * grad[h + 1] + fz0 * grad[h + 2]
                h = (perm[aa + k1] & 15) * 3
                g001 = fx0 * grad[h] + fy0 * grad[h + 1] + fz1 * grad[h + 2]
                h = (perm[ba + k1] & 15) * 3
                g101 = fx1 * grad[h] + fy0 * grad[h + 1] + fz1 * grad[h + 2]
                h = (perm[ab + k1] & 15) * 3
                g011 = fx0 * grad[h] + fy1 * grad[h + 1] + fz1 * grad[h + 2]
                h = (perm[bb + k1] & 15) * 3
                g111 = fx1 * grad[h] + fy1 * grad[h + 1] + fz1 * grad[h + 2]
                l00 = g000 + u * (g100 - g000)
                l10 = g010 + u * (g110 - g010)
                l01 = g001 + u * (g101 - g001)
                l11 = g011 + u * (g111 - g011)
                m0 = l00 + v * (l10 - l00)
                m1 = l01 + v * (l11 - l01)
                tot[p - s] += (m0 + w * (m1 - m0)) * amp
            vmax += amp
            freq *= lacunarity
            amp *= persistence
        for p in range(s, e):
            out[p] = tot[p - s] / vmax
