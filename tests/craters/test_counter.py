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


# ---------------------------------------------------------------- distributions from words
def _words_uniforms(n, key):
    from craters.counter import uniform_from_words

    counters = np.zeros((n, 4), dtype=np.uint64)
    counters[:, 0] = np.arange(n, dtype=np.uint64)
    return uniform_from_words(philox4x64(counters, key)[:, 0])


@pytest.mark.parametrize("mean", [0.0, 0.3, 3.0, 40.0, 400.0])
def test_poisson_counts_have_the_poisson_distribution(mean):
    from scipy import stats

    from craters.counter import poisson_from_uniform

    k = poisson_from_uniform(_words_uniforms(40000, (9, int(mean * 10))), mean)
    assert abs(k.mean() - mean) <= 4.0 * math.sqrt(max(mean, 1e-9) / len(k)) + 1e-12
    if mean > 0:
        # the CDF at a few quantiles (inversion: P(k <= q) is exact up to sampling noise)
        for q in np.unique(stats.poisson.ppf([0.1, 0.5, 0.9], mean)):
            share = (k <= q).mean()
            assert abs(share - stats.poisson.cdf(q, mean)) < 0.01


def test_poisson_inversion_matches_scipys_quantiles():
    from scipy import stats

    from craters.counter import poisson_from_uniform

    u = np.linspace(0.0, 0.999, 400)
    for mean in (0.5, 7.0, 120.0):
        got = poisson_from_uniform(u, mean)
        want = stats.poisson.ppf(u, mean)
        # ties at a CDF step may fall either side by one rounding
        assert np.abs(got - want).max() <= 1 and (got == want).mean() > 0.97


def test_power_law_sizes_follow_the_cumulative_law():
    from scipy import stats

    from craters.counter import power_law_from_uniform

    d = power_law_from_uniform(_words_uniforms(30000, (3, 3)), 10.0, 1000.0, -1.8)
    assert d.min() >= 10.0 and d.max() < 1000.0
    a, b = 10.0 ** -1.8, 1000.0 ** -1.8
    cdf = lambda x: (a - np.asarray(x) ** -1.8) / (a - b)  # noqa: E731
    assert stats.kstest(d, cdf).statistic < 0.01


@pytest.mark.parametrize(("call", "message"), [
    (lambda f: f.poisson_from_uniform(1.0, 2.0), "in \\[0, 1\\)"),
    (lambda f: f.poisson_from_uniform(0.5, 501.0), "mean"),
    (lambda f: f.poisson_from_uniform(0.5, -1.0), "mean"),
    (lambda f: f.power_law_from_uniform(0.5, 2.0, 1.0, -2.0), "d_min < d_max"),
    (lambda f: f.power_law_from_uniform(0.5, 1.0, 2.0, 0.5), "slope"),
])
def test_distribution_inputs_are_checked(call, message):
    import craters.counter as f

    with pytest.raises(ValueError, match=message):
        call(f)


def test_the_distribution_kernels_match_their_python_reference_bit_for_bit():
    from craters.counter import poisson_from_uniform, power_law_from_uniform

    def poisson_ref(u, mean):
        p = _exp_ref(-mean)
        cdf, k = p, 0
        while u >= cdf and p > 0.0:
            k += 1
            p = p * mean / k
            cdf += p
        return k

    def power_ref(u, lo, hi, s):
        a, b = _exp_ref(s * _log_ref(lo)), _exp_ref(s * _log_ref(hi))
        return _exp_ref(_log_ref(a - u * (a - b)) / s)

    u = _words_uniforms(2000, (11, 12))
    means = np.linspace(0.0, 60.0, 2000)
    assert poisson_from_uniform(u, means).tolist() == [poisson_ref(a, m) for a, m in
                                                       zip(u, means, strict=True)]
    got = power_law_from_uniform(u, 3.0, 50.0, -2.3)
    assert got.tobytes() == np.array([power_ref(a, 3.0, 50.0, -2.3) for a in u]).tobytes()
