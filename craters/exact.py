"""Linear algebra whose bytes do not depend on the CPU (issue 34: same seed, same bytes on
any x86-64 CPU).

numpy hands ``@``, ``dot`` and ``matmul`` of float64 arrays to OpenBLAS, which picks its
kernels by the CPU (Haswell, Zen, SkylakeX ...): they sum in different orders and some fuse
multiply-adds, so the same product differs in its last bits from one machine to another
(forcing ``OPENBLAS_CORETYPE=Sandybridge`` on one AVX2 machine changed the bytes of 7 of
the 29 golden outputs). These sum each element over the inner index in increasing order,
without fused multiply-adds, in compiled loops: slower than BLAS for large matrices, used
where a product decides output bytes. :func:`abs2` is the squared modulus of complex numbers
as two products and a sum: numpy's ``abs`` of a complex array has SIMD loops that differ in
the last bit between AVX2 and SSE (``NPY_DISABLE_CPU_FEATURES=X86_V3`` changed the bytes of
both spectrum commands).

Examples
--------
>>> import numpy as np
>>> from craters.exact import matmul
>>> matmul(np.array([[1.0, 2.0]]), np.array([[3.0], [4.0]]))
array([[11.]])
"""

from __future__ import annotations

import numpy as np

from ._exact_kernels import _dot_kernel, _matmul_kernel

__all__ = ["abs2", "dot", "matmul"]


def matmul(a, b) -> np.ndarray:
    """``a @ b`` of 2-D (or 1-D, as a row / column) float64 arrays, in a fixed order."""
    a = np.asarray(a, dtype=np.float64)
    b = np.asarray(b, dtype=np.float64)
    a2 = a[None, :] if a.ndim == 1 else a
    b2 = b[:, None] if b.ndim == 1 else b
    if a2.ndim != 2 or b2.ndim != 2 or a2.shape[1] != b2.shape[0]:
        raise ValueError(f"matmul: shapes {a.shape} and {b.shape} do not multiply")
    out = np.empty((a2.shape[0], b2.shape[1]))
    _matmul_kernel(np.ascontiguousarray(a2), np.ascontiguousarray(b2), out)
    if a.ndim == 1:
        out = out[0]
    if b.ndim == 1:
        out = out[..., 0]
    return out


def dot(a, b) -> float:
    """``sum(a * b)`` of two 1-D float64 arrays, in increasing index order."""
    a = np.ascontiguousarray(a, dtype=np.float64).ravel()
    b = np.ascontiguousarray(b, dtype=np.float64).ravel()
    if a.shape != b.shape:
        raise ValueError(f"dot: shapes {a.shape} and {b.shape} differ")
    return float(_dot_kernel(a, b))


def abs2(z) -> np.ndarray:
    """``|z|**2`` of a complex array as ``re*re + im*im`` (elementwise, IEEE, the same bits on
    every CPU; no square root to undo)."""
    z = np.asarray(z)
    return z.real * z.real + z.imag * z.imag
