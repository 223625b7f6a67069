"""The one normals module: named weightings and summation orders, each caller's bits.

The references below are the routines the module replaced (the mesh surface's, the mesh
slopes', the boulders', gravity's, the implicit distance's, the body slopes' and the
sensors'), kept in pure numpy: every caller must get the very same bits from
:mod:`latlong.geometry.normals` as it did from its own copy.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from latlong import Body, LatLongGrid, read_shape_model
from latlong._grid_kernels import lon_table
from latlong.geometry._normal_kernels import (
    _area_normals_kernel,
    _max_normals_kernel,
    _normalize_rows_kernel,
    _normals_from_radii_kernel,
)
from latlong.geometry.normals import (
    face_normals,
    lat_long_vertex_normals,
    tangent_frames,
    triangle_normals,
    vertex_areas,
    vertex_normal_sums,
    vertex_normals,
    vertex_normals_and_areas,
)

DATA = Path(__file__).parents[1] / "data"


@pytest.fixture(scope="module")
def lumpy():
    """A closed mesh with uneven facets: a stretched, noisy lat/long body."""
    g = LatLongGrid(9)
    rng = np.random.default_rng(5)
    body = Body(g, 10.0 + rng.uniform(0, 2.0, g.n_vertices), stretch=(1.4, 1.0, 0.7))
    return body.vertices(), g.triangles()


@pytest.fixture(scope="module")
def itokawa():
    m = read_shape_model(DATA / "itokawa_8.obj", units="km")
    return m.vertices, m.faces


@pytest.fixture(params=["lumpy", "itokawa"])
def mesh(request):
    return request.getfixturevalue(request.param)


# --------------------------------------------------------------------------- the old copies
def old_mesh_surface_normals(vertices, faces):
    """latlong.mesh.topology.vertex_normals: full cross products, np.bincount per corner."""
    a, b, c = (vertices[faces[:, k]] for k in range(3))
    fn = np.cross(b - a, c - a)
    acc = np.zeros_like(vertices)
    for k in range(3):
        for d in range(3):
            acc[:, d] += np.bincount(faces[:, k], weights=fn[:, d], minlength=len(vertices))
    norm = np.linalg.norm(acc, axis=1, keepdims=True)
    return acc / np.where(norm > 0, norm, 1.0)


def old_gravity_normals(v, f):
    """latlong.gravity._mesh_field (and boulder_normals, mesh_slopes): np.add.at per
    corner column of the cross products."""
    normals = np.zeros_like(v)
    tri = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])
    for k in range(3):
        np.add.at(normals, f[:, k], tri)
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    return normals


def old_mesh_slopes_normals_and_areas(v, f):
    """latlong.slopes.mesh_slopes: half cross products, running sums per column; areas
    summed per column first."""
    tri_n = 0.5 * np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])
    third = np.linalg.norm(tri_n, axis=1) / 3.0
    normals = np.zeros_like(v)
    area = np.zeros(len(v))
    for k in range(3):
        np.add.at(normals, f[:, k], tri_n)
        area += np.bincount(f[:, k], weights=third, minlength=len(v))
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    return normals, area


def old_boulder_normals(vertices, faces):
    """craters.boulders.boulder_normals: a batch of meshes sharing faces."""
    v = np.asarray(vertices, dtype=np.float64)
    a, b, c = v[:, faces[:, 0]], v[:, faces[:, 1]], v[:, faces[:, 2]]
    fn = np.cross(b - a, c - a)
    acc = np.zeros_like(v)
    for k in range(3):
        np.add.at(acc, (slice(None), faces[:, k]), fn)
    acc /= np.linalg.norm(acc, axis=2, keepdims=True)
    return acc


def old_pseudo_normals(verts, faces):
    """latlong.implicit.distance._normals: unit face normals, angle-weighted sums."""
    corners = [verts[faces[:, k]] for k in range(3)]
    cross = np.cross(corners[1] - corners[0], corners[2] - corners[0])
    norm = np.linalg.norm(cross, axis=1, keepdims=True)
    face_n = np.where(norm > 0, cross / np.where(norm > 0, norm, 1.0), 0.0)
    vert_n = np.zeros_like(verts)
    for k in range(3):
        u = corners[(k + 1) % 3] - corners[k]
        v = corners[(k + 2) % 3] - corners[k]
        cosang = np.einsum("ij,ij->i", u, v) / np.maximum(
            np.linalg.norm(u, axis=1) * np.linalg.norm(v, axis=1), 1e-300)
        angle = np.arccos(np.clip(cosang, -1.0, 1.0))
        for axis in range(3):
            vert_n[:, axis] += np.bincount(faces[:, k], weights=angle * face_n[:, axis],
                                           minlength=len(verts))
    return face_n, vert_n


def old_ray_mesh_face_normals(v, f):
    """latlong.sensors.RayMesh.face_normals."""
    tri = v[f]
    c = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    norm = np.linalg.norm(c, axis=1)
    norm[norm == 0] = 1.0
    return c / norm[:, None]


def reference_vertex_normals(verts, tris):
    """Pure numpy: half cross products summed at the corners; a third of each area."""
    a, b, c = verts[tris[:, 0]], verts[tris[:, 1]], verts[tris[:, 2]]
    fn = 0.5 * np.cross(b - a, c - a)
    acc = np.zeros_like(verts)
    area = np.zeros(len(verts))
    for k in range(3):
        np.add.at(acc, tris[:, k], fn)
        np.add.at(area, tris[:, k], np.linalg.norm(fn, axis=1) / 3.0)
    return acc, area


def reference_faces_order(verts, tris):
    """Triangle after triangle, each triangle's three corners in turn (the kernel's
    order), in numpy scalars."""
    acc = np.zeros_like(verts)
    for a, b, c in tris:
        n = 0.5 * np.cross(verts[b] - verts[a], verts[c] - verts[a])
        for v in (a, b, c):
            acc[v] += n
    return acc


def reference_max_normals(v, f):
    """Max (1999): cross product over the squared lengths of the vertex's two edges."""
    out = np.zeros_like(v)
    for a, b, c in f:
        n = np.cross(v[b] - v[a], v[c] - v[a])
        for p, q, r in ((a, b, c), (b, c, a), (c, a, b)):
            out[p] += n / (np.sum((v[q] - v[p]) ** 2) * np.sum((v[r] - v[p]) ** 2))
    return out / np.linalg.norm(out, axis=1, keepdims=True)


