"""Numba kernels for boulders on rasters: bilinear ground, footprint gradients,
heightfield maximum."""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from craters.kernels import bilinear, read_only_inputs


@read_only_inputs("out")
@njit(cache=True, parallel=True)
def _bilinear_kernel(z, cols, rows, out):
    """Bilinear heights at fractional pixels (cols[i], rows[i]) into ``out``; NaN outside
    the pixel centres (``craters.kernels.bilinear``, blend form)."""
    for i in prange(cols.shape[0]):
        out[i] = bilinear(z, rows[i], cols[i], True)


@read_only_inputs("out")
@njit(cache=True)
def _bilinear_serial_kernel(z, cols, rows, out):
    """:func:`_bilinear_kernel` without a parallel region (small calls)."""
    for i in range(cols.shape[0]):
        out[i] = bilinear(z, rows[i], cols[i], True)


@njit(cache=True, inline="always")
def _gradient_at(z, known, r, c, axis, p):
    """``numpy.gradient(where(known, z, 0), p)[axis]`` at pixel (r, c): central
    differences inside, one-sided on the border."""
    n = z.shape[axis]
    i = r if axis == 0 else c
    lo = i - 1 if i > 0 else i
    hi = i + 1 if i < n - 1 else i
    if axis == 0:
        a = z[hi, c] if known[hi, c] else 0.0
        b = z[lo, c] if known[lo, c] else 0.0
    else:
        a = z[r, hi] if known[r, hi] else 0.0
        b = z[r, lo] if known[r, lo] else 0.0
    return (a - b) / ((hi - lo) * p)


@read_only_inputs("out")
@njit(cache=True)
def _window_gradient_kernel(z, known, p, r0, r1, c0, c1, out):
    """Mean height gradient (d/dcol, d/drow per metre) over the windows
    ``[r0[k]:r1[k], c0[k]:c1[k]]``, unknown pixels read as 0 -> out (k, 2)."""
    for k in range(r0.shape[0]):
        gc = 0.0
        gr = 0.0
        for r in range(r0[k], r1[k]):
            for c in range(c0[k], c1[k]):
                gc += _gradient_at(z, known, r, c, 1, p)
                gr += _gradient_at(z, known, r, c, 0, p)
        count = (r1[k] - r0[k]) * (c1[k] - c0[k])
        out[k, 0] = gc / count
        out[k, 1] = gr / count


@njit(cache=True)
def _raster_max_kernel(z, verts, faces):
    """Raise ``z`` to the top of every boulder: heightfield maximum, in place.

    ``verts`` (k, V, 3) are boulder vertices as (column, row, height in metres), the
    column and row fractional pixel indices; every triangle of ``faces`` is scanned
    over the pixel centres inside it (seen from above) and each pixel keeps the highest
    of its height and the triangle's height there: the boulder's top. Serial: a maximum
    does not depend on the order, so the result is the same whatever the thread count.
    """
    rows, cols = z.shape
    for b in range(verts.shape[0]):
        for f in range(faces.shape[0]):
            i0, i1, i2 = faces[f, 0], faces[f, 1], faces[f, 2]
            x0 = verts[b, i0, 0]
            y0 = verts[b, i0, 1]
            x1 = verts[b, i1, 0]
            y1 = verts[b, i1, 1]
            x2 = verts[b, i2, 0]
            y2 = verts[b, i2, 1]
            det = (x1 - x0) * (y2 - y0) - (x2 - x0) * (y1 - y0)
            if det == 0.0:
                continue
            c_lo = max(int(np.ceil(min(x0, x1, x2))), 0)
            c_hi = min(int(np.floor(max(x0, x1, x2))), cols - 1)
            r_lo = max(int(np.ceil(min(y0, y1, y2))), 0)
            r_hi = min(int(np.floor(max(y0, y1, y2))), rows - 1)
            z0 = verts[b, i0, 2]
            z1 = verts[b, i1, 2]
            z2 = verts[b, i2, 2]
            for r in range(r_lo, r_hi + 1):
                for c in range(c_lo, c_hi + 1):
                    w1 = ((c - x0) * (y2 - y0) - (x2 - x0) * (r - y0)) / det
                    w2 = ((x1 - x0) * (r - y0) - (c - x0) * (y1 - y0)) / det
                    w0 = 1.0 - w1 - w2
                    if w0 < -1e-12 or w1 < -1e-12 or w2 < -1e-12:
                        continue
                    h = w0 * z0 + w1 * z1 + w2 * z2
                    if h > z[r, c]:
                        z[r, c] = h
