"""The implicit backend (Li et al. 2020, 2022): metaballs over a sphere packing, LCSN
craters on a multi-level 3-D grid, Gabor micro-detail, marching cubes.

Pipeline (:func:`implicit_surface`):

1. **Sphere packing** (:func:`sphere_packing`) of a closed constraint mesh: the mesh is
   voxelised by ray parity along x (a numba scan of every grid column), the inside is
   distance-transformed (``scipy.ndimage.distance_transform_edt``; the boundary lies half
   a voxel beyond the last inside voxel), and balls are placed greedily, the largest
   free ball first (inside the shape, not overlapping the balls already placed: a
   non-uniform packing in the spirit of Weller & Zachmann's ProtoSphere), down to a
   minimum radius. Coverage = packed volume / mesh volume.
2. **Metaballs** (:func:`fit_metaballs`): Wyvill's soft-object kernel
   ``(1 - d^2/R^2)^3`` (compact support R = blend x ball radius, so every ball's own
   iso-surface sits at the same fraction of its radius) summed over the balls; the
   blend factor and the iso-value T are *fitted to the constraint*: on 20 000 points
   uniform on the constraint surface, T is the median of f weighted by 1/|grad f|,
   which minimises the mean first-order distance |f - T| / |grad f| of those points to
   the iso-surface, and the blend factor with the smallest such mean is kept.
3. **Field**: on a grid of spacing ``voxel_m`` the signed distance to the metaball
   surface is approximated to first order, ``d = (f - T) / |grad f|`` (> 0 inside).
4. **Craters** (:class:`LcsnLayer`): the multi-level grid has cells of ``cell_m / 2^l``
   at level l (each cell holds 2^3 cells of the next level); a layer uses the finest
   level whose cells hold its largest crater. Every cell of that level that the coarse
   surface passes through (a triangle of the base mesh has its centroid in it) receives
   one impulse with the layer's probability, at a uniform random point of the surface
   inside the cell (a Poisson point conditioned on the cell); its diameter is drawn by
   inversion sampling in [d_min, d_max] (Li 2022 eq. 17-21,
   :func:`craters.sample_power_law_diameters`). The layer's kernel
   (:mod:`craters.lcsn`) is scaled self-similarly to that diameter (rim-crest diameter,
   or apparent diameter for kernels without a rim), its heights times the layer weight
   omega (eq. 2) and optionally set to a random depth/diameter ratio, and added to d in
   the impulse's tangent frame: r = distance from the surface normal through the
   impulse, z = height along it; the kernel fades to 0 over the last 20 % of its
   support radius (where it is < 1e-3 of its extreme) and beyond ``|z|`` = its
   largest height + a quarter of its support (C1 smoothstep over as much again: room
   for the surface to curve away from the tangent plane), so it does not reach the
   far side of the body unless that is closer.
5. **Gabor noise** (:mod:`latlong.gabor`) is added near the surface.
6. **Marching cubes** (VTK flying edges) on the zero level gives a closed, outward
   oriented triangle mesh; only its largest connected piece is kept (how much area was
   dropped is recorded). The crater catalog lists every impulse (position on the
   coarse surface, normal, diameter and as-added depth / rim height).

For star-shaped results :meth:`ImplicitSurface.to_body` casts the mesh onto a
:class:`~latlong.LatLongGrid` (:func:`latlong.shapes.from_shape_model`), so slopes,
strips, boulders and exports of the lat/long toolkit apply.
"""

from __future__ import annotations

import dataclasses
import logging
import math
from pathlib import Path

import numpy as np

import craters as _craters
from craters._shared import (
    atomic_path,
    check_int,
    check_positive,
    check_range,
    normalize_rng,
    parse_spec,
    physical_memory_bytes,
    progress_bar,
)

from . import _implicit_kernels as _k
from .shapes import ShapeModel, read_shape_model, sample_surface

__all__ = ["MESH_SUFFIXES", "ImplicitSurface", "LcsnLayer", "Metaballs", "SpherePacking",
           "fit_metaballs", "implicit_surface", "parse_lcsn_spec", "sphere_packing",
           "write_mesh"]

logger = logging.getLogger(__name__)
MESH_SUFFIXES = (".ply", ".obj", ".stl", ".vtp", ".vtk")
_BIN = 16  # grid points per bin edge
_PACK_BYTES_PER_VOXEL = 48  # peak of the packing per voxel (measured 42.6: EDT + flags)
_GROWTH_STEPS = 6  # enlargements (x 1.5 margin each) of the grid around a bulging surface
_BLENDS = (1.25, 1.5, 1.75, 2.0, 2.5, 3.0)
_FIT_SAMPLES = 20000
# triangles per (constraint area / voxel^2) of the flying-edges metaball surfaces:
# 3.07 (Itokawa q=32), 3.11 (Eros 7790), 3.30 (Bennu) measured
_TRIANGLES_PER_AREA = 3.1
_KERNEL_EPS = 1e-3  # a kernel's support: where it has fallen below this share of its extreme


