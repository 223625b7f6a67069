"""The implicit build (:func:`implicit_surface`): steps 1-6 of the :mod:`latlong.implicit`
notes, each stage a function of its own.

A plan (the checked inputs and the sizes derived from them: voxel, level-0 cell, layer
levels, the band of the field craters and noise can move), then packing and metaballs
(:mod:`.packing`, :mod:`.metaballs`), the coarse field (the constraint's signed
distance, :mod:`.distance`, blended with the metaballs') on a voxel grid grown until the
surface stays inside it, the crater impulses (:mod:`.layers`) and Gabor noise
(:mod:`.gabor`) added near the surface, then marching cubes (VTK flying edges) on the
zero level: a closed, outward oriented triangle mesh, of which only the largest
connected piece is kept (how much area was dropped is recorded). The result is an
:class:`~latlong.implicit.surface.ImplicitSurface`.
"""

from __future__ import annotations

import dataclasses
import logging
import math
import time

import numpy as np

import craters as _craters
from craters._shared import (
    ParameterError,
    ParameterTypeError,
    check_int,
    check_positive,
    check_range,
    normalize_rng,
    physical_memory_bytes,
    progress_bar,
)

from ..shapes import ShapeModel, as_shape_model
from . import _kernels as _k
from .distance import mesh_distance, smoothed_constraint
from .gabor import GaborNoise, add_gabor, gabor_impulses
from .grid import VoxelGrid
from .layers import LcsnLayer, draw_impulses, largest_height, layer_levels, measure_shape
from .metaballs import Metaballs, fit_metaballs, metaball_distance
from .packing import SpherePacking, sphere_packing
from .surface import ImplicitSurface

__all__ = ["implicit_surface"]

logger = logging.getLogger(__name__)
_GROWTH_STEPS = 6  # enlargements (x 1.5 margin each) of the grid around a bulging surface
# triangles per (constraint area / voxel^2) of the flying-edges metaball surfaces:
# 3.07 (Itokawa q=32), 3.11 (Eros 7790), 3.30 (Bennu) measured
_TRIANGLES_PER_AREA = 3.1


def _estimate_bytes(shape) -> int:
    # float64 first-order field, distance, crater field, noise; int64 seed ids; int32 x3
    # distance-transform indices; bool masks
    return int(np.prod(shape)) * (8 * 5 + 12 + 4)