# --------------------------------------------------------------------------- same bits
def test_mesh_surfaces_keep_their_bits(mesh):
    v, f = mesh
    assert np.array_equal(vertex_normals(v, f, "area"), old_mesh_surface_normals(v, f))


def test_corner_order_keeps_gravity_and_mesh_slope_bits(mesh):
    v, f = mesh
    got = vertex_normals(v, f, "area", order="corners")
    assert np.array_equal(got, old_gravity_normals(v, f))
    normals, area = old_mesh_slopes_normals_and_areas(v, f)
    assert np.array_equal(got, normals)
    assert np.array_equal(vertex_areas(v, f), area)


def test_a_batch_keeps_the_boulders_bits(rng):
    from craters.boulders import BoulderShape, boulder_meshes

    verts, faces = boulder_meshes(rng.integers(0, 2**62, 4), BoulderShape())
    lv = max(faces)
    v = verts[:, :10 * 4**lv + 2]
    got = vertex_normals(v, faces[lv], "area", order="corners")
    assert np.array_equal(got, old_boulder_normals(v, faces[lv]))


def test_angle_sums_keep_the_implicit_distance_normals(mesh):
    # the facet normals to the bit; the corner angles are atan2(|cross|, dot) now, not
    # the arc cosine of the old code: the same angles but for the last bits (and slivers)
    v, f = mesh
    face_n, vert_n = old_pseudo_normals(v, f)
    assert np.array_equal(face_normals(v, f, unit=True), face_n)
    np.testing.assert_allclose(vertex_normal_sums(v, f, "angle"), vert_n, rtol=1e-12,
                               atol=1e-12 * np.abs(vert_n).max())


def test_face_normals_keep_the_ray_mesh_and_stl_bits(mesh):
    v, f = mesh
    unit = face_normals(v, f, unit=True)
    assert np.array_equal(unit, old_ray_mesh_face_normals(v, f))
    assert np.array_equal(triangle_normals(v[f], unit=True), unit)
    corners = v[f].astype(np.float32)  # the STL writer's float32 corners keep float32
    stl = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    norm = np.linalg.norm(stl, axis=1, keepdims=True)
    stl = np.divide(stl, norm, out=np.zeros_like(stl), where=norm > 0)
    got = triangle_normals(corners, unit=True)
    assert got.dtype == np.float32 and np.array_equal(got, stl)