# --------------------------------------------------------------------------- packing
@dataclasses.dataclass(frozen=True)
class SpherePacking:
    """Non-overlapping balls inside a closed mesh (metres)."""

    centers: np.ndarray
    """(n, 3) ball centres, metres."""
    radii: np.ndarray
    """(n,) ball radii, metres, largest first."""
    voxel_m: float
    """Spacing of the voxel grid the packing was computed on, metres."""
    coverage: float
    """Packed volume / volume of the constraint mesh."""
    odd_columns: int
    """Voxel columns whose ray grazed an edge (an odd number of crossings)."""


def _voxel_grid(lo, hi, h: float, pad: int):
    # a small irrational offset keeps grid rays off the mesh's edges and vertices
    origin = np.asarray(lo, dtype=np.float64) - pad * h + h * np.array([0.3183, 0.2718, 0.1414])
    dims = np.ceil((np.asarray(hi) - origin) / h).astype(np.int64) + pad + 1
    return origin, dims


def sphere_packing(model: ShapeModel, *, n_voxels: int = 128, min_radius_m: float | None = None,
                   max_spheres: int = 200_000) -> SpherePacking:
    """Greedy largest-free-ball packing of a closed mesh (module notes, step 1).

    Parameters
    ----------
    model : ShapeModel
        The constraint: closed, outward oriented, metres.
    n_voxels : int
        Voxels along the model's longest bounding-box side (the packing's resolution).
    min_radius_m : float, optional
        Smallest ball, metres (default 2 voxels).
    max_spheres : int
        Stop after this many balls.

    Examples
    --------
    >>> import pyvista as pv
    >>> from latlong.shapes import ShapeModel
    >>> s = pv.Sphere(radius=10.0, theta_resolution=48, phi_resolution=48)
    >>> m = ShapeModel(s.points.astype(float), s.faces.reshape(-1, 4)[:, 1:].astype(int))
    >>> p = sphere_packing(m, n_voxels=40)
    >>> round(float(p.radii[0]), 1), bool(0.5 < p.coverage < 1.0)
    (9.5, True)
    """
    from scipy.ndimage import distance_transform_edt

    if not isinstance(model, ShapeModel):
        raise TypeError(f"`model` must be a ShapeModel; got {type(model).__name__}")
    n_voxels = check_int("n_voxels", n_voxels, 8, 1024)
    max_spheres = check_int("max_spheres", max_spheres, 1, 10**7)
    lo, hi = model.vertices.min(axis=0), model.vertices.max(axis=0)
    h = float((hi - lo).max()) / n_voxels
    r_min = 2.0 * h if min_radius_m is None else check_positive("min_radius_m", min_radius_m)
    origin, dims = _voxel_grid(lo, hi, h, 2)
    need = _PACK_BYTES_PER_VOXEL * float(np.prod(np.asarray(dims, dtype=float)))
    if need > 0.6 * physical_memory_bytes():
        raise ValueError(f"`n_voxels` = {n_voxels}: the packing grid {dims[0]} x {dims[1]} x "
                         f"{dims[2]} needs about {need / 2**30:.1f} GiB; this machine has "
                         f"{physical_memory_bytes() / 2**30:.1f} GiB: use fewer voxels")
    inside = np.zeros((dims[2], dims[1], dims[0]), dtype=np.uint8)
    odd = _k._voxelize_kernel(np.ascontiguousarray(model.vertices, np.float64),
                              np.ascontiguousarray(model.faces, np.int64), origin, h, inside)
    if not inside.any():
        raise ValueError(f"`n_voxels` = {n_voxels} is too coarse: no voxel centre lies inside "
                         f"{model.source or 'the model'}")
    free = distance_transform_edt(inside, sampling=h) - 0.5 * h
    free[inside == 0] = -np.inf
    centers = np.empty((max_spheres, 3))
    radii = np.empty(max_spheres)
    n = _k._pack_kernel(free, origin, h, r_min, centers, radii)
    if n == 0:
        raise ValueError(f"`min_radius_m` = {r_min:g} m is larger than the largest ball that "
                         "fits inside the model")
    centers, radii = centers[:n].copy(), radii[:n].copy()
    coverage = float((4.0 / 3.0) * math.pi * (radii**3).sum() / model.volume_m3)
    if odd:
        logger.info("%d voxel columns grazed an edge of the mesh", odd)
    return SpherePacking(centers, radii, h, coverage, int(odd))


