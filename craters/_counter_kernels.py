"""Numba kernel of :mod:`craters.counter`: Philox4x64-10 (Salmon et al. 2011)."""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

_M0 = np.uint64(0xD2E7470EE14C6C93)
_M1 = np.uint64(0xCA5A826395121157)
_W0 = np.uint64(0x9E3779B97F4A7C15)
_W1 = np.uint64(0xBB67AE8584CAA73B)
_LOW32 = np.uint64(0xFFFFFFFF)
_S32 = np.uint64(32)


@njit(cache=True, inline="always")
def _mulhilo(a, b):
    """(high, low) 64-bit halves of the 128-bit product of two uint64."""
    a_lo = a & _LOW32
    a_hi = a >> _S32
    b_lo = b & _LOW32
    b_hi = b >> _S32
    p0 = a_lo * b_lo
    p1 = a_lo * b_hi
    p2 = a_hi * b_lo
    p3 = a_hi * b_hi
    carry = ((p0 >> _S32) + (p1 & _LOW32) + (p2 & _LOW32)) >> _S32
    return p3 + (p1 >> _S32) + (p2 >> _S32) + carry, a * b


@njit(cache=True, parallel=True)
def _philox_kernel(counters, keys, out):
    """out[i] = Philox4x64-10(counters[i], keys[i]); rows independent (in parallel blocks
    of 4096: a parallel region costs more than a few thousand rows)."""
    n = counters.shape[0]
    for b in prange((n + 4095) // 4096):
        _philox_rows(counters, keys, out, b * 4096, min(n, (b + 1) * 4096))


@njit(cache=True)
def _philox_rows(counters, keys, out, lo, hi):
    """Rows lo..hi-1 of :func:`_philox_kernel`."""
    for i in range(lo, hi):
        c0 = counters[i, 0]
        c1 = counters[i, 1]
        c2 = counters[i, 2]
        c3 = counters[i, 3]
        k0 = keys[i, 0]
        k1 = keys[i, 1]
        for r in range(10):
            if r > 0:
                k0 = k0 + _W0
                k1 = k1 + _W1
            hi0, lo0 = _mulhilo(_M0, c0)
            hi1, lo1 = _mulhilo(_M1, c2)
            c0, c1, c2, c3 = hi1 ^ c1 ^ k0, lo1, hi0 ^ c3 ^ k1, lo0
        out[i, 0] = c0
        out[i, 1] = c1
        out[i, 2] = c2
        out[i, 3] = c3


# --------------------------------------------------------------------------- portable math
# exp and log in +, -, *, / only (the algorithms of e_exp.c and e_log.c of fdlibm, Sun
# Microsystems' freely distributable libm), so their bytes do not depend on the libm or
# the CPU (numba does not contract a * b + c into a fused multiply-add without fastmath).
_LN2_HI = 6.93147180369123816490e-01
_LN2_LO = 1.90821492927058770002e-10
_INV_LN2 = 1.44269504088896338700e+00
_P1 = 1.66666666666666019037e-01
_P2 = -2.77777777770155933842e-03
_P3 = 6.61375632143793436117e-05
_P4 = -1.65339022054652515390e-06
_P5 = 4.13813679705723846039e-08
_EXP_MAX = 7.09782712893383973096e+02
_EXP_MIN = -7.45133219101941108420e+02
_LG1 = 6.666666666666735130e-01
_LG2 = 3.999999999940941908e-01
_LG3 = 2.857142874366239149e-01
_LG4 = 2.222219843214978396e-01
_LG5 = 1.818357216161805012e-01
_LG6 = 1.531383769920937332e-01
_LG7 = 1.479819860511658591e-01
_SQRT_HALF = 0.7071067811865476


@njit(cache=True)
def _exp(x):
    """e**x, < 1 ulp, the same bytes everywhere (fdlibm's argument reduction and
    polynomial)."""
    if x != x:
        return x
    if x > _EXP_MAX:
        return math.inf
    if x < _EXP_MIN:
        return 0.0
    ax = abs(x)
    if ax < 3.725290298461914e-09:  # 2**-28
        return 1.0 + x
    k = 0
    hi = x
    lo = 0.0
    if ax > 0.34657359027997264:  # 0.5 ln 2
        if ax < 1.0397207708399179:  # 1.5 ln 2
            k = 1 if x > 0.0 else -1
        else:
            k = int(_INV_LN2 * x + (0.5 if x > 0.0 else -0.5))
        hi = x - k * _LN2_HI
        lo = k * _LN2_LO
        x = hi - lo
    t = x * x
    c = x - t * (_P1 + t * (_P2 + t * (_P3 + t * (_P4 + t * _P5))))
    if k == 0:
        return 1.0 - ((x * c) / (c - 2.0) - x)
    y = 1.0 - ((lo - (x * c) / (2.0 - c)) - hi)
    return math.ldexp(y, k)


@njit(cache=True)
def _log(x):
    """Natural logarithm, < 1 ulp, the same bytes everywhere (fdlibm's reduction to
    [sqrt(2)/2, sqrt(2)) and polynomial); -inf at 0, nan below."""
    if x != x or x < 0.0:
        return math.nan
    if x == 0.0:
        return -math.inf
    if x == math.inf:
        return x
    m, e = math.frexp(x)
    if m < _SQRT_HALF:
        m = 2.0 * m
        e -= 1
    f = m - 1.0
    k = float(e)
    s = f / (2.0 + f)
    z = s * s
    w = z * z
    t1 = w * (_LG2 + w * (_LG4 + w * _LG6))
    t2 = z * (_LG1 + w * (_LG3 + w * (_LG5 + w * _LG7)))
    r = t2 + t1
    hfsq = 0.5 * f * f
    return k * _LN2_HI - ((hfsq - (s * (hfsq + r) + k * _LN2_LO)) - f)


@njit(cache=True)
def _exp_kernel(x, out):
    for i in range(x.shape[0]):
        out[i] = _exp(x[i])


@njit(cache=True)
def _log_kernel(x, out):
    for i in range(x.shape[0]):
        out[i] = _log(x[i])


# --------------------------------------------------------------------------- model ages
_LN10 = math.log(10.0)  # (craters.local's too: the kernels and the numpy path agree)


@njit(cache=True)
def _pf_bisect_kernel(coeffs_rev, target, a, b, halvings, out):
    """log10(D / km) where a production function's shape N(>D) / N(>1 km) meets
    ``target`` (decreasing in D), bisected ``halvings`` times from [a, b]: the
    operations of the numpy bisection over ``craters.local._pf_shape(layer, 10**v km)``
    that it replaced (the reference in tests/craters/test_local_model_age.py), one
    element at a time, so the same bytes (``coeffs_rev``: the polynomial's coefficients
    but a0, highest first)."""
    for i in range(target.shape[0]):
        lo = a
        hi = b
        for _ in range(halvings):
            mid = 0.5 * (lo + hi)
            x = _log(_exp(mid * _LN10) * 1e3 * 1e-3) / _LN10
            s = 0.0
            for c in coeffs_rev:
                s = (s + c) * x
            if _exp(s * _LN10) > target[i]:
                lo = mid
            else:
                hi = mid
        out[i] = 0.5 * (lo + hi)


@njit(cache=True)
def _age_bisect_kernel(c0, c1, c2, c3, target, a, b, halvings, out):
    """The age (Gyr) where a chronology N(>1 km) = c0 (e^(c1 t) - 1) + c2 t^2 + c3 t
    (increasing) meets ``target``, bisected as :func:`_pf_bisect_kernel`."""
    for i in range(target.shape[0]):
        lo = a
        hi = b
        for _ in range(halvings):
            mid = 0.5 * (lo + hi)
            if c0 * (_exp(c1 * mid) - 1.0) + c2 * mid * mid + c3 * mid < target[i]:
                lo = mid
            else:
                hi = mid
        out[i] = 0.5 * (lo + hi)


# --------------------------------------------------------------------------- distributions
@njit(cache=True)
def _poisson(u, mean):
    """The Poisson(``mean``) count whose CDF first exceeds ``u`` (inversion; exact
    operations but for :func:`_exp`; a CDF that stops growing ends the search)."""
    p = _exp(-mean)
    cdf = p
    k = 0
    while u >= cdf and p > 0.0:
        k += 1
        p = p * mean / k
        cdf += p
    return k


@njit(cache=True)
def _poisson_kernel(u, mean, out):
    for i in range(u.shape[0]):
        out[i] = _poisson(u[i], mean[i])


@njit(cache=True)
def _power_law(u, d_min, d_max, slope):
    """The diameter whose cumulative share N(>D) ~ D**slope of [d_min, d_max) is ``u``."""
    a = _exp(slope * _log(d_min))
    b = _exp(slope * _log(d_max))
    return _exp(_log(a - u * (a - b)) / slope)


@njit(cache=True)
def _power_law_kernel(u, d_min, d_max, slope, out):
    for i in range(u.shape[0]):
        out[i] = _power_law(u[i], d_min[i], d_max[i], slope[i])


# fdlibm s_atan.c: atan in +, -, *, / (the same bytes everywhere)
_ATAN_HI = (4.63647609000806093515e-01, 7.85398163397448278999e-01,
            9.82793723247329054082e-01, 1.57079632679489655800e+00)
_ATAN_LO = (2.26987774529616870924e-17, 3.06161699786838301793e-17,
            1.39033110312309984516e-17, 6.12323399573676603587e-17)
_AT = (3.33333333333329318027e-01, -1.99999999998764832476e-01,
       1.42857142725034663711e-01, -1.11111104054623557880e-01,
       9.09088713343650656196e-02, -7.69187620504482999495e-02,
       6.66107313738753120669e-02, -5.83357013379057348645e-02,
       4.97687799461593236017e-02, -3.65315727442169155270e-02,
       1.62858201153657823623e-02)


@njit(cache=True)
def _atan(x):
    """atan(x), < 1 ulp, the same bytes everywhere (fdlibm's ``s_atan.c``)."""
    if x != x:
        return x
    neg = x < 0.0
    ax = -x if neg else x
    if ax >= 3.602879701896397e16:  # 2**55: atan = +-pi/2
        r = _ATAN_HI[3] + _ATAN_LO[3]
        return -r if neg else r
    idx = -1
    if ax < 0.4375:
        if ax < 3.725290298461914e-09:  # 2**-28
            return x
    elif ax < 1.1875:
        if ax < 0.6875:  # 7/16 <= |x| < 11/16
            idx = 0
            ax = (2.0 * ax - 1.0) / (2.0 + ax)
        else:  # 11/16 <= |x| < 19/16
            idx = 1
            ax = (ax - 1.0) / (ax + 1.0)
    elif ax < 2.4375:  # 19/16 <= |x| < 39/16
        idx = 2
        ax = (ax - 1.5) / (1.0 + 1.5 * ax)
    else:  # 39/16 <= |x| < 2**55
        idx = 3
        ax = -1.0 / ax
    z = ax * ax
    w = z * z
    s1 = z * (_AT[0] + w * (_AT[2] + w * (_AT[4] + w * (_AT[6] + w * (_AT[8] + w * _AT[10])))))
    s2 = w * (_AT[1] + w * (_AT[3] + w * (_AT[5] + w * (_AT[7] + w * _AT[9]))))
    if idx < 0:
        r = ax - ax * (s1 + s2)
    else:
        r = _ATAN_HI[idx] - ((ax * (s1 + s2) - _ATAN_LO[idx]) - ax)
    return -r if neg else r


@njit(cache=True)
def _atan_kernel(x, out):
    for i in range(x.shape[0]):
        out[i] = _atan(x[i])


# --------------------------------------------------------------------------- cells
@njit(cache=True, inline="always")
def _face_uv(x, y, z):
    """(face, u, v) of a direction on the gnomonic cube (craters.cells)."""
    ax = abs(x)
    ay = abs(y)
    az = abs(z)
    if ax >= ay and ax >= az:
        a, m, p, q = 0, x, y, z
    elif ay >= az:
        a, m, p, q = 1, y, z, x
    else:
        a, m, p, q = 2, z, x, y
    am = abs(m)
    return 2 * a + (0 if m > 0.0 else 1), p / am, q / am


@njit(cache=True, inline="always")
def _face_point(face, u, v):
    """(x, y, z) of the point (u, v) of a cube face (not normalised; no allocation)."""
    a = face // 2
    s = 1.0 if face % 2 == 0 else -1.0
    if a == 0:
        return s, u, v
    if a == 1:
        return v, s, u
    return u, v, s


@njit(cache=True, inline="always")
def _cell_index(level, u):
    """The cell row or column of face coordinate ``u`` at ``level``."""
    n = 1 << level
    return min(max(int(np.floor((u + 1.0) * 0.5 * n)), 0), n - 1)


@njit(cache=True, inline="always")
def _cell_id(level, face, u, v):
    """The uint64 cell id (craters.cells) of face coordinates (u, v) at ``level``."""
    return (np.uint64(level) << np.uint64(57)) | (np.uint64(face) << np.uint64(54)) \
        | (np.uint64(_cell_index(level, u)) << np.uint64(27)) \
        | np.uint64(_cell_index(level, v))


@njit(cache=True)
def _cell_of_kernel(points, level, out):
    """(face, i, j) of each point's gnomonic cube cell at ``level`` (craters.cells)."""
    for k in range(points.shape[0]):
        f, u, v = _face_uv(points[k, 0], points[k, 1], points[k, 2])
        out[k, 0] = f
        out[k, 1] = _cell_index(level, u)
        out[k, 2] = _cell_index(level, v)


@njit(cache=True)
def _corner_angle(u, v):
    return _atan(u * v / np.sqrt(1.0 + u * u + v * v))


@njit(cache=True)
def _cell_solid_angle_kernel(level, i, j, out):
    scale = 2.0 / (1 << level)
    for k in range(i.shape[0]):
        u0 = -1.0 + i[k] * scale
        u1 = -1.0 + (i[k] + 1) * scale
        v0 = -1.0 + j[k] * scale
        v1 = -1.0 + (j[k] + 1) * scale
        out[k] = (_corner_angle(u1, v1) - _corner_angle(u0, v1)) \
            - (_corner_angle(u1, v0) - _corner_angle(u0, v0))