def implicit_surface(constraint, layers=(), *, gabor=None, voxel_m: float | None = None,
                     target_polygons: int = 200_000, units: str | None = None,
                     cell_m: float | None = None, packing_voxels: int = 128,
                     min_sphere_m: float | None = None, constraint_weight: float = 1.0,
                     rng=None, progress: bool = False) -> ImplicitSurface:
    """Build an implicit asteroid from a constraint mesh (module notes).

    Parameters
    ----------
    constraint : ShapeModel, str or Path
        Closed mesh (a path is read with :func:`latlong.shapes.read_shape_model`, which
        needs ``units``). It is moved so that its volume centroid is the origin.
    layers : sequence of LcsnLayer
        Crater layers, each on its grid level.
    gabor : GaborNoise, optional
        Micro-detail added near the surface.
    voxel_m : float, optional
        Marching-cubes spacing, metres. Default: from ``target_polygons`` (flying
        edges gave 3.1 triangles per (constraint area / voxel^2) on Itokawa, Bennu, Eros).
    target_polygons : int
        Wanted number of output triangles when ``voxel_m`` is not given.
    cell_m : float, optional
        Cell size of grid level 0, metres (default: the largest d_max_m of the layers).
    packing_voxels, min_sphere_m
        :func:`sphere_packing` resolution and smallest ball.
    constraint_weight : float
        Weight in [0, 1] of the constraint's own signed distance in the coarse field
        (:func:`~latlong.implicit.distance.mesh_distance` of the constraint after a
        butterfly subdivision to the voxel): 1 (default) follows the constraint, smooth
        where it is smooth; 0 is the bare metaball surface over the packing (Li et al.
        2020; one dome per packed ball shows); between, the two signed distances are blended.
    rng : int, Generator or None
        Seed: impulses, diameters, depths, Gabor impulses (and the fit's samples).

    Returns
    -------
    ImplicitSurface
        The catalog has ``lat_deg, lon_deg`` (direction of the impulse from the origin),
        ``diameter_m`` (rim crest; apparent diameter for rimless kernels), ``kind``
        (simple, flat-floored, fresh, complex), ``layer``, ``level``,
        ``centre_x_m .. centre_z_m`` (on the coarse surface), ``normal_x .. normal_z``,
        and the as-added ``depth_m`` (below the surface, kinds 1-3), ``rim_height_m``,
        ``uplift_m`` (kind 4), ``apparent_diameter_m`` and ``weight`` (height factor).
    """
    t0 = time.perf_counter()
    constraint, layers = _checked_inputs(constraint, layers, gabor, units)
    target_polygons = check_int("target_polygons", target_polygons, 100, 10**9)
    weight = check_range("constraint_weight", constraint_weight, 0.0, 1.0)
    seed = int(rng) if isinstance(rng, int | np.integer) and not isinstance(rng, bool) else None
    rng = normalize_rng(rng)
    plan = _plan(constraint, layers, gabor, weight, seed, voxel_m, target_polygons, cell_m)
    stages = _Stages(progress, t0)

    stages.start("packing")
    base_shape = _base_shape(plan, packing_voxels, min_sphere_m, rng)
    stages.done("packing_s")
    stages.start("coarse field")
    grid, base = _coarse_grid(plan, base_shape.metaballs, base_shape.smooth)
    stages.done("field_s")
    stages.start("impulses")
    base_verts, base_faces = grid.contour(base)
    normals = base_shape.metaballs if weight == 0.0 else _FieldNormals(grid, base)
    imp, cat_cols = draw_impulses(plan.layers, plan.shapes, plan.levels, plan.cell_m,
                                  base_verts, base_faces, normals, rng)
    field = _add_craters(imp, grid, base, plan.band)
    stages.done("craters_s")
    stages.start("gabor")
    n_gabor = _add_noise(plan, grid, base, field, rng)
    stages.done("gabor_s")
    stages.start("marching cubes")
    verts, faces = grid.contour(field)
    verts, faces, dropped, pieces = _largest_piece(verts, faces)
    stages.done("contour_s")
    catalog = _catalog(imp, cat_cols)
    stages.bar.close()
    metadata = _metadata(plan, grid, base_shape, n_gabor, pieces, dropped, len(faces))
    kept = {k: imp[k] for k in ("centers", "normals", "kinds", "params", "support", "zhalf")}
    return ImplicitSurface(verts, faces, catalog, metadata, base_shape.packing,
                           base_shape.metaballs, stages.times, base_verts, base_faces, kept)


@dataclasses.dataclass(frozen=True)
class _Plan:
    """What the build starts from: the checked inputs and the sizes derived from them."""

    constraint: ShapeModel
    """The constraint as given (its own frame)."""
    centre: np.ndarray
    """Its volume centroid, metres: the origin of the build."""
    model: ShapeModel
    """The constraint moved so that its volume centroid is the origin."""
    layers: list
    """The crater layers (:class:`LcsnLayer`)."""
    shapes: list
    """Each layer's measured reference kernel (:class:`~.layers.CraterShape`)."""
    levels: list
    """Each layer's grid level."""
    gabor: GaborNoise | None
    """The micro-detail noise, if any."""
    weight: float
    """The constraint's weight in the coarse field, [0, 1]."""
    seed: int | None
    """The seed when one was given as an integer (for the metadata)."""
    voxel_m: float
    """Marching-cubes spacing, metres."""
    cell_m: float
    """Cell size of grid level 0, metres."""
    max_disp: float
    """Twice the largest height each layer's craters can add, summed (two overlapping
    craters), metres: the band of the field where craters can move the surface."""
    gabor_band: float
    """Six amplitudes of the noise, metres (0 without noise)."""
    band: float
    """Half-width of the band around the coarse surface where the field is exact and
    the craters and noise are added, metres."""


