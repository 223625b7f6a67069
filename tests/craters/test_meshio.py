"""The shared mesh writers (latlong.meshio.writers): every format reads back as written."""

from __future__ import annotations

import numpy as np
import pytest

from latlong.meshio.writers import MESH_SUFFIXES, MeshSource, array_source, write_mesh


def _tetra(fields: bool):
    v = np.array([[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 3.0, 0.0], [0.0, 0.0, 4.5]])
    f = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    extra = {"height_m": np.array([0.5, 1.5, 2.5, 3.5], np.float32),
             "layer": np.array([0, 1, 1, 2], np.uint8)} if fields else {}
    return v, f, array_source(v, f, "a tetrahedron, metres", **extra)


@pytest.mark.parametrize("fields", [False, True])
@pytest.mark.parametrize("suffix", [s for s in MESH_SUFFIXES if s != ".glb"])
def test_formats_read_back(tmp_path, suffix, fields):
    import pyvista as pv

    v, f, src = _tetra(fields)
    mesh = pv.read(write_mesh(src, tmp_path / f"t{suffix}"))
    if suffix == ".stl":  # STL repeats the corners of every facet
        assert mesh.n_cells == 4 and np.allclose(np.sort(np.unique(mesh.points, axis=0), 0),
                                                 np.sort(v, 0))
        return
    assert np.array_equal(mesh.points, v.astype(np.float32))
    cells = mesh.cells if suffix == ".vtk" else mesh.faces  # .vtk: an unstructured grid
    assert np.array_equal(cells.reshape(-1, 4)[:, 1:], f)
    if fields and suffix == ".ply":  # VTK's PLY reader skips extra properties: parse them
        raw = (tmp_path / "t.ply").read_bytes()
        body = raw[raw.index(b"end_header\n") + 11:]
        rec = np.frombuffer(body, np.dtype([("xyz", "<f4", 3), ("height_m", "<f4"),
                                            ("layer", "u1")]), count=4)
        assert np.array_equal(rec["height_m"], [0.5, 1.5, 2.5, 3.5])
        assert np.array_equal(rec["layer"], [0, 1, 1, 2])
    elif fields and suffix != ".obj":
        assert np.array_equal(mesh.point_data["height_m"], [0.5, 1.5, 2.5, 3.5])
        assert np.array_equal(mesh.point_data["layer"], [0, 1, 1, 2])


def test_glb_reads_back(tmp_path):
    import trimesh

    v, f, src = _tetra(False)
    scene = trimesh.load(write_mesh(src, tmp_path / "t.glb"))
    (geom,) = scene.geometry.values()
    assert np.allclose(geom.vertices, v) and np.array_equal(geom.faces, f)


def test_chunks_and_groups_give_the_same_bytes_as_one_piece(tmp_path):
    """A mesh delivered in several chunks and groups writes the bytes of one piece (OBJ
    adds its group lines)."""
    v, f, whole = _tetra(True)
    values = {"height_m": np.array([0.5, 1.5, 2.5, 3.5], np.float32),
              "layer": np.array([0, 1, 1, 2], np.uint8)}

    def vertex_chunks():
        yield v[:1], {k: a[:1] for k, a in values.items()}
        yield v[1:], {k: a[1:] for k, a in values.items()}

    split = MeshSource(4, 4, vertex_chunks, lambda: [(None, [f[:3], f[3:]])],
                       lambda: [v[f[:2]], v[f[2:]]], whole.fields, whole.title)
    for suffix in (".ply", ".stl", ".vtp", ".vtk", ".glb", ".obj"):
        a = write_mesh(whole, tmp_path / f"a{suffix}").read_bytes()
        b = write_mesh(split, tmp_path / f"b{suffix}").read_bytes()
        assert a == b, suffix


def test_unknown_suffix_writes_nothing(tmp_path):
    with pytest.raises(ValueError, match="unknown mesh format.*allowed: .ply"):
        write_mesh(_tetra(False)[2], tmp_path / "t.xyz")
    assert list(tmp_path.iterdir()) == []


def test_background_writer_keeps_order_and_raises_write_errors(tmp_path):
    from latlong.meshio.chunks import BackgroundWriter

    with open(tmp_path / "x.bin", "wb") as fh, BackgroundWriter(fh) as out:
        for k in range(50):
            out.write(bytes([k]) * 1000)
    assert (tmp_path / "x.bin").read_bytes() == b"".join(bytes([k]) * 1000 for k in range(50))

    class Full:
        def write(self, data):
            raise OSError("No space left on device")

    out = BackgroundWriter(Full())
    out.write(b"abc")
    with pytest.raises(OSError, match="No space"):
        out.write(b"def")
    out.close()


@pytest.mark.parametrize("threads", [1, 2, 4])
def test_ordered_chunks_keeps_order_and_bounds_the_buffers(threads):
    import threading
    import time

    from latlong.meshio.chunks import ordered_chunks

    made = []
    lock = threading.Lock()

    def buffer():
        with lock:
            made.append(1)
        return np.zeros(1)

    def make(i, buf):
        time.sleep(0.001 * ((7 * i) % 5))  # finish out of order
        buf[0] = i
        return buf

    seen, prev = [], None
    for k, buf in enumerate(ordered_chunks(make, range(60), buffer, threads=threads)):
        seen.append(int(buf[0]))
        assert buf[0] == k
        assert prev is None or prev[0] == k - 1  # the one before is intact too (written)
        prev = buf
    assert seen == list(range(60)) and len(made) <= 2 * threads + 2

    def fails(i, buf):
        if i == 5:
            raise OSError("disk full")
        return i

    with pytest.raises(OSError, match="disk full"):
        list(ordered_chunks(fails, range(20), lambda: None, threads=threads))


def test_meshio_reads_the_legacy_vtk(tmp_path):
    """The legacy .vtk is an unstructured grid of triangles: meshio reads it (it has no
    reader for legacy POLYDATA, and exits on one), with its points, triangles and fields;
    VTK and craterform's own reader read the same, in the same order."""
    meshio = pytest.importorskip("meshio")  # in the test extra
    import pyvista as pv

    from latlong.meshio.readers import read_vtk_mesh

    v, f, src = _tetra(True)
    path = write_mesh(src, tmp_path / "t.vtk")
    mesh = meshio.read(path)
    assert np.array_equal(mesh.points, v.astype(np.float32))
    assert [c.type for c in mesh.cells] == ["triangle"]
    assert np.array_equal(mesh.cells[0].data, f)
    assert np.array_equal(mesh.point_data["height_m"].ravel(), [0.5, 1.5, 2.5, 3.5])
    assert np.array_equal(mesh.point_data["layer"].ravel(), [0, 1, 1, 2])
    grid = pv.read(path)
    assert isinstance(grid, pv.UnstructuredGrid) and grid.n_cells == 4
    points, faces, fields = read_vtk_mesh(path)
    assert np.array_equal(points, v) and np.array_equal(faces, f)
    assert np.array_equal(fields["layer"], [0, 1, 1, 2])
