"""Metaballs fitted to a sphere packing (steps 2-3 of
:func:`latlong.implicit.implicit_surface`).

The soft-object kernel of Wyvill, McPheeters & Wyvill 1986, ``(1 - d^2/R^2)^3`` (compact
support R = blend x ball radius, so every ball's own iso-surface sits at the same fraction
of its radius) summed over the balls; the blend factor and the iso-value T are *fitted to
the constraint*: on 20 000 points uniform on the constraint surface, T is the median of f
weighted by 1/|grad f|, which minimises the mean first-order distance |f - T| / |grad f|
of those points to the iso-surface, and the blend factor with the smallest such mean is
kept. On a voxel grid,
:func:`metaball_distance` turns the field into a signed distance to that surface.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from craters._shared import ParameterError, check_int, check_range, normalize_rng

from ..shapes import ShapeModel, sample_surface
from . import _kernels as _k
from .grid import VoxelGrid
from .packing import SpherePacking

__all__ = ["Metaballs", "fit_metaballs", "metaball_distance"]

_BLENDS = (1.25, 1.5, 1.75, 2.0, 2.5, 3.0)
_FIT_SAMPLES = 20000


@dataclasses.dataclass(frozen=True)
class Metaballs:
    """A Wyvill metaball field ``f = sum (1 - |p - c|^2 / R^2)^3`` and its iso-value."""

    centers: np.ndarray
    """(n, 3) centres, metres."""
    support: np.ndarray
    """(n,) support radii R = blend x ball radius, metres."""
    iso: float
    """The surface is f = iso (inside: f > iso)."""
    blend: float
    """Support radius / ball radius."""
    fit_mean_m: float
    """Mean first-order distance of the constraint's surface samples to the iso-surface."""

    def field(self, points) -> tuple[np.ndarray, np.ndarray]:
        """f and grad f (1/m) at points (n, 3)."""
        pts = np.ascontiguousarray(np.asarray(points, dtype=np.float64).reshape(-1, 3))
        out = np.empty((len(pts), 4))
        _k._metaball_points_kernel(pts, self.centers, self.support, out)
        return out[:, 0], out[:, 1:]

    def distance(self, points) -> np.ndarray:
        """First-order signed distance to the iso-surface, metres (> 0 inside)."""
        f, g = self.field(points)
        return (f - self.iso) / np.maximum(np.linalg.norm(g, axis=1), self._g_floor)

    def normals(self, points) -> np.ndarray:
        """Outward unit normals -grad f / |grad f| at points (n, 3)."""
        _, g = self.field(points)
        n = -g / np.maximum(np.linalg.norm(g, axis=1, keepdims=True), 1e-300)
        return n

    @property
    def _g_floor(self) -> float:
        # far outside f = 0 and grad f = 0: the distance becomes -(extent of the field)
        lo = (self.centers - self.support[:, None]).min(axis=0)
        hi = (self.centers + self.support[:, None]).max(axis=0)
        return self.iso / float(np.linalg.norm(hi - lo))


def _weighted_median(values: np.ndarray, weights: np.ndarray) -> float:
    order = np.argsort(values, kind="stable")
    cw = np.cumsum(weights[order])
    return float(values[order][np.searchsorted(cw, 0.5 * cw[-1])])


