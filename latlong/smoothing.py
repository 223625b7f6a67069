"""Geodesic Gaussian smoothing of per-vertex fields: heat diffusion on a grid pyramid.

A Gaussian of standard deviation ``sigma`` (geodesic, on a sphere of radius R) is the
heat kernel at time ``t = sigma^2 / 2``: it multiplies the spherical harmonic of degree
``l`` by ``exp(-l (l + 1) sigma^2 / (2 R^2))``. Diffusing on the full grid costs
``(sigma / h)^2`` explicit steps, far too many for wide filters, so the field goes down
a pyramid of coarser nested grids (each about half the magnitude, anti-alias filtered
by a short diffusion before sampling) until the grid spacing is about a third of sigma,
is diffused there for the remaining variance, and comes back up by interpolation with a
short diffusion at each level to remove the interpolation creases. The variances of all
the diffusions add up to ``sigma^2``; the area-weighted mean is kept exactly.
"""

from __future__ import annotations

import functools
import math

import numpy as np

from craters._shared import ParameterError, check_int, check_positive, check_range
from craters.exact import dot

from .grid import LatLongGrid

__all__ = ["MAX_SIGMA_RAD", "check_smooth_width", "fwhm_to_sigma", "heat_smooth", "smooth"]

_FWHM_PER_SIGMA = 2.0 * math.sqrt(2.0 * math.log(2.0))
# pyramid settings (relative to grid spacings h): stop coarsening once the next level's
# spacing would exceed sigma / _COARSEST; anti-alias and de-crease diffusions
_COARSEST = 3.0
_PRE = 0.7
_POST = 0.5
#: Widest smoothing, geodesic sigma in radians: at pi (half the circumference) the
#: degree-1 harmonic is already down to exp(-pi^2) = 5e-5 and a wider Gaussian only
#: costs time (~ sigma^2 diffusion steps on the coarsest grid: hours at sigma = 1e6).
MAX_SIGMA_RAD = math.pi


def fwhm_to_sigma(width: float) -> float:
    """Standard deviation of a Gaussian whose full width at half maximum is ``width``."""
    return float(width) / _FWHM_PER_SIGMA


@functools.lru_cache(maxsize=8)
def _operator(magnitude: int):
    """Cotangent Laplacian (CSR, unit sphere), lumped masses and a stable time step."""
    import scipy.sparse as sp  # here: importing scipy loads argparse

    grid = LatLongGrid(magnitude)
    p = grid.unit_vectors()
    t = grid.triangles()
    a, b, c = p[t[:, 0]], p[t[:, 1]], p[t[:, 2]]
    cross = np.cross(b - a, c - a)
    dbl_area = np.linalg.norm(cross, axis=1)
    rows, cols, vals = [], [], []
    # cotangent of the angle at each corner, weighting the opposite edge
    for (_, j, k), (pi, pj, pk) in (((0, 1, 2), (a, b, c)), ((1, 2, 0), (b, c, a)),
                                     ((2, 0, 1), (c, a, b))):
        cot = np.einsum("ij,ij->i", pj - pi, pk - pi) / dbl_area
        w = 0.5 * cot
        rows += [t[:, j], t[:, k]]
        cols += [t[:, k], t[:, j]]
        vals += [w, w]
    n = grid.n_vertices
    off = sp.coo_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                        shape=(n, n)).tocsr()
    off.sum_duplicates()
    diag = -np.asarray(off.sum(axis=1)).ravel()
    lap = (off + sp.diags(diag)).tocsr()
    mass = np.bincount(t.ravel(), weights=np.repeat(dbl_area / 6.0, 3), minlength=n)
    # Gershgorin bound on the largest eigenvalue of M^-1 L; dt = 1 / bound keeps every
    # mode's amplification factor in [0, 1] (monotone damping, no ringing)
    bound = np.max(2.0 * np.abs(diag) / mass)
    return lap, mass, 1.0 / bound


def _diffuse(magnitude: int, f: np.ndarray, variance: float) -> np.ndarray:
    """Explicit heat diffusion on the unit-sphere grid for ``t = variance / 2``."""
    if variance <= 0:
        return f
    lap, mass, dt = _operator(magnitude)
    t = 0.5 * variance
    steps = max(1, math.ceil(t / dt))
    tau = t / steps
    inv_m = tau / mass
    f = f.copy()
    for _ in range(steps):
        f += inv_m * (lap @ f)
    return f


def _sample(src_m: int, f: np.ndarray, dst: LatLongGrid) -> np.ndarray:
    colat = (np.pi / 2) - dst.latitudes()
    return LatLongGrid(src_m).interpolate(f, colat, dst.longitudes())


