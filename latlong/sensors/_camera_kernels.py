"""Numba kernels of :mod:`latlong.sensors.camera`: Brown–Conrady distortion as OpenCV
defines it, and its inverse by Newton's method."""

from __future__ import annotations

import numpy as np
from numba import njit, prange


@njit(cache=True, inline="always")
def _distort(x, y, k1, k2, p1, p2, k3):
    """OpenCV's Brown–Conrady model (``cv::projectPoints``): normalised undistorted
    (x, y) -> distorted (xd, yd) and the Jacobian d(xd, yd)/d(x, y)."""
    r2 = x * x + y * y
    radial = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3))
    dradial = k1 + r2 * (2.0 * k2 + 3.0 * k3 * r2)  # d radial / d r2
    xd = x * radial + 2.0 * p1 * x * y + p2 * (r2 + 2.0 * x * x)
    yd = y * radial + p1 * (r2 + 2.0 * y * y) + 2.0 * p2 * x * y
    j11 = radial + 2.0 * x * x * dradial + 2.0 * p1 * y + 6.0 * p2 * x
    j12 = 2.0 * x * y * dradial + 2.0 * p1 * x + 2.0 * p2 * y
    j21 = 2.0 * x * y * dradial + 2.0 * p1 * x + 2.0 * p2 * y
    j22 = radial + 2.0 * y * y * dradial + 6.0 * p1 * y + 2.0 * p2 * x
    return xd, yd, j11, j12, j21, j22


@njit(cache=True, inline="always")
def _undistort_one(xd, yd, k1, k2, p1, p2, k3, iterations):
    """Newton's inverse of :func:`_distort` at one point: (x, y, converged)."""
    x, y = xd, yd
    for _ in range(iterations):
        fx, fy, a, b, c, d = _distort(x, y, k1, k2, p1, p2, k3)
        ex, ey = fx - xd, fy - yd
        if abs(ex) + abs(ey) <= 1e-14 * (1.0 + abs(xd) + abs(yd)):
            return x, y, True
        det = a * d - b * c
        if det == 0.0 or not np.isfinite(det):
            return x, y, False
        x -= (d * ex - b * ey) / det
        y -= (a * ey - c * ex) / det
    return x, y, False


@njit(cache=True, parallel=True)
def _pixel_rays_kernel(fx, fy, cx, cy, k1, k2, p1, p2, k3, distorted, rotation, out):
    """Unit directions through the pixel centres (integer + 0.5), rotated by ``rotation``
    (camera -> body); NaN where the distortion cannot be inverted."""
    h, w = out.shape[0], out.shape[1]
    for j in prange(h):
        yd = (j + 0.5 - cy) / fy
        for i in range(w):
            xd = (i + 0.5 - cx) / fx
            x, y, ok = xd, yd, True
            if distorted:
                x, y, ok = _undistort_one(xd, yd, k1, k2, p1, p2, k3, 50)
            if not ok:
                out[j, i, 0] = out[j, i, 1] = out[j, i, 2] = np.nan
                continue
            inv = 1.0 / np.sqrt(x * x + y * y + 1.0)
            x, y, z = x * inv, y * inv, inv
            for k in range(3):
                out[j, i, k] = rotation[k, 0] * x + rotation[k, 1] * y + rotation[k, 2] * z


@njit(cache=True, parallel=True)
def _undistort_kernel(xd, yd, k1, k2, p1, p2, k3, iterations, x_out, y_out, ok):
    """Invert :func:`_distort` point by point (Newton from the distorted point; ``ok``
    False where it did not converge to 1e-14, e.g. beyond the model's fold)."""
    for i in prange(xd.shape[0]):
        x_out[i], y_out[i], ok[i] = _undistort_one(xd[i], yd[i], k1, k2, p1, p2, k3,
                                                   iterations)
