r"""The plan of a layer stack: where its layers lie and which craters and boulders each
takes (Martin, Parkes & Dunstan 2014, IV.A; the run is :func:`dem.enhance`).

Geometry
--------
Layer 0 is the ``size``-square window of the base DEM around the target; layer k is the
2x expansion of the ``(size + 1) / 2``-square footprint of layer k - 1 centred on the
target (on the pixel of layer k - 1 nearest it: the target is followed to the finest
layer's precision, not only to layer 0's pixel), shifted to stay one pixel clear of the
layer's border if the target is near it
(:func:`layer_windows`). :class:`StackGeometry` places every layer in the *layer-0 grid
frame* (metres, pixel (i, j) of layer 0 at (j p0, i p0)); layer k's grid frame is the
same frame shifted by its offset, so no rounding enters.

Craters: one population for the whole area
------------------------------------------
One population (``craters.population``: power-law layers N_cum = c D^k per m^2, or
model-age layers from a production function and chronology) is drawn for the area of
layer 0 and split: each crater goes into the *finest* layer that contains it
entirely -- its ejecta edge (1.5 D, times 1 + rim irregularity) plus one pixel clear of
the layer's border pixels -- provided that layer resolves it (D >= ``min_crater_px``
pixels); otherwise it is rejected and counted. Drawing all of it would be impossible
(11 layers of 1025^2 from 100 m pixels reach 5 cm: ~1e11 craters of a few pixels), so
the draw is organised by diameter *band* without changing its law: a crater of
diameter D can only be kept by layers whose pixels resolve it, ``L >= b(D)`` with band
``b`` = [m p_b, m p_(b-1)) (m = ``min_crater_px``, p_b the pixel size of layer b), and
all of those lie inside layer b's area. A Poisson process restricted to disjoint
(diameter band x area) sets gives independent Poisson processes with the same density,
so drawing band b (``craters.population`` over layer b's area, the law truncated to the
band) and only *counting* the craters of the band outside layer b's area (one Poisson
number each, as for the diameters below the finest layer's ``m`` pixels) yields exactly
the distribution of "one catalog for layer 0, then split".

A crater whose centre lies inside the rim of a larger, *younger* crater of any layer was
erased when that crater formed: it is dropped before stamping (:func:`erased_by_younger`),
so no layer shows (or lists) an older crater inside a younger rim -- across layers too,
where the finer layer's stamping could not know the coarser crater's age. Every count is
recorded: drawn = stamped + erased on steep ground + erased by a younger crater +
rejected.

Boulders (``min_boulder_px``) are split by the same banded draw (:func:`plan_boulders`):
each goes into the finest layer that holds its whole footprint (``0.87 D`` from its
centre, plus one pixel) and resolves it.

Randomness: one ``seed`` feeds every draw through ``numpy.random.SeedSequence(seed,
spawn_key=(tag, ...))`` streams (:func:`seed_stream`; the tags are the ``STREAM_*``
constants): one per diameter band for each population, one per count, one per layer
for stamping.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from typing import Any

import numpy as np
from rasterio.windows import Window

import craters
from craters._shared import ParameterError

from .boulders import BOULDER_REACH, draw_boulders
from .core import Dem

__all__ = ["MAX_STAMPED", "StackGeometry", "layer_windows", "plan_boulders", "plan_craters",
           "seed_stream", "stack_geometry"]

#: Largest expected number of craters (or boulders) to stamp in one stack.
MAX_STAMPED = 20_000_000
# largest Poisson mean of a rejected count (numpy's limit is ~9e18)
_MAX_COUNT_MEAN = 1e15
#: Tags (first spawn-key entry) of the random streams of a stack.
STREAM_CRATER_BAND, STREAM_CRATER_OUTSIDE, STREAM_CRATER_SMALL, STREAM_STAMP = 1, 2, 3, 4
STREAM_BOULDER_BAND, STREAM_BOULDER_OUTSIDE, STREAM_BOULDER_SMALL = 5, 6, 7


def seed_stream(seed: int, *key: int) -> np.random.Generator:
    """The generator of ``numpy.random.SeedSequence(seed, spawn_key=key)``."""
    return np.random.default_rng(np.random.SeedSequence(seed, spawn_key=key))


# --------------------------------------------------------------------------- geometry
@dataclasses.dataclass(frozen=True, slots=True)
class StackGeometry:
    """Layer placement in layer-0 pixel index units (exact binary fractions)."""

    size: int
    """Pixels per side of every layer."""
    offsets: tuple[tuple[float, float], ...]
    """Layer-0 index (row, col) of each layer's pixel (0, 0)."""
    pixel0_m: float
    """Pixel side of layer 0 in the stack's local frame, metres."""

    @property
    def n_layers(self) -> int:
        return len(self.offsets)

    def pixel_m(self, k: int) -> float:
        """Pixel side of layer k, metres."""
        return self.pixel0_m / 2.0**k

    def centres(self, k: int) -> tuple[float, float, float, float]:
        """Layer k's pixel-centre rectangle in the layer-0 grid frame: x0, x1, y0, y1 (m)."""
        r, c = self.offsets[k]
        span = (self.size - 1) / 2.0**k
        p = self.pixel0_m
        return c * p, (c + span) * p, r * p, (r + span) * p

    def area_ranges(self, k: int):
        """x and y ranges (m, layer-0 grid frame) of layer k's pixel footprints."""
        x0, x1, y0, y1 = self.centres(k)
        h = self.pixel_m(k) / 2.0
        return (x0 - h, x1 + h), (y0 - h, y1 + h)

    def area_m2(self, k: int) -> float:
        """Area of layer k's pixel footprints, m^2."""
        return (self.size * self.pixel_m(k)) ** 2


