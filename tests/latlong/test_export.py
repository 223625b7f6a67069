"""Renderer export: strips, patch trees, LODs, glTF binary, VTP strips."""

from __future__ import annotations

import json

import numpy as np
import pytest
import pyvista as pv

from latlong import Body, LatLongGrid, perlin_fbm
from latlong.gltf import export_glb, export_vtp_strips, unit_vectors_of
from latlong.slopes import vertex_normals
from latlong.strips import (
    band_strip,
    join_strips,
    patch_tree,
    strip_triangles,
    triangle_strips,
)


def canonical(tri):
    """Rotate each triangle so its smallest index comes first (orientation kept)."""
    tri = np.asarray(tri)
    i = np.argmin(tri, axis=1)
    r = np.arange(len(tri))
    out = np.stack([tri[r, i], tri[r, (i + 1) % 3], tri[r, (i + 2) % 3]], axis=1)
    return out[np.lexsort(out.T[::-1])]


@pytest.mark.parametrize("m", [*range(1, 65), 500])
def test_strips_are_the_triangulation(m):
    g = LatLongGrid(m)
    strips = triangle_strips(g)
    assert len(strips) == 2 * m
    got = np.concatenate([strip_triangles(s) for s in strips])
    assert np.array_equal(canonical(got), canonical(g.triangles()))  # same set, same winding


def test_strip_sub_ranges_and_joins():
    g = LatLongGrid(20)
    band = g.band_triangles(7, 8)
    n = len(band)
    for lo, hi in ((0, n), (3, 17), (n - 5, n), (10, 11)):
        got = strip_triangles(band_strip(g, 7, lo, hi))
        assert np.array_equal(canonical(got), canonical(band[lo:hi]))
    joined = join_strips([band_strip(g, b) for b in range(4)])
    want = np.concatenate([g.band_triangles(b, b + 1) for b in range(4)])
    assert np.array_equal(canonical(strip_triangles(joined)), canonical(want))
    # the strips are efficient: about one vertex per triangle
    total = sum(len(s) for s in triangle_strips(LatLongGrid(200)))
    assert total < 1.01 * LatLongGrid(200).n_triangles


@pytest.mark.parametrize("m,k", [(1, 2), (16, 4), (64, 8), (64, 64), (500, 64)])
def test_patch_tree_leaves(m, k):
    g = LatLongGrid(m)
    leaves = list(patch_tree(g, k).leaves())
    all_tri, bo = g.triangles(), g.band_offsets()
    tri = []
    for leaf in leaves:
        assert leaf.n_strips() < k or leaf.longest(g) < k
        for b in range(leaf.band_lo, leaf.band_hi):
            lo, hi = leaf.triangle_range(g, b)
            tri.append(all_tri[bo[b] + lo:bo[b] + hi])
    # the leaves partition the triangulation
    assert np.array_equal(canonical(np.concatenate(tri)), canonical(g.triangles()))


@pytest.fixture(scope="module")
def body():
    g = LatLongGrid(64)
    return Body.from_heights(g, 100.0, perlin_fbm(g, 1.5, 6, 0.5, 2.0, 10.0, rng=1),
                             stretch=(1.5, 1.0, 1.0))


def test_lod_is_the_nested_body(body):
    for level in (1, 2, 3):
        coarse = body.lod(level)
        assert coarse.magnitude == 64 // 2**level
        idx = body.grid.nested_indices(coarse.grid)
        assert np.array_equal(coarse.vertices(), body.vertices()[idx])  # exactly
    with pytest.raises(ValueError, match="divisible"):
        Body.sphere(LatLongGrid(6), 1.0).lod(2)


def test_normals_and_unit_vectors(body):
    assert np.abs(body.vertex_normals() - vertex_normals(body)[0]).max() < 1e-6
    g = body.grid
    idx = np.array([0, 1, 7, 500, g.n_vertices - 2, g.n_vertices - 1])
    assert np.array_equal(unit_vectors_of(g, idx), g.unit_vectors()[idx])


def non_degenerate(faces):
    f = np.asarray(faces)
    return int(((f[:, 0] != f[:, 1]) & (f[:, 1] != f[:, 2]) & (f[:, 0] != f[:, 2])).sum())


