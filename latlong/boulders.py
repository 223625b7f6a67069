"""Boulders on a body (Martin 2014, V.C): populations from the body's area, placement.

The shapes and size distributions are :mod:`craters.boulders`. Positions are uniform on
the body's actual surface or, for a share ``near``, around crater rims and ejecta.
Placement aligns the boulder's up axis (z) with the local surface normal, turns it by a
random azimuth about the normal, and sets its deepest point ``burial`` below the
triangle mesh a renderer draws.
"""

from __future__ import annotations

import functools

import numpy as np

import craters as _craters
from craters._shared import check_int, normalize_rng
from craters.boulders import (
    BoulderLayer,
    BoulderNode,
    BoulderShape,
    boulder,
    boulder_meshes,
    boulder_world_meshes,
    catalog_shape,
    draw_boulder_layer,
    iter_boulder_meshes,
    mesh_chunk,
    near_crater_draws,
    orientations,
    parse_boulder_spec,
    placed_columns,
    rest_on_ground,
)

from .body import Body
from .surface import band_areas, sample_surface_points

__all__ = ["BoulderLayer", "BoulderNode", "BoulderShape", "boulder", "boulder_meshes",
           "boulder_population", "boulder_world_meshes", "catalog_shape",
           "iter_boulder_meshes", "parse_boulder_spec", "place_boulders"]



def _move(lat_deg, lon_deg, dist_rad, az):
    """Points at angular distance ``dist_rad`` and azimuth ``az`` (from north) from each
    (lat, lon) along great circles."""
    la, lo = np.radians(lat_deg), np.radians(lon_deg)
    la2 = np.arcsin(np.clip(np.sin(la) * np.cos(dist_rad)
                            + np.cos(la) * np.sin(dist_rad) * np.cos(az), -1, 1))
    lo2 = lo + np.arctan2(np.sin(az) * np.sin(dist_rad) * np.cos(la),
                          np.cos(dist_rad) - np.sin(la) * np.sin(la2))
    return np.degrees(la2), np.mod(np.degrees(lo2), 360.0)


def boulder_population(body: Body, layers, *, rng=None) -> np.ndarray:
    """A boulder catalog for ``body`` (before placement): counts from its actual area.

    Columns: ``lat_deg, lon_deg, diameter_m, burial_frac, azimuth_deg, seed, layer`` plus
    the crater-catalog defaults (``age_gyr = degradation = 0``, ``kind = "boulder"``).
    """
    if isinstance(layers, BoulderLayer):
        layers = [layers]
    if not layers or not all(isinstance(la, BoulderLayer) for la in layers):
        raise TypeError("`layers` must be a BoulderLayer or a non-empty list of them")
    rng = normalize_rng(rng)
    totals = band_areas(body)
    area = float(totals.sum())
    parts = []
    cat = body.craters
    for idx, la in enumerate(layers):
        cols = draw_boulder_layer(la, area, idx, rng)
        n = len(cols["diameter_m"])
        lat, lon, _ = sample_surface_points(body, totals, n, rng)
        n_near = int(round(la.near * n)) if cat is not None and len(cat) else 0
        if n_near:
            assert cat is not None  # n_near > 0 needs craters
            pick, r, az = near_crater_draws(cat["diameter_m"], n_near, rng)
            rloc = np.asarray(body.radius_m)
            la2, lo2 = _move(cat["lat_deg"][pick], cat["lon_deg"][pick], r / rloc, az)
            lat[:n_near], lon[:n_near] = la2, lo2
        parts.append(_craters.make_catalog(lat_deg=lat, lon_deg=lon, **cols))
    return np.concatenate(parts)


# --------------------------------------------------------------------------- placement
def _depths(body: Body, points: np.ndarray, nrm: np.ndarray) -> np.ndarray:
    """Depth below the body's triangle mesh of each boulder's points (k, c, 3): for every
    point the mesh point on the ray from the body's centre through it, depth measured
    along the boulder's normal (k, 3); positive = below the surface. Returns (k, c)."""
    stretch = np.asarray(body.stretch)
    q = points.reshape(-1, 3) / stretch
    r = np.linalg.norm(q, axis=1)
    colat = np.arccos(np.clip(q[:, 2] / r, -1, 1))
    lon = np.arctan2(q[:, 1], q[:, 0])
    scale = body.grid.surface_radii(body.radii_m, colat, lon) / r
    under = (q * scale[:, None]) * stretch
    return np.einsum("kci,ki->kc", under.reshape(points.shape) - points, nrm)


