"""The mesh-reader registry: one reader per suffix, used by shape models and the sensors."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import craters
from latlong import Body, LatLongGrid, place_boulders, read_shape_model
from latlong.geometry.surface import Surface
from latlong.meshio.readers import MESH_READERS, MeshData, read_mesh, read_vtk_mesh
from latlong.meshio.writers import MESH_WRITERS

DATA = Path(__file__).parents[1] / "data"


@pytest.fixture(scope="module")
def rocky(tmp_path_factory):
    """A body with placed boulders written as every mesh format."""
    grid = LatLongGrid(10)
    body = Body.sphere(grid, 40.0)
    cat = craters.make_catalog(lat_deg=[5.0, -20.0], lon_deg=[10.0, 200.0],
                               diameter_m=[3.0, 2.0], burial_frac=[0.2, 0.3],
                               azimuth_deg=[0.0, 40.0], seed=[1, 2])
    body = body.replace(boulders=place_boulders(body, cat))
    folder = tmp_path_factory.mktemp("rocky")
    for suffix in MESH_WRITERS:
        body.save(folder / f"b{suffix}")
    return body, folder


def test_every_written_format_reads_back(rocky):
    body, folder = rocky
    v, f, fields = body.mesh_source().arrays()
    for suffix in MESH_WRITERS:
        m = read_mesh(folder / f"b{suffix}", units="m")
        assert isinstance(m, MeshData) and isinstance(m, Surface)
        if suffix == ".glb":  # a body's own glTF: patches, levels of detail, rock nodes
            assert len(m.faces) >= len(f)
            continue
        assert m.faces.shape == f.shape, suffix
        np.testing.assert_allclose(m.vertices[m.faces], v[f], atol=1e-4)


def test_craterform_ply_fields_and_vtk_agree(rocky):
    body, folder = rocky
    fast = read_mesh(folder / "b.ply", units="m")
    assert set(fast.fields) == {"height_m", "boulder_id"}
    ids = body.mesh_source().arrays()[2]["boulder_id"]
    assert np.array_equal(fast.fields["boulder_id"], ids)
    vtk_v, vtk_f, _ = read_vtk_mesh(folder / "b.ply")  # VTK drops the extra fields
    assert np.array_equal(fast.vertices, vtk_v) and np.array_equal(fast.faces, vtk_f)


def test_units_and_what_the_text_reader_accepts(tmp_path):
    km = read_mesh(DATA / "itokawa_8.obj", units="km")
    m = read_mesh(DATA / "itokawa_8.obj", units="m")
    assert np.array_equal(km.vertices, 1000.0 * m.vertices)
    quad = tmp_path / "q.obj"  # a polygon is fanned, negative indices are relative
    quad.write_text("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf -4 -3 -2 -1\n")
    assert read_mesh(quad, units="m").faces.tolist() == [[0, 1, 2], [0, 2, 3]]
    plate = tmp_path / "p.tab"  # PDS count format, 1-based
    plate.write_text("4 2\n1 0 0 0\n2 1 0 0\n3 1 1 0\n4 0 1 0\n1 1 2 3\n2 1 3 4\n")
    assert read_mesh(plate, units="m").faces.tolist() == [[0, 1, 2], [0, 2, 3]]


@pytest.mark.parametrize(("name", "text", "needle"), [
    ("e.obj", "# nothing\n", "cannot read mesh .* it is empty"),
    ("b.tab", "3 1\n1 0 0 0\n2 1 0 0\n3 0 1 0\n1 1 2 9\n", "out of range \\[1, 9\\] for 3"),
    ("h.tab", "3 2\n1 0 0 0\n", "header says 3 vertices and 2 facets"),
    ("x.xyz", "1 2 3\n", "unknown format '.xyz'"),
    ("n.ply", "not a mesh\n", "cannot read mesh .* not a PLY file"),
])
def test_one_line_errors(tmp_path, name, text, needle):
    (tmp_path / name).write_text(text)
    with pytest.raises(ValueError, match=needle) as info:
        read_mesh(tmp_path / name, units="m")
    assert "\n" not in str(info.value)
    with pytest.raises(ValueError, match="units"):
        read_mesh(tmp_path / name, units="au")


def test_shape_models_read_through_the_registry(tmp_path):
    model = read_shape_model(DATA / "itokawa_8.obj", units="km")
    model.save(tmp_path / "i.ply")
    again = read_shape_model(tmp_path / "i.ply", units="m")
    assert len(again.faces) == len(model.faces)
    assert abs(again.volume_m3 / model.volume_m3 - 1) < 1e-6
    assert set(MESH_READERS) >= set(MESH_WRITERS)
