"""The constraint's own field (step 3 of :func:`latlong.implicit.implicit_surface`): the
signed distance to the constraint mesh, after an interpolating subdivision that makes
its flat facets a smooth surface.

:func:`smoothed_constraint` subdivides the constraint (VTK's modified butterfly scheme,
Zorin, Schroeder & Sweldens 1996: it keeps every vertex of the model and gives a
smooth limit surface through them) until its edges are at most 1.5 voxels long, so
that marching cubes does not show the model's facets. :func:`mesh_distance` computes
the exact signed Euclidean distance to a closed mesh in a band of 1.5 voxels around it
(closest point on each triangle, sign from angle-weighted pseudo-normals; numba,
binned like every grid kernel here), then everywhere else by the closest-point
transform that :func:`~latlong.implicit.metaballs.metaball_distance` also uses: each
grid point takes the distance to the tangent plane at the closest foot point among
the band points in the 3 x 3 x 3 block around its nearest band point (the band is
three grid points thick: denser than the metaballs' seeds, which need 5 x 5 x 5),
and that band point's sign.
"""

from __future__ import annotations

import math

import numpy as np

from craters._shared import ParameterError, check_choice, check_int, check_positive

from ..geometry.normals import face_normals, vertex_normal_sums
from ..shapes import ShapeModel
from . import _distance_kernels as _dk
from . import _kernels as _k
from .grid import VoxelGrid

__all__ = ["SMOOTHING", "mesh_distance", "smoothed_constraint"]

SMOOTHING = ("butterfly", "loop", "linear", "none")
"""Subdivision schemes of :func:`smoothed_constraint`: ``butterfly`` interpolates the
vertices; ``loop`` approximates them (smoother, it flattens the model's relief at its
facet scale: on Bennu's radar model the slope KS distance of
:func:`~latlong.implicit.fidelity.shape_fidelity` is 0.41 against butterfly's 0.02);
``linear`` keeps the facets."""
_MAX_LEVELS = 4
_EDGE_VOXELS = 1.5  # the subdivided constraint's mean edge, voxels (at most)
_BAND_VOXELS = 1.5  # exact distances within this many voxels of the mesh


def smoothed_constraint(model: ShapeModel, voxel_m: float, *, smooth: str = "butterfly",
                        subdivisions: int | None = None) -> tuple[ShapeModel, int]:
    """The constraint subdivided for a grid of ``voxel_m``, and the number of levels.

    ``subdivisions=None`` takes the fewest levels (each halves the edges) that bring
    the mean edge to at most 1.5 ``voxel_m`` (at most 4; finer facets do not show
    through marching cubes at that voxel: on Eros's 7790-plate model 2 and 3 levels
    give the same distance and slope distribution, 3 takes 0.6 s longer);
    ``smooth="none"`` (or 0 levels) returns the model unchanged.
    """
    check_choice("smooth", smooth, SMOOTHING)
    if subdivisions is None:
        ratio = model.mean_edge_m / (_EDGE_VOXELS * voxel_m)
        subdivisions = min(_MAX_LEVELS, max(0, math.ceil(math.log2(ratio)))) if ratio > 1 else 0
    subdivisions = check_int("subdivisions", subdivisions, 0, _MAX_LEVELS)
    if smooth == "none" or subdivisions == 0:
        return model, 0
    mesh = model.to_pyvista().subdivide(subdivisions, subfilter=smooth)
    faces = np.asarray(mesh.faces).reshape(-1, 4)[:, 1:].astype(np.int64)
    return ShapeModel(np.asarray(mesh.points, dtype=np.float64), faces, model.source), \
        subdivisions