def test_faces_order_is_triangle_after_triangle(mesh):
    v, f = mesh
    want = reference_faces_order(v, f)
    assert np.array_equal(vertex_normal_sums(v, f, "area", order="faces"), want)
    normals, area = vertex_normals_and_areas(v, [f[:100], f[100:]])
    norm = np.linalg.norm(want, axis=1, keepdims=True)
    assert np.array_equal(normals, want / np.where(norm > 0, norm, 1.0))
    np.testing.assert_allclose(area, reference_vertex_normals(v, f)[1], rtol=1e-12)


def test_max_weights(mesh):
    v, f = mesh
    np.testing.assert_allclose(vertex_normals(v, f, "max"), reference_max_normals(v, f),
                               rtol=1e-12, atol=1e-12)


def test_max_is_exact_on_a_sphere():
    g = LatLongGrid(6)
    v = g.unit_vectors() * 3.0
    got = vertex_normals(v, g.triangles(), "max")
    area = vertex_normals(v, g.triangles(), "area")
    assert np.abs(got - g.unit_vectors()).max() < 1e-12
    assert np.abs(area - g.unit_vectors()).max() > 1e-6  # the area weighting is not


def test_weightings_agree_on_a_smooth_body():
    v, f = Body.sphere(LatLongGrid(20), 10.0, stretch=(1.4, 1.0, 0.7)).mesh()
    a, b, c = (vertex_normals(v, f, w) for w in ("area", "angle", "max"))
    assert np.degrees(np.arccos(np.clip(np.einsum("ij,ij->i", a, b), -1, 1))).max() < 2
    assert np.degrees(np.arccos(np.clip(np.einsum("ij,ij->i", a, c), -1, 1))).max() < 2


def test_untouched_vertices_and_bad_names(itokawa):
    v, f = itokawa
    v = np.concatenate([v, [[1e6, 0.0, 0.0]]])  # a vertex no face uses
    for w in ("area", "angle", "max"):
        assert (vertex_normals(v, f, w)[-1] == 0).all()
    with pytest.raises(ValueError, match="weighting"):
        vertex_normals(v, f, "mean")
    with pytest.raises(ValueError, match="order"):
        vertex_normals(v, f, "area", order="random")
    with pytest.raises(ValueError, match="order"):
        vertex_normals(v, f, "max", order="corners")


def test_tangent_frames_are_orthonormal(rng):
    up = rng.normal(size=(50, 3))
    up[0] = [0.0, 0.0, 2.0]  # a pole
    up[1] = [0.0, 0.0, -1.0]
    fr = tangent_frames(up)
    assert np.allclose(np.einsum("nij,nkj->nik", fr, fr), np.eye(3), atol=1e-12)
    assert np.allclose(fr[:, 2], up / np.linalg.norm(up, axis=1, keepdims=True))
    assert np.allclose(np.linalg.det(fr), 1.0)
    assert np.allclose(fr[2:, 0, 2], 0.0)  # east is horizontal away from the poles


def test_body_vertex_normals_are_the_streamed_ones(lumpy):
    g = LatLongGrid(9)
    body = Body(g, np.linalg.norm(lumpy[0] / (1.4, 1.0, 0.7), axis=1),
                stretch=(1.4, 1.0, 0.7))
    got = body.vertex_normals("area")
    assert got.dtype == np.float32
    assert np.array_equal(got, lat_long_vertex_normals(g, body.radii_m, body.stretch))
    assert np.array_equal(got, g.vertex_normals(body.radii_m, body.stretch))
    want = vertex_normals(*body.mesh(), "area")
    assert np.abs(got - want).max() < 1e-6
    np.testing.assert_allclose(body.vertex_normals("max"), vertex_normals(*body.mesh(), "max"))