def _checked_inputs(constraint, layers, gabor, units):
    """The constraint as a ShapeModel (read from a file in ``units``) and the layers as
    a list, with the kinds of ``layers`` and ``gabor`` checked."""
    constraint = as_shape_model(constraint, units=units, what="constraint", name="constraint")
    layers = list(layers)
    for la in layers:
        if not isinstance(la, LcsnLayer):
            raise TypeError(f"`layers` must hold LcsnLayer objects; got {type(la).__name__}")
    if gabor is not None and not isinstance(gabor, GaborNoise):
        raise TypeError(f"`gabor` must be a latlong.implicit.GaborNoise; got "
                        f"{type(gabor).__name__}")
    return constraint, layers


def _plan(constraint, layers, gabor, weight, seed, voxel_m, target_polygons,
          cell_m) -> _Plan:
    """The build's sizes: voxel (from the polygon budget), level-0 cell, layer levels,
    measured kernels and the band of the field that craters and noise can move."""
    centre = constraint.volume_centroid
    model = ShapeModel(constraint.vertices - centre, constraint.faces, constraint.source)
    if voxel_m is None:
        voxel_m = math.sqrt(_TRIANGLES_PER_AREA * model.area_m2 / target_polygons)
    h = check_positive("voxel_m", voxel_m)
    if cell_m is None:
        cell_m = max((la.d_max_m for la in layers), default=1.0)
    cell_m = check_positive("cell_m", cell_m)
    levels = layer_levels(layers, cell_m)
    for la in layers:
        if la.d_max_m < 4.0 * h:
            logger.warning("LCSN layer %s (%g-%g m) is at most 4 voxels of %.3g m across: its "
                           "craters are barely resolved", la.kernel, la.d_min_m, la.d_max_m, h)
    shapes = [measure_shape(la.params) for la in layers]
    max_disp = 2.0 * sum(largest_height(s, la) for s, la in zip(shapes, layers, strict=True))
    gabor_band = 6.0 * gabor.amplitude_m if gabor is not None else 0.0
    band = max_disp + gabor_band + 3.0 * h
    return _Plan(constraint, centre, model, layers, shapes, levels, gabor, weight, seed, h,
                 cell_m, max_disp, gabor_band, band)


class _Stages:
    """The build's progress bar and the wall time of each stage, seconds."""

    def __init__(self, progress: bool, t0: float):
        self.bar = progress_bar(total=6, enabled=progress, desc="implicit")
        self.times: dict[str, float] = {}
        self._t0 = t0

    def start(self, name: str) -> None:
        self.bar.set_description(name)

    def done(self, key: str) -> None:
        self.times[key] = time.perf_counter() - self._t0 - sum(self.times.values())
        self.bar.update()


@dataclasses.dataclass(frozen=True)
class _BaseShape:
    """The coarse shape's ingredients: the packing, its metaballs, the smoothed constraint."""

    packing: SpherePacking
    metaballs: Metaballs
    smooth: ShapeModel
    """The constraint after butterfly subdivision to the voxel (itself at weight 0)."""
    subdivisions: int
    """How many subdivisions that took."""


def _base_shape(plan: _Plan, packing_voxels, min_sphere_m, rng) -> _BaseShape:
    """Sphere packing of the constraint, the metaballs fitted over it and the smoothed
    constraint (step 1-2 of the module notes)."""
    try:
        packing = sphere_packing(plan.model, n_voxels=packing_voxels, min_radius_m=min_sphere_m)
    except (ParameterError, ParameterTypeError) as exc:  # name this function's parameters
        raise exc.renamed({"n_voxels": "packing_voxels",
                           "min_radius_m": "min_sphere_m"}.get(exc.name, exc.name)) from None
    meta = fit_metaballs(packing, plan.model, rng=rng.integers(2**63))
    if plan.weight > 0:
        smooth, subdivisions = smoothed_constraint(plan.model, plan.voxel_m)
    else:
        smooth, subdivisions = plan.model, 0
    return _BaseShape(packing, meta, smooth, subdivisions)