def fit_metaballs(packing: SpherePacking, model: ShapeModel, *, blends=_BLENDS,
                  n_samples: int = _FIT_SAMPLES, rng=0) -> Metaballs:
    """Metaballs over ``packing`` with blend factor and iso-value fitted to ``model``.

    For each blend factor (support radius / ball radius) the iso-value is the weighted
    median of f at ``n_samples`` points uniform on the constraint surface (weights
    1/|grad f|); the blend with the smallest mean first-order distance wins.
    """
    if not isinstance(packing, SpherePacking):
        raise TypeError(f"`packing` must be a SpherePacking; got {type(packing).__name__}")
    n_samples = check_int("n_samples", n_samples, 100, 10**7)
    blends = [check_range("blends", b, 1.01, 10.0) for b in blends]
    pts = np.ascontiguousarray(sample_surface(model, n_samples, rng=normalize_rng(rng)))
    best = None
    out = np.empty((len(pts), 4))
    for blend in blends:
        support = packing.radii * blend
        _k._metaball_points_kernel(pts, packing.centers, support, out)
        g = np.linalg.norm(out[:, 1:], axis=1)
        ok = g > 0
        if ok.mean() < 0.99:  # samples outside every support: this blend cannot fit
            continue
        w = 1.0 / g[ok]
        iso = _weighted_median(out[ok, 0], w)
        if not iso > 0:
            continue
        mean = float(np.mean(np.abs(out[ok, 0] - iso) * w))
        if best is None or mean < best[0]:
            best = (mean, blend, iso)
    if best is None:
        raise ValueError("no blend factor reaches the constraint surface from the packing; "
                         "pack with a smaller `min_radius_m`")
    mean, blend, iso = best
    return Metaballs(packing.centers, packing.radii * blend, iso, blend, mean)


def metaball_distance(meta: Metaballs, grid: VoxelGrid) -> np.ndarray:
    """Signed Euclidean distance to the metaball surface on the grid (> 0 inside), m.

    The first-order estimate (f - T) / |grad f| is accurate next to the surface but not
    deeper (in the gaps between packed balls f barely exceeds T: a crater bowl would
    carve too deep there). So it is used only at the *seeds*, the grid points with a
    neighbour across the surface, to find their foot points on the surface
    (p - d grad d / |grad d|); every grid point then takes the distance to the tangent
    plane at the closest foot point among the seeds around its nearest seed
    (``scipy.ndimage.distance_transform_edt`` indices): a closest-point transform.
    """
    from scipy.ndimage import distance_transform_edt

    g_floor = meta._g_floor
    first = np.full(grid.shape, -meta.iso / g_floor)
    lo, hi = grid.index_boxes(meta.centers, meta.support)
    nbins, offsets, items, active = grid.bins(lo, hi)
    _k._metaball_grid_kernel(grid.origin, grid.h, active, grid.bin_size, nbins, offsets, items,
                             meta.centers, meta.support, meta.iso, g_floor, first)
    inside = first > 0
    seed = np.zeros(grid.shape, dtype=bool)
    for axis in range(3):
        a = [slice(None)] * 3
        b = [slice(None)] * 3
        a[axis], b[axis] = slice(None, -1), slice(1, None)
        cross = inside[tuple(a)] != inside[tuple(b)]
        seed[tuple(a)] |= cross
        seed[tuple(b)] |= cross
    if not seed.any():
        raise ParameterError("voxel_m", f"= {grid.h:.4g} m: no grid point falls inside the body "
                         "(the voxel is coarser than the body); use a smaller voxel or more "
                         "polygons")
    idx = np.argwhere(seed)  # (k, j, i), C order
    pts = grid.origin + idx[:, ::-1] * grid.h
    grad = grid.gradient(first, pts)
    unit = grad / np.maximum(np.linalg.norm(grad, axis=1, keepdims=True), 1e-300)
    # a seed is less than one voxel from the crossing next to it: the first-order
    # estimate can overshoot where the field is flat
    reach = np.clip(first[seed], -grid.h, grid.h)
    foot = np.ascontiguousarray(pts - reach[:, None] * unit)
    seed_id = np.full(grid.shape, -1, dtype=np.int64)
    seed_id[seed] = np.arange(len(idx))
    nearest = distance_transform_edt(~seed, return_distances=False, return_indices=True)
    dist = np.empty(grid.shape)
    _k._closest_distance_kernel(grid.origin, grid.h, nearest, seed_id, foot,
                                np.ascontiguousarray(unit), first, np.inf, 2, dist)
    return dist
