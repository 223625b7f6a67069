"""Boulders: multi-resolution meshes, populations, placement, outputs."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import craters
from craters._boulder_kernels import _noise_kernel
from craters.boulders import parse_boulder_spec
from craters.boulders.meshes import _boulder_meshes
from latlong import (
    Body,
    BoulderLayer,
    BoulderShape,
    LatLongGrid,
    boulder,
    boulder_meshes,
    boulder_population,
    boulder_world_meshes,
    load,
    perlin_fbm,
    place_boulders,
)

MASK = 2**64 - 1


def mix64(z: int) -> int:
    """Reference splitmix64 finaliser (Steele, Lea & Flood) in Python integers."""
    z = ((z ^ (z >> 30)) * 0xBF58476D1CE4E5B9) & MASK
    z = ((z ^ (z >> 27)) * 0x94D049BB133111EB) & MASK
    return z ^ (z >> 31)


def reference_noise(seed: int, k: int) -> float:
    gold = 0x9E3779B97F4A7C15
    s = mix64((seed + gold) & MASK)
    a = mix64(s ^ ((k * gold) & MASK))
    b = mix64((a + gold) & MASK)
    u1 = ((a >> 11) + 1) * 2.0**-53
    u2 = (b >> 11) * 2.0**-53
    return float(np.sqrt(-2.0 * np.log(u1)) * np.cos(2.0 * np.pi * u2))


def test_noise_kernel_matches_python_reference():
    seeds = np.array([0, 1, 2**63 - 1, 123456789], dtype=np.uint64)
    out = np.empty((4, 50))
    _noise_kernel(seeds, out)
    for i, s in enumerate(seeds):
        for k in (0, 1, 17, 49):
            assert out[i, k] == pytest.approx(reference_noise(int(s), k), rel=1e-13, abs=1e-13)
    big = np.empty((200, 500))
    _noise_kernel(np.arange(200, dtype=np.uint64), big)
    assert abs(big.mean()) < 0.01 and abs(big.std() - 1) < 0.01


def closed_outward_manifold(v, f, centre):
    """Every undirected edge in exactly two faces with opposite directions, Euler
    characteristic 2, positive volume, and every face seen from outside from ``centre``
    (star-shaped about it, genus 0: the radial projection is one-to-one, so no face
    crosses another)."""
    e = np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]])
    directed = {tuple(x) for x in e}
    assert len(directed) == len(e), "an edge is used twice in the same direction"
    assert all((b, a) in directed for a, b in directed), "an edge has one face only"
    n_edges = len(e) // 2
    assert len(v) - n_edges + len(f) == 2
    assert len(np.unique(f)) == len(v)
    a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    volume = np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6.0
    assert volume > 0
    a, b, c = a - centre, b - centre, c - centre
    return np.einsum("ij,ij->i", a, np.cross(b, c)).min() > 0


@pytest.mark.parametrize("shape", [BoulderShape(), BoulderShape(base_level=1, n_levels=3,
                                                               roughness=0.5, flatten=0.3),
                                   BoulderShape(roughness=1.0, flatten=0.1, elongation=4.0),
                                   BoulderShape(roughness=0.0, elongation=1.0, flatten=1.0)])
@pytest.mark.parametrize("seed", [1, 2, 3])
def test_levels_counts_subsets_and_manifolds(shape, seed):
    node = boulder(rng=seed, shape=shape)
    meshes = node.meshes()
    seed64 = np.random.default_rng(seed).integers(0, 2**63, dtype=np.uint64)
    v_all, _, centre = _boulder_meshes([seed64], shape)
    assert np.array_equal(v_all[0], meshes[-1][0])
    assert [lv for lv in shape.levels] == list(range(shape.base_level,
                                                     shape.base_level + shape.n_levels))
    for lv, (v, f) in zip(shape.levels, meshes, strict=True):
        assert v.shape == (10 * 4**lv + 2, 3)
        assert f.shape == (20 * 4**lv, 3)
        assert closed_outward_manifold(v, f, centre[0])
        assert (v.max(axis=0) - v.min(axis=0)).max() <= 1.0 + 1e-12
    v, _ = meshes[-1]
    assert (v.max(axis=0) - v.min(axis=0)).max() == pytest.approx(1.0)  # the finest: unit
    for (v0, _), (v1, _) in zip(meshes, meshes[1:], strict=False):
        assert np.array_equal(v0, v1[:len(v0)])  # exact subsets
    # the bi-resolution tree: low branch = level B, high = node of the finer levels
    assert node.level == shape.base_level
    if shape.n_levels > 1:
        assert node.high.level == shape.base_level + 1 or isinstance(node.high, tuple)


def test_shape_parameters_act():
    base = boulder_meshes([7], BoulderShape(roughness=0.0, elongation=2.0, flatten=0.5))[0][0]
    ext = base.max(axis=0) - base.min(axis=0)
    assert ext[0] == pytest.approx(1.0) and ext[1] == pytest.approx(0.5, rel=0.01)
    assert ext[2] == pytest.approx(0.25, rel=0.01)
    smooth = boulder_meshes([7], BoulderShape(roughness=0.0, elongation=1.0, flatten=1.0))[0][0]
    r = np.linalg.norm(smooth - smooth.mean(axis=0), axis=1)
    assert r.std() / r.mean() < 0.06  # a subdivided icosahedron: 5 % radius spread
    rough = boulder_meshes([7], BoulderShape(roughness=0.6, elongation=1.0, flatten=1.0))[0][0]
    r2 = np.linalg.norm(rough - rough.mean(axis=0), axis=1)
    assert r2.std() / r2.mean() > 2 * r.std() / r.mean()
    # a boulder depends on its seed only, not on its neighbours in the batch
    a = boulder_meshes([5, 6, 7])[0]
    assert np.array_equal(a[2], boulder_meshes([7])[0][0])
    assert not np.array_equal(a[0], a[1])


@pytest.mark.parametrize("kwargs,needle", [
    ({"base_level": -1}, "base_level"), ({"n_levels": 0}, "n_levels"),
    ({"base_level": 5, "n_levels": 4}, "base_level"), ({"flatten": 0.0}, "flatten"),
    ({"roughness": 2.0}, "roughness"), ({"elongation": 9.0}, "elongation")])
def test_bad_shapes(kwargs, needle):
    with pytest.raises(ValueError, match=needle):
        BoulderShape(**kwargs)


@pytest.mark.parametrize("spec,needle", [
    ("c=0,k=-3,d_min_m=1,d_max_m=2", "`c`"), ("c=1,k=3,d_min_m=1,d_max_m=2", "`k`"),
    ("c=1,k=-3,d_min_m=2,d_max_m=1", "d_min_m"), ("c=1,k=-3,d_min_m=1", "missing d_max_m"),
    ("c=1,k=-3,d_min_m=1,d_max_m=2,burial_max=0.95", "burial_max"),
    ("c=1,k=-3,d_min_m=1,d_max_m=2,x=1", "x=1"),
    ("c=1,k=-3,dmin=1,d_max_m=2", "now d_min_m="),
    ("c=1,k=x,d_min_m=1,d_max_m=2", "k must be a number")])
def test_bad_layer_specs(spec, needle):
    with pytest.raises(ValueError, match=needle):
        parse_boulder_spec(spec)


@pytest.fixture(scope="module")
def rough_body():
    g = LatLongGrid(120)
    h = perlin_fbm(g, 3.0, 6, 0.5, 2.0, 40.0, rng=3)
    return Body.from_heights(g, 1000.0, h, stretch=(1.2, 1.0, 0.8))


def surface_under(body, p):
    """Independent reference: the body's triangle hit by the ray from the centre
    through each world point ``p`` (brute force over the triangles near the ray)."""
    g = body.grid
    verts = body.vertices()
    tri = g.triangles()
    cen = verts[tri].mean(axis=1)
    out = np.empty_like(p)
    for k, q in enumerate(p):
        d = q / np.linalg.norm(q)
        near = np.argsort(-(cen / np.linalg.norm(cen, axis=1, keepdims=True)) @ d)[:40]
        a, b, c = (verts[tri[near, i]] for i in range(3))
        e1, e2 = b - a, c - a
        h = np.cross(d, e2)
        det = (e1 * h).sum(1)
        s = -a
        u = (s * h).sum(1) / det
        qq = np.cross(s, e1)
        v = (qq @ d) / det
        t = (e2 * qq).sum(1) / det
        inside = (u >= -1e-9) & (v >= -1e-9) & (u + v <= 1 + 1e-9) & (t > 0)
        assert inside.any()
        out[k] = t[inside][0] * d
    return out


def test_placement_burial_and_nothing_floats(rough_body):
    layer = BoulderLayer(c=1e-3, k=-3.0, d_min_m=2.0, d_max_m=40.0, burial_max=0.5)
    found = boulder_population(rough_body, layer, rng=1)
    assert len(found) > 500
    placed = place_boulders(rough_body, found)
    size = placed["diameter_m"]
    assert np.all(np.abs(placed["bottom_depth_m"] - placed["burial_m"]) <= 0.05 * size)
    assert np.all(placed["bottom_depth_m"] > 0)
    # independent check on the world meshes: over ALL vertices of each boulder, the
    # deepest below the triangles the renderer draws is buried by the burial depth
    shape = BoulderShape()
    nv = 10 * 4**shape.levels[-1] + 2
    verts, _ = boulder_world_meshes(placed)
    verts = verts.reshape(len(placed), nv, 3)
    nrm = np.stack([placed["normal_x"], placed["normal_y"], placed["normal_z"]], 1)
    q = verts.reshape(-1, 3) / rough_body.stretch
    r = np.linalg.norm(q, axis=1)
    rad = rough_body.grid.surface_radii(rough_body.radii_m, np.arccos(q[:, 2] / r),
                                        np.arctan2(q[:, 1], q[:, 0]))
    under = (rad / r)[:, None] * q * rough_body.stretch
    depth = np.einsum("kvi,ki->kv", under.reshape(verts.shape) - verts, nrm)
    deepest = depth.max(axis=1)
    err = np.abs(deepest - placed["burial_m"]) / size
    assert err.max() < 0.05
    assert (deepest > 0).all()  # nothing floats
    # and nothing sinks out of sight: at least 40 % of the height stands out (burial is at
    # most half the height; the ground under the top is not flat)
    assert (-depth.min(axis=1) > 0.4 * placed["height_m"]).all()
    assert np.allclose(placed["burial_m"], placed["burial_frac"] * placed["height_m"])
    extent = np.einsum("kvi,ki->kv", verts, nrm)
    assert np.allclose(extent.max(1) - extent.min(1), placed["height_m"])
    # the same for a sample, brute force against the triangles
    pick = np.random.default_rng(0).choice(len(placed), 40, replace=False)
    low = verts[pick, np.argmax(depth[pick], axis=1)]
    d2 = np.einsum("ki,ki->k", surface_under(rough_body, low) - low, nrm[pick])
    assert np.allclose(d2, deepest[pick], rtol=1e-9, atol=1e-9 * size.max())
    # up axes follow the surface: close to the normals of the mesh under the boulders
    up = np.stack([placed["quat_w"], placed["quat_x"], placed["quat_y"], placed["quat_z"]], 1)
    assert np.allclose(np.linalg.norm(up, axis=1), 1.0)
    from scipy.spatial.transform import Rotation

    rot = Rotation.from_quat(up[:, [1, 2, 3, 0]]).as_matrix()
    assert np.allclose(rot[:, :, 2], nrm, atol=1e-9)


def test_surface_radii_matches_brute_force(rough_body):
    g = rough_body.grid
    rng = np.random.default_rng(4)
    colat = np.arccos(rng.uniform(-1, 1, 200))
    lon = rng.uniform(0, 2 * np.pi, 200)
    got = g.surface_radii(rough_body.radii_m, colat, lon)
    u = np.stack([np.sin(colat) * np.cos(lon), np.sin(colat) * np.sin(lon), np.cos(colat)], 1)
    plain = Body(g, rough_body.radii_m, radius_m=rough_body.radius_m)
    want = np.linalg.norm(surface_under(plain, u), axis=1)
    assert np.allclose(got, want, rtol=1e-12)
    # exact at vertices
    idx = rng.choice(g.n_vertices, 50)
    at = g.surface_radii(rough_body.radii_m, np.pi / 2 - g.latitudes()[idx], g.longitudes()[idx])
    assert np.allclose(at, rough_body.radii_m[idx], rtol=1e-12)


def test_population_counts_and_size_frequency_exponent(rough_body):
    layer = BoulderLayer(c=1e-3, k=-2.5, d_min_m=1.0, d_max_m=50.0)
    cat = boulder_population(rough_body, layer, rng=9)
    from latlong.surface import band_areas

    area = float(band_areas(rough_body).sum())
    mean = area * layer.c * (layer.d_min_m**layer.k - layer.d_max_m**layer.k)
    assert abs(len(cat) - mean) < 4 * np.sqrt(mean)
    k_fit = craters.fit_power_law_exponent(cat["diameter_m"], layer.d_min_m, layer.d_max_m)
    assert abs(k_fit / layer.k - 1) < 0.05
    assert cat["diameter_m"].min() >= 1.0 and cat["diameter_m"].max() <= 50.0
    assert (cat["kind"] == "boulder").all()
    # burial fractions uniform in [0.001, burial_max]
    frac = cat["burial_frac"]
    assert frac.min() >= 1e-3 and frac.max() <= layer.burial_max
    assert abs(frac.mean() - layer.burial_max / 2) < 0.02
    assert len(np.unique(cat["seed"])) == len(cat)


def test_boulders_near_craters():
    g = LatLongGrid(60)
    body = Body.from_heights(g, 500.0, np.zeros(g.n_vertices))
    cat = craters.make_catalog(lat_deg=[10.0, -30.0], lon_deg=[20.0, 200.0],
                               diameter_m=[120.0, 80.0])
    body = body.replace(craters=cat)
    found = boulder_population(body, BoulderLayer(c=0.05, k=-3, d_min_m=1, d_max_m=5,
                                                  near=1.0), rng=2)
    assert len(found) > 50
    lat, lon = np.radians(found["lat_deg"]), np.radians(found["lon_deg"])
    u = np.stack([np.cos(lat) * np.cos(lon), np.cos(lat) * np.sin(lon), np.sin(lat)], 1)
    cl, co = np.radians(cat["lat_deg"]), np.radians(cat["lon_deg"])
    c = np.stack([np.cos(cl) * np.cos(co), np.cos(cl) * np.sin(co), np.sin(cl)], 1)
    dist_m = np.arccos(np.clip(u @ c.T, -1, 1)) * 500.0
    ratio = (dist_m / (0.5 * cat["diameter_m"])).min(axis=1)
    assert ratio.max() <= 2.0 + 1e-9 and np.median(ratio) > 1.0


def test_determinism_and_save_load(rough_body, tmp_path):
    layer = BoulderLayer(c=5e-3, k=-3.0, d_min_m=3.0, d_max_m=30.0)
    a = place_boulders(rough_body, boulder_population(rough_body, layer, rng=5))
    b = place_boulders(rough_body, boulder_population(rough_body, layer, rng=5))
    assert a.tobytes() == b.tobytes()
    body = rough_body.replace(boulders=a)
    body.save(tmp_path / "b.npz")
    back = load(tmp_path / "b.npz")
    assert back.boulders.tobytes() == a.tobytes()
    va, fa = boulder_world_meshes(a, level=1)
    vb, fb = boulder_world_meshes(back.boulders, level=1)
    assert np.array_equal(va, vb) and np.array_equal(fa, fb)
    assert va.shape == (42 * len(a), 3) and fa.shape == (80 * len(a), 3)
    shape = dataclasses.replace(BoulderShape(), flatten=0.4)
    c = place_boulders(rough_body, a, shape=shape)
    assert c["shape_flatten"][0] == 0.4


def test_bad_placement_inputs(rough_body):
    with pytest.raises(TypeError, match="body"):
        place_boulders("x", np.zeros(0))
    cat = craters.make_catalog(lat_deg=[0.0], lon_deg=[0.0], diameter_m=[1.0])
    with pytest.raises(ValueError, match="burial_frac"):
        place_boulders(rough_body, cat)
    with pytest.raises(TypeError, match="layers"):
        boulder_population(rough_body, [])
    with pytest.raises(ValueError, match="limit 2e7"):
        boulder_population(rough_body, BoulderLayer(c=10.0, k=-3, d_min_m=0.01, d_max_m=1))


@pytest.fixture(scope="module")
def body_with_boulders():
    g = LatLongGrid(24)
    h = perlin_fbm(g, 2.0, 4, 0.5, 2.0, 15.0, rng=1)
    body = Body.from_heights(g, 400.0, h, stretch=(1.1, 1.0, 0.9))
    cat = boulder_population(body, BoulderLayer(c=4e-4, k=-3, d_min_m=2, d_max_m=12), rng=2)
    return body.replace(boulders=place_boulders(body, cat))


def test_mesh_exports_merge_boulders(body_with_boulders, tmp_path):
    import pyvista as pv
    import trimesh

    body = body_with_boulders
    nb = len(body.boulders)
    assert nb > 20
    n, t = body.n_vertices, body.grid.n_triangles
    bv, bf = boulder_world_meshes(body.boulders)
    for suffix in ("ply", "obj", "stl", "vtp"):
        path = tmp_path / f"b.{suffix}"
        body.export(path)
        if suffix == "vtp":
            mesh = pv.read(path)
            assert (mesh.n_points, mesh.n_cells) == (n + len(bv), t + len(bf))
            ids = mesh.point_data["boulder_id"]
            assert (ids[:n] == -1).all() and np.array_equal(ids[n:], np.repeat(np.arange(nb),
                                                                                 642))
            assert np.allclose(mesh.points[n:], bv, rtol=1e-6)
            continue
        mesh = trimesh.load(path, process=False)
        assert len(mesh.faces) == t + len(bf)
        if suffix == "stl":
            got = mesh.triangles[t:]
            assert np.allclose(got, bv[bf], rtol=1e-6)
            continue
        assert len(mesh.vertices) == n + len(bv)
        assert np.allclose(mesh.vertices[n:], bv, rtol=1e-6)
        assert np.array_equal(mesh.faces[t:], bf + n)
        assert mesh.is_watertight and mesh.is_winding_consistent
    # PLY: boulder_id per vertex
    raw = (tmp_path / "b.ply").read_bytes()
    head, _, body_bytes = raw.partition(b"end_header\n")
    assert b"property int boulder_id" in head
    rec = np.frombuffer(body_bytes[:(n + len(bv)) * 20],
                        dtype=[("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("h", "<f4"),
                               ("b", "<i4")])
    assert (rec["b"][:n] == -1).all() and (rec["b"][n:] == np.repeat(np.arange(nb), 642)).all()
    assert np.allclose(rec["h"][:n], body.heights_m, atol=1e-3)


def gltf_positions(gl, blob, mesh_index):
    acc = gl.accessors[gl.meshes[mesh_index].primitives[0].attributes.POSITION]
    view = gl.bufferViews[acc.bufferView]
    return np.frombuffer(blob[view.byteOffset:view.byteOffset + view.byteLength],
                         dtype="<f4").reshape(-1, 3)


def test_glb_boulder_nodes(body_with_boulders, tmp_path):
    import pygltflib
    from scipy.spatial.transform import Rotation

    from latlong.gltf import export_glb

    body = body_with_boulders
    nb = len(body.boulders)
    path = tmp_path / "b.glb"
    man = export_glb(body, path, patch_k=16, lod=2)
    assert [lv["boulder_level"] for lv in man["levels"]] == [3, 2, 1]
    gl = pygltflib.GLTF2().load(str(path))
    blob = gl.binary_blob()
    for level in range(3):
        (top,) = gl.scenes[level].nodes  # the level's node, +Y up; boulders under it
        roots = [gl.nodes[i] for i in gl.nodes[top].children]
        rocks = [r for r in roots if r.name == f"lod{level}/boulders"]
        assert len(rocks) == 1 and len(rocks[0].children) == nb
        blevel = man["levels"][level]["boulder_level"]
        want, _ = boulder_world_meshes(body.boulders, level=blevel)
        nv = 10 * 4**blevel + 2
        for i, child in enumerate(rocks[0].children):
            node = gl.nodes[child]
            assert node.extras["id"] == i and len(node.extras["lod_meshes"]) == 4
            local = gltf_positions(gl, blob, node.mesh).astype(np.float64)
            assert local.shape == (nv, 3)
            prim = gl.meshes[node.mesh].primitives[0]
            assert prim.mode == 4
            world = (Rotation.from_quat(node.rotation).apply(local * node.scale[0])
                     + node.translation)
            assert np.allclose(world, want[i * nv:(i + 1) * nv], atol=1e-6 * 500)
    # the boulder triangles load in VTK's reader with the body
    import pyvista as pv
    import vtk

    reader = vtk.vtkGLTFReader()
    reader.SetFileName(str(path))
    reader.UpdateInformation()
    reader.SetCurrentScene(1)
    reader.Update()
    it = reader.GetOutput().NewIterator()
    it.InitTraversal()
    count = 0
    while not it.IsDoneWithTraversal():
        count += pv.wrap(it.GetCurrentDataObject()).triangulate().n_cells
        it.GoToNextItem()
    assert count >= body.lod(1).grid.n_triangles + nb * 320
    # deterministic bytes
    export_glb(body, tmp_path / "c.glb", patch_k=16, lod=2)
    assert (tmp_path / "c.glb").read_bytes() == path.read_bytes()


def test_cli_build_with_boulders_same_bytes_any_thread_count(run_cli, tmp_path):
    outs = {}
    for tag, env in (("a", {}), ("b", {}), ("t1", {"NUMBA_NUM_THREADS": "1"})):
        d = tmp_path / tag
        d.mkdir()
        proc = run_cli("latlong", "build", "--base", "fbm", "--magnitude", "48", "--radius-m",
                       "300", "--craters", "c=0.05,k=-2,d_min_m=10,d_max_m=60",
                       "--boulders", "c=1e-3,k=-3,d_min_m=1,d_max_m=8,near=0.3",
                       "--boulders", "c=5e-3,k=-2.5,d_min_m=8,d_max_m=20,burial_max=0.2",
                       "--seed", "4",
                       "-o", str(d / "a.npz"), "-o", str(d / "a.ply"), "-o", str(d / "a.glb"),
                       "--boulder-catalog", str(d / "rocks.csv"), "-q", env=env)
        assert proc.returncode == 0, proc.stderr
        outs[tag] = [(d / n).read_bytes() for n in ("a.npz", "a.ply", "a.glb", "rocks.csv")]
    assert outs["a"] == outs["b"] == outs["t1"]
    body = load(tmp_path / "a" / "a.npz")
    rocks = craters.read_catalog(tmp_path / "a" / "rocks.csv")
    assert len(rocks) == len(body.boulders) > 100
    for name in ("lat_deg", "lon_deg", "diameter_m", "burial_m", "centre_x_m", "quat_w"):
        assert np.allclose(rocks[name], body.boulders[name], rtol=1e-12)
    assert set(np.unique(body.boulders["layer"])) == {0, 1}
    assert body.metadata["boulders"][0]["near"] == 0.3
    assert body.metadata["boulder_shape"]["flatten"] == 0.6


def test_cli_boulders_from_config_and_export(run_cli, tmp_path):
    cfg = tmp_path / "scene.toml"
    cfg.write_text('magnitude = 30\nbase = "sphere"\nradius_m = 200\nseed = 3\nquiet = true\n'
                   'boulder_flatten = 0.4\n[[boulders]]\nc = 0.003\nk = -3.0\n'
                   'd_min_m = 1\nd_max_m = 6\nburial_max = 0.3\n')
    out = tmp_path / "s.npz"
    proc = run_cli("latlong", "build", "--config", str(cfg), "-o", str(out))
    assert proc.returncode == 0, proc.stderr
    body = load(out)
    assert len(body.boulders) > 20 and (body.boulders["shape_flatten"] == 0.4).all()
    assert body.boulders["burial_frac"].max() <= 0.3
    proc = run_cli("latlong", "export", str(out), "-o", str(tmp_path / "s.glb"), "--lod", "1")
    assert proc.returncode == 0, proc.stderr
    import json

    man = json.loads((tmp_path / "s.json").read_text())
    assert man["boulders"]["count"] == len(body.boulders)


@pytest.mark.parametrize("args,needles", [
    (["--boulders", "c=0,k=-3,d_min_m=1,d_max_m=5"], ["--boulders", "`c`"]),
    (["--boulders", "c=1e-3,k=3,d_min_m=1,d_max_m=5"], ["--boulders", "`k`"]),
    (["--boulders", "c=1e-3,k=-3,d_min_m=5,d_max_m=1"], ["--boulders", "d_min_m"]),
    (["--boulders", "c=1e-3,k=-3,d_min_m=1"], ["--boulders", "missing d_max_m"]),
    (["--boulders", "c=1e-3,k=-3,d_min_m=1,d_max_m=5,size=3"], ["--boulders", "size=3"]),
    (["--boulders", "c=1e-3,k=-3,d_min_m=1,d_max_m=5,burial_max=1.5"],
     ["--boulders", "burial_max"]),
    (["--boulders", "c=1e-3,k=-3,d_min_m=1,d_max_m=500"], ["--boulders", "fifth"]),
    (["--boulders", "c=1e-3,k=-3,d_min_m=1,d_max_m=5", "--boulder-flatten", "0"],
     ["flatten"]),
    (["--boulders", "c=1e-3,k=-3,d_min_m=1,d_max_m=5", "--boulder-roughness", "3"],
     ["roughness"]),
    (["--boulder-catalog", "r.csv"], ["--boulder-catalog", "--boulders"]),
    # the count limit (past the memory estimate, which test_bad_inputs covers)
    (["--boulders", "c=100,k=-3,d_min_m=0.001,d_max_m=5", "--max-memory-gb", "1e12"],
     ["boulders", "2e7"]),
])
def test_cli_bad_boulder_input(run_cli, tmp_path, args, needles, one_line_error):
    proc = run_cli("latlong", "build", "--magnitude", "20", "--radius-m", "1000", *args,
                   "-o", "out.npz", cwd=tmp_path)
    one_line_error(proc, *needles)
    assert list(tmp_path.iterdir()) == []


def test_shape_levels_chunks_and_mixed_catalogs(rough_body):
    from craters.boulders import catalog_shape, mesh_chunk

    s = BoulderShape(base_level=1.0, n_levels=2.0)  # integral floats become ints
    assert s.levels == range(1, 3) and isinstance(s.base_level, int)
    assert [len(v) for v, _ in boulder(rng=1, shape=BoulderShape(n_levels=1)).meshes()] == [12]
    # chunks keep about 4 M finest vertices: 4096 boulders of 642, 102 of 40 962
    assert mesh_chunk(BoulderShape()) == 4096
    assert mesh_chunk(BoulderShape(base_level=3, n_levels=4)) == 102
    layer = BoulderLayer(c=1e-4, k=-3.0, d_min_m=2.0, d_max_m=20.0)
    found = boulder_population(rough_body, layer, rng=2)
    a = place_boulders(rough_body, found[:5])
    b = place_boulders(rough_body, found[5:10], shape=BoulderShape(flatten=1.2))
    assert catalog_shape(b).flatten == 1.2
    with pytest.raises(ValueError, match="mixes boulder shapes"):
        boulder_world_meshes(np.concatenate([a, b]))


def test_replace_is_pure_and_a_new_surface_needs_its_boulders_placed(rough_body):
    """Body.replace recomputes nothing: new radii on a body with boulders are refused
    unless its boulders are given (placed again explicitly, or dropped)."""
    layer = BoulderLayer(c=2e-4, k=-3.0, d_min_m=2.0, d_max_m=20.0)
    body = rough_body.replace(boulders=place_boulders(
        rough_body, boulder_population(rough_body, layer, rng=3)))
    assert len(body.boulders) > 20
    with pytest.raises(ValueError, match="boulders"):
        body.replace(radii_m=body.radii_m + 7.0)
    bare = body.replace(radii_m=body.radii_m + 7.0, boulders=None)
    lifted = bare.replace(boulders=place_boulders(bare, body.boulders))
    assert np.array_equal(lifted.radii_m, body.radii_m + 7.0)
    assert not np.allclose(lifted.boulders["centre_x_m"], body.boulders["centre_x_m"])
    same = body.replace(metadata={"note": "x"})  # not the surface: boulders kept as they are
    assert np.array_equal(same.boulders, body.boulders)
    with pytest.raises(ValueError, match="placed catalog"):
        rough_body.replace(boulders=boulder_population(rough_body, layer, rng=3))