def _coarse_grid(plan: _Plan, meta: Metaballs, smooth: ShapeModel):
    """The voxel grid and the coarse field on it: the constraint's box plus the band,
    grown until the field is < 0 on its boundary (a bulge of the metaballs past the
    constraint); refused up front when the grid would not fit in memory."""
    h, band = plan.voxel_m, plan.band
    lo, hi = plan.model.vertices.min(axis=0), plan.model.vertices.max(axis=0)
    margin = 0.05 * float((hi - lo).max()) + band
    for _ in range(_GROWTH_STEPS):
        glo, ghi = lo - margin, hi + margin
        zyx = (np.ceil((ghi - glo) / h).astype(np.int64) + 1)[::-1]
        shape = (int(zyx[0]), int(zyx[1]), int(zyx[2]))
        need = _estimate_bytes(shape)
        if need > 0.6 * physical_memory_bytes():
            raise ParameterError("voxel_m", f"= {h:.4g} m needs a {shape[2]} x {shape[1]} x "
                                 f"{shape[0]} grid, about {need / 2**30:.1f} GiB; this machine "
                                 f"has {physical_memory_bytes() / 2**30:.1f} GiB: use fewer "
                                 "polygons or a larger voxel")
        grid = VoxelGrid(glo, h, shape)
        base = _coarse_field(meta, smooth, grid, plan.weight, band + 2.0 * h)
        rim = max(base[0].max(), base[-1].max(), base[:, 0].max(), base[:, -1].max(),
                  base[:, :, 0].max(), base[:, :, -1].max())  # on the grid's boundary
        if rim < -band:
            return grid, base
        margin *= 1.5
    raise ValueError(f"the metaball surface still reaches the border of a grid "
                     f"{margin:.4g} m larger than the constraint after "
                     f"{_GROWTH_STEPS} enlargements; check the constraint mesh "
                     "(closed, consistently oriented)")


def _add_craters(imp: dict, grid: VoxelGrid, base: np.ndarray, band: float) -> np.ndarray:
    """The coarse field plus the crater kernels (:func:`~.layers.draw_impulses`) where
    ``|base| < band``."""
    field = base.copy()
    if len(imp["centers"]):
        # the ball around the support cylinder (radius support, half-height 2 zhalf)
        lo_i, hi_i = grid.index_boxes(imp["centers"], np.hypot(imp["support"],
                                                               2.0 * imp["zhalf"]))
        nbins, offsets, items, active = grid.bins(lo_i, hi_i)
        _k._crater_grid_kernel(grid.origin, grid.h, active, grid.bin_size, nbins, offsets,
                               items, lo_i, hi_i, imp["centers"], imp["normals"], imp["kinds"],
                               imp["params"], imp["support"], imp["zhalf"], base, band, field)
    return field


def _add_noise(plan: _Plan, grid: VoxelGrid, base: np.ndarray, field: np.ndarray,
               rng) -> int:
    """Add the Gabor noise (if any) to ``field`` near the surface; the number of impulses."""
    gabor, h = plan.gabor, plan.voxel_m
    if gabor is None:
        return 0
    finest = max(p.frequency + p.bandwidth for p in gabor.patches)
    if finest * 2.0 * h > 1.0:
        logger.warning("Gabor noise reaches %.3g cycles/m, finer than the %.3g m voxels "
                       "resolve (%.3g cycles/m): that part aliases; use more polygons or "
                       "coarser noise", finest, h, 0.5 / h)
    g = gabor_impulses(gabor, base, grid, plan.max_disp + plan.gabor_band, rng)
    if len(g["pos"]):
        noise = np.zeros_like(field)
        add_gabor(g, grid, field, plan.gabor_band + 2.0 * h, noise)
        field += noise
    return len(g["pos"])


def _catalog(imp: dict, cat_cols: dict) -> np.ndarray:
    """The crater catalog of the impulses (columns in :func:`implicit_surface`)."""
    centers = imp["centers"]
    norm = np.linalg.norm(centers, axis=1) if len(centers) else np.zeros(0)
    lat = np.degrees(np.arcsin(np.clip(centers[:, 2] / np.maximum(norm, 1e-300), -1, 1)))
    lon = np.mod(np.degrees(np.arctan2(centers[:, 1], centers[:, 0])), 360.0)
    return _craters.make_catalog(
        lat_deg=lat, lon_deg=lon, diameter_m=cat_cols["diameter_m"],
        kind=cat_cols["kind"] if len(centers) else np.zeros(0, "U16"),
        layer=cat_cols["layer"].astype(np.int64), level=cat_cols["level"].astype(np.int64),
        centre_x_m=centers[:, 0], centre_y_m=centers[:, 1], centre_z_m=centers[:, 2],
        normal_x=imp["normals"][:, 0], normal_y=imp["normals"][:, 1],
        normal_z=imp["normals"][:, 2], depth_m=cat_cols["depth_m"],
        rim_height_m=cat_cols["rim_height_m"], uplift_m=cat_cols["uplift_m"],
        apparent_diameter_m=cat_cols["apparent_diameter_m"], weight=cat_cols["weight"])


