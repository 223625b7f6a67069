"""Cratering on any closed triangle mesh (latlong.mesh): kernels against plain references,
closed 2-manifold outputs without flipped triangles, crater profiles, geodesic reach,
boulders, the command line and determinism."""

from __future__ import annotations

import logging
from pathlib import Path

import numpy as np
import pytest
import pyvista as pv
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import dijkstra

import craters
from latlong.mesh import (
    TriangleGrid,
    adjacency,
    mesh_boulder_population,
    mesh_checks,
    mesh_crater_population,
    mesh_surface,
    place_mesh_boulders,
    refinement_plan,
    stamp_mesh_craters,
)
from latlong.mesh._kernels import _geodesic_gather
from latlong.mesh._stamp_kernels import _point_mass_kernel
from latlong.mesh.cratering import down_directions
from latlong.mesh.refine import nsection
from latlong.shapes import ShapeModel, from_shape_model, read_shape_model

DATA = Path(__file__).resolve().parents[1] / "data"
PROFILE_TOL = 0.02  # of the depth, as on bodies (tests/latlong/test_cratering.py)


def model_of(poly) -> ShapeModel:
    poly = poly.triangulate().clean()
    return ShapeModel(np.asarray(poly.points, dtype=np.float64),
                      np.asarray(poly.faces).reshape(-1, 4)[:, 1:].astype(np.int64))


def face_normals(v, f):
    return np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])


@pytest.fixture(scope="module")
def itokawa8():
    return mesh_surface(read_shape_model(DATA / "itokawa_8.obj", units="km"), 6.0)


# --------------------------------------------------------------------------- kernels
def test_nsection_matches_barycentric_reference():
    m = model_of(pv.Icosphere(radius=10.0, nsub=1))
    n = 4
    v, f = nsection(m.vertices, m.faces, n)
    # plain reference: every (i, j) barycentric point of every face, merged
    i, j = np.meshgrid(np.arange(n + 1), np.arange(n + 1), indexing="ij")
    keep = i + j <= n
    a, b, c = (m.vertices[m.faces[:, k]] for k in range(3))
    ref = (a[:, None] + (i[keep] / n)[None, :, None] * (b - a)[:, None]
           + (j[keep] / n)[None, :, None] * (c - a)[:, None]).reshape(-1, 3)
    ref = np.unique(np.round(ref, 9), axis=0)
    assert np.array_equal(np.unique(np.round(v, 9), axis=0), ref)
    assert len(v) == len(ref) and len(f) == len(m.faces) * n * n
    assert np.allclose(v[:len(m.vertices)], m.vertices)
    chk = mesh_checks(v, f)
    assert chk["edges_not_in_two_faces"] == 0 and chk["directed_edges_repeated"] == 0
    assert chk["euler_characteristic"] == 2
    # orientation kept: each small face turns like its parent
    parent = np.repeat(np.arange(len(m.faces)), n * n)
    assert (np.einsum("ij,ij->i", face_normals(v, f),
                      face_normals(m.vertices, m.faces)[parent]) > 0).all()


def test_geodesic_gather_matches_dijkstra():
    m = model_of(pv.Icosphere(radius=50.0, nsub=3))
    v, f = m.vertices, m.faces
    voff, vnbr, _, _ = adjacency(f, len(v))
    rows = np.repeat(np.arange(len(v)), np.diff(voff))
    w = np.linalg.norm(v[rows] - v[vnbr], axis=1)
    graph = csr_matrix((w, (rows, vnbr)), shape=(len(v), len(v)))
    seeds, seed_d = np.array([0, 5, 17]), np.array([0.5, 1.0, 0.2])
    limit = 20.0
    ref = np.min(dijkstra(graph, indices=seeds) + seed_d[:, None], axis=0)
    mark, gdist = np.zeros(len(v), np.int64), np.zeros(len(v))
    for epoch in (1, 2):  # the work arrays are reused without clearing
        got, d = _geodesic_gather(v, voff, vnbr, seeds, seed_d, limit, mark, gdist, epoch)
        assert set(got) == set(np.flatnonzero(ref <= limit))
        assert np.allclose(d, ref[got])
        assert (np.diff(d) >= -1e-12).all()  # settled in order of distance


def test_closest_points_match_vtk():
    m = model_of(pv.ParametricEllipsoid(30.0, 20.0, 10.0, u_res=40, v_res=30, w_res=4))
    rng = np.random.default_rng(1)
    pts = rng.normal(size=(300, 3)) * [30.0, 20.0, 10.0] * rng.uniform(0.3, 1.6, (300, 1))
    grid = TriangleGrid.build(m.vertices, m.faces)
    face, uv, dist = grid.closest(pts)
    a, b, c = (m.vertices[m.faces[face, k]] for k in range(3))
    q = a + uv[:, :1] * (b - a) + uv[:, 1:] * (c - a)
    assert np.allclose(np.linalg.norm(q - pts, axis=1), dist)
    _, ref = pv.PolyData(m.vertices, np.hstack([np.full((len(m.faces), 1), 3), m.faces]).ravel()
                         ).find_closest_cell(pts, return_closest_point=True)
    assert np.allclose(dist, np.linalg.norm(ref - pts, axis=1), atol=1e-9)