def placement_request(catalog, shape, max_iterations: int,
                      position: tuple[str, ...]) -> tuple[np.ndarray, BoulderShape]:
    """Check a boulder placement once (a body's, a mesh's): ``(catalog, shape)`` with the
    catalog's ``position`` columns and what placement reads; errors name the parameter."""
    shape = BoulderShape() if shape is None else shape
    if not isinstance(shape, BoulderShape):
        raise TypeError(f"`shape` must be a BoulderShape; got {type(shape).__name__}")
    cat = np.asarray(catalog)
    for name in (*position, "diameter_m", "burial_frac", "azimuth_deg", "seed"):
        if name not in (cat.dtype.names or ()):
            raise ValueError(f"boulder catalog needs a {name!r} column")
    check_int("max_iterations", max_iterations, 1, 100)
    return cat, shape


def place_boulders(body: Body, catalog, *, shape: BoulderShape | None = None,
                   max_iterations: int = 12) -> np.ndarray:
    """Place a boulder catalog on ``body``; returns the catalog with the placement.

    Each boulder's up axis is the local surface normal (area-weighted vertex normals
    interpolated at its position), turned by its ``azimuth_deg``; its centre is set so
    that its deepest point (finest level) is ``burial_m = burial_frac x height`` below the
    body's triangle mesh (height = the boulder's extent along the normal):
    depth of a vertex = distance along the normal to the mesh point directly under it (on
    the ray from the body's centre); iterated until every boulder is within 1e-9 of its
    size, at most ``max_iterations`` times. Adds ``centre_x_m, centre_y_m, centre_z_m``,
    ``normal_x, normal_y, normal_z``, ``quat_w, quat_x, quat_y, quat_z``, ``height_m``,
    ``burial_m`` and
    ``bottom_depth_m`` (the burial achieved: depth of the deepest vertex).
    """
    if not isinstance(body, Body):
        raise TypeError(f"`body` must be a Body; got {type(body).__name__}")
    cat, shape = placement_request(catalog, shape, max_iterations, ("lat_deg", "lon_deg"))
    n = len(cat)
    grid = body.grid
    stretch = np.asarray(body.stretch)
    colat = np.radians(90.0 - cat["lat_deg"])
    lon = np.radians(cat["lon_deg"])
    u = np.stack([np.sin(colat) * np.cos(lon), np.sin(colat) * np.sin(lon), np.cos(colat)], 1)
    # the surface is the triangle mesh itself (what a renderer draws), not an interpolation
    surface = grid.surface_radii(body.radii_m, colat, lon)[:, None] * u * stretch
    normals = body.vertex_normals("area").astype(np.float64)
    nrm = np.stack([grid.interpolate(normals[:, c], colat, lon) for c in range(3)], 1)
    nrm /= np.linalg.norm(nrm, axis=1, keepdims=True)
    rot = orientations(nrm, np.radians(cat["azimuth_deg"]))
    centre = np.empty((n, 3))
    achieved, height, burial = np.empty(n), np.empty(n), np.empty(n)
    depths = functools.partial(_depths, body)
    chunk = mesh_chunk(shape)
    for s0 in range(0, n, chunk):  # a chunk of boulders at a time (bounded memory)
        sl = slice(s0, min(s0 + chunk, n))
        verts, _ = boulder_meshes(cat["seed"][sl], shape)
        world = np.einsum("kij,kvj->kvi", rot[sl], verts * cat["diameter_m"][sl, None, None])
        centre[sl], achieved[sl], height[sl], burial[sl] = rest_on_ground(
            depths, world, surface[sl], nrm[sl], cat["burial_frac"][sl], cat["diameter_m"][sl],
            max_iterations=max_iterations)
    cols = placed_columns(cat, centre, nrm, rot, height, burial, achieved, shape)
    return _craters.make_catalog(**cols)
