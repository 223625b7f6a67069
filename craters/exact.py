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

__all__ = ["abs2", "dot", "matmul", "plane_residual"]


def matmul(a, b) -> np.ndarray:
    """``a @ b`` of 2-D (or 1-D, as a row / column) float64 arrays, in a fixed order."""
    a = np.asarray(a, dtype=np.float64)
    b = np.asarray(b, dtype=np.float64)
    a2 = a[None, :] if a.ndim == 1 else a
    b2 = b[:, None] if b.ndim == 1 else b
    if a2.ndim != 2 or b2.ndim != 2 or a2.shape[1] != b2.shape[0]:
        raise ValueError(f"matmul: shapes {a.shape} and {b.shape} do not multiply")
    out = np.empty((a2.shape[0], b2.shape[1]))
    from ._exact_kernels import _matmul_kernel  # numba loads here

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
    from ._exact_kernels import _dot_kernel  # numba loads here

    return float(_dot_kernel(a, b))


def abs2(z) -> np.ndarray:
    """``|z|**2`` of a complex array as ``re*re + im*im`` (elementwise, IEEE, the same bits on
    every CPU; no square root to undo)."""
    z = np.asarray(z)
    return z.real * z.real + z.imag * z.imag


def plane_residual(z) -> np.ndarray:
    """``z`` (rows, cols) minus its least-squares plane ``c0 + c1 col + c2 row`` over the
    whole grid, in a fixed order: with the coordinates centred, the columns 1, col and row
    of the design are orthogonal on a full grid, so the plane is the mean plus the two
    projections (in-order sums, :func:`matmul`); numpy's ``lstsq`` gives the same plane to
    rounding, but through LAPACK, whose kernels vary with the CPU (``OPENBLAS_CORETYPE``
    changed the bytes of ``dem spectrum``)."""
    z = np.asarray(z, dtype=np.float64)
    if z.ndim != 2 or not z.size:
        raise ValueError(f"plane_residual: needs a non-empty 2-D array; got shape {z.shape}")
    rows, cols = z.shape
    xc = np.arange(cols) - 0.5 * (cols - 1)  # half-integers: exact
    yc = np.arange(rows) - 0.5 * (rows - 1)
    row_sums = matmul(z, np.ones(cols))
    mean = dot(row_sums, np.ones(rows)) / z.size
    sxx, syy = dot(xc, xc), dot(yc, yc)
    gx = dot(matmul(z, xc), np.ones(rows)) / (rows * sxx) if sxx > 0 else 0.0
    gy = dot(row_sums, yc) / (cols * syy) if syy > 0 else 0.0
    return z - ((mean + gx * xc)[None, :] + (gy * yc)[:, None])