def test_depths_along_normals_on_a_box():
    m = model_of(pv.Box(bounds=(-10, 10, -10, 10, -1, 1), level=4))
    grid = TriangleGrid.build(m.vertices, m.faces)
    rng = np.random.default_rng(2)
    pts = np.column_stack([rng.uniform(-8, 8, (20, 5, 2)).reshape(-1, 2),
                           rng.uniform(0.2, 3.0, 100)]).reshape(20, 5, 3)
    up = np.tile([0.0, 0.0, 1.0], (20, 1))
    got = grid.depths(pts, up, margin_m=1.0)
    assert np.allclose(got, 1.0 - pts[..., 2])  # the top face, never the bottom one
    assert np.isnan(grid.depths(pts + [40.0, 0, 0], up, margin_m=1.0)).all()


def test_point_mass_kernel_matches_numpy():
    rng = np.random.default_rng(3)
    p, q, m = rng.normal(size=(50, 3)), rng.normal(size=(70, 3)) * 3, rng.uniform(-1, 2, 70)
    out = np.empty_like(p)
    _point_mass_kernel(p, q, m, 0.3, out)
    d = q[None] - p[:, None]
    ref = np.einsum("pm,pmk->pk", m / ((d * d).sum(2) + 0.3) ** 1.5, d)
    assert np.allclose(out, ref, rtol=1e-12, atol=1e-12)


def test_down_directions_point_to_the_centre_of_a_sphere():
    m = mesh_surface(model_of(pv.Icosphere(radius=100.0, nsub=3)), 4.0)
    pts = m.vertices[::11]
    down = down_directions(m.vertices, m.faces, pts)
    cos = -np.einsum("ij,ij->i", down, pts / np.linalg.norm(pts, axis=1, keepdims=True))
    assert np.degrees(np.arccos(np.clip(cos, -1, 1))).max() < 0.5


def test_refinement_plan_keeps_butterfly_levels():
    assert refinement_plan(9.65, 1.0) == (3, 1)
    assert refinement_plan(9.65, 0.8) == (2, 3)
    assert refinement_plan(9.65, 0.8, "linear") == (0, 12)
    assert refinement_plan(1.0, 2.0) == (0, 1)


# --------------------------------------------------------------------------- surfaces
def test_cratered_itokawa_is_closed_and_unflipped(itokawa8):
    s = itokawa8
    assert s.checks()["edges_not_in_two_faces"] == 0
    cat = mesh_crater_population(s, [craters.CraterLayer(c=0.2, k=-2, d_min_m=8.0,
                                                         d_max_m=60.0)], rng=1)
    out = stamp_mesh_craters(s, cat, rng=2, target=craters.small_body(160.0, 1900.0))
    assert len(out.craters) > 0.8 * len(cat)
    chk = out.checks()
    assert chk["edges_not_in_two_faces"] == 0 and chk["directed_edges_repeated"] == 0
    assert chk["euler_characteristic"] == 2
    dots = np.einsum("ij,ij->i", face_normals(s.vertices, s.faces),
                     face_normals(out.vertices, out.faces))
    assert (dots > 0).all()
    assert np.abs(out.heights_m).max() > 1.0
    # the catalog's centres are on the cratered surface (up to the next craters' change)
    _, _, dist = TriangleGrid.build(out.vertices, out.faces).closest(
        np.column_stack([out.craters["centre_x_m"], out.craters["centre_y_m"],
                         out.craters["centre_z_m"]]))
    assert np.median(dist) < 0.5


def test_single_crater_follows_profile_on_smooth_mesh():
    s = mesh_surface(model_of(pv.Icosphere(radius=1000.0, nsub=3)), 16.0)
    d = 20 * s.mean_edge_m
    depth = float(craters.fresh_morphometry(d)["depth_m"])
    for k in (0, 1000, 2000):
        c = s.vertices[k]
        cat = craters.make_catalog(lat_deg=[0.0], lon_deg=[0.0], diameter_m=[d],
                                   centre_x_m=[c[0]], centre_y_m=[c[1]], centre_z_m=[c[2]])
        out = stamp_mesh_craters(s, cat, roughness=False)
        row = out.craters[0]
        up = np.array([row["normal_x"], row["normal_y"], row["normal_z"]])
        r = s.vertices - np.array([row["centre_x_m"], row["centre_y_m"], row["centre_z_m"]])
        dist = np.linalg.norm(r - np.outer(r @ up, up), axis=1)
        near = (dist < 1.6 * d) & (r @ up > -0.5 * d)
        want = craters.radial_profile(dist[near] / (d / 2), d)
        assert np.abs((out.heights_m - s.heights_m)[near] - want).max() <= PROFILE_TOL * depth
        far = (dist > 1.5 * d * 1.01) | (r @ up < -0.5 * d)
        assert (out.vertices[far] == s.vertices[far]).all()


