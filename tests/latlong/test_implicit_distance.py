"""The implicit backend's coarse field from the constraint itself (latlong.implicit.distance)
and how closely the coarse surface follows the constraint (latlong.implicit.fidelity)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import pyvista as pv

from craters._shared import ParameterError
from latlong.implicit import (
    VoxelGrid,
    implicit_surface,
    mesh_distance,
    shape_fidelity,
    smoothed_constraint,
)
from latlong.implicit import _distance_kernels as DK
from latlong.implicit.distance import _face_boxes, _normals
from latlong.shapes import ShapeModel, read_shape_model

DATA = Path(__file__).parents[1] / "data"


def lumpy_model(res=12, seed=0) -> ShapeModel:
    """A closed, outward oriented, non-convex blob (a sphere with random radii)."""
    s = pv.Sphere(radius=1.0, theta_resolution=res, phi_resolution=res).clean()
    rng = np.random.default_rng(seed)
    p = np.asarray(s.points, float)
    p *= (5.0 + rng.uniform(-1.0, 1.0, len(p)))[:, None]
    return ShapeModel(p, s.faces.reshape(-1, 4)[:, 1:].astype(np.int64))


def segment_distance(p, a, b):
    ab = b - a
    t = np.clip(((p - a) @ ab) / (ab @ ab), 0.0, 1.0)
    return np.linalg.norm(p - (a + t[:, None] * ab), axis=1)


def triangle_distance_reference(p, a, b, c):
    """Distance of points p (n, 3) to triangle abc: the projection on its plane when it
    falls inside (barycentric), else the nearest of the three edges (not Ericson's
    Voronoi regions)."""
    n = np.cross(b - a, c - a)
    n /= np.linalg.norm(n)
    q = p - ((p - a) @ n)[:, None] * n
    v0, v1, v2 = b - a, c - a, q - a
    d00, d01, d11 = v0 @ v0, v0 @ v1, v1 @ v1
    d20, d21 = v2 @ v0, v2 @ v1
    den = d00 * d11 - d01 * d01
    v = (d11 * d20 - d01 * d21) / den
    w = (d00 * d21 - d01 * d20) / den
    inside = (v >= 0) & (w >= 0) & (v + w <= 1)
    edge = np.minimum.reduce([segment_distance(p, a, b), segment_distance(p, b, c),
                              segment_distance(p, c, a)])
    return np.where(inside, np.abs((p - a) @ n), edge)


def winding_number(p, verts, faces):
    """Generalised winding number (Van Oosterom & Strackee 1983 solid angles): ~1 inside."""
    total = np.zeros(len(p))
    for f in faces:
        a, b, c = (verts[f[k]] - p for k in range(3))
        la, lb, lc = (np.linalg.norm(x, axis=1) for x in (a, b, c))
        num = np.einsum("ij,ij->i", a, np.cross(b, c))
        den = (la * lb * lc + np.einsum("ij,ij->i", a, b) * lc
               + np.einsum("ij,ij->i", b, c) * la + np.einsum("ij,ij->i", c, a) * lb)
        total += 2.0 * np.arctan2(num, den)
    return total / (4.0 * np.pi)


def test_band_kernel_matches_reference():
    model = lumpy_model()
    verts, faces = model.vertices, model.faces
    grid = VoxelGrid(np.array([-6.3, -6.2, -6.1]), 0.45, (28, 29, 30))
    face_n, edge_n, vert_n = _normals(verts, faces)
    band = 1.5 * grid.h
    lo, hi = _face_boxes(verts, faces, grid, band)
    nbins, offsets, items, active = grid.bins(lo, hi)
    dist = np.full(grid.shape, np.nan)
    face_id = np.full(grid.shape, -1, np.int32)  # as mesh_distance: one compiled kernel
    DK._band_distance_kernel(grid.origin, grid.h, active, grid.bin_size, nbins, offsets, items,
                             lo, hi, verts, faces, face_n, edge_n, vert_n, band, dist, face_id)
    k, j, i = np.meshgrid(*(np.arange(m) for m in grid.shape), indexing="ij")
    pts = grid.origin + np.stack([i, j, k], -1).reshape(-1, 3) * grid.h
    per_face = np.stack([triangle_distance_reference(pts, *verts[f]) for f in faces], axis=1)
    want = per_face.min(axis=1)
    inside = winding_number(pts, verts, faces) > 0.5
    got, fid = dist.ravel(), face_id.ravel()
    in_band = want < band
    assert (fid >= 0).sum() > 1000 and np.array_equal(fid >= 0, in_band)
    np.testing.assert_allclose(np.abs(got[in_band]), want[in_band], rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(per_face[in_band, fid[in_band]], want[in_band], atol=1e-12)
    off = np.abs(got[in_band]) > 1e-9  # the sign from pseudo-normals = the winding number's
    assert np.array_equal(got[in_band][off] > 0, inside[in_band][off])
    foot, normal = np.empty((in_band.sum(), 3)), np.empty((in_band.sum(), 3))
    DK._feet_kernel(np.ascontiguousarray(pts[in_band]), fid[in_band], verts, faces, face_n,
                    foot, normal)
    np.testing.assert_allclose(np.linalg.norm(pts[in_band] - foot, axis=1), want[in_band],
                               rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(np.linalg.norm(normal, axis=1), 1.0)


def test_nearest_sign_kernel_matches_the_gather():
    rng = np.random.default_rng(3)
    values = rng.normal(size=(7, 8, 9))
    values[0, 0, :3] = 0.0  # 0 is not > 0
    nearest = np.stack([rng.integers(0, m, (7, 8, 9)) for m in values.shape]).astype(np.int32)
    out = np.empty(values.shape, np.int8)
    DK._nearest_sign_kernel(nearest, values, out)
    want = np.where(values[nearest[0], nearest[1], nearest[2]] > 0, 1, -1)
    assert np.array_equal(out, want)


def test_mesh_distance_is_the_distance_to_a_sphere():
    s = pv.Sphere(radius=10.0, theta_resolution=96, phi_resolution=96)
    model = ShapeModel(np.asarray(s.points, float), s.faces.reshape(-1, 4)[:, 1:].astype(int))
    grid = VoxelGrid(np.full(3, -14.0), 0.5, (57, 57, 57))
    k, j, i = np.meshgrid(*(np.arange(m) for m in grid.shape), indexing="ij")
    r = np.linalg.norm(grid.origin + np.stack([i, j, k], -1) * grid.h, axis=-1)
    want = 10.0 - r  # > 0 inside
    d = mesh_distance(model, grid)
    sag = 10.0 * (1 - np.cos(np.pi / 96))  # the facets lie up to this far inside the sphere
    band = np.abs(want) < 1.5 * grid.h  # exact there; the closest-point transform beyond
    assert np.abs(d - want)[band].max() < sag + 0.02 * grid.h
    assert np.abs(d - want).max() < 0.1 * grid.h
    far = mesh_distance(model, grid, exact_m=2.0)  # beyond: an upper bound, same sign
    near = np.abs(want) < 2.0
    np.testing.assert_array_equal(far[near], d[near])
    assert (np.sign(far) == np.sign(d)).all() and (np.abs(far) >= np.abs(d) - 1e-9).all()
    with pytest.raises(ParameterError, match="voxel_m"):
        mesh_distance(model, VoxelGrid(np.full(3, 40.0), 0.5, (4, 4, 4)))


def test_grid_normals_of_a_distance_field():
    grid = VoxelGrid(np.full(3, -12.0), 0.5, (49, 49, 49))
    k, j, i = np.meshgrid(*(np.arange(m) for m in grid.shape), indexing="ij")
    values = 10.0 - np.linalg.norm(grid.origin + np.stack([i, j, k], -1) * grid.h, axis=-1)
    rng = np.random.default_rng(3)
    p = rng.normal(size=(500, 3))
    p *= (10.0 / np.linalg.norm(p, axis=1))[:, None]
    n = grid.normals(values, p)
    np.testing.assert_allclose(n, p / 10.0, atol=2e-3)  # outward, between grid points


def test_smoothed_constraint_keeps_the_vertices():
    model = lumpy_model()
    smooth, levels = smoothed_constraint(model, model.mean_edge_m / 5.0)
    assert levels == 2 and len(smooth.faces) == 16 * len(model.faces)
    np.testing.assert_allclose(smooth.vertices[:len(model.vertices)], model.vertices,
                               atol=1e-9)  # interpolating: every model vertex stays
    assert smoothed_constraint(model, 1.0, smooth="none") == (model, 0)


@pytest.mark.parametrize("name", ["bennu_radar_sbgat.obj", "itokawa_32.obj"])
def test_coarse_surface_follows_the_constraint(name):
    """Issue 16 acceptance at a small size: mean distance <= 0.3 %, 99th percentile <= 1 %
    of the long axis, slope-against-a-5 %-smoothed-copy KS distance <= 0.1; the bare
    metaballs (constraint_weight=0, the field before issue 16) fail it. At 20 000
    triangles the voxel is ~2 % of the axis, so the local normal is averaged over 2 %
    (1 % at the 200 000 of the acceptance figures). Not Itokawa's 768-plate model: its
    facets (7 % of the axis) are coarser than the 5 % smoothing scale, and the smooth
    surface through its vertices leaves them by up to 1.1 % of the axis."""
    model = read_shape_model(DATA / name, units="km")
    moved = ShapeModel(model.vertices - model.volume_centroid, model.faces)
    got = {}
    for weight in (1.0, 0.0):
        surf = implicit_surface(model, target_polygons=20_000, constraint_weight=weight, rng=1)
        assert surf.metadata["constraint"]["weight"] == weight
        got[weight] = shape_fidelity((surf.base_vertices, surf.base_faces), moved,
                                     n_points=4000, fine=0.02, rng=0)
    new, old = got[1.0], got[0.0]
    assert new.mean_fraction <= 0.003 and new.p99_fraction <= 0.01 and new.slope_ks <= 0.1
    assert old.slope_ks > 0.3 and old.mean_fraction > 0.003  # one dome per packed ball


def test_constraint_weight_blends_the_two_fields():
    model = read_shape_model(DATA / "itokawa_8.obj", units="km")
    moved = ShapeModel(model.vertices - model.volume_centroid, model.faces)
    means = [shape_fidelity((s.base_vertices, s.base_faces), moved, n_points=2000).mean_m
             for s in (implicit_surface(model, target_polygons=5000, constraint_weight=w, rng=1)
                       for w in (0.0, 0.5, 1.0))]
    assert means[0] > means[1] > means[2]
    with pytest.raises(ParameterError, match="constraint_weight"):
        implicit_surface(model, target_polygons=5000, constraint_weight=1.5)