# --------------------------------------------------------------------------- metaballs
@dataclasses.dataclass(frozen=True)
class Metaballs:
    """A Wyvill metaball field ``f = sum (1 - |p - c|^2 / R^2)^3`` and its iso-value."""

    centers: np.ndarray
    """(n, 3) centres, metres."""
    support: np.ndarray
    """(n,) support radii R = blend x ball radius, metres."""
    iso: float
    """The surface is f = iso (inside: f > iso)."""
    blend: float
    """Support radius / ball radius."""
    fit_mean_m: float
    """Mean first-order distance of the constraint's surface samples to the iso-surface."""

    def field(self, points) -> tuple[np.ndarray, np.ndarray]:
        """f and grad f (1/m) at points (n, 3)."""
        pts = np.ascontiguousarray(np.asarray(points, dtype=np.float64).reshape(-1, 3))
        out = np.empty((len(pts), 4))
        _k._metaball_points_kernel(pts, self.centers, self.support, out)
        return out[:, 0], out[:, 1:]

    def distance(self, points) -> np.ndarray:
        """First-order signed distance to the iso-surface, metres (> 0 inside)."""
        f, g = self.field(points)
        return (f - self.iso) / np.maximum(np.linalg.norm(g, axis=1), self._g_floor)

    def normals(self, points) -> np.ndarray:
        """Outward unit normals -grad f / |grad f| at points (n, 3)."""
        _, g = self.field(points)
        n = -g / np.maximum(np.linalg.norm(g, axis=1, keepdims=True), 1e-300)
        return n

    @property
    def _g_floor(self) -> float:
        # far outside f = 0 and grad f = 0: the distance becomes -(extent of the field)
        lo = (self.centers - self.support[:, None]).min(axis=0)
        hi = (self.centers + self.support[:, None]).max(axis=0)
        return self.iso / float(np.linalg.norm(hi - lo))


def _weighted_median(values: np.ndarray, weights: np.ndarray) -> float:
    order = np.argsort(values, kind="stable")
    cw = np.cumsum(weights[order])
    return float(values[order][np.searchsorted(cw, 0.5 * cw[-1])])


def fit_metaballs(packing: SpherePacking, model: ShapeModel, *, blends=_BLENDS,
                  n_samples: int = _FIT_SAMPLES, rng=0) -> Metaballs:
    """Metaballs over ``packing`` with blend factor and iso-value fitted to ``model``.

    For each blend factor (support radius / ball radius) the iso-value is the weighted
    median of f at ``n_samples`` points uniform on the constraint surface (weights
    1/|grad f|); the blend with the smallest mean first-order distance wins.
    """
    if not isinstance(packing, SpherePacking):
        raise TypeError(f"`packing` must be a SpherePacking; got {type(packing).__name__}")
    n_samples = check_int("n_samples", n_samples, 100, 10**7)
    blends = [check_range("blends", b, 1.01, 10.0) for b in blends]
    pts = np.ascontiguousarray(sample_surface(model, n_samples, rng=normalize_rng(rng)))
    best = None
    out = np.empty((len(pts), 4))
    for blend in blends:
        support = packing.radii * blend
        _k._metaball_points_kernel(pts, packing.centers, support, out)
        g = np.linalg.norm(out[:, 1:], axis=1)
        ok = g > 0
        if ok.mean() < 0.99:  # samples outside every support: this blend cannot fit
            continue
        w = 1.0 / g[ok]
        iso = _weighted_median(out[ok, 0], w)
        if not iso > 0:
            continue
        mean = float(np.mean(np.abs(out[ok, 0] - iso) * w))
        if best is None or mean < best[0]:
            best = (mean, blend, iso)
    if best is None:
        raise ValueError("no blend factor reaches the constraint surface from the packing; "
                         "pack with a smaller `min_radius_m`")
    mean, blend, iso = best
    return Metaballs(packing.centers, packing.radii * blend, iso, blend, mean)


