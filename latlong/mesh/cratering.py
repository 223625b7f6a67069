"""Craters on any closed triangle mesh: populations on its true surface and stamping via
local height grids over the mesh's own neighbourhoods (:mod:`latlong.mesh._stamp_kernels`).

Stamping (:func:`stamp_mesh_craters`): each crater is centred at the surface point
closest to its ``centre_x_m, centre_y_m, centre_z_m`` (found on the surface as given,
then followed as earlier craters move it). Its region is the set of vertices within
graph distance of the centre (Dijkstra over the mesh edges: geodesic reach, never the
other side of a neck or a thin part), in a frame whose up axis is the surface normal
averaged over the obliterated region; each vertex gets its true distance and azimuth in
that plane and its height along up. Then as on the lat/long body
(:func:`latlong.stamp_craters`, Martin 2014 V.A): a quadric base fitted to the
obliterated region, a local height grid at the local vertex spacing for the rim
offsets, slope erosion (the base's normal against the vertical: the direction of the
body's constant-density self-gravity at the centre, :func:`down_directions`, not the
radial direction, which on a body that is not star-shaped can lie along the surface),
the profile of :func:`craters.stamping_profiles` (fresh morphology by size on
``target``, diffusion degradation by age), irregular rim and roughness; vertices move
along up by their height change. A crater whose region holds a face turned more than
``max_tilt_deg`` from up (a fold or an edge within its reach: no height field) is left
out and counted (``metadata["craters_skipped_no_height_field"]``). The arguments every
surface's stamping shares are checked once (:func:`craters.stamp.stamp_request`).
"""

from __future__ import annotations

import dataclasses
import logging

import numpy as np

import craters as _craters
from craters._shared import check_range, normalize_rng, progress_bar
from craters.profile import DEFAULT_EJECTA_EDGE
from craters.stamp import (
    StampingProfiles,
    as_stamped,
    stamp_request,
    stamped_after,
    stamping_profiles,
)
from craters.targets import Target

from ..geometry.normals import face_normals
from ._stamp_kernels import _point_mass_kernel, _stamp_mesh_kernel
from .surface import MeshSurface, lat_lon_deg
from .topology import TriangleGrid, adjacency

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
    names = cat.dtype.names
    assert names is not None  # a catalog: a structured array
    cols = {k: cat[k] for k in names}
    cols["lat_deg"], cols["lon_deg"] = lat_lon_deg(p)
    cols.update(centre_x_m=p[:, 0], centre_y_m=p[:, 1], centre_z_m=p[:, 2])
    return _craters.make_catalog(**cols)


def stamp_mesh_craters(surface: MeshSurface, catalog, *, roughness=True, rng=None,
                       progress: bool = False, irregularity: float = 0.02,
                       slope_erosion: bool = True, onset_deg: float = 20.0,
                       full_deg: float = 45.0, target: str | Target = "moon",
                       ejecta_edge: float = DEFAULT_EJECTA_EDGE,
                       max_tilt_deg: float = 75.0) -> MeshSurface:
    """Stamp a crater catalog on a mesh surface, oldest first (the method: module notes);
    returns a new surface.

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
    as stamped seen from the origin; craters erased on steep ground or left out where
    their region folds are counted in its metadata (``craters_erased_steep``,
    ``craters_skipped_no_height_field``).
    """
    if not isinstance(surface, MeshSurface):
        raise TypeError(f"`surface` must be a MeshSurface; got {type(surface).__name__}")
    if surface.boulders is not None and len(surface.boulders):
        raise ValueError("`surface` has placed boulders: stamp the craters first, then place "
                         "the boulders (latlong.mesh.place_mesh_boulders)")
    req = stamp_request(catalog, columns=("centre_x_m", "centre_y_m", "centre_z_m"),
                        onto="a mesh", roughness=roughness, irregularity=irregularity,
                        ejecta_edge=ejecta_edge, slope_erosion=slope_erosion,
                        onset_deg=onset_deg, full_deg=full_deg)
    tilt = check_range("max_tilt_deg", max_tilt_deg, 1.0, 90.0)
    cat = req.catalog
    rim_tabs, seeds = req.draws(len(cat), normalize_rng(rng))
    run = _MeshStamp.of(surface, cat, stamping_profiles(cat, target, ejecta_edge=req.ejecta_edge),
                        rim_tabs, seeds, req)
    cos_tilt = float(np.cos(np.radians(tilt)))
    step = _BATCH if progress else max(len(cat), 1)
    for s in progress_bar(range(0, len(cat), step), enabled=progress, desc="craters"):
        _stamp_mesh_kernel(*run.mesh, *run.args(s, s + step, cos_tilt))
    return run.result(surface, cat, seeds, tilt)


