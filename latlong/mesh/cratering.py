"""Craters on any closed triangle mesh: populations on its true surface and stamping via
local height grids over the mesh's own neighbourhoods (:mod:`latlong.mesh._stamp_kernels`).
"""

from __future__ import annotations

import logging

import numpy as np

import craters as _craters
from craters._shared import check_range, normalize_rng, progress_bar
from craters.profile import DEFAULT_EJECTA_EDGE
from craters.stamp import as_stamped, resolve_roughness, stamping_profiles
from craters.targets import Target

from ._stamp_kernels import _point_mass_kernel, _stamp_mesh_kernel
from .surface import MeshSurface, lat_lon_deg
from .topology import TriangleGrid, adjacency, face_normals

__all__ = ["down_directions", "mesh_crater_population", "sample_mesh_points", "stamp_mesh_craters"]

logger = logging.getLogger(__name__)
_BATCH = 512  # craters per kernel call when a progress bar is shown


def sample_mesh_points(vertices, faces, n: int, rng) -> tuple[np.ndarray, np.ndarray]:
    """``n`` points uniform on a triangle mesh (area-weighted faces, uniform inside):
    (face (n,), uv (n, 2)) with the point ``a + u (b - a) + v (c - a)``; draws from the
    Generator ``rng`` in a fixed order."""
    area = 0.5 * np.linalg.norm(face_normals(vertices, faces), axis=1)
    cum = np.cumsum(area)
    face = np.minimum(np.searchsorted(cum, rng.random(n) * cum[-1], side="right"),
                      len(faces) - 1)
    uv = rng.random((n, 2))
    flip = uv.sum(axis=1) > 1
    uv[flip] = 1.0 - uv[flip]
    return face, uv


def _points(vertices, faces, face, uv) -> np.ndarray:
    a, b, c = (vertices[faces[face, k]] for k in range(3))
    return a + uv[:, :1] * (b - a) + uv[:, 1:] * (c - a)


def down_directions(vertices, faces, points, *, block: int = 32) -> np.ndarray:
    """Unit directions of the self-gravity of a constant-density closed mesh at
    ``points`` (n, 3), for slope erosion where "downhill" is not towards the centre
    (Itokawa's neck, the ends of an elongated body).

    The body is the signed sum of the tetrahedra (origin, a, b, c) of its faces
    (volume-integral decomposition of a polyhedron, e.g. Werner & Scheeres 1997, sect.
    2); the tetrahedra of ``block`` consecutive faces (a compact patch of a refined
    mesh) are lumped into two point masses, their positive and their negative parts, at
    their volume centroids. The near field of such lumps is approximate (a few
    degrees at a lump's own distance): enough to tell a wall from a floor, not a
    gravity model (that is :func:`latlong.gravity`'s job).
    """
    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces, dtype=np.int64)
    a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    vol = np.einsum("ij,ij->i", a, np.cross(b, c)) / 6.0
    cen = (a + b + c) / 4.0
    group = np.arange(len(f)) // block
    masses, centres = [], []
    for part in (vol > 0, vol < 0):
        w = np.where(part, vol, 0.0)
        m = np.bincount(group, weights=w)
        mc = np.stack([np.bincount(group, weights=w * cen[:, k]) for k in range(3)], 1)
        ok = m != 0
        masses.append(m[ok])
        centres.append(mc[ok] / m[ok, None])
    m, q = np.concatenate(masses), np.ascontiguousarray(np.concatenate(centres))
    p = np.ascontiguousarray(np.asarray(points, dtype=np.float64).reshape(-1, 3))
    soft = float((np.abs(vol).sum() / len(f) * block) ** (2.0 / 3.0))  # a lump's size^2
    g = np.empty_like(p)
    _point_mass_kernel(p, q, m, soft, g)
    return g / np.linalg.norm(g, axis=1, keepdims=True)


