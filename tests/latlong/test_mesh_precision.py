"""Mesh files of a small window far from its origin keep their detail (issue 33's finding):
float32 positions step 0.125 m at the Moon's radius, so a centimetre window of the Moon in
its body frame came out terraced; past 100 km from the origin the positions are float64
(PLY, VTP, VTK; OBJ with 12 digits), read back exactly by craterform and by VTK."""

from __future__ import annotations

import numpy as np
import pytest

from latlong.meshio.readers import read_mesh
from latlong.meshio.writers import FLOAT64_BEYOND_M, array_source, write_mesh

MOON_M = 1_737_400.0


def _window(radius_m: float, step_m: float = 0.01, n: int = 8):
    """An n x n grid of ``step_m`` on the sphere of ``radius_m`` (body frame), triangulated."""
    i, j = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
    x, y = (i * step_m).ravel(), (j * step_m).ravel()
    z = np.sqrt(radius_m**2 - x**2 - y**2) + 0.003 * np.sin(i.ravel() + 2 * j.ravel())
    verts = np.column_stack([x, y, z])
    k = (i[:-1, :-1] * n + j[:-1, :-1]).ravel()
    faces = np.concatenate([np.column_stack([k, k + n, k + 1]),
                            np.column_stack([k + 1, k + n, k + n + 1])])
    return verts, faces


@pytest.mark.parametrize("suffix", [".ply", ".vtp", ".vtk", ".obj"])
def test_a_centimetre_window_of_the_moon_keeps_its_millimetres(tmp_path, suffix):
    verts, faces = _window(MOON_M)
    path = write_mesh(array_source(verts, faces, "moon window"), tmp_path / f"w{suffix}")
    back = read_mesh(path, units="m")
    tol = 1e-5 if suffix == ".obj" else 1e-9  # 12 significant digits of 1.7e6 m
    assert np.abs(back.vertices - verts).max() < tol
    # float32 flattens the +-3 mm relief onto one 0.125 m step; the file keeps every height
    assert np.ptp(verts[:, 2].astype(np.float32)) == 0
    assert np.ptp(back.vertices[:, 2]) > 0.005


def test_a_small_body_stays_float32(tmp_path):
    verts, faces = _window(500.0, step_m=1.0)
    src = array_source(verts, faces, "asteroid window")
    assert src.position_type == "<f4" and FLOAT64_BEYOND_M == 1e5
    head = write_mesh(src, tmp_path / "a.ply").read_bytes()[:400]
    assert b"property float x" in head
    assert b"property double x" in write_mesh(array_source(*_window(MOON_M), "moon"),
                                              tmp_path / "m.ply").read_bytes()[:400]


def test_vtk_reads_the_float64_points(tmp_path):
    # (VTK's PLY reader keeps float32 points whatever the file holds: .vtp or .vtk for VTK)
    import pyvista as pv

    verts, faces = _window(MOON_M)
    for suffix in (".vtp", ".vtk"):
        mesh = pv.read(write_mesh(array_source(verts, faces, "moon"), tmp_path / f"v{suffix}"))
        assert mesh.points.dtype == np.float64
        assert np.abs(np.asarray(mesh.points) - verts).max() < 1e-9
