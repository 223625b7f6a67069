"""Numba kernels of :mod:`craters.exact`: sums in a fixed order (no fast-math, so no
reassociation and no fused multiply-adds: the same bytes on every x86-64 CPU)."""

from __future__ import annotations

from numba import njit


@njit(cache=True)
def _matmul_kernel(a, b, out):
    """``out = a @ b``, each element summed over the inner index in increasing order."""
    n, m = a.shape
    p = b.shape[1]
    for i in range(n):
        for j in range(p):
            out[i, j] = 0.0
        for k in range(m):
            aik = a[i, k]
            for j in range(p):
                out[i, j] += aik * b[k, j]


@njit(cache=True)
def _dot_kernel(a, b):
    """Sum of ``a[i] * b[i]`` in increasing i."""
    acc = 0.0
    for i in range(a.shape[0]):
        acc += a[i] * b[i]
    return acc

