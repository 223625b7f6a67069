"""Numba kernels of the gap fill: keyed white noise over a box, multigrid Laplace solve."""

from __future__ import annotations

from numba import njit

from ._rng_kernels import STREAM_FILL, _pixel_normal


@njit(cache=True)
def _noise_box_kernel(key, level, row0, col0, out):
    """``out[i, j]`` = the standard normal keyed by ``(key, level, row0 + i, col0 + j)``.

    Global lattice indices at ``level``: the same pixel gets the same deviate whatever
    box, tile or thread count computes it (one thread: one call per hole, mostly small).
    """
    rows, cols = out.shape
    for i in range(rows):
        for j in range(cols):
            out[i, j] = _pixel_normal(key, STREAM_FILL, level, row0 + i, col0 + j)


@njit(cache=True)
def _smooth_kernel(e, f, wn, ws, ww, we, d, active, color):
    """One red-black Gauss-Seidel half sweep of ``A e = f`` on the ``active`` pixels.

    ``(A e)_p = sum_k w_k (e_k - e_p) - d_p e_p``: weights ``wn, ws, ww, we`` to the
    four neighbours and a Dirichlet term ``d`` (links to known pixels, where ``e = 0``).
    The arrays carry a ring of inactive pixels with zero weights around the grid (no
    bounds checks). Pixels of one colour read only the other colour, so the order
    within a colour does not matter; one thread (the calls are many and small).
    """
    rows, cols = e.shape
    for r in range(1, rows - 1):
        for c in range(1 + (r + 1 + color) % 2, cols - 1, 2):
            if not active[r, c]:
                continue
            n = wn[r, c] + ws[r, c] + ww[r, c] + we[r, c] + d[r, c]
            if n > 0.0:
                s = (wn[r, c] * e[r - 1, c] + ws[r, c] * e[r + 1, c] + ww[r, c] * e[r, c - 1]
                     + we[r, c] * e[r, c + 1])
                e[r, c] = (s - f[r, c]) / n


@njit(cache=True)
def _residual_kernel(e, f, wn, ws, ww, we, d, active, out):
    """``out = f - A e`` on the ``active`` pixels (see :func:`_smooth_kernel`), 0 elsewhere."""
    rows, cols = e.shape
    out[:] = 0.0
    for r in range(1, rows - 1):
        for c in range(1, cols - 1):
            if not active[r, c]:
                continue
            s = (wn[r, c] * (e[r - 1, c] - e[r, c]) + ws[r, c] * (e[r + 1, c] - e[r, c])
                 + ww[r, c] * (e[r, c - 1] - e[r, c]) + we[r, c] * (e[r, c + 1] - e[r, c]))
            out[r, c] = f[r, c] - (s - d[r, c] * e[r, c])


@njit(cache=True)
def _restrict_kernel(r, out):
    """``out`` = ``r`` summed over 2 x 2 blocks; both carry a ring (pixel i of ``r`` goes to
    ``(i - 1) // 2 + 1``)."""
    rows, cols = r.shape
    out[:] = 0.0
    for i in range(1, rows - 1):
        for j in range(1, cols - 1):
            out[(i - 1) // 2 + 1, (j - 1) // 2 + 1] += r[i, j]


@njit(cache=True)
def _prolong_kernel(e_c, active, scale, e):
    """``e += scale *`` the block's value of ``e_c`` on the ``active`` pixels (rings as in
    :func:`_restrict_kernel`)."""
    rows, cols = e.shape
    for i in range(1, rows - 1):
        for j in range(1, cols - 1):
            if active[i, j]:
                e[i, j] += scale * e_c[(i - 1) // 2 + 1, (j - 1) // 2 + 1]


@njit(cache=True)
def _sor_kernel(z, solve, omega, tol, max_sweeps):
    """Laplace equation on the ``solve`` pixels of ``z`` by successive over-relaxation.

    Each ``solve`` pixel becomes the mean of its usable 4-neighbours (``solve`` pixels
    and finite others: Dirichlet data; neighbours outside ``z`` or NaN and not solved
    are left out), sweeping in a fixed order from the values in ``z`` (finite on
    ``solve``) until the largest change of a sweep is <= ``tol`` or after
    ``max_sweeps``; returns the number of sweeps. For small holes (one call, no set-up).
    """
    rows, cols = z.shape
    for sweep in range(max_sweeps):
        big = 0.0
        for r in range(rows):
            for c in range(cols):
                if not solve[r, c]:
                    continue
                s = 0.0
                n = 0
                if r > 0 and (solve[r - 1, c] or z[r - 1, c] == z[r - 1, c]):
                    s += z[r - 1, c]
                    n += 1
                if r < rows - 1 and (solve[r + 1, c] or z[r + 1, c] == z[r + 1, c]):
                    s += z[r + 1, c]
                    n += 1
                if c > 0 and (solve[r, c - 1] or z[r, c - 1] == z[r, c - 1]):
                    s += z[r, c - 1]
                    n += 1
                if c < cols - 1 and (solve[r, c + 1] or z[r, c + 1] == z[r, c + 1]):
                    s += z[r, c + 1]
                    n += 1
                if n == 0:
                    continue
                step = omega * (s / n - z[r, c])
                z[r, c] += step
                if abs(step) > big:
                    big = abs(step)
        if big <= tol:
            return sweep + 1
    return max_sweeps