def test_crater_never_reaches_the_other_side_of_a_thin_plate():
    s = mesh_surface(model_of(pv.Box(bounds=(-60, 60, -60, 60, -1, 1), level=2)), 2.0,
                     center="origin", smooth="linear")
    cat = craters.make_catalog(lat_deg=[90.0], lon_deg=[0.0], diameter_m=[20.0],
                               centre_x_m=[0.0], centre_y_m=[0.0], centre_z_m=[1.0])
    out = stamp_mesh_craters(s, cat, roughness=False)
    assert len(out.craters) == 1
    bottom = s.vertices[:, 2] < 0
    moved = (out.vertices != s.vertices).any(axis=1)
    assert moved[~bottom].sum() > 50 and not moved[bottom].any()


def test_boulders_rest_on_the_mesh(itokawa8):
    layer = craters.BoulderLayer(c=0.01, k=-2.5, d_min_m=4.0, d_max_m=12.0, burial_max=0.5)
    found = mesh_boulder_population(itokawa8, [layer], rng=4)
    placed = place_mesh_boulders(itokawa8, found)
    assert len(placed) == len(found) > 10
    assert np.allclose(placed["bottom_depth_m"], placed["burial_m"], atol=0.05 * 12.0)
    with_rocks = itokawa8.replace(boulders=placed)
    mesh = with_rocks.to_pyvista()
    assert mesh.n_points > itokawa8.n_vertices


def test_tiny_non_star_fraction_is_accepted_with_a_warning(caplog):
    eros = read_shape_model(DATA / "eros007790.tab", units="km")
    with caplog.at_level(logging.WARNING, logger="latlong.shapes"):
        body = from_shape_model(eros, 300)
    assert "1 of 540002 grid directions" in caplog.text and "outermost" in caplog.text
    assert 0 < body.metadata["non_star_fraction"] < 1e-5
    ito = read_shape_model(DATA / "itokawa_8.obj", units="km")
    with pytest.raises(craters._shared.ParameterError, match="not star-shaped") as err:
        from_shape_model(ito, 60)
    assert err.value.name == "crossings" and "`surface` mesh" in str(err.value)


# --------------------------------------------------------------------------- command line
def mesh_build(run_cli, out: Path, *extra, threads="2"):
    return run_cli("latlong", "build", "--base", f"shape:{DATA / 'itokawa_8.obj'}",
                   "--shape-units", "km", "--surface", "mesh", "--spacing-m", "8",
                   "--craters", "c=0.2,k=-2,d_min_m=10,d_max_m=30", "--boulders",
                   "c=0.005,k=-2.5,d_min_m=4,d_max_m=12,near=0.3", "--seed", "3", *extra,
                   "-q", env={"NUMBA_NUM_THREADS": threads})


def test_cli_mesh_surface_outputs_same_bytes_any_thread_count(run_cli, tmp_path):
    files = {}
    for threads in ("1", "2"):
        d = tmp_path / threads
        d.mkdir()
        proc = mesh_build(run_cli, d, "-o", str(d / "a.ply"), "-o", str(d / "a.obj"),
                          "--catalog", str(d / "c.csv"), "--boulder-catalog",
                          str(d / "b.csv"), threads=threads)
        assert proc.returncode == 0, proc.stderr
        files[threads] = [(d / n).read_bytes() for n in ("a.ply", "a.obj", "c.csv", "b.csv")]
    assert files["1"] == files["2"]
    mesh = pv.read(tmp_path / "1" / "a.ply")  # the body and each boulder: closed spheres
    chk = mesh_checks(np.asarray(mesh.points), np.asarray(mesh.faces).reshape(-1, 4)[:, 1:])
    n_boulders = len(craters.read_catalog(tmp_path / "1" / "b.csv"))
    assert chk["edges_not_in_two_faces"] == 0 and chk["directed_edges_repeated"] == 0
    assert n_boulders > 5 and chk["euler_characteristic"] == 2 * (1 + n_boulders)
    assert len(craters.read_catalog(tmp_path / "1" / "c.csv")) > 20


@pytest.mark.parametrize("args,needles", [
    (["--surface", "mesh", "-o", "x.npz"], ["--surface mesh", ".npz"]),
    (["--surface", "ball", "-o", "x.ply"], ["--surface", "ball"]),
    (["--spacing-m", "2", "--shape-crossings", "outermost", "-o", "x.ply"],
     ["--spacing-m", "--surface mesh"]),
    (["--surface", "mesh", "--spacing-m", "-1", "-o", "x.ply"], ["--spacing-m", "> 0"]),
    (["--surface", "mesh", "--shape-smooth", "loop", "-o", "x.ply"],
     ["--shape-smooth", "--surface mesh"]),
    (["-o", "x.ply"], ["--shape-crossings", "--surface mesh"]),
])
def test_cli_mesh_errors_are_one_line(run_cli, tmp_path, args, needles):
    proc = run_cli("latlong", "build", "--base", f"shape:{DATA / 'itokawa_8.obj'}",
                   "--shape-units", "km", "--magnitude", "60", *args, cwd=tmp_path)
    assert proc.returncode == 2, proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error:"), proc.stderr
    for needle in needles:
        assert needle in lines[0], lines[0]
    assert not list(tmp_path.iterdir())
