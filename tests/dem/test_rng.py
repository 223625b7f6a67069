"""The counter-based Gaussian: splitmix64 against a pure-Python reference, statistics."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import stats

from dem._rng_kernels import _normals_kernel, key_from_rng

MASK = 2**64 - 1


def splitmix64(x: int) -> int:
    """Reference: Steele, Lea & Flood's splitmix64 step in Python integers."""
    z = (x + 0x9E3779B97F4A7C15) & MASK
    z = ((z ^ (z >> 30)) * 0xBF58476D1CE4E5B9) & MASK
    z = ((z ^ (z >> 27)) * 0x94D049BB133111EB) & MASK
    return z ^ (z >> 31)


def reference_normal(key, stream, level, row, col) -> float:
    h = splitmix64((key ^ stream) & MASK)
    for v in (level, row, col):
        h = splitmix64(h ^ (v & MASK))
    u1 = ((h >> 11) + 1) * 2.0**-53
    u2 = (splitmix64(h) >> 11) * 2.0**-53
    return float(np.sqrt(-2.0 * np.log(u1)) * np.cos(2.0 * np.pi * u2))


def kernel_normals(key, stream, level, rows, cols):
    rows = np.asarray(rows, dtype=np.int64)
    cols = np.asarray(cols, dtype=np.int64)
    out = np.empty(rows.shape[0])
    _normals_kernel(key, stream, level, rows, cols, out)
    return out


@pytest.mark.parametrize("key", [0, 1, 123456789, 2**63 - 1])
@pytest.mark.parametrize("level", [0, 3, 40])
def test_matches_reference(key, level):
    rows = [0, 1, -1, 5, 10**9, -(10**9)]
    cols = [0, 7, 3, -2, 12345, 2**40]
    got = kernel_normals(key, 1, level, rows, cols)
    want = [reference_normal(key, 1, level, r, c) for r, c in zip(rows, cols, strict=True)]
    np.testing.assert_allclose(got, want, rtol=1e-14, atol=1e-14)


def test_gaussian_and_uncorrelated():
    rows, cols = np.divmod(np.arange(400 * 400), 400)
    z = kernel_normals(42, 1, 2, rows, cols)
    assert abs(z.mean()) < 0.01 and abs(z.std() - 1) < 0.01
    assert stats.kstest(z, "norm").pvalue > 1e-3
    g = z.reshape(400, 400)
    for a, b in ((g[:, 1:], g[:, :-1]), (g[1:], g[:-1]), (g[1:, 1:], g[:-1, :-1])):
        assert abs(np.corrcoef(a.ravel(), b.ravel())[0, 1]) < 0.01


def test_streams_levels_keys_differ():
    rows, cols = np.zeros(1000, np.int64), np.arange(1000)
    base = kernel_normals(7, 1, 1, rows, cols)
    for other in (kernel_normals(8, 1, 1, rows, cols), kernel_normals(7, 2, 1, rows, cols),
                  kernel_normals(7, 1, 2, rows, cols), kernel_normals(7, 1, 1, rows + 1, cols)):
        assert abs(np.corrcoef(base, other)[0, 1]) < 0.1


def test_key_from_rng():
    assert key_from_rng(5) == key_from_rng(5)
    assert key_from_rng(5)[1] == 5 and key_from_rng(6)[0] != key_from_rng(5)[0]
    key, seed = key_from_rng(np.random.default_rng(5))
    assert seed is None and key == key_from_rng(5)[0]
    assert 0 <= key_from_rng(None)[0] < 2**63
    with pytest.raises(TypeError, match="rng"):
        key_from_rng("5")
    with pytest.raises(ValueError, match="rng"):
        key_from_rng(-1)
