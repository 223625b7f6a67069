"""Numba kernels of :mod:`latlong.preview`."""

from __future__ import annotations

import numpy as np
from numba import njit

from craters.kernels import read_only_inputs

__all__ = ["_extent_kernel"]


@read_only_inputs("out")
@njit(cache=True)
def _extent_kernel(vertices, centre, view, right, up, out):
    """``out = [max (p - c).view, max |(p - c).right|, max |(p - c).up|]`` over the
    vertices, in one pass (the same products as numpy's ``rel @ v``)."""
    a = -np.inf
    b = 0.0
    c = 0.0
    for i in range(vertices.shape[0]):
        x = vertices[i, 0] - centre[0]
        y = vertices[i, 1] - centre[1]
        z = vertices[i, 2] - centre[2]
        a = max(a, x * view[0] + y * view[1] + z * view[2])
        b = max(b, abs(x * right[0] + y * right[1] + z * right[2]))
        c = max(c, abs(x * up[0] + y * up[1] + z * up[2]))
    out[0] = a
    out[1] = b
    out[2] = c
