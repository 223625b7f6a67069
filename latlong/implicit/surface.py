"""The implicit build (:func:`implicit_surface`) and its result (:class:`ImplicitSurface`).

The pipeline is in the :mod:`latlong.implicit` notes. This module runs it: packing and
metaballs (:mod:`.packing`, :mod:`.metaballs`), the coarse field (the constraint's signed
distance, :mod:`.distance`, blended with the metaballs') on a voxel grid grown until the
surface stays inside it, the crater impulses (:mod:`.layers`) and Gabor noise
(:mod:`.gabor`) added near the surface, then marching cubes (VTK flying edges) on the
zero level: a closed, outward oriented triangle mesh, of which only the largest
connected piece is kept (how much area was dropped is recorded).

For star-shaped results :meth:`ImplicitSurface.to_body` casts the mesh onto a
:class:`~latlong.LatLongGrid` (:func:`latlong.shapes.from_shape_model`), so slopes,
strips, boulders and exports of the lat/long toolkit apply; it is the only place where
the implicit backend meets the lat/long grid.
"""

from __future__ import annotations

import dataclasses
import logging
import math

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

from ..geometry.meshes import TriangleMeshSurface
from ..meshio.writers import MESH_SUFFIXES, MeshSource, array_source
from ..shapes import ShapeModel, as_shape_model
from . import _kernels as _k
from .distance import mesh_distance, smoothed_constraint
from .gabor import GaborNoise, add_gabor, gabor_impulses
from .grid import VoxelGrid
from .layers import LcsnLayer, draw_impulses, largest_height, layer_levels, measure_shape
from .metaballs import Metaballs, fit_metaballs, metaball_distance
from .packing import SpherePacking, sphere_packing

__all__ = ["MESH_SUFFIXES", "ImplicitSurface", "implicit_surface"]

logger = logging.getLogger(__name__)
_GROWTH_STEPS = 6  # enlargements (x 1.5 margin each) of the grid around a bulging surface
# triangles per (constraint area / voxel^2) of the flying-edges metaball surfaces:
# 3.07 (Itokawa q=32), 3.11 (Eros 7790), 3.30 (Bennu) measured
_TRIANGLES_PER_AREA = 3.1


