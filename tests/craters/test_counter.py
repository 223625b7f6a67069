"""Counter-based words (craters.counter): Philox4x64-10 against numpy's Philox, a pure-numpy
reference of the numba kernel, and locality (a row's words do not depend on the others)."""

import math

import numpy as np
import pytest

from craters.counter import philox4x64, uniform_from_words

M0, M1 = np.uint64(0xD2E7470EE14C6C93), np.uint64(0xCA5A826395121157)
W0, W1 = np.uint64(0x9E3779B97F4A7C15), np.uint64(0xBB67AE8584CAA73B)


def _mulhilo_ref(a, b):
    """128-bit product by Python integers (the reference of the kernel's 32-bit split)."""
    prod = [int(x) * int(y) for x, y in zip(np.atleast_1d(a), np.atleast_1d(b), strict=True)]
    return (np.array([p >> 64 for p in prod], dtype=np.uint64),
            np.array([p & (2**64 - 1) for p in prod], dtype=np.uint64))


def philox_ref(counters, keys):
    """Philox4x64-10 in numpy and Python integers (Salmon et al. 2011, Random123)."""
    c = np.array(counters, dtype=np.uint64).reshape(-1, 4).copy()
    k = np.broadcast_to(np.array(keys, dtype=np.uint64).reshape(-1, 2), (len(c), 2)).copy()
    with np.errstate(over="ignore"):
        for r in range(10):
            if r:
                k[:, 0] += W0
                k[:, 1] += W1
            hi0, lo0 = _mulhilo_ref(np.full(len(c), M0), c[:, 0])
            hi1, lo1 = _mulhilo_ref(np.full(len(c), M1), c[:, 2])
            c = np.stack([hi1 ^ c[:, 1] ^ k[:, 0], lo1, hi0 ^ c[:, 3] ^ k[:, 1], lo0], axis=1)
    return c


@pytest.mark.parametrize("key", [(0, 0), (1, 2), (2**64 - 1, 2**63 + 12345)])
@pytest.mark.parametrize("start", [(0, 0, 0, 0), (2**64 - 3, 7, 0, 2**62), (5, 2**64 - 1,
                                                                          2**64 - 1, 9)])
def test_the_words_are_numpys_philox(key, start):
    gen = np.random.Philox(key=np.array(key, np.uint64), counter=np.array(start, np.uint64))
    expected = gen.random_raw(4 * 5).reshape(5, 4)  # counters start + 1 .. start + 5
    counters, value = [], sum(int(v) << (64 * i) for i, v in enumerate(start))
    for _ in range(5):
        value = (value + 1) % 2**256
        counters.append([(value >> (64 * i)) & (2**64 - 1) for i in range(4)])
    np.testing.assert_array_equal(philox4x64(np.array(counters, np.uint64), key), expected)


def test_the_kernel_matches_its_reference():
    rng = np.random.default_rng(3)
    counters = rng.integers(0, 2**64, size=(257, 4), dtype=np.uint64, endpoint=False)
    keys = rng.integers(0, 2**64, size=(257, 2), dtype=np.uint64, endpoint=False)
    np.testing.assert_array_equal(philox4x64(counters, keys), philox_ref(counters, keys))
    np.testing.assert_array_equal(philox4x64(counters, keys[0]), philox_ref(counters, keys[0]))


def test_a_rows_words_do_not_depend_on_the_others():
    rng = np.random.default_rng(4)
    counters = rng.integers(0, 2**64, size=(1000, 4), dtype=np.uint64, endpoint=False)
    whole = philox4x64(counters, (42, 7))
    pick = rng.permutation(1000)[:37]
    np.testing.assert_array_equal(philox4x64(counters[pick], (42, 7)), whole[pick])
    np.testing.assert_array_equal(philox4x64(counters[5], (42, 7))[0], whole[5])


def test_uniform_numbers_are_exact_multiples_of_2_to_minus_53():
    words = np.array([0, 2**11 - 1, 2**11, 2**63, 2**64 - 1], dtype=np.uint64)
    u = uniform_from_words(words)
    assert u.tolist() == [0.0, 0.0, 2.0**-53, 0.5, 1.0 - 2.0**-53]
    many = uniform_from_words(philox4x64(np.arange(4000, dtype=np.uint64).reshape(-1, 4), (1, 1)))
    assert 0.0 <= many.min() and many.max() < 1.0
    assert abs(many.mean() - 0.5) < 0.01  # 4000 uniforms: sd of the mean 0.0046


