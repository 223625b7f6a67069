"""Body: radii, stretch, lossless .npz, mesh export formats."""

from __future__ import annotations

import numpy as np
import pytest

from latlong import Body, LatLongGrid, load, perlin_fbm


@pytest.fixture
def body():
    g = LatLongGrid(8)
    h = perlin_fbm(g, 1.5, 4, 0.5, 2.0, 3.0, rng=2)
    return Body.from_heights(g, 20.0, h, stretch=(2.0, 1.0, 0.5), metadata={"seed": 2})


def test_vertices_heights_and_stretch(body):
    v = body.vertices()
    u = body.grid.unit_vectors()
    assert np.allclose(v, u * body.radii_m[:, None] * [2.0, 1.0, 0.5])
    assert np.allclose(body.heights_m, body.radii_m - 20.0)
    assert np.array_equal(body.vertices(5, 9), v[5:9])


def test_immutable(body):
    with pytest.raises(ValueError):
        body.radii_m[0] = 1.0
    other = body.replace(radii_m=body.radii_m + 1)
    assert not np.array_equal(other.radii_m, body.radii_m)
    with pytest.raises(TypeError, match="unknown"):
        body.replace(colour="red")


def test_save_load_roundtrip_and_determinism(body, tmp_path):
    a, b = tmp_path / "a.npz", tmp_path / "b.npz"
    body.save(a)
    body.save(b)
    assert a.read_bytes() == b.read_bytes()
    back = load(a)
    assert np.array_equal(back.radii_m, body.radii_m)
    assert back.radius_m == body.radius_m
    assert np.array_equal(back.stretch, body.stretch)
    assert back.metadata == {"seed": 2}
    assert back.magnitude == 8
    with np.load(a, allow_pickle=False) as z:  # no pickles inside
        assert set(z.files) >= {"radii_m", "magnitude", "metadata_json"}
    assert [p.name for p in tmp_path.iterdir() if p.name.startswith(".")] == []


def test_load_errors(tmp_path):
    with pytest.raises(FileNotFoundError, match="does not exist"):
        load(tmp_path / "missing.npz")
    bad = tmp_path / "bad.npz"
    bad.write_bytes(b"not a zip")
    with pytest.raises(ValueError, match="is not a body .npz.*not a .npz .zip. archive"):
        load(bad)
    other = tmp_path / "other.npz"
    np.savez(other, x=np.zeros(3))
    with pytest.raises(ValueError, match="not a craterform body"):
        load(other)


def _mesh(tmp, name):
    Body.sphere(LatLongGrid(4), 10.0).export(tmp / name)


def _pickles(tmp, name):
    np.savez(tmp / name, x=np.array([{"a": 1}], dtype=object))


def _npy(tmp, name):
    np.save(tmp / name, np.zeros(3))


@pytest.mark.parametrize("name,make,why", [
    ("b.ply", _mesh, "a .ply file is a mesh, which holds no lat/long body"),
    ("b.obj", _mesh, "a .obj file is a mesh"),
    ("b.npz", _pickles, "holds Python objects .pickles., which a body never does"),
    ("b.npy", _npy, "it is not a .npz .zip. archive"),
])
def test_load_says_a_body_npz_is_needed(tmp_path, name, make, why):
    """Not numpy's "pickled data ... allow_pickle" message (issue 19 item 7)."""
    make(tmp_path, name)
    with pytest.raises(ValueError, match=f"is not a body .npz .*{why}") as info:
        load(tmp_path / name)
    assert "allow_pickle" not in str(info.value)


def read_binary_ply(path):
    """Minimal reader for the PLY layout we write (pure numpy reference)."""
    data = path.read_bytes()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode("ascii").splitlines()
    nv = int(next(h for h in header if h.startswith("element vertex")).split()[-1])
    nf = int(next(h for h in header if h.startswith("element face")).split()[-1])
    v = np.frombuffer(data, dtype="<f4", count=nv * 4, offset=end).reshape(nv, 4)
    f = np.frombuffer(data, dtype=np.dtype([("n", "u1"), ("v", "<i4", (3,))]), count=nf,
                      offset=end + nv * 16)
    assert (f["n"] == 3).all()
    return v, f["v"]


def test_ply_export(body, tmp_path):
    p = tmp_path / "m.ply"
    body.export(p)
    v, f = read_binary_ply(p)
    assert np.allclose(v[:, :3], body.vertices().astype(np.float32))
    assert np.allclose(v[:, 3], body.heights_m.astype(np.float32))
    assert np.array_equal(f, body.grid.triangles())
    import pyvista as pv

    mesh = pv.read(p)
    assert mesh.n_points == body.n_vertices and mesh.n_cells == body.grid.n_triangles


@pytest.mark.parametrize("suffix", [".stl", ".obj", ".vtp", ".vtk"])
def test_other_formats_read_back(body, tmp_path, suffix):
    import pyvista as pv

    p = tmp_path / f"m{suffix}"
    body.export(p)
    mesh = pv.read(p)
    assert mesh.n_cells == body.grid.n_triangles
    pts = np.asarray(mesh.points)
    if suffix != ".stl":  # STL stores corners per facet
        assert mesh.n_points == body.n_vertices
        assert np.allclose(pts, body.vertices(), atol=1e-4)
    if suffix in (".vtp", ".vtk"):
        assert np.allclose(mesh.point_data["height_m"], body.heights_m)


def test_stl_normals_point_outward(body, tmp_path):
    p = tmp_path / "m.stl"
    body.export(p)
    rec = np.frombuffer(p.read_bytes()[84:], dtype=np.dtype(
        [("n", "<f4", (3,)), ("v", "<f4", (3, 3)), ("a", "<u2")]))
    centroid = rec["v"].mean(axis=1)
    assert (np.einsum("ij,ij->i", rec["n"], centroid) > 0).mean() > 0.99


def test_export_bad_suffix_leaves_nothing(body, tmp_path):
    with pytest.raises(ValueError, match="unknown mesh format"):
        body.export(tmp_path / "m.xyz")
    assert list(tmp_path.iterdir()) == []


def test_pyvista_height_array(body):
    mesh = body.to_pyvista()
    assert np.allclose(mesh.point_data["height_m"], body.heights_m)


@pytest.mark.parametrize("radii,match", [
    (np.full(98, -1.0), "> 0"), (np.full(98, np.nan), "finite"), (np.ones(5), "shape")])
def test_bad_radii(radii, match):
    with pytest.raises(ValueError, match=match):
        Body(LatLongGrid(4), radii)


def test_bad_stretch_and_metadata():
    g = LatLongGrid(2)
    with pytest.raises(ValueError, match="stretch"):
        Body.sphere(g, 1.0, stretch=(1, 0, 1))
    with pytest.raises(TypeError, match="JSON"):
        Body.sphere(g, 1.0, metadata={"x": object()})