def test_glb_loads_in_three_readers(body, tmp_path):
    path = tmp_path / "b.glb"
    man = export_glb(body, path, patch_k=16, lod=2)
    expected = [2 * body.lod(level).n_vertices - 4 for level in range(3)]
    assert [lv["n_triangles"] for lv in man["levels"]] == expected
    import pygltflib

    gl = pygltflib.GLTF2().load(str(path))
    assert len(gl.scenes) == 3 and all(p.mode == 5 for m in gl.meshes for p in m.primitives)
    import trimesh

    scene = trimesh.load(path, process=False)
    faces = [scene.geometry[scene.graph[n][1]].faces for n in scene.graph.nodes_geometry]
    assert sum(non_degenerate(f) for f in faces) == expected[0]
    # upright: the body's north pole (+Z) is glTF's +Y, its +Y glTF's -Z
    world = scene.to_geometry().vertices
    v = body.vertices()
    assert world[:, 1].max() == pytest.approx(v[:, 2].max(), rel=1e-6)
    assert world[:, 2].min() == pytest.approx(-v[:, 1].max(), rel=1e-6)
    assert world[:, 0].max() == pytest.approx(v[:, 0].max(), rel=1e-6)
    import vtk

    for level in range(3):
        reader = vtk.vtkGLTFReader()
        reader.SetFileName(str(path))
        reader.UpdateInformation()
        reader.SetCurrentScene(level)
        reader.Update()
        it = reader.GetOutput().NewIterator()
        it.InitTraversal()
        count = 0
        while not it.IsDoneWithTraversal():
            tri = pv.wrap(it.GetCurrentDataObject()).triangulate()
            count += non_degenerate(tri.faces.reshape(-1, 4)[:, 1:])
            it.GoToNextItem()
        assert count == expected[level]
    # manifest: bounding spheres hold their patches' vertices; byte ranges point at them
    doc = json.loads(path.with_suffix(".json").read_text())
    raw = path.read_bytes()
    base = doc["bin_chunk_offset"]
    for patch in doc["levels"][0]["patches"][::7]:
        off, n = patch["bytes"]["positions"]
        pos = np.frombuffer(raw[base + off: base + off + n], dtype="<f4").reshape(-1, 3)
        d = np.linalg.norm(pos - np.asarray(patch["centre_m"]), axis=1)
        assert d.max() <= patch["radius_m"] * (1 + 1e-6) + 1e-6


def test_the_camera_shades_with_the_gltf_normals(body):
    """One vertex-normal definition (angle-weighted, as Mitsuba 3 and Blender compute
    theirs): the camera's smooth shading normals of a body are the glTF export's."""
    from latlong.geometry.normals import lat_long_vertex_normals
    from latlong.sensors import RayMesh

    camera = RayMesh(*body.mesh()).vertex_normals
    gltf = lat_long_vertex_normals(body.grid, body.radii_m, body.stretch, weighting="angle")
    assert np.abs(camera - gltf).max() < 1e-6  # float32 in the file


def test_separate_levels_are_one_file_each(body, tmp_path, run_cli):
    """--lods separate: level l in <stem>.lod<l>.glb, one scene each (what Blender's
    importer needs: it puts every scene of one file into one Blender scene)."""
    import pygltflib

    path = tmp_path / "s.glb"
    man = export_glb(body, path, patch_k=16, lod=2, lods="separate")
    assert man["files"] == ["s.glb", "s.lod1.glb", "s.lod2.glb"]
    one = export_glb(body, tmp_path / "one.glb", patch_k=16, lod=2)
    for level, name in enumerate(man["files"]):
        gl = pygltflib.GLTF2().load(str(tmp_path / name))
        assert len(gl.scenes) == 1 and gl.nodes[gl.scenes[0].nodes[0]].name == f"lod{level}"
        doc = json.loads((tmp_path / name).with_suffix(".json").read_text())
        assert doc["levels"][0]["n_triangles"] == one["levels"][level]["n_triangles"]
        assert doc["levels"][0]["level"] == level
    with pytest.raises(ValueError, match="lods"):
        export_glb(body, tmp_path / "x.glb", lods="nested")
    body.save(tmp_path / "b.npz")
    r = run_cli("latlong", "export", str(tmp_path / "b.npz"), "-o", str(tmp_path / "c.glb"),
                "--lod", "1", "--lods", "separate", "-q")
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "c.lod1.glb").is_file() and (tmp_path / "c.lod1.json").is_file()
    r = run_cli("latlong", "export", str(tmp_path / "b.npz"), "-o", str(tmp_path / "c.glb"),
                "--lod", "1", "--lods", "separate", "-q")
    assert r.returncode == 2 and "exists" in r.stderr


def test_export_is_deterministic(body, tmp_path):
    a, b = tmp_path / "a.glb", tmp_path / "b.glb"
    export_glb(body, a, patch_k=32, lod=1)
    export_glb(body, b, patch_k=32, lod=1)
    assert a.read_bytes() == b.read_bytes()
    ma = json.loads(a.with_suffix(".json").read_text())
    mb = json.loads(b.with_suffix(".json").read_text())
    assert ma.pop("glb") == "a.glb" and mb.pop("glb") == "b.glb"
    assert ma.pop("buffers") == ["a.glb"] and mb.pop("buffers") == ["b.glb"] and ma == mb