def mesh_crater_population(surface: MeshSurface, layers, *, rng=None) -> np.ndarray:
    """A crater catalog for ``surface``: counts from its area, centres uniform on it.

    Columns of :func:`craters.population` with ``lat_deg, lon_deg`` the direction of the
    centre seen from the origin (the centre of mass) and ``centre_x_m, centre_y_m,
    centre_z_m`` the point on the surface (on a body that is not star-shaped a direction
    can cross the surface more than once: the 3-D centre is the position).
    """
    if not isinstance(surface, MeshSurface):
        raise TypeError(f"`surface` must be a MeshSurface; got {type(surface).__name__}")
    rng = normalize_rng(rng)
    cat = _craters.population(layers, area_m2=surface.area_m2, rng=rng)
    face, uv = sample_mesh_points(surface.vertices, surface.faces, len(cat), rng)
    p = _points(surface.vertices, surface.faces, face, uv)
    cols = {k: cat[k] for k in cat.dtype.names}
    cols["lat_deg"], cols["lon_deg"] = lat_lon_deg(p)
    cols.update(centre_x_m=p[:, 0], centre_y_m=p[:, 1], centre_z_m=p[:, 2])
    return _craters.make_catalog(**cols)


def stamp_mesh_craters(surface: MeshSurface, catalog, *, roughness=True, rng=None,
                       progress: bool = False, irregularity: float = 0.02,
                       slope_erosion: bool = True, onset_deg: float = 20.0,
                       full_deg: float = 45.0, target: str | Target = "moon",
                       ejecta_edge: float = DEFAULT_EJECTA_EDGE,
                       max_tilt_deg: float = 75.0) -> MeshSurface:
    """Stamp a crater catalog on a mesh surface, oldest first; returns a new surface.

    Each crater is centred at the surface point closest to its ``centre_x_m,
    centre_y_m, centre_z_m`` (found on the surface as given, then followed as earlier
    craters move it). Its region is the set of vertices within graph distance of the
    centre (Dijkstra over the mesh edges: geodesic reach, never the other side of a
    neck or a thin part), in a frame whose up axis is the surface normal averaged over
    the obliterated region; each vertex gets its true distance and azimuth in that
    plane and its height along up. Then as on the lat/long body
    (:func:`latlong.stamp_craters`, Martin 2014 V.A): a quadric base fitted to the
    obliterated region, a local height grid at the local vertex spacing for the rim
    offsets, slope erosion (the base's normal against the vertical: the direction of
    the body's constant-density self-gravity at the centre, :func:`down_directions`,
    not the radial direction, which on a body that is not star-shaped can lie along the
    surface), the profile of :func:`craters.stamping_profiles` (fresh morphology by size
    on ``target``, diffusion degradation by age), irregular rim and roughness; vertices
    move along up by their height change. A crater whose region holds a face turned
    more than ``max_tilt_deg`` from up (a fold or an edge within its reach: no height
    field) is left out and counted (``metadata["craters_skipped_no_height_field"]``).

    Parameters
    ----------
    surface : MeshSurface
    catalog : structured array
        ``diameter_m``, the 3-D centre columns (:func:`mesh_crater_population`),
        optionally ``age_gyr`` (stamping order), ``degradation``, ``kind``.
    roughness, rng, irregularity, slope_erosion, onset_deg, full_deg, target, ejecta_edge
        As in :func:`latlong.stamp_craters`.
    max_tilt_deg : float
        Largest angle between a face of the region and the crater's up axis.

    Returns
    -------
    MeshSurface whose ``craters`` are the catalog as stamped (columns of
    :func:`latlong.stamp_craters`: the degradation used, rim radius, depth, rim height,
    slope, 3-D centre, ``normal_x, normal_y, normal_z`` (the up axis), seed,
    ``max_change_m``, ``n_vertices``, ``spacing_m``), ``lat_deg, lon_deg`` of the centre
    as stamped seen from the origin.
    """
    if not isinstance(surface, MeshSurface):
        raise TypeError(f"`surface` must be a MeshSurface; got {type(surface).__name__}")
    if surface.boulders is not None and len(surface.boulders):
        raise ValueError("`surface` has placed boulders: stamp the craters first, then place "
                         "the boulders (latlong.mesh.place_mesh_boulders)")
    cat = _craters.sort_oldest_first(_craters.validate_catalog(catalog))
    names = cat.dtype.names
    if not all(k in names for k in ("centre_x_m", "centre_y_m", "centre_z_m")):
        raise ValueError("`catalog` needs centre_x_m, centre_y_m, centre_z_m columns (the 3-D "
                         "centres) to stamp on a mesh")
    rough, irregular = resolve_roughness(roughness)
    irregularity = check_range("irregularity", irregularity, 0.0, 0.3)
    ejecta_edge = check_range("ejecta_edge", ejecta_edge, 1.5, 20.0)
    onset = check_range("onset_deg", onset_deg, 0.0, 90.0)
    full = check_range("full_deg", full_deg, 0.0, 90.0)
    tilt = check_range("max_tilt_deg", max_tilt_deg, 1.0, 90.0)
    if slope_erosion and full <= onset:
        raise ValueError(f"`full_deg` must be > onset_deg ({onset}); got {full}")
    irr = irregularity if irregular else 0.0
    n = len(cat)
    rng = normalize_rng(rng)
    rim_tabs = _craters.rim_perturbations(n, irr, rng=rng)
    seeds = rng.integers(0, 2**63, size=n, dtype=np.uint64)
    pos = np.array(surface.vertices, dtype=np.float64, copy=True)
    heights = np.array(surface.heights_m, dtype=np.float64, copy=True)
    faces = np.ascontiguousarray(surface.faces)
    centres = np.stack([cat["centre_x_m"], cat["centre_y_m"], cat["centre_z_m"]], 1)
    face_of, uv, _ = TriangleGrid.build(pos, faces).closest(centres)
    vertical = -down_directions(pos, faces, _points(pos, faces, face_of, uv))
    voff, vnbr, foff, fids = adjacency(faces, len(pos))
    prof = stamping_profiles(cat, target, ejecta_edge=ejecta_edge)
    diam = np.ascontiguousarray(cat["diameter_m"], dtype=np.float64)
    outs = {k: np.zeros(n) for k in ("slope", "maxdh", "nvert", "sp")}
    scale = np.ones(n)
    centre = np.zeros((n, 3))
    normal = np.zeros((n, 3))
    state = np.zeros(n, dtype=np.int64)
    rough_arr = np.array([rough.bowl, rough.wall, rough.ejecta])
    gain = 2.0 ** (rough.fractal_dimension - 3.0)
    mark = np.zeros(len(pos), dtype=np.int64)
    gdist = np.zeros(len(pos))
    epoch = np.zeros(1, dtype=np.int64)
    cos_tilt = float(np.cos(np.radians(tilt)))
    step = _BATCH if progress else max(n, 1)
    for s in progress_bar(range(0, n, step), enabled=progress, desc="craters"):
        e = min(s + step, n)
        _stamp_mesh_kernel(pos, heights, faces, voff, vnbr, foff, fids, face_of[s:e], uv[s:e],
                           vertical[s:e], diam[s:e], prof.tables[s:e], prof.depth_m[s:e],
                           rim_tabs[s:e], seeds[s:e], ejecta_edge, bool(slope_erosion), onset,
                           full, rough_arr, gain, cos_tilt, mark, gdist, epoch, scale[s:e],
                           outs["slope"][s:e], centre[s:e], normal[s:e], outs["maxdh"][s:e],
                           outs["nvert"][s:e], outs["sp"][s:e], state[s:e])
    cols = {k: cat[k] for k in names}
    lat, lon = lat_lon_deg(centre)
    cols.update(as_stamped(prof, scale, diam), lat_deg=lat, lon_deg=lon, slope_deg=outs["slope"],
                centre_x_m=centre[:, 0], centre_y_m=centre[:, 1], centre_z_m=centre[:, 2],
                normal_x=normal[:, 0], normal_y=normal[:, 1], normal_z=normal[:, 2], seed=seeds,
                max_change_m=outs["maxdh"], n_vertices=outs["nvert"].astype(np.int64),
                spacing_m=outs["sp"])
    stamped = _craters.make_catalog(**cols)[state == 0]
    erased, skipped = int((state == 1).sum()), int((state == 2).sum())
    if erased:
        logger.info("%d of %d craters fell on ground steeper than %g deg and were erased",
                    erased, n, full)
    if skipped:
        logger.info("%d of %d craters left out: their region folds more than %g deg from "
                    "their plane (no height field)", skipped, n, tilt)
    if surface.craters is not None and len(surface.craters):
        try:
            stamped = np.concatenate([surface.craters, stamped.astype(surface.craters.dtype)])
        except (TypeError, ValueError):
            logger.warning("previous crater catalog has other columns; keeping only the new")
    meta = {**surface.metadata,
            "craters_erased_steep": surface.metadata.get("craters_erased_steep", 0) + erased,
            "craters_skipped_no_height_field":
                surface.metadata.get("craters_skipped_no_height_field", 0) + skipped}
    return surface.replace(vertices=pos, heights_m=heights, craters=stamped, metadata=meta)
