"""Multi-resolution meshes: crack-free stitching, orientation, frame, PLY/VTP files."""

from __future__ import annotations

import collections

import numpy as np
import pytest
import pyvista
from affine import Affine
from rasterio.windows import Window

import dem
from dem.frame import pixel_affine
from dem.mesh import mesh_arrays, to_mesh


@pytest.fixture(scope="module")
def stack():
    seed = dem.Dem(np.random.default_rng(2).normal(0, 30, (9, 9)), pixel_size_m=400.0)
    e = dem.expand(seed, 2, fractal_dimension=2.3, roughness=0.05, rng=1)  # 33^2, 100 m
    base = dem.Dem(e.heights, Affine(100.0, 0, 1000.0, 0, -100.0, 9000.0), "EPSG:32633")
    x, y = base.xy(6, 26)  # off centre: the footprints shift to stay inside
    return dem.enhance({"layers": 4, "size": 17, "seed": 1, "target": [float(x), float(y)],
                        "craters": ["c=0.05,k=-2,d_min_m=20,d_max_m=800"]}, dem=base)


def test_mesh_is_one_closed_sheet_without_cracks(stack):
    v, f, layer = mesh_arrays(stack)
    n, w = 17, 9
    assert len(v) == 3 * (n * n - w * w) + n * n
    assert len(np.unique(f)) == len(v)  # every vertex used
    edges = np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]])
    directed = collections.Counter(map(tuple, edges))
    assert max(directed.values()) == 1  # consistently oriented, no duplicated triangle
    undirected = collections.Counter(map(tuple, np.sort(edges, axis=1)))
    boundary = [e for e, c in undirected.items() if c == 1]
    assert set(undirected.values()) == {1, 2}
    assert len(boundary) == 4 * (n - 1)  # only layer 0's outline is open
    assert set(layer[np.unique(boundary)]) == {0}
    # no T-junction: no vertex lies inside an edge it does not belong to -- checked through
    # Euler's formula for a disc (V - E + F = 1), which a crack or a T-junction breaks
    assert len(v) - len(undirected) + len(f) == 1


def test_triangles_face_up_and_have_the_layer_sizes(stack):
    v, f, layer = mesh_arrays(stack)
    a = v[f[:, 1], :2] - v[f[:, 0], :2]
    b = v[f[:, 2], :2] - v[f[:, 0], :2]
    area2 = a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]
    assert (area2 > 0).all()
    sizes = stack.pixel_sizes_m()
    finest = layer[f].min(axis=1) == 3
    assert np.allclose(area2[finest & (layer[f].max(axis=1) == 3)], sizes[3] ** 2)
    assert area2.sum() / 2 == pytest.approx((16 * sizes[0]) ** 2)  # layer 0's area, once


def test_shared_vertices_are_where_both_layers_put_them(stack):
    frame = stack.frame
    for k, (r0, c0, w) in enumerate(stack.windows):
        coarse, fine = stack.layers[k], stack.layers[k + 1]
        s = np.arange(w)
        rows = np.concatenate([np.full(w, r0), np.full(w, r0 + w - 1), r0 + s, r0 + s])
        cols = np.concatenate([c0 + s, c0 + s, np.full(w, c0), np.full(w, c0 + w - 1)])
        a, b = pixel_affine(coarse, frame), pixel_affine(fine, frame)
        pa = np.stack(a @ (cols, rows))
        pb = np.stack(b @ (2 * (cols - c0), 2 * (rows - r0)))
        assert np.abs(pa - pb).max() < 1e-6
        assert np.array_equal(coarse.heights[rows, cols],
                              fine.heights[2 * (rows - r0), 2 * (cols - c0)])
    v, _, layer = mesh_arrays(stack)
    assert v[layer == 3][:, :2].min(axis=0) == pytest.approx(-8 * stack.pixel_sizes_m()[3]
                                                             * np.ones(2), abs=1e-6)


@pytest.mark.parametrize("suffix", [".ply", ".vtp"])
def test_files_read_back_as_the_mesh(tmp_path, stack, suffix):
    v, f, layer = mesh_arrays(stack)
    path = to_mesh(stack, tmp_path / f"m{suffix}")
    m = pyvista.read(path)
    assert m.n_points == len(v) and m.n_cells == len(f)
    assert np.abs(m.points - v).max() < 1e-3 * max(1.0, np.abs(v).max() * 1e-4)
    assert np.array_equal(m.regular_faces, f)
    if suffix == ".vtp":
        assert np.array_equal(m.point_data["layer"], layer)
    again = to_mesh(stack, tmp_path / f"n{suffix}")
    assert again.read_bytes() == path.read_bytes()
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted([f"m{suffix}", f"n{suffix}"])


def test_single_dem_mesh_and_errors(tmp_path, lola_crop):
    small = lola_crop.crop(Window(100, 100, 9, 9))
    v, f, layer = mesh_arrays(small)
    assert len(v) == 81 and len(f) == 128 and (layer == 0).all()
    assert np.abs(v[40, :2]).max() < 1e-6  # the centre pixel is the origin
    assert v[:, 0].max() == pytest.approx(4 * small.pixel_size_m[0], rel=1e-3)
    z = np.array(small.heights)
    z[2, 2] = np.nan
    with pytest.raises(ValueError, match="NaN"):
        to_mesh(small.replace(heights=z), tmp_path / "x.ply")
    with pytest.raises(ValueError, match="unknown mesh format"):
        to_mesh(small, tmp_path / "x.xyz")
    with pytest.raises(TypeError, match="Stack or a Dem"):
        to_mesh(np.zeros((3, 3)), tmp_path / "x.ply")
    assert list(tmp_path.iterdir()) == []


def test_footprint_touching_the_border_is_refused(stack):
    base = stack.layers[0]
    fine = dem.expand(base, 1, 2.3, 0.05, Window(0, 0, 9, 9), rng=1)
    s = dem.Stack([base, fine], [(0, 0, 9)], stack.frame)
    with pytest.raises(ValueError, match="one pixel clear"):
        mesh_arrays(s)