def test_past_4_gib_levels_go_to_external_buffers(body, tmp_path, monkeypatch):
    import latlong.gltf as gltf

    monkeypatch.setattr(gltf, "GLB_LIMIT", 100_000)  # pretend the data is too large
    path = tmp_path / "big.glb"
    man = export_glb(body, path, patch_k=16, lod=1)
    assert man["buffers"] == ["big.lod0.bin", "big.lod1.bin"]
    raw_glb = path.read_bytes()
    json_len = int(np.frombuffer(raw_glb[12:16], dtype="<u4")[0])
    assert len(raw_glb) == 12 + 8 + json_len  # a JSON chunk only, no embedded binary
    doc = json.loads(raw_glb[20:20 + json_len])
    assert [b["uri"] for b in doc["buffers"]] == man["buffers"]
    for b in doc["buffers"]:
        assert (tmp_path / b["uri"]).stat().st_size == b["byteLength"]
    import trimesh

    scene = trimesh.load(path, process=False)
    faces = [scene.geometry[scene.graph[n][1]].faces for n in scene.graph.nodes_geometry]
    assert sum(non_degenerate(f) for f in faces) == body.grid.n_triangles
    patch = man["levels"][1]["patches"][0]
    raw = (tmp_path / "big.lod1.bin").read_bytes()
    off, n = patch["bytes"]["indices"]
    assert len(np.frombuffer(raw[off:off + n], dtype="<u4")) == patch["strip_length"]


def test_vtp_strips(body, tmp_path):
    path = tmp_path / "s.vtp"
    export_vtp_strips(body, path)
    mesh = pv.read(path)
    assert mesh.n_strips == 2 * body.magnitude
    tri = mesh.triangulate().faces.reshape(-1, 4)[:, 1:]
    assert non_degenerate(tri) == body.grid.n_triangles
    assert "Normals" in mesh.point_data and "height_m" in mesh.point_data


def test_export_cli(run_cli, tmp_path, body):
    model = tmp_path / "m.npz"
    body.save(model)
    out = tmp_path / "m.glb"
    proc = run_cli("latlong", "export", str(model), "-o", str(out), "--patch-k", "16",
                   "--lod", "3", "-q")
    assert proc.returncode == 0, proc.stderr
    assert out.exists() and out.with_suffix(".json").exists()
    for args, needle in ((["--lod", "7"], "--lod"), (["--patch-k", "1"], "--patch-k")):
        proc = run_cli("latlong", "export", str(model), "-o", str(tmp_path / "x.glb"), *args)
        assert proc.returncode == 2 and needle in proc.stderr
        assert len(proc.stderr.strip().splitlines()) == 1
    assert not (tmp_path / "x.glb").exists()


def replay_a_steps(na, nb, steps):
    """Reference: replay the zipper step by step (ring-a advances among ``steps``)."""
    i = j = 0
    for _ in range(steps):
        if na > 1 and i < na and (j >= nb or (i + 1) * nb <= (j + 1) * na):
            i += 1
        else:
            j += 1
    return i


@pytest.mark.parametrize("na,nb", [(1, 6), (6, 12), (12, 6), (18, 24), (600, 606),
                                   (606, 600), (7, 7), (5, 13)])
def test_zipper_state_in_closed_form(na, nb):
    from latlong._grid_kernels import _zipper_a_steps

    steps = na + nb if na > 1 else nb
    assert [_zipper_a_steps(na, nb, s) for s in range(steps + 1)] == [
        replay_a_steps(na, nb, s) for s in range(steps + 1)]


def test_longitude_table_is_the_unit_vectors():
    from latlong._grid_kernels import lon_table

    g = LatLongGrid(7)
    table = lon_table(7, g.ring_offsets())
    u, off = g.unit_vectors(), g.ring_offsets()
    for r in range(1, 2 * 7):  # cos(lat) * table = the unit vectors' x and y, exactly
        row = off[min(r, 14 - r)] - 1
        n = off[r + 1] - off[r]
        lat = 0.5 * np.pi - r * (np.pi / 14)
        assert np.array_equal(np.cos(lat) * table[row:row + n], u[off[r]:off[r + 1], :2])