@pytest.mark.parametrize(("counters", "key", "message"), [
    ([[0, 0, 0]], (0, 0), "counters"),
    ([[0, 0, 0, -1]], (0, 0), "negative"),
    ([[0.5, 0, 0, 0]], (0, 0), "integers"),
    ([[0, 0, 0, 0]] * 3, [[0, 0]] * 2, "one per counter"),
])
def test_bad_input_is_named(counters, key, message):
    with pytest.raises((ValueError, TypeError), match=message):
        philox4x64(counters, key)


# ---------------------------------------------------------------- portable exp and log
def _ulps(a, b):
    """Distance in units in the last place between float64 arrays."""
    ia = np.asarray(a, np.float64).view(np.int64)
    ib = np.asarray(b, np.float64).view(np.int64)
    return np.abs(ia - ib)


def _sample(rng, n=20000):
    return np.concatenate([rng.uniform(-745, 709, n), rng.uniform(-2, 2, n),
                           rng.uniform(-1e-6, 1e-6, n // 10),
                           [0.0, -0.0, 1.0, -1.0, 0.34657359027997264, 1.0397207708399179,
                            709.78, -745.0, 2.0**-29]])


def test_portable_exp_is_within_one_ulp():
    from craters.counter import portable_exp

    x = _sample(np.random.default_rng(5))
    got = portable_exp(x)
    ref = np.array([math.exp(v) for v in x])
    assert _ulps(got, ref).max() <= 1
    assert portable_exp(np.array([np.inf, -np.inf, 710.0, -746.0])).tolist() == \
        [np.inf, 0.0, np.inf, 0.0]
    assert np.isnan(portable_exp(np.nan))


def test_portable_log_is_within_one_ulp():
    from craters.counter import portable_log

    rng = np.random.default_rng(6)
    x = np.concatenate([np.exp(rng.uniform(-700, 700, 20000)), rng.uniform(0.5, 2.0, 20000),
                        [1.0, 2.0, 0.5, 0.7071067811865476, 5e-324, 1.7976931348623157e308]])
    got = portable_log(x)
    ref = np.array([math.log(v) for v in x])
    assert _ulps(got, ref).max() <= 1
    with np.errstate(divide="ignore", invalid="ignore"):
        assert portable_log(0.0) == -np.inf and np.isnan(portable_log(-1.0))


def _exp_ref(x):
    """The kernel's algorithm in Python floats (IEEE doubles, no fused operations)."""
    from craters import _counter_kernels as k

    if x > k._EXP_MAX:
        return math.inf
    if x < k._EXP_MIN:
        return 0.0
    if abs(x) < 2.0**-28:
        return 1.0 + x
    kk, hi, lo = 0, x, 0.0
    if abs(x) > 0.34657359027997264:
        if abs(x) < 1.0397207708399179:
            kk = 1 if x > 0 else -1
        else:
            kk = int(k._INV_LN2 * x + (0.5 if x > 0 else -0.5))
        hi = x - kk * k._LN2_HI
        lo = kk * k._LN2_LO
        x = hi - lo
    t = x * x
    c = x - t * (k._P1 + t * (k._P2 + t * (k._P3 + t * (k._P4 + t * k._P5))))
    if kk == 0:
        return 1.0 - ((x * c) / (c - 2.0) - x)
    return math.ldexp(1.0 - ((lo - (x * c) / (2.0 - c)) - hi), kk)


def _log_ref(x):
    from craters import _counter_kernels as k

    m, e = math.frexp(x)
    if m < k._SQRT_HALF:
        m, e = 2.0 * m, e - 1
    f = m - 1.0
    s = f / (2.0 + f)
    z = s * s
    w = z * z
    r = z * (k._LG1 + w * (k._LG3 + w * (k._LG5 + w * k._LG7))) + \
        w * (k._LG2 + w * (k._LG4 + w * k._LG6))
    hfsq = 0.5 * f * f
    return e * k._LN2_HI - ((hfsq - (s * (hfsq + r) + e * k._LN2_LO)) - f)


def test_the_portable_kernels_match_their_python_reference_bit_for_bit():
    from craters.counter import portable_exp, portable_log

    rng = np.random.default_rng(7)
    x = _sample(rng, 3000)
    assert portable_exp(x).tobytes() == np.array([_exp_ref(v) for v in x]).tobytes()
    y = np.exp(rng.uniform(-700, 700, 6000))
    assert portable_log(y).tobytes() == np.array([_log_ref(v) for v in y]).tobytes()