@dataclasses.dataclass(frozen=True)
class ImplicitSurface(TriangleMeshSurface):
    """A marching-cubes mesh of an implicit body and the crater catalog that made it: a
    :class:`~latlong.geometry.surface.Surface` (normals, frames and measures:
    :class:`~latlong.geometry.meshes.TriangleMeshSurface`)."""

    vertices: np.ndarray
    """(V, 3) float64 positions, metres, in the frame of the constraint moved so that its
    volume centroid is the origin."""
    faces: np.ndarray
    """(F, 3) int64, counter-clockwise seen from outside; closed."""
    catalog: np.ndarray
    """Crater catalog (structured array; see :func:`implicit_surface`)."""
    metadata: dict
    """Parameters, packing and fit figures (JSON-serialisable, deterministic)."""
    packing: SpherePacking | None = None
    metaballs: Metaballs | None = None
    timings_s: dict = dataclasses.field(default_factory=dict)
    """Wall time of each stage, seconds (not part of the metadata)."""
    base_vertices: np.ndarray | None = None
    """The coarse metaball surface (before craters and noise): (V, 3) metres."""
    base_faces: np.ndarray | None = None
    """Its triangles (F, 3)."""
    impulses: dict | None = None
    """The crater kernels as added (catalog order): ``centers, normals, kinds, params``
    (kappa, beta, gamma, a, b per row, heights already weighted), ``support, zhalf``."""

    def crater_heights(self, points, rows=None) -> np.ndarray:
        """Sum of the crater kernels (metres, up = outward) at points (n, 3), as added
        to the field; ``rows`` restricts it to some craters (catalog rows)."""
        pts = np.ascontiguousarray(np.asarray(points, dtype=np.float64).reshape(-1, 3))
        imp = self.impulses or {}
        sel = slice(None) if rows is None else np.atleast_1d(np.asarray(rows, dtype=np.int64))
        out = np.zeros(len(pts))
        if imp and len(imp["centers"]):
            arrays = [np.ascontiguousarray(imp[k][sel]) for k in (
                "centers", "normals", "kinds", "params", "support", "zhalf")]
            _k._crater_points_kernel(pts, *arrays, out)
        return out

    @property
    def craters(self) -> np.ndarray:
        """The crater catalog (:attr:`catalog`): the surface's craters."""
        return self.catalog

    @property
    def boulders(self) -> None:
        """No boulders: the implicit backend places none."""
        return None

    def is_watertight(self) -> bool:
        """Every edge belongs to exactly two faces, each direction once."""
        e = np.concatenate([self.faces[:, [0, 1]], self.faces[:, [1, 2]],
                            self.faces[:, [2, 0]]])
        directed = e[:, 0] * len(self.vertices) + e[:, 1]
        undirected = np.sort(e, axis=1)
        _, counts = np.unique(undirected, axis=0, return_counts=True)
        return bool((counts == 2).all() and np.unique(directed).size == directed.size)

    def mesh_source(self) -> MeshSource:
        """The mesh for the shared mesh writers."""
        return array_source(self.vertices, self.faces, "craterform implicit body, metres")

    def to_body(self, magnitude: int, *, crossings: str = "error"):
        """Cast the mesh onto a lat/long grid of ``magnitude`` from the origin.

        ``crossings="error"`` raises ValueError (with the affected share of directions)
        unless the surface is star-shaped from the origin; ``"outermost"`` or
        ``"innermost"`` keep one crossing (overhangs are then lost). The body keeps the
        crater catalog (:func:`latlong.shapes.from_shape_model`).
        """
        from ..shapes import from_shape_model  # the backend's one meeting with the grid

        model = ShapeModel(self.vertices, self.faces, "implicit surface")
        body = from_shape_model(model, magnitude, center="origin", crossings=crossings,
                                smooth="none", subdivisions=0,
                                metadata={"implicit": self.metadata})
        return body.replace(craters=self.catalog if len(self.catalog) else None)


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
        where it is smooth; 0 is the bare metaball surface over the packing (Li et al.;
        one dome per packed ball shows); between, the two signed distances are blended.
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
    import time

    times: dict[str, float] = {}
    t0 = time.perf_counter()
    constraint = as_shape_model(constraint, units=units, what="constraint", name="constraint")
    layers = list(layers)
    for la in layers:
        if not isinstance(la, LcsnLayer):
            raise TypeError(f"`layers` must hold LcsnLayer objects; got {type(la).__name__}")
    if gabor is not None and not isinstance(gabor, GaborNoise):
        raise TypeError(f"`gabor` must be a latlong.implicit.GaborNoise; got "
                        f"{type(gabor).__name__}")
    target_polygons = check_int("target_polygons", target_polygons, 100, 10**9)
    weight = check_range("constraint_weight", constraint_weight, 0.0, 1.0)
    seed = int(rng) if isinstance(rng, int | np.integer) and not isinstance(rng, bool) else None
    rng = normalize_rng(rng)
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
    # twice the largest height each layer's craters can add (two overlapping ones) bounds
    # the band of the field where craters can move the surface
    max_disp = 2.0 * sum(largest_height(s, la) for s, la in zip(shapes, layers, strict=True))
    gabor_band = 6.0 * gabor.amplitude_m if gabor is not None else 0.0
    band = max_disp + gabor_band + 3.0 * h

    bar = progress_bar(total=6, enabled=progress, desc="implicit")
    bar.set_description("packing")
    try:
        packing = sphere_packing(model, n_voxels=packing_voxels, min_radius_m=min_sphere_m)
    except (ParameterError, ParameterTypeError) as exc:  # name this function's parameters
        raise exc.renamed({"n_voxels": "packing_voxels",
                           "min_radius_m": "min_sphere_m"}.get(exc.name, exc.name)) from None
    meta = fit_metaballs(packing, model, rng=rng.integers(2**63))
    smooth, levels_sub = smoothed_constraint(model, h) if weight > 0 else (model, 0)
    times["packing_s"] = time.perf_counter() - t0
    bar.update()

    # the grid: the constraint's box plus the band, grown until the field is < 0 on its
    # boundary (a bulge of the metaballs past the constraint)
    lo, hi = model.vertices.min(axis=0), model.vertices.max(axis=0)
    margin = 0.05 * float((hi - lo).max()) + band
    for attempt in range(_GROWTH_STEPS + 1):
        if attempt == _GROWTH_STEPS:
            raise ValueError(f"the metaball surface still reaches the border of a grid "
                             f"{margin:.4g} m larger than the constraint after "
                             f"{_GROWTH_STEPS} enlargements; check the constraint mesh "
                             "(closed, consistently oriented)")
        glo, ghi = lo - margin, hi + margin
        shape = tuple(int(v) for v in (np.ceil((ghi - glo) / h).astype(np.int64) + 1)[::-1])
        need = _estimate_bytes(shape)
        if need > 0.6 * physical_memory_bytes():
            raise ParameterError("voxel_m", f"= {h:.4g} m needs a {shape[2]} x {shape[1]} x "
                             f"{shape[0]} grid, about {need / 2**30:.1f} GiB; this machine has "
                             f"{physical_memory_bytes() / 2**30:.1f} GiB: use fewer polygons "
                             "or a larger voxel")
        grid = VoxelGrid(glo, h, shape)
        bar.set_description("coarse field")
        base = _coarse_field(meta, smooth, grid, weight, band + 2.0 * h)
        rim = max(base[0].max(), base[-1].max(), base[:, 0].max(), base[:, -1].max(),
                  base[:, :, 0].max(), base[:, :, -1].max())  # on the grid's boundary
        if rim < -band:
            break
        margin *= 1.5
    times["field_s"] = time.perf_counter() - t0 - sum(times.values())
    bar.update()

    bar.set_description("impulses")
    base_verts, base_faces = grid.contour(base)
    normals = meta if weight == 0.0 else _FieldNormals(grid, base)
    imp, cat_cols = draw_impulses(layers, shapes, levels, cell_m, base_verts, base_faces,
                                  normals, rng)
    field = base.copy()
    if len(imp["centers"]):
        # the ball around the support cylinder (radius support, half-height 2 zhalf)
        lo_i, hi_i = grid.index_boxes(imp["centers"], np.hypot(imp["support"],
                                                               2.0 * imp["zhalf"]))
        nbins, offsets, items, active = grid.bins(lo_i, hi_i)
        _k._crater_grid_kernel(grid.origin, h, active, grid.bin_size, nbins, offsets, items,
                               lo_i, hi_i, imp["centers"], imp["normals"], imp["kinds"],
                               imp["params"], imp["support"], imp["zhalf"], base, band, field)
    times["craters_s"] = time.perf_counter() - t0 - sum(times.values())
    bar.update()

    bar.set_description("gabor")
    n_gabor = 0
    if gabor is not None:
        finest = max(p.frequency + p.bandwidth for p in gabor.patches)
        if finest * 2.0 * h > 1.0:
            logger.warning("Gabor noise reaches %.3g cycles/m, finer than the %.3g m voxels "
                           "resolve (%.3g cycles/m): that part aliases; use more polygons or "
                           "coarser noise", finest, h, 0.5 / h)
        g = gabor_impulses(gabor, base, grid, max_disp + gabor_band, rng)
        n_gabor = len(g["pos"])
        if n_gabor:
            noise = np.zeros_like(field)
            add_gabor(g, grid, field, gabor_band + 2.0 * h, noise)
            field += noise
    times["gabor_s"] = time.perf_counter() - t0 - sum(times.values())
    bar.update()

    bar.set_description("marching cubes")
    verts, faces = grid.contour(field)
    verts, faces, dropped, pieces = _largest_piece(verts, faces)
    times["contour_s"] = time.perf_counter() - t0 - sum(times.values())
    bar.update()

    centers = imp["centers"]
    norm = np.linalg.norm(centers, axis=1) if len(centers) else np.zeros(0)
    lat = np.degrees(np.arcsin(np.clip(centers[:, 2] / np.maximum(norm, 1e-300), -1, 1)))
    lon = np.mod(np.degrees(np.arctan2(centers[:, 1], centers[:, 0])), 360.0)
    catalog = _craters.make_catalog(
        lat_deg=lat, lon_deg=lon, diameter_m=cat_cols["diameter_m"],
        kind=cat_cols["kind"] if len(centers) else np.zeros(0, "U16"),
        layer=cat_cols["layer"].astype(np.int64), level=cat_cols["level"].astype(np.int64),
        centre_x_m=centers[:, 0], centre_y_m=centers[:, 1], centre_z_m=centers[:, 2],
        normal_x=imp["normals"][:, 0], normal_y=imp["normals"][:, 1],
        normal_z=imp["normals"][:, 2], depth_m=cat_cols["depth_m"],
        rim_height_m=cat_cols["rim_height_m"], uplift_m=cat_cols["uplift_m"],
        apparent_diameter_m=cat_cols["apparent_diameter_m"], weight=cat_cols["weight"])
    bar.close()
    metadata = {
        "generator": "craterform latlong implicit",
        "source": constraint.source,
        "constraint_centre_m": [float(v) for v in centre],
        "constraint_volume_m3": constraint.volume_m3,
        "voxel_m": h, "grid_shape_zyx": list(shape), "band_m": band,
        "packing": {"spheres": len(packing.radii), "voxel_m": packing.voxel_m,
                    "coverage": packing.coverage, "min_radius_m": float(packing.radii.min()),
                    "max_radius_m": float(packing.radii.max()),
                    "odd_columns": packing.odd_columns},
        "metaballs": {"blend": meta.blend, "iso": meta.iso, "fit_mean_m": meta.fit_mean_m},
        "constraint": {"weight": weight, "smoothing": "butterfly",
                       "subdivisions": levels_sub, "triangles": len(smooth.faces)},
        "seed": seed, "cell_m": cell_m, "levels": levels,
        "layers": [{**dataclasses.asdict(la), "kernel": la.kernel if isinstance(la.kernel, str)
                    else dataclasses.asdict(la.kernel)} for la in layers],
        "gabor": None if gabor is None else {**gabor.describe(), "impulses": n_gabor},
        "pieces": pieces, "dropped_area_fraction": dropped,
        "triangles": len(faces),
    }
    kept = {k: imp[k] for k in ("centers", "normals", "kinds", "params", "support", "zhalf")}
    return ImplicitSurface(verts, faces, catalog, metadata, packing, meta, times, base_verts,
                           base_faces, kept)


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
