"""Paths to surfaces (latlong.load_surface): a body .npz, mesh files with their fields."""

from __future__ import annotations

import numpy as np
import pytest

import craters
import latlong
from craters._shared import ParameterError
from latlong.geometry.surface import Surface


@pytest.fixture(scope="module")
def rocky(tmp_path_factory):
    """A 200 m sphere with five boulders, saved as .npz and exported as PLY."""
    body = latlong.Body.sphere(latlong.LatLongGrid(16), 200.0)
    rocks = latlong.boulder_population(body, craters.BoulderLayer(c=0.05, k=-2.0, d_min_m=4.0,
                                                                   d_max_m=8.0), rng=3)
    body = body.replace(boulders=latlong.place_boulders(body, rocks[:5]))
    folder = tmp_path_factory.mktemp("loader")
    return body, body.save(folder / "b.npz"), body.export(folder / "b.ply")


def test_a_body_file_is_a_body_and_a_mesh_file_a_surface(rocky, tmp_path):
    body, npz, ply = rocky
    assert isinstance(latlong.load_surface(npz), latlong.Body)
    mesh = latlong.load_surface(ply)
    assert isinstance(mesh, latlong.MeshData) and isinstance(mesh, Surface)
    assert mesh.craters is None and mesh.boulders is None
    assert mesh.metadata == {"source": str(ply), "fields": ["boulder_id", "height_m"]}
    ids = mesh.fields["boulder_id"]
    assert (ids[:body.n_vertices] == -1).all() and set(ids[body.n_vertices:]) == set(range(5))
    verts, faces = mesh.mesh()  # the surface without the boulders
    assert len(verts) == len(ids) and len(faces) == body.grid.n_triangles
    np.testing.assert_allclose(verts[:body.n_vertices], body.vertices(), atol=1e-4)
    radial = verts[:body.n_vertices] / np.linalg.norm(verts[:body.n_vertices], axis=1)[:, None]
    normals = mesh.vertex_normals()[:body.n_vertices]
    assert (np.einsum("ij,ij->i", normals, radial) > 0.99).all()
    frames = mesh.local_frames(verts[:3] * 1.01)
    np.testing.assert_allclose(frames[:, 2], normals[:3])
    np.testing.assert_allclose(np.einsum("nij,nkj->nik", frames, frames),
                               np.broadcast_to(np.eye(3), (3, 3, 3)), atol=1e-12)
    # written again, it reads back the same (PLY: float32 positions, the fields kept)
    again = latlong.load_surface(mesh.save(tmp_path / "again.ply"))
    np.testing.assert_array_equal(again.vertices, mesh.vertices)
    np.testing.assert_array_equal(again.faces, mesh.faces)
    np.testing.assert_array_equal(again.fields["boulder_id"], ids)


def test_units_and_errors(rocky, tmp_path):
    _, _, ply = rocky
    km = latlong.load_surface(ply, units="km")
    np.testing.assert_allclose(km.vertices, 1000.0 * latlong.load_surface(ply).vertices)
    with pytest.raises(ParameterError, match="units"):
        latlong.load_surface(ply, units="mm")
    text = tmp_path / "model.xyz"
    text.write_text("1 2 3\n")
    with pytest.raises(ParameterError, match="model"):
        latlong.load_surface(text)
    with pytest.raises(FileNotFoundError):
        latlong.load_surface(tmp_path / "missing.ply")
    empty = tmp_path / "empty.ply"
    empty.write_bytes(b"ply\nformat binary_little_endian 1.0\nelement vertex 0\nproperty "
                      b"float x\nproperty float y\nproperty float z\nelement face 0\n"
                      b"property list uchar int vertex_indices\nend_header\n")
    with pytest.raises(ValueError, match="no triangles"):
        latlong.load_surface(empty)