#: A default site is landing-like: the pixel nearest the base DEM's centre (within a
#: quarter of the layer size) whose 3 x 3 neighbourhood has Horn slopes at most this many
#: degrees at the base's pixel scale (else the one with the gentlest such neighbourhood).
LANDING_SLOPE_LIMIT_DEG = 5.0


def landing_site(base: Dem, size: int) -> tuple[tuple[int, int], float]:
    """The default site (:data:`LANDING_SLOPE_LIMIT_DEG`): its base pixel (row, col) and
    the steepest Horn slope of its 3 x 3 neighbourhood, degrees.

    The user's ``target`` pins a site; without one the stack should not land on a crater
    wall (issue 36: a target on one left 16 % of a stack's 59 m layer steeper than
    35 deg). Slopes at the base's scale are all this can see; the layers below
    inherit them.
    """
    from scipy.ndimage import maximum_filter

    from .terrain import slope

    rows, cols = base.shape
    r_c, c_c = rows // 2, cols // 2
    reach = max((size - 1) // 4, 1)
    # two pixels of margin: the Horn slope of every neighbour sees its own neighbours
    r0, r1 = max(r_c - reach, 2), min(r_c + reach + 1, rows - 2)
    c0, c1 = max(c_c - reach, 2), min(c_c + reach + 1, cols - 2)
    if r1 <= r0 or c1 <= c0:
        return (r_c, c_c), math.nan
    s = slope(base.crop(Window(c0 - 2, r0 - 2, c1 - c0 + 4, r1 - r0 + 4)))
    worst = maximum_filter(np.where(np.isfinite(s), s, 90.0), size=3)[2:-2, 2:-2]
    rr, cc = np.mgrid[r0:r1, c0:c1]
    dist2 = (rr - r_c) ** 2 + (cc - c_c) ** 2
    ok = worst <= LANDING_SLOPE_LIMIT_DEG
    if ok.any():
        pick = np.flatnonzero(ok.ravel())[np.argmin(dist2[ok])]
    else:
        pick = int(np.lexsort((dist2.ravel(), worst.ravel()))[0])
    i, j = np.unravel_index(pick, worst.shape)
    return (int(rr[i, j]), int(cc[i, j])), float(worst[i, j])


def layer_windows(base: Dem, target, size: int, n_layers: int, *, site_px=None):
    """Where the layers lie: ``(window of layer 0 in the base, footprints (row_off,
    col_off, width) of layers 1.. in their parents, target pixel in layer 0, target pixel
    in the base)``; ``target`` is (X, Y) in world coordinates or None (a landing-like
    site near the centre: the base pixel ``site_px`` when the caller has it already,
    else :func:`landing_site`'s)."""
    rows, cols = base.shape
    if rows < size or cols < size:
        raise ParameterError("size", f"{size} needs a base DEM of at least {size} x {size} "
                             f"pixels; it has {rows} x {cols}")
    if target is None:
        r_t, c_t = site_px if site_px is not None else landing_site(base, size)[0]
        row_f, col_f = r_t + 0.5, c_t + 0.5
    else:
        col_f, row_f = ~base.transform @ target
        if not (0 <= row_f < rows and 0 <= col_f < cols):
            b = base.bounds
            raise ParameterError("target", f"{list(target)} is outside the base DEM (bounds "
                             f"left {b.left:.10g}, bottom {b.bottom:.10g}, right {b.right:.10g}, "
                             f"top {b.top:.10g})")
        r_t, c_t = int(math.floor(row_f)), int(math.floor(col_f))
    r0 = min(max(r_t - (size - 1) // 2, 0), rows - size)
    c0 = min(max(c_t - (size - 1) // 2, 0), cols - size)
    # the target in the layer's pixel-centre coordinates (pixel i's centre at i), kept to
    # the finest layer's precision: each footprint centres on the pixel nearest it (a
    # target on a coarse pixel's corner would otherwise leave every finer layer half a
    # layer-0 pixel away: 5 km on LOLA's 4 ppd)
    tf = (row_f - 0.5 - r0, col_f - 0.5 - c0)
    w = (size + 1) // 2
    half = (w - 1) // 2
    windows = []
    for _ in range(1, n_layers):
        # centred on the target, else shifted to keep one pixel clear of the layer's border
        # (the mesh stitches each footprint to a ring of coarser cells around it)
        rr = min(max(math.floor(tf[0] + 0.5) - half, 1), size - w - 1)
        cc = min(max(math.floor(tf[1] + 0.5) - half, 1), size - w - 1)
        windows.append((rr, cc, w))
        tf = (2.0 * (tf[0] - rr), 2.0 * (tf[1] - cc))
    return Window(c0, r0, size, size), windows, (r_t - r0, c_t - c0), (r_t, c_t)


def stack_geometry(size: int, windows, pixel0_m: float) -> StackGeometry:
    """The :class:`StackGeometry` of layers of ``size`` pixels with footprints
    ``windows`` (from :func:`layer_windows`) and layer-0 pixels of ``pixel0_m`` metres."""
    offsets = [(0.0, 0.0)]
    for k, (rr, cc, _) in enumerate(windows, start=1):
        r, c = offsets[-1]
        offsets.append((r + rr / 2.0 ** (k - 1), c + cc / 2.0 ** (k - 1)))
    return StackGeometry(size, tuple(offsets), pixel0_m)


# --------------------------------------------------------------------------- banded draw
@dataclasses.dataclass(frozen=True, slots=True)
class _Drawn:
    """What a banded draw draws (craters or boulders)."""

    noun: str
    streams: tuple[int, int, int]
    """Stream tags of the band draws, the counts outside a band's area, the small ones."""
    draw: Callable
    """``draw(specs, x_range_m, y_range_m, rng)``: a catalog with ``x_m, y_m, diameter_m``
    and ``layer`` (the index into ``specs``)."""
    reach: Callable
    """``reach(catalog)``: each item's horizontal reach from its centre, metres."""
    count: Callable
    """``count(spec, area_m2, d_min_m, d_max_m)``: the expected number of items of a
    layer spec in a diameter range on an area (its cumulative law)."""


def _poisson(rng: np.random.Generator, mean: float, what: str, noun: str) -> int:
    if mean > _MAX_COUNT_MEAN:
        raise ValueError(f"{what}: about {mean:.3g} {noun}s; the {noun} layers ask for an "
                         f"absurd number of small {noun}s (raise d_min_m or lower c)")
    return int(rng.poisson(mean)) if mean > 0 else 0


def _assign(cat, reach, geometry: StackGeometry, b: int, per_layer: list, next_index: int):
    """Put each item of band ``b`` into the finest layer L >= b holding its ``reach``
    (metres) plus one pixel clear of the layer's border pixels; give the kept ones stack
    indices from ``next_index``. Returns (kept mask, next free index)."""
    best = np.full(len(cat), -1, dtype=np.int64)
    for L in range(b, geometry.n_layers):
        x0, x1, y0, y1 = geometry.centres(L)
        m = reach + geometry.pixel_m(L)
        inside = ((cat["x_m"] - m >= x0) & (cat["x_m"] + m <= x1)
                  & (cat["y_m"] - m >= y0) & (cat["y_m"] + m <= y1))
        best[inside] = L
    keep = best >= 0
    kept = cat[keep]
    ids = np.arange(next_index, next_index + len(kept), dtype=np.int64)
    kept = craters.make_catalog(**{name: kept[name] for name in kept.dtype.names}, index=ids)
    for L in np.unique(best[keep]):
        per_layer[L].append(kept[best[keep] == L])
    return keep, next_index + len(kept)


def _plan_banded(specs, geometry: StackGeometry, drawn: _Drawn, *, min_px: float, seed: int):
    """The banded draw of the module notes, for craters or boulders (``drawn``).

    Returns (per layer the list of its catalog parts, accounting).
    """
    specs = list(specs)
    noun = drawn.noun
    n = geometry.n_layers
    # per layer the size band it takes, [lo[b], hi[b]) metres: at least ``min_px`` of its
    # pixels, too small for the coarser layer
    lo = [min_px * geometry.pixel_m(b) for b in range(n)]
    hi = [math.inf] + lo[:-1]
    area0 = geometry.area_m2(0)

    def truncated(b):
        out = []
        for i, s in enumerate(specs):
            d0, d1 = max(s.d_min_m, lo[b]), min(s.d_max_m, hi[b])
            if d0 < d1:
                out.append((i, dataclasses.replace(s, d_min_m=d0, d_max_m=d1)))
        return out

    def count(area, s, d0, d1):
        return drawn.count(s, area, d0, d1)

    bands = [truncated(b) for b in range(n)]
    expected = sum(count(geometry.area_m2(b), s, s.d_min_m, s.d_max_m)
                   for b in range(n) for _, s in bands[b])
    if expected > MAX_STAMPED:
        raise ValueError(f"the {noun} layers put about {expected:.3g} {noun}s into the stack "
                         f"(limit {MAX_STAMPED:.0e}); raise d_min_m or lower c")
    tag_band, tag_outside, tag_small = drawn.streams
    per_layer: list[list[np.ndarray]] = [[] for _ in range(n)]
    band_rows: list[dict[str, Any]] = []
    next_index = 0
    for b in range(n):
        entry = {"layer": b, "d_min_m": lo[b], "d_max_m": hi[b] if b else None,
                 "drawn": 0, "assigned": 0, "rejected": 0}
        band_rows.append(entry)
        if not bands[b]:
            continue
        idx = np.array([i for i, _ in bands[b]], dtype=np.int64)
        xr, yr = geometry.area_ranges(b)
        cat = drawn.draw([s for _, s in bands[b]], xr, yr, seed_stream(seed, tag_band, b))
        cat["layer"] = idx[cat["layer"]]
        outside = area0 - geometry.area_m2(b)
        n_out = _poisson(seed_stream(seed, tag_outside, b),
                         sum(count(outside, s, s.d_min_m, s.d_max_m) for _, s in bands[b]),
                         f"{noun} diameter band {b}", noun)
        keep, next_index = _assign(cat, drawn.reach(cat), geometry, b, per_layer, next_index)
        entry.update(drawn=len(cat) + n_out, assigned=int(keep.sum()),
                     rejected=int((~keep).sum()) + n_out)
    small = 0.0
    for s in specs:
        d1 = min(s.d_max_m, lo[-1])
        if s.d_min_m < d1:
            small += count(area0, s, s.d_min_m, d1)
    n_small = _poisson(seed_stream(seed, tag_small), small, f"{noun}s below the finest layer",
                       noun)
    accounting = {"drawn": sum(e["drawn"] for e in band_rows) + n_small,
                  "assigned": [sum(len(c) for c in parts) for parts in per_layer],
                  "rejected": sum(e["rejected"] for e in band_rows) + n_small,
                  "rejected_below_finest": n_small, "bands": band_rows}
    return per_layer, accounting


def plan_craters(specs, geometry: StackGeometry, *, min_px: float, reach_radii: float,
                 seed: int):
    """Split one crater population of layer 0's area into per-layer catalogs.

    Parameters
    ----------
    specs : sequence of crater layers
        ``craters.CraterLayer`` (power law) or ``craters.ModelAgeLayer`` (model age);
        each band draws the layer truncated to the band (``dataclasses.replace`` of its
        diameter range) through its own cumulative law.
    geometry : StackGeometry
        Layer placement (:func:`stack_geometry`).
    min_px : float
        Smallest diameter a layer takes, in its pixels.
    reach_radii : float
        Crater reach (ejecta edge with rim irregularity) in crater radii.
    seed : int

    Returns
    -------
    catalogs : list of structured arrays
        Per layer, its craters with positions ``x_m, y_m`` in the *layer-0 grid frame*
        and an ``index`` column unique over the stack (oldest first within a layer).
    accounting : dict
        ``drawn``, ``assigned`` (per layer), ``rejected``, ``rejected_below_finest``
        and one entry per diameter band (see the module notes).
    """
    def draw(layers, x_range_m, y_range_m, rng):
        return craters.population(layers, x_range_m=x_range_m, y_range_m=y_range_m, rng=rng)

    drawn = _Drawn("crater", (STREAM_CRATER_BAND, STREAM_CRATER_OUTSIDE, STREAM_CRATER_SMALL),
                   draw, lambda cat: reach_radii * cat["diameter_m"] / 2.0,
                   lambda s, area, d0, d1: s.expected_count(area, d0, d1))
    per_layer, accounting = _plan_banded(specs, geometry, drawn, min_px=min_px, seed=seed)
    empty = craters.make_catalog(x_m=[], y_m=[], diameter_m=[], layer=np.zeros(0, np.int64),
                                 index=np.zeros(0, np.int64))
    catalogs = [np.concatenate(parts) if parts else empty for parts in per_layer]
    gone = erased_by_younger(catalogs)
    accounting["erased_by_younger_crater"] = [int(g.sum()) for g in gone]
    catalogs = [craters.sort_oldest_first(c[~g]) for c, g in zip(catalogs, gone, strict=True)]
    accounting.update(min_crater_px=min_px, reach_radii=reach_radii)
    return catalogs, accounting


def erased_by_younger(catalogs) -> list[np.ndarray]:
    """Per catalog, which craters have their centre inside the rim (``diameter_m / 2``
    from its centre, ``x_m, y_m`` in one frame) of a larger crater of *any* catalog that
    is younger (``age_gyr``): craters that crater erased when it formed."""
    from scipy.spatial import cKDTree

    sizes = [len(c) for c in catalogs]
    if not sum(sizes):
        return [np.zeros(n, bool) for n in sizes]
    x = np.concatenate([c["x_m"] for c in catalogs])
    y = np.concatenate([c["y_m"] for c in catalogs])
    d = np.concatenate([c["diameter_m"] for c in catalogs])
    age = np.concatenate([c["age_gyr"] for c in catalogs])
    tree = cKDTree(np.column_stack([x, y]))
    near = tree.query_ball_point(np.column_stack([x, y]), 0.5 * d)
    counts = np.fromiter((len(v) for v in near), dtype=np.int64, count=len(near))
    owner = np.repeat(np.arange(len(d)), counts)  # the containing (larger) crater
    inner = np.fromiter((i for v in near for i in v), dtype=np.int64, count=int(counts.sum()))
    hit = (d[inner] < d[owner]) & (age[inner] > age[owner])
    gone = np.zeros(len(d), bool)
    gone[inner[hit]] = True
    return np.split(gone, np.cumsum(sizes)[:-1])


def plan_boulders(specs, geometry: StackGeometry, *, min_px: float, seed: int):
    """Split one boulder population of layer 0's area into per-layer catalogs.

    The banded draw of :func:`plan_craters` (module notes), with each boulder's reach
    its whole footprint (``0.87 D`` from its centre); positions are in the layer-0 grid
    frame. Returns per layer its catalog (None without boulders) and the accounting.
    """
    drawn = _Drawn("boulder",
                   (STREAM_BOULDER_BAND, STREAM_BOULDER_OUTSIDE, STREAM_BOULDER_SMALL),
                   lambda layers, xr, yr, rng: draw_boulders(layers, xr, yr, rng=rng),
                   lambda cat: BOULDER_REACH * cat["diameter_m"],
                   lambda s, area, d0, d1: craters.expected_count(area, s.c, s.k, d0, d1))
    per_layer, accounting = _plan_banded(specs, geometry, drawn, min_px=min_px, seed=seed)
    catalogs = [np.concatenate(parts) if parts else None for parts in per_layer]
    accounting["min_boulder_px"] = min_px
    return catalogs, accounting
