"""Every kind of surface implements :class:`latlong.geometry.surface.Surface` alike."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import craters
from latlong import Body, ImplicitSurface, LatLongGrid, ShapeModel, read_shape_model
from latlong.geometry.surface import Resamplable, Surface
from latlong.mesh import mesh_surface

DATA = Path(__file__).parents[1] / "data"


def _sphere_mesh(radius_m: float = 50.0):
    g = LatLongGrid(10)
    return g.unit_vectors() * radius_m, g.triangles()


@pytest.fixture(scope="module")
def surfaces():
    grid = LatLongGrid(12)
    body = Body.sphere(grid, 50.0, stretch=(1.2, 1.0, 0.9), metadata={"seed": 1})
    cat = craters.make_catalog(lat_deg=[10.0], lon_deg=[20.0], diameter_m=[9.0])
    body = body.replace(craters=cat)
    mesh = mesh_surface(DATA / "itokawa_8.obj", 40.0, units="km")
    v, f = _sphere_mesh()
    implicit = ImplicitSurface(v, f, cat, {"kind": "test"})
    model = read_shape_model(DATA / "itokawa_8.obj", units="km")
    return {"body": body, "mesh": mesh, "implicit": implicit, "model": model}


@pytest.fixture(params=["body", "mesh", "implicit", "model"])
def surface(request, surfaces):
    return surfaces[request.param]


def test_each_kind_is_a_surface(surface):
    assert isinstance(surface, Surface)
    v, f = surface.mesh()
    assert v.ndim == 2 and v.shape[1] == 3 and v.dtype == np.float64
    assert f.ndim == 2 and f.shape[1] == 3 and f.min() >= 0 and f.max() < len(v)
    assert isinstance(surface.metadata, dict)
    assert surface.boulders is None or surface.boulders.dtype.names
    assert surface.craters is None or "diameter_m" in surface.craters.dtype.names


@pytest.mark.parametrize("weighting", ["area", "angle", "max"])
def test_vertex_normals_point_outward(surface, weighting):
    v, _ = surface.mesh()
    n = surface.vertex_normals(weighting)
    assert n.shape == v.shape
    assert np.allclose(np.linalg.norm(n, axis=1), 1.0, atol=1e-6)
    outward = np.einsum("ij,ij->i", n, v - v.mean(axis=0))
    assert np.mean(outward > 0) > 0.9  # shape models have concave parts


def test_local_frames_at_the_vertices(surface):
    v, _ = surface.mesh()
    pick = v[:: max(1, len(v) // 25)]
    fr = surface.local_frames(pick)
    assert fr.shape == (len(pick), 3, 3)
    assert np.allclose(np.einsum("nij,nkj->nik", fr, fr), np.eye(3), atol=1e-9)
    assert np.allclose(np.linalg.det(fr), 1.0)
    normals = surface.vertex_normals("area")[:: max(1, len(v) // 25)]
    assert np.einsum("ij,ij->i", fr[:, 2], normals).min() > 0.99  # up: the normal there


@pytest.mark.parametrize("suffix", [".ply", ".obj", ".stl"])
def test_save_writes_the_mesh_source(surface, tmp_path, suffix):
    path = surface.save(tmp_path / f"s{suffix}")
    assert path.exists() and path.stat().st_size > 0
    src = surface.mesh_source()
    v, f = surface.mesh()
    assert src.n_vertices >= len(v) and src.n_faces >= len(f)


def test_a_body_saves_natively_or_as_a_mesh(surfaces, tmp_path):
    body = surfaces["body"]
    body.save(tmp_path / "b.npz")
    body.save(tmp_path / "b.ply")
    body.export(tmp_path / "e.ply")
    assert (tmp_path / "b.ply").read_bytes() == (tmp_path / "e.ply").read_bytes()
    assert (tmp_path / "b.npz").read_bytes()[:2] == b"PK"


def test_a_body_resamples_itself(surfaces):
    body = surfaces["body"]
    assert isinstance(body, Resamplable)
    assert not isinstance(surfaces["mesh"], Resamplable)
    assert body.resampled(body.n_vertices) is body
    small = body.resampled(LatLongGrid(5).n_vertices + 10)
    assert small.magnitude == 5 and np.array_equal(small.stretch, body.stretch)
    assert np.allclose(small.radii_m, 50.0)


def test_shape_models_have_no_catalogs(surfaces):
    model = surfaces["model"]
    assert isinstance(model, ShapeModel)
    assert model.craters is None and model.boulders is None
    assert model.metadata == {"source": model.source}
    assert model.volume_m3 > 0 and model.area_m2 > 0


def test_a_body_resamples_as_the_preview_did(surfaces):
    body = surfaces["body"]
    small = LatLongGrid(7)
    want = body.grid.interpolate(body.radii_m, np.pi / 2 - small.latitudes(),
                                 small.longitudes())
    got = body.resampled(small.n_vertices)
    assert got.magnitude == 7 and np.array_equal(got.radii_m, want)
    assert got.radius_m == body.radius_m


@pytest.mark.parametrize("kind", ["mesh", "implicit", "model"])
def test_any_surface_previews(surfaces, kind, tmp_path):
    from PIL import Image

    from latlong import render_preview

    render_preview(surfaces[kind], tmp_path / "p.png", width_px=48, height_px=32)
    img = np.asarray(Image.open(tmp_path / "p.png"))
    assert img.shape == (32, 48, 3) and img.max() > 0