def reference_patches(body, patch_k):
    """The glTF patch data the numpy way (the export before its kernels): per leaf the
    joined strip, np.unique, float32 positions (u * r) * s, normals (angle-weighted, as
    the camera's: the streamed kernel, itself checked against numpy in test_patchdata),
    bounds."""
    from latlong.geometry.normals import lat_long_vertex_normals

    grid = body.grid
    normals = lat_long_vertex_normals(grid, body.radii_m, body.stretch, weighting="angle")
    radii, stretch = np.asarray(body.radii_m), np.asarray(body.stretch)
    for leaf in patch_tree(grid, patch_k).leaves():
        strip = join_strips(leaf.strips(grid))
        if len(strip) < 3:
            continue
        idx, local = np.unique(strip, return_inverse=True)
        pos = (unit_vectors_of(grid, idx) * radii[idx, None] * stretch).astype(np.float32)
        lo, hi = pos.min(axis=0), pos.max(axis=0)
        centre = 0.5 * (lo.astype(np.float64) + hi)
        radius = float(np.sqrt(((pos - centre) ** 2).sum(axis=1).max()))
        yield pos, normals[idx], local.astype(np.uint32), centre, radius, len(
            strip_triangles(strip))


@pytest.mark.parametrize("m,k,stretch", [(1, 2, (1, 1, 1)), (5, 2, (1, 1, 1)),
                                         (24, 3, (1.5, 1.0, 0.75)), (40, 16, (1, 2, 1))])
def test_glb_patches_match_the_numpy_reference(tmp_path, m, k, stretch):
    g = LatLongGrid(m)
    body = Body.from_heights(g, 50.0, np.random.default_rng(m).normal(0, 2, g.n_vertices),
                             stretch=stretch)
    man = export_glb(body, tmp_path / "p.glb", patch_k=k)
    raw = (tmp_path / "p.glb").read_bytes()
    base = man["bin_chunk_offset"]
    want = list(reference_patches(body, k))
    got = man["levels"][0]["patches"]
    assert len(got) == len(want)
    for patch, (pos, nrm, ind, centre, radius, n_tri) in zip(got, want, strict=True):
        for name, data in (("positions", pos), ("normals", nrm), ("indices", ind)):
            off, n = patch["bytes"][name]
            assert raw[base + off:base + off + n] == np.ascontiguousarray(data).tobytes()
        assert patch["centre_m"] == centre.tolist() and patch["radius_m"] == radius
        assert patch["n_triangles"] == n_tri and patch["strip_length"] == len(ind)


@pytest.mark.parametrize("with_boulders", [False, True])
def test_ply_fast_path_gives_the_generic_bytes(tmp_path, with_boulders):
    import dataclasses

    from latlong import BoulderLayer, boulder_population, place_boulders
    from latlong.export import body_mesh_source
    from latlong.meshio.writers import write_mesh

    g = LatLongGrid(24)
    body = Body.from_heights(g, 400.0, perlin_fbm(g, 2.0, 4, 0.5, 2.0, 15.0, rng=1),
                             stretch=(1.1, 1.0, 0.9))
    if with_boulders:
        cat = boulder_population(body, BoulderLayer(c=4e-4, k=-3, d_min_m=2, d_max_m=12),
                                 rng=2)
        body = body.replace(boulders=place_boulders(body, cat))
    body.export(tmp_path / "fast.ply")
    src = dataclasses.replace(body_mesh_source(body), vertex_records=None, face_records=None)
    write_mesh(src, tmp_path / "generic.ply")
    assert (tmp_path / "fast.ply").read_bytes() == (tmp_path / "generic.ply").read_bytes()


def test_ply_fast_path_in_several_chunks(tmp_path, monkeypatch):
    import latlong.export as export

    body = Body.from_heights(LatLongGrid(30), 10.0, np.linspace(-1, 1, 5402))
    body.export(tmp_path / "one.ply")
    monkeypatch.setattr(export, "_CHUNK", 1000)  # several vertex and face chunks
    body.export(tmp_path / "many.ply")
    assert (tmp_path / "one.ply").read_bytes() == (tmp_path / "many.ply").read_bytes()


def test_glb_in_several_groups(tmp_path, body, monkeypatch):
    import latlong.patchdata as patchdata

    export_glb(body, tmp_path / "one.glb", patch_k=8, lod=1)
    monkeypatch.setattr(patchdata, "GROUP_BYTES", 5000)  # many groups of patches
    export_glb(body, tmp_path / "many.glb", patch_k=8, lod=1)
    assert (tmp_path / "one.glb").read_bytes() == (tmp_path / "many.glb").read_bytes()


def test_ply_without_the_longitude_table_gives_the_same_bytes(tmp_path, monkeypatch):
    """Past _TABLE_BYTES the PLY kernel computes the longitudes' cosines and sines itself
    (no 8 B a vertex table for huge bodies): the same records."""
    import latlong.export as export

    body = Body.from_heights(LatLongGrid(30), 10.0, np.linspace(-1, 1, 5402),
                             stretch=(1.2, 1.0, 0.9))
    body.export(tmp_path / "table.ply")
    monkeypatch.setattr(export, "_TABLE_BYTES", 0)
    body.export(tmp_path / "computed.ply")
    assert (tmp_path / "table.ply").read_bytes() == (tmp_path / "computed.ply").read_bytes()
