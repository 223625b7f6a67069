"""Counter-based words (craters.counter): Philox4x64-10 against numpy's Philox, a pure-numpy
reference of the numba kernel, and locality (a row's words do not depend on the others)."""

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
