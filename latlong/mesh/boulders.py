"""Boulders on a mesh surface: populations from its area, placement on the triangles.

As on the lat/long body (:mod:`latlong.boulders`, Martin 2014 V.C): positions uniform
on the surface or, for a share ``near``, around crater rims (in the crater's plane, then
onto the closest surface point); each boulder's up axis is the surface normal there
(vertex normals interpolated in its triangle), it turns by its azimuth and sinks until
its deepest point is its burial below the triangle mesh, the depth of a point measured
along the boulder's normal to the mesh (:meth:`TriangleGrid.depths`: the nearest crossing
on faces turned along the normal, so never the other side of a thin part).
"""

from __future__ import annotations

import functools

import numpy as np

import craters as _craters
from craters._shared import normalize_rng
from craters.boulders import (
    BoulderLayer,
    BoulderShape,
    boulder_meshes,
    draw_boulder_layer,
    mesh_chunk,
    near_crater_draws,
    orientations,
    placed_columns,
    rest_on_ground,
)

from ..boulders import placement_request
from .cratering import sample_mesh_points
from .surface import MeshSurface, lat_lon_deg
from .topology import TriangleGrid

__all__ = ["mesh_boulder_population", "place_mesh_boulders"]


def _points(vertices, faces, face, uv):
    a, b, c = (vertices[faces[face, k]] for k in range(3))
    return a + uv[:, :1] * (b - a) + uv[:, 1:] * (c - a)


def mesh_boulder_population(surface: MeshSurface, layers, *, rng=None) -> np.ndarray:
    """A boulder catalog for ``surface`` (before placement): counts from its area.

    Columns as :func:`latlong.boulder_population` (``lat_deg, lon_deg`` seen from the
    origin) plus the ground point ``ground_x_m, ground_y_m, ground_z_m`` on the surface.
    A layer's share ``near`` goes around the rims of the surface's craters (weighted by
    their area, 1-2 crater radii from the centre in the crater's plane).
    """
    if not isinstance(surface, MeshSurface):
        raise TypeError(f"`surface` must be a MeshSurface; got {type(surface).__name__}")
    if isinstance(layers, BoulderLayer):
        layers = [layers]
    if not layers or not all(isinstance(la, BoulderLayer) for la in layers):
        raise TypeError("`layers` must be a BoulderLayer or a non-empty list of them")
    rng = normalize_rng(rng)
    v, f = surface.vertices, surface.faces
    area = surface.area_m2
    cat = surface.craters
    grid = None
    parts = []
    for idx, la in enumerate(layers):
        cols = draw_boulder_layer(la, area, idx, rng)
        n = len(cols["diameter_m"])
        p = _points(v, f, *sample_mesh_points(v, f, n, rng))
        n_near = int(round(la.near * n)) if cat is not None and len(cat) else 0
        if n_near:
            assert cat is not None  # n_near > 0 needs craters
            pick, r, az = near_crater_draws(cat["diameter_m"], n_near, rng)
            up = np.stack([cat["normal_x"], cat["normal_y"], cat["normal_z"]], 1)[pick]
            ref = np.where(np.abs(up[:, 2:]) < 0.9, [[0.0, 0.0, 1.0]], [[1.0, 0.0, 0.0]])
            east = np.cross(ref, up)
            east /= np.linalg.norm(east, axis=1, keepdims=True)
            north = np.cross(up, east)
            c = np.stack([cat["centre_x_m"], cat["centre_y_m"], cat["centre_z_m"]], 1)[pick]
            q = c + r[:, None] * (np.cos(az)[:, None] * east + np.sin(az)[:, None] * north)
            grid = grid or TriangleGrid.build(v, f)
            face, uv, _ = grid.closest(q)
            p[:n_near] = _points(v, f, face, uv)
        lat, lon = lat_lon_deg(p)
        parts.append(_craters.make_catalog(lat_deg=lat, lon_deg=lon, **cols, ground_x_m=p[:, 0],
                                           ground_y_m=p[:, 1], ground_z_m=p[:, 2]))
    return np.concatenate(parts)


def place_mesh_boulders(surface: MeshSurface, catalog, *, shape: BoulderShape | None = None,
                        max_iterations: int = 12) -> np.ndarray:
    """Place a boulder catalog on ``surface``; returns the catalog with the placement.

    The columns of :func:`latlong.place_boulders` (centre, normal, rotation, height,
    burial, ``bottom_depth_m``); each boulder rests at the surface point closest to its
    ``ground_x_m, ground_y_m, ground_z_m`` (module notes).
    """
    if not isinstance(surface, MeshSurface):
        raise TypeError(f"`surface` must be a MeshSurface; got {type(surface).__name__}")
    cat, shape = placement_request(catalog, shape, max_iterations,
                                   ("ground_x_m", "ground_y_m", "ground_z_m"))
    n = len(cat)
    v, f = surface.vertices, surface.faces
    grid = TriangleGrid.build(v, f)
    face, uv, _ = grid.closest(np.stack([cat["ground_x_m"], cat["ground_y_m"],
                                         cat["ground_z_m"]], 1))
    ground = _points(v, f, face, uv)
    vn = surface.vertex_normals("area")
    w = np.stack([1.0 - uv.sum(axis=1), uv[:, 0], uv[:, 1]], 1)
    nrm = np.einsum("kc,kci->ki", w, vn[f[face]])
    nrm /= np.linalg.norm(nrm, axis=1, keepdims=True)
    rot = orientations(nrm, np.radians(cat["azimuth_deg"]))
    centre = np.empty((n, 3))
    achieved, height, burial = np.empty(n), np.empty(n), np.empty(n)
    chunk = mesh_chunk(shape)
    depths = functools.partial(grid.depths, margin_m=2.0 * grid.cell_m)
    for s0 in range(0, n, chunk):  # a chunk of boulders at a time (bounded memory)
        sl = slice(s0, min(s0 + chunk, n))
        verts, _ = boulder_meshes(cat["seed"][sl], shape)
        size = cat["diameter_m"][sl]
        world = np.einsum("kij,kvj->kvi", rot[sl], verts * size[:, None, None])
        centre[sl], achieved[sl], height[sl], burial[sl] = rest_on_ground(
            depths, world, ground[sl], nrm[sl], cat["burial_frac"][sl], size,
            max_iterations=max_iterations)
    cols = placed_columns(cat, centre, nrm, rot, height, burial, achieved, shape)
    cols["ground_x_m"], cols["ground_y_m"], cols["ground_z_m"] = ground.T
    cols["lat_deg"], cols["lon_deg"] = lat_lon_deg(ground)
    return _craters.make_catalog(**cols)