def _metadata(plan: _Plan, grid: VoxelGrid, base_shape: _BaseShape, n_gabor: int,
              pieces: int, dropped: float, triangles: int) -> dict:
    """The build's parameters, packing and fit figures (JSON-serialisable)."""
    packing, meta, gabor = base_shape.packing, base_shape.metaballs, plan.gabor
    return {
        "generator": "craterform latlong implicit",
        "source": plan.constraint.source,
        "constraint_centre_m": [float(v) for v in plan.centre],
        "constraint_volume_m3": plan.constraint.volume_m3,
        "voxel_m": plan.voxel_m, "grid_shape_zyx": list(grid.shape), "band_m": plan.band,
        "packing": {"spheres": len(packing.radii), "voxel_m": packing.voxel_m,
                    "coverage": packing.coverage, "min_radius_m": float(packing.radii.min()),
                    "max_radius_m": float(packing.radii.max()),
                    "odd_columns": packing.odd_columns},
        "metaballs": {"blend": meta.blend, "iso": meta.iso, "fit_mean_m": meta.fit_mean_m},
        "constraint": {"weight": plan.weight, "smoothing": "butterfly",
                       "subdivisions": base_shape.subdivisions,
                       "triangles": len(base_shape.smooth.faces)},
        "seed": plan.seed, "cell_m": plan.cell_m, "levels": plan.levels,
        "layers": [{**dataclasses.asdict(la), "kernel": la.kernel if isinstance(la.kernel, str)
                    else dataclasses.asdict(la.kernel)} for la in plan.layers],
        "gabor": None if gabor is None else {**gabor.describe(), "impulses": n_gabor},
        "pieces": pieces, "dropped_area_fraction": dropped,
        "triangles": triangles,
    }


@dataclasses.dataclass(frozen=True, slots=True)
class _FieldNormals:
    """The crater impulses' normals from the coarse field (when the constraint's field
    is blended in; the bare metaballs give theirs analytically)."""

    grid: VoxelGrid
    """The field's grid."""
    values: np.ndarray
    """The coarse field, > 0 inside."""

    def normals(self, points):
        return self.grid.normals(self.values, points)


def _coarse_field(meta: Metaballs, smooth: ShapeModel, grid: VoxelGrid, weight: float,
                  exact_m: float) -> np.ndarray:
    """Signed distance of the coarse surface (> 0 inside): ``weight`` x that of the
    smoothed constraint (exact to ``exact_m`` from it, an upper bound beyond) +
    (1 - ``weight``) x that of the metaball surface."""
    if weight == 0.0:
        return metaball_distance(meta, grid)
    dist = mesh_distance(smooth, grid, exact_m=exact_m)
    if weight < 1.0:
        dist *= weight
        dist += (1.0 - weight) * metaball_distance(meta, grid)
    return dist


def _largest_piece(verts, faces):
    """Keep the largest connected piece (by area); return it and the dropped area share."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    n = len(verts)
    e = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]]])
    graph = coo_matrix((np.ones(len(e)), (e[:, 0], e[:, 1])), shape=(n, n))
    n_comp, label = connected_components(graph, directed=False)
    a, b, c = (verts[faces[:, k]] for k in range(3))
    area = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1)
    if n_comp == 1:
        return verts, faces, 0.0, 1
    comp_area = np.bincount(label[faces[:, 0]], weights=area, minlength=n_comp)
    keep = int(np.argmax(comp_area))
    fmask = label[faces[:, 0]] == keep
    used = np.flatnonzero(label == keep)
    remap = np.full(n, -1, np.int64)
    remap[used] = np.arange(len(used))
    dropped = float(1.0 - comp_area[keep] / comp_area.sum())
    return verts[used], remap[faces[fmask]], dropped, int((comp_area > 0).sum())