# --------------------------------------------------------------------------- grid helpers
@dataclasses.dataclass(frozen=True)
class _Grid:
    origin: np.ndarray
    h: float
    shape: tuple[int, int, int]  # (nz, ny, nx)

    def index_boxes(self, centers, reach):
        """Inclusive (i, j, k) index boxes of balls (centre, reach) clipped to the grid."""
        c = (np.asarray(centers) - self.origin) / self.h
        rr = np.asarray(reach)[:, None] / self.h
        nx = np.array(self.shape[::-1])
        lo = np.clip(np.floor(c - rr), 0, nx - 1).astype(np.int64)
        hi = np.clip(np.ceil(c + rr), -1, nx - 1).astype(np.int64)
        hi[(c + rr < 0).any(axis=1) | (c - rr > nx - 1).any(axis=1)] = -1
        return np.ascontiguousarray(lo), np.ascontiguousarray(hi)

    def bins(self, lo, hi):
        """CSR bin lists (offsets, items) and the bins that hold any item."""
        nbins = np.array([-(-n // _BIN) for n in self.shape[::-1]], dtype=np.int64)
        counts = np.zeros(int(nbins.prod()), np.int64)
        _k._bin_count(lo, hi, _BIN, nbins, counts)
        offsets = np.concatenate([[0], np.cumsum(counts)]).astype(np.int64)
        items = np.empty(offsets[-1], np.int64)
        _k._bin_fill(lo, hi, _BIN, nbins, offsets, items)
        return nbins, offsets, items, np.flatnonzero(counts).astype(np.int64)

    def _nearest(self, points):
        ijk = np.rint((np.asarray(points) - self.origin) / self.h).astype(np.int64)
        return np.clip(ijk, 0, np.array(self.shape[::-1]) - 1)

    def sample(self, values, points) -> np.ndarray:
        """``values`` at the grid point nearest to each point."""
        i, j, k = self._nearest(points).T
        return values[k, j, i]

    def gradient(self, values, points) -> np.ndarray:
        """Central-difference gradient of ``values`` at the grid point nearest to each
        point, (n, 3) per metre (one-sided on the border)."""
        ijk = self._nearest(points)
        top = np.array(self.shape[::-1]) - 1
        out = np.empty((len(ijk), 3))
        for axis in range(3):
            up, dn = ijk.copy(), ijk.copy()
            up[:, axis] = np.minimum(up[:, axis] + 1, top[axis])
            dn[:, axis] = np.maximum(dn[:, axis] - 1, 0)
            span = (up[:, axis] - dn[:, axis]) * self.h
            out[:, axis] = (values[up[:, 2], up[:, 1], up[:, 0]] -
                            values[dn[:, 2], dn[:, 1], dn[:, 0]]) / np.maximum(span, 1e-300)
        return out


def _contour(values: np.ndarray, grid: _Grid):
    """Flying-edges zero level of ``values`` (> 0 inside): (vertices, faces) outward."""
    import pyvista as pv

    img = pv.ImageData(dimensions=grid.shape[::-1], spacing=(grid.h,) * 3,
                       origin=tuple(grid.origin))
    v = np.ascontiguousarray(values, dtype=np.float64).ravel()
    v = np.where(v == 0.0, -1e-9 * grid.h, v)  # no vertex exactly on a grid point
    img.point_data["F"] = v
    surf = img.contour([0.0], scalars="F", method="flying_edges")
    if surf.n_cells == 0:
        raise ValueError("the implicit surface is empty at this resolution")
    surf = surf.triangulate()
    verts = np.asarray(surf.points, dtype=np.float64)
    faces = np.asarray(surf.faces).reshape(-1, 4)[:, 1:].astype(np.int64)
    a, b, c = (verts[faces[:, k]] for k in range(3))
    if np.einsum("ij,ij->", a, np.cross(b, c)) < 0:
        faces = faces[:, ::-1].copy()
    return verts, faces


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


# --------------------------------------------------------------------------- craters
@dataclasses.dataclass(frozen=True, slots=True)
class LcsnLayer:
    """One crater layer of the multi-level grid (Li 2022 §3.1, eq. 2, §4.1)."""

    kernel: str | _craters.LcsnParams
    """Crater shape: a name of :data:`craters.LCSN_PRESETS` or LcsnParams; it is scaled
    to every drawn diameter."""
    d_min_m: float
    """Smallest diameter, metres (rim crest; apparent diameter for rimless kernels; the
    nominal 2/sqrt(gamma) for degraded kernels with neither)."""
    d_max_m: float
    """Largest diameter, metres; sets the layer's grid level (cells >= d_max_m)."""
    exponent: float = 3.0
    """B of the cumulative law N(>D) ~ D^-B inside the layer (Li 2022 uses B = 3)."""
    probability: float = 0.5
    """Chance that a surface cell of the level receives an impulse, (0, 1]."""
    weight: float = 1.0
    """omega of eq. 2: the kernel's heights are multiplied by it, [0, 1]."""
    depth_ratio: tuple[float, float] | None = None
    """Depth (kinds 1-3: H_t) or uplift (kind 4: H_c) over diameter, uniform in this
    range per crater (before the weight); None keeps the kernel's own ratio."""

    def __post_init__(self):
        if isinstance(self.kernel, str):
            if self.kernel not in _craters.LCSN_PRESETS:
                raise ValueError(f"`kernel` must be one of {', '.join(_craters.LCSN_PRESETS)} "
                                 f"or a craters.LcsnParams; got {self.kernel!r}")
        elif not isinstance(self.kernel, _craters.LcsnParams):
            raise TypeError(f"`kernel` must be a preset name or craters.LcsnParams; got "
                            f"{type(self.kernel).__name__}")
        lo = check_positive("d_min_m", self.d_min_m)
        hi = check_positive("d_max_m", self.d_max_m)
        if lo >= hi:
            raise ValueError(f"`d_min_m` must be < d_max_m ({hi!r}); got {lo!r}")
        check_range("exponent", self.exponent, -10.0, 10.0)
        p = check_range("probability", self.probability, 0.0, 1.0)
        if p == 0:
            raise ValueError("`probability` must be in (0, 1]; got 0.0")
        check_range("weight", self.weight, 0.0, 1.0)
        if self.depth_ratio is not None:
            r = tuple(self.depth_ratio)
            if len(r) != 2:
                raise ValueError(f"`depth_ratio` must be (low, high); got {self.depth_ratio!r}")
            a, b = (check_range("depth_ratio", v, 0.0, 2.0) for v in r)
            if not 0 < a <= b:
                raise ValueError(f"`depth_ratio` must be (low, high) with 0 < low <= high; "
                                 f"got {self.depth_ratio!r}")

    @property
    def params(self) -> _craters.LcsnParams:
        if isinstance(self.kernel, str):
            return _craters.LCSN_PRESETS[self.kernel]
        return self.kernel


def _ratio_range(text: str) -> tuple[float, float]:
    lo, _, hi = text.partition(":")
    return float(lo), float(hi or lo)


_SPEC_ITEMS = {"kernel": ("kernel", str), "dmin": ("d_min_m", float), "dmax": ("d_max_m", float),
               "B": ("exponent", float), "p": ("probability", float), "w": ("weight", float),
               "hd": ("depth_ratio", _ratio_range)}


def parse_lcsn_spec(spec: str) -> LcsnLayer:
    """Parse ``kernel=NAME,dmin=500,dmax=1000[,B=3,p=0.5,w=1,hd=0.15:0.25]`` (metres).

    Examples
    --------
    >>> parse_lcsn_spec("kernel=table-a1-1km-0gyr,dmin=500,dmax=1000,hd=0.1:0.2").depth_ratio
    (0.1, 0.2)
    """
    values = parse_spec(spec, _SPEC_ITEMS, ("kernel", "dmin", "dmax"), "LCSN layer")
    try:
        return LcsnLayer(**values)
    except (ValueError, TypeError) as exc:
        raise ValueError(f"LCSN layer {spec!r}: {exc}") from None


_KIND_NAMES = {1: "simple", 2: "flat-floored", 3: "fresh", 4: "complex"}


@dataclasses.dataclass(frozen=True)
class _Shape:
    """A layer's reference kernel, measured once: what scaling needs."""

    kind: int
    raw: dict
    diameter: float  # D_rim, or D_a without a rim
    morph: dict
    support: float  # in metres of the reference kernel
    amplitude: float  # largest |kernel|
    depth: float  # H_t (kinds 1-3) or H_c (kind 4)


def _measure_shape(params: _craters.LcsnParams) -> _Shape:
    kind, raw = params.kind, params.raw
    morph = _craters.lcsn_morphometry(kind, "numeric", **raw)
    d = morph.get("D_rim", math.nan)
    if not math.isfinite(d):
        d = morph.get("D_a", math.nan)
    if not math.isfinite(d) and kind in (3, 4):
        # a degraded kernel whose rim has decayed into the bowl and that never returns to
        # the datum (Table A.1, 300 m at 2-3 Gyr): its nominal rim diameter 2 / sqrt(gamma)
        d = 2.0 / math.sqrt(raw["gamma"])
    if not math.isfinite(d):
        raise ValueError(f"LCSN kernel (kind {kind}) has no apparent diameter to scale by; "
                         "choose another kernel")
    r = np.linspace(0.0, 10.0 * d, 200_001)
    v = np.abs(_craters.lcsn_kernel(kind, r, **raw))
    amp = float(v.max())
    reach = float(r[np.flatnonzero(v >= _KERNEL_EPS * amp).max()])
    depth = morph["H_c"] if kind == 4 else morph["H_t"]
    return _Shape(kind, raw, d, morph, reach / 0.8, amp, depth)


def _largest_height(shape: _Shape, la: LcsnLayer) -> float:
    """The largest |height| (m) one crater of the layer can add: at d_max_m, weighted."""
    ratio = la.depth_ratio[1] * shape.diameter / shape.depth if la.depth_ratio else 1.0
    return shape.amplitude * la.d_max_m / shape.diameter * la.weight * ratio


def _layer_levels(layers, cell_m: float) -> list[int]:
    levels = []
    for la in layers:
        level = int(math.floor(math.log2(cell_m / la.d_max_m) + 1e-12))
        if level < 0:
            raise ValueError(f"`cell_m` = {cell_m:g} m is smaller than a layer's d_max_m "
                             f"({la.d_max_m:g} m): level-0 cells must hold the largest crater")
        levels.append(level)
    return levels


def _impulses(layers, shapes, levels, cell_m, base_verts, base_faces, metaballs, rng):
    """Draw every layer's impulses on the base surface; return kernel arrays + catalog."""
    a, b, c = (base_verts[base_faces[:, k]] for k in range(3))
    centroid = (a + b + c) / 3.0
    area = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1)
    lo = base_verts.min(axis=0)
    parts = []
    for idx, (la, shape, level) in enumerate(zip(layers, shapes, levels, strict=True)):
        cell = cell_m / 2**level
        key3 = np.floor((centroid - lo) / cell).astype(np.int64)
        dims = key3.max(axis=0) + 1
        key = (key3[:, 2] * dims[1] + key3[:, 1]) * dims[0] + key3[:, 0]
        order = np.argsort(key, kind="stable")
        cells, start = np.unique(key[order], return_index=True)
        end = np.append(start[1:], len(order))
        chosen = np.flatnonzero(rng.random(len(cells)) < la.probability)
        n = len(chosen)
        # a uniform point of the surface inside each chosen cell
        cum = np.cumsum(area[order])
        before = np.where(start[chosen] > 0, cum[start[chosen] - 1], 0.0)
        target = before + rng.random(n) * (cum[end[chosen] - 1] - before)
        tri = order[np.minimum(np.searchsorted(cum, target, side="right"), end[chosen] - 1)]
        u, v = rng.random(n), rng.random(n)
        flip = u + v > 1
        u[flip], v[flip] = 1 - u[flip], 1 - v[flip]
        pos = a[tri] + u[:, None] * (b[tri] - a[tri]) + v[:, None] * (c[tri] - a[tri])
        diam = (_craters.sample_power_law_diameters(n, la.d_min_m, la.d_max_m, la.exponent,
                                                    rng=rng) if n else np.zeros(0))
        if la.depth_ratio is not None:
            ratio = rng.uniform(la.depth_ratio[0], la.depth_ratio[1], n)
            hscale = ratio * shape.diameter / shape.depth
        else:
            hscale = np.ones(n)
        hscale = hscale * la.weight
        parts.append((idx, level, shape, pos, diam, hscale))
    total = sum(len(p[3]) for p in parts)
    out = {"centers": np.zeros((total, 3)), "kinds": np.zeros(total, np.int64),
           "params": np.zeros((total, 5)), "support": np.zeros(total),
           "zhalf": np.zeros(total), "amplitude": np.zeros(total)}
    cols: dict[str, list] = {k: [] for k in (
        "diameter_m", "kind", "layer", "level", "depth_m", "rim_height_m", "uplift_m",
        "apparent_diameter_m", "weight")}
    s = 0
    for idx, level, shape, pos, diam, hscale in parts:
        n = len(pos)
        e = s + n
        scale = diam / shape.diameter
        raw = shape.raw
        out["centers"][s:e] = pos
        out["kinds"][s:e] = shape.kind
        if shape.kind in (1, 2):
            out["params"][s:e, 3] = raw["a"] * scale * hscale
            out["params"][s:e, 4] = raw["b"] / scale ** (4 if shape.kind == 2 else 2)
        else:
            out["params"][s:e, 0] = raw["kappa"] * scale * hscale
            out["params"][s:e, 1] = raw["beta"]
            out["params"][s:e, 2] = raw["gamma"] / scale**2
            out["params"][s:e, 3] = raw["a"] * scale * hscale
            out["params"][s:e, 4] = raw["b"] / scale**2
        out["support"][s:e] = shape.support * scale
        out["amplitude"][s:e] = shape.amplitude * scale * hscale
        out["zhalf"][s:e] = out["amplitude"][s:e] + 0.25 * out["support"][s:e]
        m = shape.morph
        heights = scale * hscale
        cols["diameter_m"].append(diam)
        cols["kind"].append(np.full(n, _KIND_NAMES[shape.kind]))
        cols["layer"].append(np.full(n, idx))
        cols["level"].append(np.full(n, level))
        cols["depth_m"].append(m.get("H_t", math.nan) * heights)
        cols["rim_height_m"].append(m.get("H_rim", math.nan) * heights)
        cols["uplift_m"].append(m.get("H_c", math.nan) * heights)
        cols["apparent_diameter_m"].append(m.get("D_a", math.nan) * scale)
        cols["weight"].append(hscale)
        s = e
    normals = metaballs.normals(out["centers"]) if total else np.zeros((0, 3))
    out["normals"] = np.ascontiguousarray(normals)
    cat_cols = {k: np.concatenate(v) if v else np.zeros(0) for k, v in cols.items()}
    return out, cat_cols


# --------------------------------------------------------------------------- result
@dataclasses.dataclass(frozen=True)
class ImplicitSurface:
    """A marching-cubes mesh of an implicit body and the crater catalog that made it."""

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
    def volume_m3(self) -> float:
        return ShapeModel(self.vertices, self.faces).volume_m3

    @property
    def area_m2(self) -> float:
        return ShapeModel(self.vertices, self.faces).area_m2

    def to_pyvista(self):
        """A ``pyvista.PolyData`` of the mesh."""
        return ShapeModel(self.vertices, self.faces).to_pyvista()

    def is_watertight(self) -> bool:
        """Every edge belongs to exactly two faces, each direction once."""
        e = np.concatenate([self.faces[:, [0, 1]], self.faces[:, [1, 2]],
                            self.faces[:, [2, 0]]])
        directed = e[:, 0] * len(self.vertices) + e[:, 1]
        undirected = np.sort(e, axis=1)
        _, counts = np.unique(undirected, axis=0, return_counts=True)
        return bool((counts == 2).all() and np.unique(directed).size == directed.size)

    def save(self, path) -> Path:
        """Write the mesh by suffix (:func:`write_mesh`)."""
        return write_mesh(self.vertices, self.faces, path)

    def to_body(self, magnitude: int, *, crossings: str = "error"):
        """Cast the mesh onto a lat/long grid of ``magnitude`` from the origin.

        ``crossings="error"`` raises ValueError (with the affected share of directions)
        unless the surface is star-shaped from the origin; ``"outermost"`` or
        ``"innermost"`` keep one crossing (overhangs are then lost). The body keeps the
        crater catalog (:func:`latlong.shapes.from_shape_model`).
        """
        from .shapes import from_shape_model

        model = ShapeModel(self.vertices, self.faces, "implicit surface")
        body = from_shape_model(model, magnitude, center="origin", crossings=crossings,
                                smooth="none", subdivisions=0,
                                metadata={"implicit": self.metadata})
        return body.replace(craters=self.catalog if len(self.catalog) else None)


# --------------------------------------------------------------------------- the build
def _estimate_bytes(shape) -> int:
    # float64 first-order field, distance, crater field, noise; int64 seed ids; int32 x3
    # distance-transform indices; bool masks
    return int(np.prod(shape)) * (8 * 5 + 12 + 4)


def implicit_surface(constraint, layers=(), *, gabor=None, voxel_m: float | None = None,
                     target_polygons: int = 200_000, units: str | None = None,
                     cell_m: float | None = None, packing_voxels: int = 128,
                     min_sphere_m: float | None = None, rng=None,
                     progress: bool = False) -> ImplicitSurface:
    """Build an implicit asteroid from a constraint mesh (module notes).

    Parameters
    ----------
    constraint : ShapeModel, str or Path
        Closed mesh (a path is read with :func:`latlong.shapes.read_shape_model`, which
        needs ``units``). It is moved so that its volume centroid is the origin.
    layers : sequence of LcsnLayer
        Crater layers, each on its grid level.
    gabor : latlong.gabor.GaborNoise, optional
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

    from .gabor import GaborNoise, _gabor_impulses

    times: dict[str, float] = {}
    t0 = time.perf_counter()
    if not isinstance(constraint, ShapeModel):
        if units is None:
            raise ValueError("`units` (km or m) is required when reading a constraint file")
        constraint = read_shape_model(constraint, units=units)
    layers = list(layers)
    for la in layers:
        if not isinstance(la, LcsnLayer):
            raise TypeError(f"`layers` must hold LcsnLayer objects; got {type(la).__name__}")
    if gabor is not None and not isinstance(gabor, GaborNoise):
        raise TypeError(f"`gabor` must be a latlong.gabor.GaborNoise; got {type(gabor).__name__}")
    target_polygons = check_int("target_polygons", target_polygons, 100, 10**9)
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
    levels = _layer_levels(layers, cell_m)
    for la in layers:
        if la.d_max_m < 4.0 * h:
            logger.warning("LCSN layer %s (%g-%g m) is at most 4 voxels of %.3g m across: its "
                           "craters are barely resolved", la.kernel, la.d_min_m, la.d_max_m, h)
    shapes = [_measure_shape(la.params) for la in layers]
    # twice the largest height each layer's craters can add (two overlapping ones) bounds
    # the band of the field where craters can move the surface
    max_disp = 2.0 * sum(_largest_height(s, la) for s, la in zip(shapes, layers, strict=True))
    gabor_band = 6.0 * gabor.amplitude_m if gabor is not None else 0.0
    band = max_disp + gabor_band + 3.0 * h

    bar = progress_bar(total=6, enabled=progress, desc="implicit")
    bar.set_description("packing")
    packing = sphere_packing(model, n_voxels=packing_voxels, min_radius_m=min_sphere_m)
    meta = fit_metaballs(packing, model, rng=rng.integers(2**63))
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
            raise ValueError(f"`voxel_m` = {h:.4g} m needs a {shape[2]} x {shape[1]} x "
                             f"{shape[0]} grid, about {need / 2**30:.1f} GiB; this machine has "
                             f"{physical_memory_bytes() / 2**30:.1f} GiB: use fewer polygons "
                             "or a larger voxel")
        grid = _Grid(glo, h, shape)
        bar.set_description("metaballs")
        base = _metaball_distance(meta, grid)
        rim = max(base[0].max(), base[-1].max(), base[:, 0].max(), base[:, -1].max(),
                  base[:, :, 0].max(), base[:, :, -1].max())  # on the grid's boundary
        if rim < -band:
            break
        margin *= 1.5
    times["field_s"] = time.perf_counter() - t0 - sum(times.values())
    bar.update()

    bar.set_description("impulses")
    base_verts, base_faces = _contour(base, grid)
    imp, cat_cols = _impulses(layers, shapes, levels, cell_m, base_verts, base_faces, meta,
                              rng)
    field = base.copy()
    if len(imp["centers"]):
        # the ball around the support cylinder (radius support, half-height 2 zhalf)
        lo_i, hi_i = grid.index_boxes(imp["centers"], np.hypot(imp["support"],
                                                               2.0 * imp["zhalf"]))
        nbins, offsets, items, active = grid.bins(lo_i, hi_i)
        _k._crater_grid_kernel(grid.origin, h, active, _BIN, nbins, offsets, items, lo_i, hi_i,
                               imp["centers"], imp["normals"], imp["kinds"], imp["params"],
                               imp["support"], imp["zhalf"], base, band, field)
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
        g = _gabor_impulses(gabor, base, grid, max_disp + gabor_band, rng)
        n_gabor = len(g["pos"])
        if n_gabor:
            lo_i, hi_i = grid.index_boxes(g["pos"], g["reach"])
            nbins, offsets, items, active = grid.bins(lo_i, hi_i)
            noise = np.zeros_like(field)
            _k._gabor_grid_kernel(grid.origin, h, active, _BIN, nbins, offsets, items, lo_i,
                                  hi_i, g["pos"], g["wave"], g["env"], g["amp"], g["phase"],
                                  g["cutoff2"], field, gabor_band + 2.0 * h, noise)
            field += noise
    times["gabor_s"] = time.perf_counter() - t0 - sum(times.values())
    bar.update()

    bar.set_description("marching cubes")
    verts, faces = _contour(field, grid)
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


def _metaball_distance(meta: Metaballs, grid: _Grid) -> np.ndarray:
    """Signed Euclidean distance to the metaball surface on the grid (> 0 inside), m.

    The first-order estimate (f - T) / |grad f| is accurate next to the surface but not
    deeper (in the gaps between packed balls f barely exceeds T: a crater bowl would
    carve too deep there). So it is used only at the *seeds*, the grid points with a
    neighbour across the surface, to find their foot points on the surface
    (p - d grad d / |grad d|); every grid point then takes the distance to the tangent
    plane at the closest foot point among the seeds around its nearest seed
    (``scipy.ndimage.distance_transform_edt`` indices): a closest-point transform.
    """
    from scipy.ndimage import distance_transform_edt

    g_floor = meta._g_floor
    first = np.full(grid.shape, -meta.iso / g_floor)
    lo, hi = grid.index_boxes(meta.centers, meta.support)
    nbins, offsets, items, active = grid.bins(lo, hi)
    _k._metaball_grid_kernel(grid.origin, grid.h, active, _BIN, nbins, offsets, items,
                             meta.centers, meta.support, meta.iso, g_floor, first)
    inside = first > 0
    seed = np.zeros(grid.shape, dtype=bool)
    for axis in range(3):
        a = [slice(None)] * 3
        b = [slice(None)] * 3
        a[axis], b[axis] = slice(None, -1), slice(1, None)
        cross = inside[tuple(a)] != inside[tuple(b)]
        seed[tuple(a)] |= cross
        seed[tuple(b)] |= cross
    if not seed.any():
        raise ValueError(f"`voxel_m` = {grid.h:.4g} m: no grid point falls inside the body "
                         "(the voxel is coarser than the body); use a smaller voxel or more "
                         "polygons")
    idx = np.argwhere(seed)  # (k, j, i), C order
    pts = grid.origin + idx[:, ::-1] * grid.h
    grad = grid.gradient(first, pts)
    unit = grad / np.maximum(np.linalg.norm(grad, axis=1, keepdims=True), 1e-300)
    # a seed is less than one voxel from the crossing next to it: the first-order
    # estimate can overshoot where the field is flat
    reach = np.clip(first[seed], -grid.h, grid.h)
    foot = np.ascontiguousarray(pts - reach[:, None] * unit)
    seed_id = np.full(grid.shape, -1, dtype=np.int64)
    seed_id[seed] = np.arange(len(idx))
    nearest = distance_transform_edt(~seed, return_distances=False, return_indices=True)
    dist = np.empty(grid.shape)
    _k._closest_distance_kernel(grid.origin, grid.h, nearest, seed_id, foot,
                                np.ascontiguousarray(unit), first, dist)
    return dist


# --------------------------------------------------------------------------- writers
def write_mesh(vertices, faces, path) -> Path:
    """Write a triangle mesh by suffix: binary PLY (float32 xyz, int32 faces), OBJ
    (9 significant digits), binary STL, VTP/VTK (pyvista). Atomic, deterministic bytes."""
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in MESH_SUFFIXES:
        raise ValueError(f"`path` {str(path)!r}: unknown mesh format {suffix!r}; allowed: "
                         f"{' '.join(MESH_SUFFIXES)}")
    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces, dtype=np.int64)
    with atomic_path(path) as tmp:
        if suffix == ".ply":
            header = ("ply\nformat binary_little_endian 1.0\ncomment craterform implicit "
                      f"body, metres\nelement vertex {len(v)}\nproperty float x\n"
                      "property float y\nproperty float z\n"
                      f"element face {len(f)}\nproperty list uchar int vertex_indices\n"
                      "end_header\n").encode("ascii")
            rec = np.empty(len(f), dtype=[("n", "u1"), ("v", "<i4", (3,))])
            rec["n"], rec["v"] = 3, f
            with open(tmp, "wb") as fh:
                fh.write(header)
                fh.write(v.astype("<f4").tobytes())
                fh.write(rec.tobytes())
        elif suffix == ".obj":
            with open(tmp, "w", encoding="ascii", newline="\n") as fh:
                fh.write("# craterform implicit body, metres\n")
                fh.write(("v %.9g %.9g %.9g\n" * len(v)) % tuple(v.ravel().tolist()))
                fh.write(("f %d %d %d\n" * len(f)) % tuple((f + 1).ravel().tolist()))
        elif suffix == ".stl":
            corners = v[f]
            normal = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
            norm = np.linalg.norm(normal, axis=1, keepdims=True)
            normal = np.divide(normal, norm, out=np.zeros_like(normal), where=norm > 0)
            rec = np.zeros(len(f), dtype=[("n", "<f4", (3,)), ("v", "<f4", (3, 3)),
                                          ("a", "<u2")])
            rec["n"], rec["v"] = normal, corners
            with open(tmp, "wb") as fh:
                fh.write(b"craterform implicit body, metres".ljust(80, b" "))
                fh.write(np.uint32(len(f)).tobytes())
                fh.write(rec.tobytes())
        else:
            ShapeModel(v, f).to_pyvista().save(str(tmp), binary=True)
    return path