def _normals(verts: np.ndarray, faces: np.ndarray):
    """Unit face normals, per-face edge pseudo-normals (ab, bc, ca) and angle-weighted
    vertex pseudo-normals (Baerentzen & Aanaes 2005; :mod:`latlong.geometry.normals`,
    weighting ``"angle"``, not normalised: only their sign is used)."""
    face_n = face_normals(verts, faces, unit=True)
    vert_n = vertex_normal_sums(verts, faces, "angle", order="corner-sums")
    edges = np.stack([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]], axis=1)
    key = np.sort(edges.reshape(-1, 2), axis=1)
    _, inverse = np.unique(key[:, 0] * len(verts) + key[:, 1], return_inverse=True)
    inverse = inverse.reshape(-1)
    summed = np.zeros((inverse.max() + 1, 3))
    for axis in range(3):
        summed[:, axis] = np.bincount(inverse, weights=np.repeat(face_n[:, axis], 3),
                                      minlength=len(summed))
    edge_n = np.ascontiguousarray(summed[inverse].reshape(-1, 3, 3))
    return np.ascontiguousarray(face_n), edge_n, vert_n


def _face_boxes(verts, faces, grid: VoxelGrid, reach: float):
    """Inclusive (i, j, k) index boxes of the faces grown by ``reach``, clipped."""
    corners = np.stack([verts[faces[:, k]] for k in range(3)])
    top = np.array(grid.shape[::-1]) - 1
    lo_f = (corners.min(axis=0) - reach - grid.origin) / grid.h
    hi_f = (corners.max(axis=0) + reach - grid.origin) / grid.h
    lo = np.clip(np.ceil(lo_f), 0, top).astype(np.int64)
    hi = np.clip(np.floor(hi_f), -1, top).astype(np.int64)
    hi[(hi_f < 0).any(axis=1) | (lo_f > top).any(axis=1)] = -1
    return np.ascontiguousarray(lo), np.ascontiguousarray(hi)


def mesh_distance(model: ShapeModel, grid: VoxelGrid, *,
                  exact_m: float | None = None) -> np.ndarray:
    """Signed Euclidean distance to a closed, outward oriented mesh on the grid (> 0
    inside), metres: exact within 1.5 voxels of it, a closest-point transform beyond
    (module notes). ``exact_m``: beyond about this distance (default everywhere) only
    an upper bound, the distance to the nearest band point's foot on the mesh."""
    from scipy.ndimage import distance_transform_edt

    if not isinstance(model, ShapeModel):
        raise TypeError(f"`model` must be a ShapeModel; got {type(model).__name__}")
    verts = np.ascontiguousarray(model.vertices, dtype=np.float64)
    faces = np.ascontiguousarray(model.faces, dtype=np.int64)
    face_n, edge_n, vert_n = _normals(verts, faces)
    band = _BAND_VOXELS * grid.h
    lo, hi = _face_boxes(verts, faces, grid, band)
    nbins, offsets, items, active = grid.bins(lo, hi)
    exact = np.full(grid.shape, np.nan)
    face_id = np.full(grid.shape, -1, dtype=np.int32)  # int32: half the memory to touch
    _dk._band_distance_kernel(grid.origin, grid.h, active, grid.bin_size, nbins, offsets,
                              items, lo, hi, verts, faces, face_n, edge_n, vert_n, band,
                              exact, face_id)
    seed = face_id >= 0
    if not seed.any():
        raise ParameterError("voxel_m", f"= {grid.h:.4g} m: no grid point lies within "
                             f"{_BAND_VOXELS} voxels of the constraint")
    idx = np.argwhere(seed)  # (k, j, i), C order
    pts = np.ascontiguousarray(grid.origin + idx[:, ::-1] * grid.h)
    foot = np.empty_like(pts)
    normal = np.empty_like(pts)
    _dk._feet_kernel(pts, face_id[seed], verts, faces, face_n, foot, normal)
    del face_id
    seed_id = np.full(grid.shape, -1, dtype=np.int32)
    seed_id[seed] = np.arange(len(idx), dtype=np.int32)
    nearest = distance_transform_edt(~seed, return_distances=False, return_indices=True)
    sign = np.empty(grid.shape, dtype=np.int8)  # the nearest band point's sign
    _dk._nearest_sign_kernel(nearest, exact, sign)
    far2 = np.inf if exact_m is None else (check_positive("exact_m", exact_m) / grid.h) ** 2
    at_seed = exact[seed]
    dist = exact  # every point is overwritten: reuse the memory
    _k._closest_distance_kernel(grid.origin, grid.h, nearest, seed_id, foot, normal, sign,
                                far2, 1, dist)
    dist[seed] = at_seed
    return dist
