"""Numba kernel of :mod:`craters.diffusion`: the stamping tables of many craters as the
bilinear blend (in log D and log tau) of the cached node shapes, times each crater's
fresh depth. Elementwise per crater, so the result does not depend on the thread count;
``tests/craters/test_diffusion_kernels.py`` compares it with the numpy expression."""

from __future__ import annotations

from numba import njit, prange


@njit(cache=True, parallel=True)
def _blend_tables(stack, a, b, j0, fd, ft, depth, out):
    """``out[c] = ((1 - fd)((1 - ft) S[a, j0] + ft S[a, j0 + 1])
    + fd ((1 - ft) S[b, j0] + ft S[b, j0 + 1])) depth[c]`` for every crater c (rows of ``out``),
    with S = ``stack`` (nodes, tau nodes, table) in float32."""
    n, m = out.shape
    for c in prange(n):
        ia, ib, j = a[c], b[c], j0[c]
        wd, wt = fd[c], ft[c]
        s = depth[c]
        for k in range(m):  # the numpy expression's order of operations, for the same bits
            lo = (1.0 - wt) * stack[ia, j, k] + wt * stack[ia, j + 1, k]
            hi = (1.0 - wt) * stack[ib, j, k] + wt * stack[ib, j + 1, k]
            out[c, k] = ((1.0 - wd) * lo + wd * hi) * s