@dataclasses.dataclass(frozen=True)
class _MeshStamp:
    """The arrays of one stamping run on a mesh, in the kernel's argument order: the mesh
    (positions and heights written) and its adjacency, then per crater (catalog order)
    the inputs, the options, the work arrays and the outputs
    (:func:`~latlong.mesh._stamp_kernels._stamp_mesh_kernel`)."""

    mesh: tuple
    """(positions, heights, faces, vertex -> neighbours and vertex -> faces (CSR))."""
    inputs: tuple
    """(centre face, centre uv, vertical, diameter, profile tables, depths, rim
    perturbations, seeds)."""
    options: tuple
    """(ejecta edge, slope erosion, onset, full, roughness amplitudes, gain)."""
    work: tuple
    """(vertex marks, graph distances, gather count)."""
    outputs: tuple
    """(scale, slope, centre, normal, max change, vertices touched, spacing, state)."""
    profiles: StampingProfiles
    """The catalog's profile tables and what the catalog reports of them."""

    @classmethod
    def of(cls, surface: MeshSurface, cat, prof, rim_tabs, seeds, req) -> _MeshStamp:
        n = len(cat)
        pos = np.array(surface.vertices, dtype=np.float64, copy=True)
        faces = np.ascontiguousarray(surface.faces)
        centres = np.stack([cat["centre_x_m"], cat["centre_y_m"], cat["centre_z_m"]], 1)
        face_of, uv, _ = TriangleGrid.build(pos, faces).closest(centres)
        vertical = -down_directions(pos, faces, _points(pos, faces, face_of, uv))
        mesh = (pos, np.array(surface.heights_m, dtype=np.float64, copy=True), faces,
                *adjacency(faces, len(pos)))
        inputs = (face_of, uv, vertical, np.ascontiguousarray(cat["diameter_m"], dtype=np.float64),
                  prof.tables, prof.depth_m, req.warps(prof), rim_tabs, seeds)
        options = (req.ejecta_edge, req.slope_erosion, req.onset_deg, req.full_deg,
                   req.rough_array, req.gain)
        work = (np.zeros(len(pos), dtype=np.int64), np.zeros(len(pos)),
                np.zeros(1, dtype=np.int64))
        outputs = (np.ones(n), np.zeros(n), np.zeros((n, 3)), np.zeros((n, 3)), np.zeros(n),
                   np.zeros(n), np.zeros(n), np.zeros(n, dtype=np.int64))
        return cls(mesh, inputs, options, work, outputs, prof)

    def args(self, s: int, e: int, cos_tilt: float) -> tuple:
        """The kernel's arguments after the mesh for craters s..e-1."""
        return (*(a[s:e] for a in self.inputs), *self.options, cos_tilt, *self.work,
                *(a[s:e] for a in self.outputs))

    def result(self, surface: MeshSurface, cat, seeds, tilt: float) -> MeshSurface:
        """The stamped surface: moved vertices and heights, the catalog as stamped after
        the surface's previous craters, the erased and skipped craters counted."""
        scale, slope, centre, normal, maxdh, nvert, spacing, state = self.outputs
        cols = {k: cat[k] for k in cat.dtype.names}
        lat, lon = lat_lon_deg(centre)
        cols.update(as_stamped(self.profiles, scale, self.inputs[3]), lat_deg=lat, lon_deg=lon,
                    slope_deg=slope, centre_x_m=centre[:, 0], centre_y_m=centre[:, 1],
                    centre_z_m=centre[:, 2], normal_x=normal[:, 0], normal_y=normal[:, 1],
                    normal_z=normal[:, 2], seed=seeds, max_change_m=maxdh,
                    n_vertices=nvert.astype(np.int64), spacing_m=spacing)
        stamped = _craters.make_catalog(**cols)[state == 0]
        erased, skipped = int((state == 1).sum()), int((state == 2).sum())
        if erased:
            logger.info("%d of %d craters fell on ground steeper than %g deg and were erased",
                        erased, len(cat), self.options[3])
        if skipped:
            logger.info("%d of %d craters left out: their region folds more than %g deg from "
                        "their plane (no height field)", skipped, len(cat), tilt)
        meta = {**surface.metadata,
                "craters_erased_steep": surface.metadata.get("craters_erased_steep", 0) + erased,
                "craters_skipped_no_height_field":
                    surface.metadata.get("craters_skipped_no_height_field", 0) + skipped}
        return surface.replace(vertices=self.mesh[0], heights_m=self.mesh[1], metadata=meta,
                               craters=stamped_after(surface.craters, stamped))