def heat_smooth(grid: LatLongGrid, values, sigma_rad: float) -> np.ndarray:
    """Gaussian smoothing with geodesic standard deviation ``sigma_rad`` (unit sphere).

    Returns a new array; the area-weighted mean of ``values`` is preserved exactly.
    """
    if not isinstance(grid, LatLongGrid):
        raise TypeError(f"`grid` must be a LatLongGrid; got {type(grid).__name__}")
    f0 = np.ascontiguousarray(values, dtype=np.float64)
    if f0.shape != (grid.n_vertices,):
        raise ValueError(f"`values` must have shape ({grid.n_vertices},); got {f0.shape}")
    if not np.isfinite(f0).all():
        raise ValueError("`values` must be finite")
    sigma = check_range("sigma_rad", sigma_rad, 0.0, MAX_SIGMA_RAD)
    if sigma == 0:
        return f0.copy()
    var = sigma * sigma
    # the pyramid: magnitudes M_0 = M > M_1 > ... while the next spacing stays fine enough
    mags = [grid.magnitude]
    while mags[-1] > 2:
        nxt = math.ceil(mags[-1] / 2)
        if math.pi / (2 * nxt) > sigma / _COARSEST:
            break
        mags.append(nxt)
    spacing = [math.pi / (2 * m) for m in mags]
    pre = [(_PRE * spacing[k + 1]) ** 2 for k in range(len(mags) - 1)]
    post = [(_POST * spacing[k + 1]) ** 2 for k in range(len(mags) - 1)]
    rest = var - sum(pre) - sum(post)
    if rest < 0:  # cannot happen with the settings above; keep the total honest anyway
        raise AssertionError("smoothing pyramid exceeds the requested variance")
    f = f0
    for k in range(len(mags) - 1):
        f = _diffuse(mags[k], f, pre[k])
        f = _sample(mags[k], f, LatLongGrid(mags[k + 1]))
    f = _diffuse(mags[-1], f, rest)
    for k in range(len(mags) - 2, -1, -1):
        f = _sample(mags[k + 1], f, LatLongGrid(mags[k]))
        f = _diffuse(mags[k], f, post[k])
    w = grid.vertex_areas()
    f += (dot(w, f0) - dot(w, f)) / float(w.sum())
    return f


def check_smooth_width(width_m, radius_m: float, passes: int = 1,
                       name: str = "width_m") -> float:
    """``width_m`` (FWHM, metres; parameter ``name``) as a float: finite, >= 0, and with
    ``passes`` passes no wider than :data:`MAX_SIGMA_RAD` on a body of ``radius_m``.

    Examples
    --------
    >>> check_smooth_width(1e9, 50.0)
    Traceback (most recent call last):
    ...
    craters._shared.validation.ParameterError: `width_m` must be in [0, 369.9] m (a \
Gaussian of sigma pi radians on a body of radius 50 m, 1 pass); got 1000000000.0
    """
    width_m = check_positive(name, width_m, allow_zero=True)
    radius_m = check_positive("radius_m", radius_m)
    top = MAX_SIGMA_RAD * _FWHM_PER_SIGMA * radius_m / math.sqrt(max(passes, 1))
    if width_m > top:
        raise ParameterError(name, f"must be in [0, {top:.4g}] m (a Gaussian of sigma pi "
                             f"radians on a body of radius {radius_m:g} m, {passes} "
                             f"pass{'es' if passes != 1 else ''}); got {width_m!r}")
    return width_m


def smooth(grid: LatLongGrid, values, width_m: float, *, radius_m: float,
           passes: int = 1) -> np.ndarray:
    """Geodesic Gaussian smoothing of a per-vertex field on a body of radius ``radius_m``.

    Parameters
    ----------
    grid : LatLongGrid
    values : (N,) array_like
        The field (e.g. heights in metres).
    width_m : float
        Filter width: the full width at half maximum of the Gaussian, metres measured
        along the surface of the sphere of ``radius_m``.
    radius_m : float
        Reference radius of the body, metres.
    passes : int
        Number of passes; ``p`` passes of FWHM ``w`` equal one pass of FWHM ``w sqrt(p)``.

    Returns
    -------
    (N,) float64 smoothed copy; the area-weighted mean is unchanged. Cost is O(N) for
    any width (heat diffusion on a pyramid of coarser grids, see the module notes).

    Examples
    --------
    >>> g = LatLongGrid(16)
    >>> z = g.unit_vectors()[:, 2]            # the degree-1 harmonic
    >>> s = smooth(g, z, 10.0, radius_m=10.0)
    >>> bool(abs(s[0] / z[0] - np.exp(-2 * fwhm_to_sigma(1.0) ** 2 / 2)) < 0.02)
    True
    """
    passes = check_int("passes", passes, 0, 10_000)
    width_m = check_smooth_width(width_m, radius_m, passes)
    sigma = fwhm_to_sigma(width_m) * math.sqrt(passes) / radius_m
    return heat_smooth(grid, values, sigma)
