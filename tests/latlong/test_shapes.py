"""Shape-model readers and the ray-cast import onto the lat/long grid."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import pyvista as pv

from latlong import LatLongGrid
from latlong.shapes import ShapeModel, cast_radii, from_shape_model, read_shape_model
from latlong.shapes import mean_surface_distance as _msd

DATA = Path(__file__).parents[1] / "data"
DIST_TOL = 0.005  # mean surface distance, fraction of the mean radius
VOLUME_TOL = 0.01


def mean_surface_distance(a, b, rng, n=20000):
    return _msd(a, b, n_points=n, rng=rng)


# --------------------------------------------------------------------------- readers
@pytest.mark.parametrize("name,n_faces,volume_km3", [
    ("itokawa_8.obj", 768, 0.0173), ("itokawa_32.obj", 12288, 0.0177),
    ("bennu_radar_sbgat.obj", 2692, 0.0623), ("eros001708.tab", 1708, 2491.6)])
def test_real_models(name, n_faces, volume_km3):
    m = read_shape_model(DATA / name, units="km")
    assert len(m.faces) == n_faces
    assert m.volume_m3 / 1e9 == pytest.approx(volume_km3, rel=1e-3)
    assert m.faces.min() == 0 and m.faces.max() == len(m.vertices) - 1


def write_text(path, text):
    path.write_text(text)
    return path


CUBE_V = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]]
CUBE_F = [[0, 2, 1], [0, 3, 2], [4, 5, 6], [4, 6, 7], [0, 1, 5], [0, 5, 4], [1, 2, 6],
          [1, 6, 5], [2, 3, 7], [2, 7, 6], [3, 0, 4], [3, 4, 7]]


def cube_text(base=0, quads=False):
    lines = [f"v {x} {y} {z}" for x, y, z in CUBE_V]
    lines += [f"f {a + base} {b + base} {c + base}" for a, b, c in CUBE_F]
    return "\n".join(lines) + "\n"


@pytest.mark.parametrize("suffix,base", [(".obj", 1), (".tab", 0), (".tab", 1), (".plt", 1)])
def test_vf_text_formats_and_index_bases(tmp_path, suffix, base):
    m = read_shape_model(write_text(tmp_path / f"cube{suffix}", cube_text(base)), units="m")
    assert m.volume_m3 == pytest.approx(1.0)


def test_count_format(tmp_path):
    lines = ["8 12"] + [f"{i + 1} {x} {y} {z}" for i, (x, y, z) in enumerate(CUBE_V)]
    lines += [f"{i + 1} {a + 1} {b + 1} {c + 1}" for i, (a, b, c) in enumerate(CUBE_F)]
    m = read_shape_model(write_text(tmp_path / "cube.tab", "\n".join(lines)), units="km")
    assert m.volume_m3 == pytest.approx(1e9)


def test_obj_quads_negative_indices_and_inward_faces(tmp_path):
    quads = ["v 0 0 0", "v 1 0 0", "v 1 1 0", "v 0 1 0", "v 0 0 1", "v 1 0 1", "v 1 1 1",
             "v 0 1 1", "f -8 -5 -6 -7", "f -4 -3 -2 -1", "f -8 -7 -3 -4", "f -7 -6 -2 -3",
             "f -6 -5 -1 -2", "f -5 -8 -4 -1"]
    m = read_shape_model(write_text(tmp_path / "q.obj", "\n".join(quads)), units="m")
    assert len(m.faces) == 12 and m.volume_m3 == pytest.approx(1.0)  # flipped outward


@pytest.mark.parametrize("suffix", [".ply", ".stl", ".vtp"])
def test_pyvista_formats(tmp_path, suffix):
    sphere = pv.Sphere(radius=2.0, theta_resolution=24, phi_resolution=24)
    path = tmp_path / f"s{suffix}"
    sphere.save(path)
    m = read_shape_model(path, units="km")
    assert m.volume_m3 == pytest.approx(sphere.volume * 1e9, rel=1e-6)
    assert len(m.vertices) == sphere.n_points  # STL's per-facet vertices merged


def test_reader_errors(tmp_path):
    with pytest.raises(ValueError, match="units"):
        read_shape_model(DATA / "itokawa_8.obj", units="au")
    with pytest.raises(FileNotFoundError, match="does not exist"):
        read_shape_model(tmp_path / "none.obj", units="m")
    with pytest.raises(ValueError, match="empty"):
        read_shape_model(write_text(tmp_path / "e.obj", "# nothing\n"), units="m")
    open_cube = "\n".join(cube_text(1).splitlines()[:-1])
    with pytest.raises(ValueError, match="open"):
        read_shape_model(write_text(tmp_path / "o.obj", open_cube), units="m")
    doubled = cube_text(1) + "v 0.5 -1 0.5\nf 1 2 9\n"  # a fin on edge 1-2
    with pytest.raises(ValueError, match="manifold"):
        read_shape_model(write_text(tmp_path / "n.obj", doubled), units="m")
    bad = cube_text(0).replace("f 0 2 1", "f 0 2 99")
    with pytest.raises(ValueError, match="out of range"):
        read_shape_model(write_text(tmp_path / "b.tab", bad), units="m")
    with pytest.raises(ValueError, match="unknown format"):
        read_shape_model(write_text(tmp_path / "x.xyz", "1 2 3"), units="m")
    with pytest.raises(ValueError, match="non-finite"):
        read_shape_model(write_text(tmp_path / "f.obj", cube_text(1).replace("v 1 1 1",
                                                                              "v nan 1 1")),
                         units="m")


# --------------------------------------------------------------------------- casting
def test_cast_matches_brute_force():
    m = read_shape_model(DATA / "itokawa_8.obj", units="km")
    m = ShapeModel(m.vertices - m.volume_centroid, m.faces)
    g = LatLongGrid(30)
    fast = cast_radii(m, g)
    slow = cast_radii(m, g, brute_force=True)
    for a, b in zip(fast, slow, strict=True):
        assert np.array_equal(a, b)


def test_sphere_import():
    sphere = pv.Sphere(radius=1.0, theta_resolution=60, phi_resolution=60).triangulate()
    faces = np.asarray(sphere.faces).reshape(-1, 4)[:, 1:]
    model = ShapeModel(np.asarray(sphere.points, dtype=float), faces)
    body = from_shape_model(model, 40, smooth="linear", center="origin")
    # the facets' chords sit just inside the unit sphere
    assert 0.995 < body.radii_m.min() <= body.radii_m.max() <= 1.0 + 1e-9
    assert body.metadata["non_star_fraction"] == 0.0


@pytest.mark.parametrize("name", ["itokawa_32.obj", "bennu_radar_sbgat.obj"])
@pytest.mark.parametrize("smooth", ["linear", "butterfly"])
def test_import_accuracy(name, smooth):
    m = read_shape_model(DATA / name, units="km")
    body = from_shape_model(m, 200, smooth=smooth, crossings="outermost")
    src = m.to_pyvista().translate(-m.volume_centroid)
    mesh = body.to_pyvista()
    d = mean_surface_distance(mesh, src, np.random.default_rng(0))
    assert d <= DIST_TOL * body.radii_m.mean()
    assert abs(mesh.volume / m.volume_m3 - 1) <= VOLUME_TOL


def test_coarse_model_upsampled_is_closer_to_the_fine_one():
    q8 = read_shape_model(DATA / "itokawa_8.obj", units="km")
    q32 = read_shape_model(DATA / "itokawa_32.obj", units="km")
    c = q32.volume_centroid
    fine = q32.to_pyvista().translate(-c)
    rng = np.random.default_rng(1)
    d_q8 = mean_surface_distance(q8.to_pyvista().translate(-c), fine, rng)
    body = from_shape_model(q8, 200, center=c, crossings="outermost")
    d_body = mean_surface_distance(body.to_pyvista(), fine, rng)
    assert d_body < 0.8 * d_q8


def dumbbell(r_lobe=1.0, x_lobe=1.5, r_neck=0.4, n=161):
    """A closed dumbbell: two spheres joined by a capped cylinder (marching cubes)."""
    x = np.linspace(-2.7, 2.7, n)
    y = np.linspace(-1.2, 1.2, (n * 12) // 27 + 1)
    grid = pv.RectilinearGrid(x, y, y)
    p = np.asarray(grid.points)
    s1 = np.linalg.norm(p - [x_lobe, 0, 0], axis=1) - r_lobe
    s2 = np.linalg.norm(p + [x_lobe, 0, 0], axis=1) - r_lobe
    cyl = np.maximum(np.hypot(p[:, 1], p[:, 2]) - r_neck, np.abs(p[:, 0]) - x_lobe)
    grid["sdf"] = np.minimum(np.minimum(s1, s2), cyl)
    surf = grid.contour([0.0], scalars="sdf").triangulate().clean()
    faces = np.asarray(surf.faces).reshape(-1, 4)[:, 1:]
    return ShapeModel(np.asarray(surf.points, dtype=float), faces)


def dumbbell_fraction(r_lobe=1.0, x_lobe=1.5, r_neck=0.4):
    """Area fraction of directions from the centre that cross the surface more than once:
    the ray leaves the neck (t = r_neck / sin) before reaching the lobe."""
    theta = np.linspace(1e-6, np.pi / 2, 200001)
    s, c = np.sin(theta), np.cos(theta)
    disc = r_lobe**2 - (x_lobe * s) ** 2
    hits_lobe = disc > 0
    t_lobe = x_lobe * c - np.sqrt(np.where(hits_lobe, disc, 0))
    t_exit = np.minimum(r_neck / s, x_lobe / c)
    multi = hits_lobe & (t_exit < t_lobe)
    w = np.sin(theta) * (theta[1] - theta[0])  # solid angle on one side
    return float((w * multi).sum() / w.sum())


def test_non_star_shapes_detected_and_measured():
    model = dumbbell()
    with pytest.raises(ValueError, match="not star-shaped"):
        from_shape_model(model, 60, center="origin", smooth="linear")
    outer = from_shape_model(model, 60, center="origin", smooth="linear", crossings="outermost")
    inner = from_shape_model(model, 60, center="origin", smooth="linear", crossings="innermost")
    frac = outer.metadata["non_star_fraction"]
    assert abs(frac - dumbbell_fraction()) <= 0.02
    assert (outer.radii_m >= inner.radii_m).all() and (outer.radii_m > inner.radii_m).any()
    with pytest.raises(ValueError, match="miss the surface"):
        from_shape_model(model, 20, center=(5.0, 0.0, 0.0), smooth="linear")