# --------------------------------------------------------------------------- the kernels
def test_area_kernel_matches_numpy(rng):
    verts = rng.normal(size=(30, 3))
    tris = rng.integers(0, 30, size=(80, 3))
    tris = tris[(tris[:, 0] != tris[:, 1]) & (tris[:, 1] != tris[:, 2])
                & (tris[:, 0] != tris[:, 2])]
    acc, area = np.zeros((30, 3)), np.zeros(30)
    _area_normals_kernel(verts, tris, acc, area)
    want_acc, want_area = reference_vertex_normals(verts, tris)
    np.testing.assert_allclose(acc, want_acc, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(area, want_area, rtol=1e-12, atol=1e-12)
    # without areas, into float32: the same sums, rounded at every addition
    acc32 = np.zeros((30, 3), dtype=np.float32)
    _area_normals_kernel(verts, tris, acc32, np.empty(0))
    np.testing.assert_allclose(acc32, want_acc, rtol=1e-5, atol=1e-5)


def test_max_kernel_matches_numpy(rng):
    v = rng.normal(size=(40, 3))
    f = np.array([rng.permutation(40)[:3] for _ in range(120)])
    out = np.empty_like(v)
    _max_normals_kernel(v, f.astype(np.int64), out)
    np.testing.assert_allclose(out, reference_max_normals(v, f), rtol=1e-10, atol=1e-12)


@pytest.mark.parametrize("m", [1, 2, 5, 12])
def test_streamed_normals_match_the_vertex_array(rng, m):
    grid = LatLongGrid(m)
    body = Body(grid, 50.0 + rng.uniform(0, 5, grid.n_vertices), stretch=(1.0, 1.3, 0.8))
    # float32 sums, as :func:`normals_from_radii` accumulates them (a float64 array would
    # compile the parallel kernel a second time, ~10 s in every fresh environment)
    acc = np.zeros((grid.n_vertices, 3), dtype=np.float32)
    _normals_from_radii_kernel(m, grid.ring_offsets(), grid.band_offsets(), body.radii_m,
                               np.asarray(body.stretch), lon_table(m, grid.ring_offsets()),
                               acc, False)
    want, _ = reference_vertex_normals(body.vertices(), grid.triangles())
    np.testing.assert_allclose(acc, want, rtol=2e-6, atol=2e-6 * np.abs(want).max())
    # the angle weighting (the camera's and the glTF's): numpy's unit normal x corner angle
    acc[:] = 0.0
    _normals_from_radii_kernel(m, grid.ring_offsets(), grid.band_offsets(), body.radii_m,
                               np.asarray(body.stretch), lon_table(m, grid.ring_offsets()),
                               acc, True)
    want = vertex_normal_sums(body.vertices(), grid.triangles(), "angle")
    np.testing.assert_allclose(acc, want, rtol=2e-6, atol=2e-6 * np.abs(want).max())


def test_normalised_rows_match_numpy(rng):
    acc = (rng.normal(size=(5000, 3)) * 10.0 ** rng.uniform(-6, 6, (5000, 1))).astype(np.float32)
    acc[:7] = 0.0
    want = acc.copy()  # the numpy normalisation the kernel replaced
    norm = np.sqrt((want.astype(np.float64) ** 2).sum(axis=1))
    want /= np.where(norm > 0, norm, 1.0)[:, None].astype(np.float32)
    _normalize_rows_kernel(acc)
    assert np.array_equal(acc, want)


def test_angle_kernel_is_the_numpy_angle_weighting(rng):
    """The camera's normals (the angle weighting summed facet after facet in numba) are
    numpy's angle-weighted sums (corner angles atan2(|cross|, dot), unit facet normals)."""
    from latlong.geometry._normal_kernels import _angle_normals_kernel

    grid = LatLongGrid(7)
    v = grid.unit_vectors() * (50.0 + rng.uniform(0, 5, (grid.n_vertices, 1)))
    f = grid.triangles()
    out = np.zeros_like(v)
    _angle_normals_kernel(v, f, out)
    np.testing.assert_allclose(out, vertex_normal_sums(v, f, "angle"), rtol=1e-12,
                               atol=1e-13)
    faces = vertex_normal_sums(v, f, "angle", order="faces")
    assert np.array_equal(faces, out)


def test_angle_weights_keep_a_sliver_triangles_small_angle():
    """A corner angle of 1e-9 rad: the arc cosine of its rounded cosine (1.0) is 0 and an
    arc cosine cannot tell it from 0 below ~1e-8 rad; atan2(|cross|, dot) keeps it to
    the last bits, in numba and numpy alike."""
    from latlong.geometry._normal_kernels import _angle_normals_kernel

    v = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1e-9, 0.0]])
    f = np.array([[0, 1, 2]])
    out = np.zeros_like(v)
    _angle_normals_kernel(v, f, out)
    assert np.arccos(np.dot(v[1], v[2]) / np.linalg.norm(v[2])) == 0.0  # what acos gave
    np.testing.assert_allclose(out[:, 2], [1e-9, np.pi / 2, np.pi / 2 - 1e-9], rtol=1e-15)
    np.testing.assert_allclose(vertex_normal_sums(v, f, "angle", order="corners")[:, 2],
                               out[:, 2], rtol=1e-15)
