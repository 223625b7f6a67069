r"""Multi-resolution enhancement of a DEM around a site (Martin et al., lunar paper IV.A).

:func:`enhance` builds a :class:`dem.Stack` of ``layers`` square layers of ``size`` =
2^n + 1 pixels: layer 0 is the ``size``-square window of the base DEM around the target,
and layer k is :func:`dem.expand` (one RMD doubling) of the ``(size + 1) / 2``-square
footprint of layer k - 1 centred on the target (shifted to stay one pixel clear of the
layer's border if the target is near it), so each layer is 2x finer than the last.

Craters: one population for the whole area
------------------------------------------
One power-law population (``craters.population``, N_cum = c D^k per m^2) is drawn for
the area of layer 0 and split: each crater goes into the *finest* layer that contains it
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
the distribution of "one catalog for layer 0, then split". Every count is recorded:
drawn = stamped + erased on steep ground + rejected.

Consistency (exact)
-------------------
Expansion keeps a parent's pixels as the even pixels of the child (bit for bit). Craters
break that, so after stamping the craters of layer k the stack is re-synchronised
upwards: for j = k-1 .. 0, ``layer[j][footprint] = layer[j+1][::2, ::2]``. A crater of
layer k never touches layer k's border pixels (the containment rule above), so the
change stays strictly inside each coarser footprint and the coarser layers stay
continuous; at the end ``Stack.is_consistent()`` holds exactly (and for the float32
GeoTIFFs too). Layer k+1 is expanded only after layer k's craters are in.

Boulders (``boulders``, ``min_boulder_px``) are split the same way (by diameter band,
each into the finest layer that holds its whole footprint and resolves it) and, in each
layer, placed on the ground after that layer's craters and stamped as a heightfield
maximum (:func:`dem.stamp_boulders`). What finer layers add later -- RMD detail at odd
pixels, their own boulders (a maximum again) and their smaller craters -- is superposed
on everything, so a younger small crater of a finer layer can dent a coarser layer's
boulder; the synchronisation below carries that up like any crater.

Stamping frames: crater positions are drawn in the *layer-0 grid frame* (metres, pixel
(i, j) of layer 0 at (j p0, i p0)); layer k's grid frame is the same frame shifted by
its offset, so no rounding enters. Catalogs are written in the stack's local frame
(:mod:`dem.frame`, origin at the target pixel) plus world coordinates.

Randomness: one ``seed`` feeds everything through ``numpy.random.SeedSequence(seed,
spawn_key=...)`` streams (one per diameter band for the population, one per layer for
stamping, one per count) and the counter-based expansion key, so the same seed gives
the same bytes whatever the thread count.
"""

from __future__ import annotations

import dataclasses
import logging
import math
import numbers

import numpy as np
from rasterio.windows import Window

import craters
from craters._shared import (
    check_int,
    check_positive,
    check_range,
    human_bytes,
    normalize_rng,
    physical_memory_bytes,
    progress_bar,
)

from .core import Dem
from .expansion import expand
from .fractal import fractal_fit
from .frame import grid_pixel_size, local_frame, pixel_affine
from .io import read
from .stack import Stack, check_stack_folder

__all__ = ["EnhanceConfig", "enhance", "plan_boulders", "plan_craters"]

logger = logging.getLogger(__name__)

#: Largest expected number of craters to stamp in one stack.
MAX_STAMPED = 20_000_000
# largest Poisson mean of a rejected-crater count (numpy's limit is ~9e18)
_MAX_COUNT_MEAN = 1e15
# stream tags of the SeedSequence spawn keys
_STREAM_BAND, _STREAM_OUTSIDE, _STREAM_SMALL, _STREAM_STAMP = 1, 2, 3, 4
_STREAM_BOULDER_BAND, _STREAM_BOULDER_OUTSIDE, _STREAM_BOULDER_SMALL = 5, 6, 7


def _stream(seed: int, *key: int) -> np.random.Generator:
    return np.random.default_rng(np.random.SeedSequence(seed, spawn_key=key))


@dataclasses.dataclass(frozen=True, slots=True)
class EnhanceConfig:
    """Everything that defines a stack (the keys of a ``dem enhance`` TOML scene)."""

    input: str | None = None
    """Base DEM file (GeoTIFF or PDS3 .lbl/.img); or pass the Dem to :func:`enhance`."""
    output: str | None = None
    """Output folder of the stack (layer GeoTIFFs, crater catalogs, manifest.json)."""
    target: tuple[float, float] | None = None
    """Site in world coordinates (CRS units, X then Y); default: the base DEM's centre."""
    layers: int = 11
    """Number of layers, 1..24 (layer k has pixels 2^k finer than the base)."""
    size: int = 1025
    """Pixels per side of every layer: 2^n + 1, 5..16385."""
    craters: tuple[str, ...] = ()
    """Crater layers ``c=..,k=..,dmin=..,dmax=..[,amin,amax,deg,kind]`` (metres, Gyr)."""
    min_crater_px: float = 2.0
    """Smallest crater diameter a layer takes, in its pixels (>= 1)."""
    boulders: tuple[str, ...] = ()
    """Boulder layers ``c=..,k=..,dmin=..,dmax=..[,burial,near]`` (metres; ``near`` is
    ignored on DEMs)."""
    min_boulder_px: float = 2.0
    """Smallest boulder a layer takes, in its pixels (>= 1)."""
    smooth_craters: bool = False
    """Ideal craters: no fractal overlay, circular rims."""
    fractal_dimension: float | None = None
    """F in [2, 3] of the expansion; default: estimated on layer 0."""
    roughness: float | None = None
    """Uniform RMS neighbour slope (m/m) of the expansion; default: local relief."""
    seed: int | None = None
    """Seed of everything random (a fresh one is drawn and recorded if None)."""
    band: int = 1
    """Band of the input file (1-based)."""
    pixel_size_m: float | None = None
    """Pixel size in metres, for inputs without a CRS."""
    body_radius_m: float | None = None
    """Body radius in metres, for inputs with a geographic CRS."""
    force: bool = False
    """Replace an existing output stack folder."""
    quiet: bool = False
    """No progress bars."""

    def __post_init__(self):
        def opt_str(name):
            v = getattr(self, name)
            if v is not None and (not isinstance(v, str) or not v):
                raise TypeError(f"`{name}` must be a file name; got {v!r}")

        opt_str("input")
        opt_str("output")
        if self.target is not None:
            t = self.target
            if (isinstance(t, str) or not hasattr(t, "__len__") or len(t) != 2
                    or not all(isinstance(v, numbers.Real) and not isinstance(v, bool)
                               for v in t)):
                raise TypeError(f"`target` must be [x, y] in world coordinates (CRS units); "
                                f"got {t!r}")
            if not all(math.isfinite(v) for v in t):
                raise ValueError(f"`target` must be finite; got {t!r}")
            object.__setattr__(self, "target", (float(t[0]), float(t[1])))
        object.__setattr__(self, "layers", check_int("layers", self.layers, 1, 24))
        size = check_int("size", self.size)
        if size < 5 or size > 16385 or (size - 1) & (size - 2):
            raise ValueError(f"`size` must be 2^n + 1 pixels, 5..16385 (5, 9, 17, ..., 1025, "
                             f"2049, ...); got {size}")
        object.__setattr__(self, "size", size)
        for name, parse, example in (("craters", craters.parse_layer_spec,
                                      "c=0.05,k=-2,dmin=1,dmax=500"),
                                     ("boulders", craters.parse_boulder_spec,
                                      "c=0.01,k=-3,dmin=0.5,dmax=5")):
            kind = name[:-1]
            specs = getattr(self, name)
            if isinstance(specs, str) or not isinstance(specs, list | tuple):
                raise TypeError(f"`{name}` must be a list of {kind} layer specs like "
                                f"'{example}'; got {specs!r}")
            for spec in specs:
                parse(spec)  # raises naming the spec
            object.__setattr__(self, name, tuple(specs))
        object.__setattr__(self, "min_boulder_px",
                           check_range("min_boulder_px", self.min_boulder_px, 1.0, 1e6))
        object.__setattr__(self, "min_crater_px",
                           check_range("min_crater_px", self.min_crater_px, 1.0, 1e6))
        for name in ("smooth_craters", "force", "quiet"):
            if not isinstance(getattr(self, name), bool):
                raise TypeError(f"`{name}` must be true or false; got {getattr(self, name)!r}")
        if self.fractal_dimension is not None:
            check_range("fractal_dimension", self.fractal_dimension, 2.0, 3.0)
        if self.roughness is not None:
            check_positive("roughness", self.roughness, allow_zero=True)
        if self.seed is not None:
            check_int("seed", self.seed, 0, 2**63 - 1)
        check_int("band", self.band, 1)
        for name in ("pixel_size_m", "body_radius_m"):
            if getattr(self, name) is not None:
                check_positive(name, getattr(self, name))

    @classmethod
    def keys(cls) -> tuple[str, ...]:
        """The config keys, in order."""
        return tuple(f.name for f in dataclasses.fields(cls))

    @classmethod
    def from_mapping(cls, config) -> EnhanceConfig:
        """Validate a dict (e.g. parsed TOML); unknown keys are errors."""
        if isinstance(config, cls):
            return config
        if not isinstance(config, dict):
            raise TypeError(f"`config` must be a dict of scene keys; got "
                            f"{type(config).__name__}")
        unknown = sorted(set(config) - set(cls.keys()))
        if unknown:
            raise ValueError(f"unknown config key(s) {', '.join(map(repr, unknown))}; "
                             f"allowed: {', '.join(cls.keys())}")
        return cls(**config)

    def to_dict(self) -> dict:
        """JSON-ready values that define the stack (for the manifest): all keys but
        ``output``, ``force`` and ``quiet``, so a stack's bytes do not depend on where and
        how it was written."""
        d = dataclasses.asdict(self)
        for key in ("output", "force", "quiet"):
            del d[key]
        d["craters"] = list(self.craters)
        d["boulders"] = list(self.boulders)
        d["target"] = None if self.target is None else list(self.target)
        return d


# --------------------------------------------------------------------------- geometry
@dataclasses.dataclass(frozen=True, slots=True)
class _Geometry:
    """Layer placement in layer-0 pixel index units (exact binary fractions)."""

    size: int
    offsets: tuple[tuple[float, float], ...]
    """Layer-0 index (row, col) of each layer's pixel (0, 0)."""
    pixel0_m: float

    @property
    def n_layers(self) -> int:
        return len(self.offsets)

    def pixel_m(self, k: int) -> float:
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
        return (self.size * self.pixel_m(k)) ** 2


def _windows(base: Dem, target, size: int, n_layers: int):
    """Layer-0 window, footprints of the finer layers, target pixel in layer 0."""
    rows, cols = base.shape
    if rows < size or cols < size:
        raise ValueError(f"the base DEM is {rows} x {cols} pixels; layers of `size` {size} need "
                         f"at least {size} x {size}")
    if target is None:
        r_t, c_t = rows // 2, cols // 2
    else:
        col_f, row_f = ~base.transform @ target
        if not (0 <= row_f < rows and 0 <= col_f < cols):
            b = base.bounds
            raise ValueError(f"`target` {list(target)} is outside the base DEM (bounds "
                             f"left {b.left:.10g}, bottom {b.bottom:.10g}, right {b.right:.10g}, "
                             f"top {b.top:.10g})")
        r_t, c_t = int(math.floor(row_f)), int(math.floor(col_f))
    r0 = min(max(r_t - (size - 1) // 2, 0), rows - size)
    c0 = min(max(c_t - (size - 1) // 2, 0), cols - size)
    t = (r_t - r0, c_t - c0)
    w = (size + 1) // 2
    half = (w - 1) // 2
    windows = []
    for _ in range(1, n_layers):
        # centred on the target, else shifted to keep one pixel clear of the layer's border
        # (the mesh stitches each footprint to a ring of coarser cells around it)
        rr = min(max(t[0] - half, 1), size - w - 1)
        cc = min(max(t[1] - half, 1), size - w - 1)
        windows.append((rr, cc, w))
        t = (2 * (t[0] - rr), 2 * (t[1] - cc))
    return Window(c0, r0, size, size), windows, (r_t - r0, c_t - c0), (r_t, c_t)


def _geometry(size: int, windows, pixel0_m: float) -> _Geometry:
    offsets = [(0.0, 0.0)]
    for k, (rr, cc, _) in enumerate(windows, start=1):
        r, c = offsets[-1]
        offsets.append((r + rr / 2.0 ** (k - 1), c + cc / 2.0 ** (k - 1)))
    return _Geometry(size, tuple(offsets), pixel0_m)


# --------------------------------------------------------------------------- craters
def _poisson(rng: np.random.Generator, mean: float, what: str, noun: str = "craters") -> int:
    if mean > _MAX_COUNT_MEAN:
        raise ValueError(f"{what}: about {mean:.3g} {noun}; the {noun[:-1]} layers ask for an "
                         f"absurd number of small {noun} (raise dmin or lower c)")
    return int(rng.poisson(mean)) if mean > 0 else 0


def _size_bands(geometry: _Geometry, min_px: float):
    """Per layer the size band it takes (``[lo[b], hi[b])`` metres: at least ``min_px``
    of its pixels, too small for the coarser layer) and the whole area's size in m^2."""
    lo = [min_px * geometry.pixel_m(b) for b in range(geometry.n_layers)]
    return lo, [math.inf] + lo[:-1], geometry.area_m2(0)


def _assign(cat, reach, geometry: _Geometry, b: int, per_layer: list, next_index: int):
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


def plan_craters(specs, geometry: _Geometry, *, min_px: float, reach_radii: float, seed: int,
                 degradation_kwargs: dict | None = None):
    """Split one crater population of layer 0's area into per-layer catalogs.

    Parameters
    ----------
    specs : sequence of craters.CraterLayer
    geometry : _Geometry
        Layer placement (see :func:`enhance`).
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
    specs = list(specs)
    n = geometry.n_layers
    lo, hi, area0 = _size_bands(geometry, min_px)

    def truncated(b):
        out = []
        for i, s in enumerate(specs):
            d0, d1 = max(s.d_min_m, lo[b]), min(s.d_max_m, hi[b])
            if d0 < d1:
                out.append((i, dataclasses.replace(s, d_min_m=d0, d_max_m=d1)))
        return out

    bands = [truncated(b) for b in range(n)]
    expected = sum(craters.expected_count(geometry.area_m2(b), s.c, s.k, s.d_min_m, s.d_max_m)
                   for b in range(n) for _, s in bands[b])
    if expected > MAX_STAMPED:
        raise ValueError(f"the crater layers put about {expected:.3g} craters into the stack "
                         f"(limit {MAX_STAMPED:.0e}); raise dmin or lower c")
    per_layer: list[list[np.ndarray]] = [[] for _ in range(n)]
    band_rows = []
    next_index = 0
    drawn = 0
    for b in range(n):
        entry = {"layer": b, "d_min_m": lo[b], "d_max_m": hi[b] if b else None,
                 "drawn": 0, "assigned": 0, "rejected": 0}
        band_rows.append(entry)
        if not bands[b]:
            continue
        idx = np.array([i for i, _ in bands[b]], dtype=np.int64)
        xr, yr = geometry.area_ranges(b)
        cat = craters.population([s for _, s in bands[b]], x_range_m=xr, y_range_m=yr,
                                 rng=_stream(seed, _STREAM_BAND, b),
                                 degradation_kwargs=degradation_kwargs)
        cat["layer"] = idx[cat["layer"]]
        outside = area0 - geometry.area_m2(b)
        n_out = _poisson(_stream(seed, _STREAM_OUTSIDE, b),
                         sum(craters.expected_count(outside, s.c, s.k, s.d_min_m, s.d_max_m)
                             for _, s in bands[b]), f"diameter band {b}")
        keep, next_index = _assign(cat, reach_radii * cat["diameter_m"] / 2.0, geometry, b,
                                   per_layer, next_index)
        entry.update(drawn=len(cat) + n_out, assigned=int(keep.sum()),
                     rejected=int((~keep).sum()) + n_out)
        drawn += entry["drawn"]
    small = 0.0
    for s in specs:
        d1 = min(s.d_max_m, lo[-1])
        if s.d_min_m < d1:
            small += craters.expected_count(area0, s.c, s.k, s.d_min_m, d1)
    n_small = _poisson(_stream(seed, _STREAM_SMALL), small, "craters below the finest layer")
    empty = craters.make_catalog(x_m=[], y_m=[], diameter_m=[], layer=np.zeros(0, np.int64),
                                 index=np.zeros(0, np.int64))
    catalogs = []
    for parts in per_layer:
        cat = np.concatenate(parts) if parts else empty
        catalogs.append(craters.sort_oldest_first(cat))
    assigned = [len(c) for c in catalogs]
    rejected = sum(e["rejected"] for e in band_rows) + n_small
    accounting = {"drawn": drawn + n_small, "assigned": assigned, "rejected": rejected,
                  "rejected_below_finest": n_small, "bands": band_rows,
                  "min_crater_px": min_px, "reach_radii": reach_radii}
    return catalogs, accounting


def plan_boulders(specs, geometry: _Geometry, *, min_px: float, seed: int):
    """Split one boulder population of layer 0's area into per-layer catalogs.

    The same banded draw as :func:`plan_craters`: band b (diameters [m p_b, m p_(b-1)))
    is drawn over layer b's area and each boulder goes into the finest layer that holds
    its whole footprint (``0.87 D`` from its centre, plus one pixel) clear of the
    border; the band's boulders outside layer b's area and those below the finest
    layer's ``m`` pixels are only counted. Positions are in the layer-0 grid frame.
    """
    from .boulders import _REACH, draw_boulders

    specs = list(specs)
    n = geometry.n_layers
    lo, hi, area0 = _size_bands(geometry, min_px)

    def count(area, s, d0, d1):
        return area * s.c * (d0**s.k - d1**s.k)

    per_layer: list[list[np.ndarray]] = [[] for _ in range(n)]
    bands = []
    next_index = 0
    expected = 0.0
    for b in range(n):
        for s in specs:
            d0, d1 = max(s.d_min_m, lo[b]), min(s.d_max_m, hi[b])
            if d0 < d1:
                expected += count(geometry.area_m2(b), s, d0, d1)
    if expected > MAX_STAMPED:
        raise ValueError(f"the boulder layers put about {expected:.3g} boulders into the stack "
                         f"(limit {MAX_STAMPED:.0e}); raise dmin or lower c")
    for b in range(n):
        entry = {"layer": b, "d_min_m": lo[b], "d_max_m": hi[b] if b else None,
                 "drawn": 0, "assigned": 0, "rejected": 0}
        bands.append(entry)
        trunc = []
        for i, s in enumerate(specs):
            d0, d1 = max(s.d_min_m, lo[b]), min(s.d_max_m, hi[b])
            if d0 < d1:
                trunc.append((i, dataclasses.replace(s, d_min_m=d0, d_max_m=d1)))
        if not trunc:
            continue
        idx = np.array([i for i, _ in trunc], dtype=np.int64)
        xr, yr = geometry.area_ranges(b)
        cat = draw_boulders([s for _, s in trunc], xr, yr,
                            rng=_stream(seed, _STREAM_BOULDER_BAND, b))
        cat["layer"] = idx[cat["layer"]]
        outside = area0 - geometry.area_m2(b)
        n_out = _poisson(_stream(seed, _STREAM_BOULDER_OUTSIDE, b),
                         sum(count(outside, s, s.d_min_m, s.d_max_m) for _, s in trunc),
                         f"boulder diameter band {b}", "boulders")
        keep, next_index = _assign(cat, _REACH * cat["diameter_m"], geometry, b, per_layer,
                                   next_index)
        entry.update(drawn=len(cat) + n_out, assigned=int(keep.sum()),
                     rejected=int((~keep).sum()) + n_out)
    small = sum(count(area0, s, s.d_min_m, min(s.d_max_m, lo[-1])) for s in specs
                if s.d_min_m < min(s.d_max_m, lo[-1]))
    n_small = _poisson(_stream(seed, _STREAM_BOULDER_SMALL), small,
                       "boulders below the finest layer", "boulders")
    catalogs = [np.concatenate(parts) if parts else None for parts in per_layer]
    assigned = [0 if c is None else len(c) for c in catalogs]
    accounting = {"drawn": sum(e["drawn"] for e in bands) + n_small, "assigned": assigned,
                  "rejected": sum(e["rejected"] for e in bands) + n_small,
                  "rejected_below_finest": n_small, "bands": bands, "min_boulder_px": min_px}
    return catalogs, accounting


def _stamp_boulders_layer(z, cat, geometry: _Geometry, k: int, a0, shape):
    """Place and stamp layer k's boulders (layer-0 grid positions); returns the heights
    and the placed catalog in the local frame."""
    from .boulders import _place

    if cat is None:
        cat = craters.make_catalog(x_m=[], y_m=[], diameter_m=[], burial_frac=[],
                                   azimuth_deg=[], seed=np.zeros(0, np.uint64),
                                   layer=np.zeros(0, np.int64), index=np.zeros(0, np.int64),
                                   kind=np.zeros(0, "U7"))
    p0 = geometry.pixel0_m
    local = _to_local(cat, a0, p0)
    r, c = geometry.offsets[k]
    m = np.array([[a0.a, a0.b], [a0.d, a0.e]]) / p0
    t = np.array([a0.a * c + a0.b * r + a0.c, a0.d * c + a0.e * r + a0.f])
    h, _, placed = _place(z, geometry.pixel_m(k), m, t, local, shape=shape)
    return h, placed


# --------------------------------------------------------------------------- build
def _stamp_layer(z: np.ndarray, cat: np.ndarray, geometry: _Geometry, k: int, *,
                 roughness: bool, seed: int, progress: bool):
    """Stamp layer k's craters (layer-0 grid frame positions) into a copy of ``z``."""
    if len(cat) == 0:
        return z, cat
    r, c = geometry.offsets[k]
    p0 = geometry.pixel0_m
    cols = {name: cat[name] for name in cat.dtype.names}
    cols["x_m"] = cat["x_m"] - c * p0
    cols["y_m"] = cat["y_m"] - r * p0
    grid = craters.make_catalog(**cols)
    h, stamped = craters.stamp_many(z, geometry.pixel_m(k), grid, roughness=roughness,
                                    rng=_stream(seed, _STREAM_STAMP, k),
                                    progress=progress, return_catalog=True)
    # back to layer-0 grid positions, exactly as planned
    order = np.argsort(cat["index"])
    pos = order[np.searchsorted(cat["index"], stamped["index"], sorter=order)]
    stamped["x_m"] = cat["x_m"][pos]
    stamped["y_m"] = cat["y_m"][pos]
    return h, stamped


def _propagate_up(arrays: list[np.ndarray], windows, k: int) -> None:
    """Make layers k-1 .. 0 agree with layer k: coarse footprint = fine even pixels."""
    for j in range(k - 1, -1, -1):
        r0, c0, w = windows[j]
        arrays[j][r0:r0 + w, c0:c0 + w] = arrays[j + 1][::2, ::2]


def _to_local(cat: np.ndarray, a0, p0: float) -> np.ndarray:
    """Catalog positions: layer-0 grid frame -> local frame (pixel affine ``a0``)."""
    u, v = cat["x_m"] / p0, cat["y_m"] / p0
    cols = {name: cat[name] for name in cat.dtype.names}
    cols["x_m"] = a0.a * u + a0.b * v + a0.c
    cols["y_m"] = a0.d * u + a0.e * v + a0.f
    return craters.make_catalog(**cols)


def enhance(config, *, dem: Dem | None = None, progress: bool = False) -> Stack:
    """Build (and with ``output``, write) a multi-resolution stack with craters per layer.

    See the module notes for the algorithm, the crater split and how the layers are
    kept consistent.

    Parameters
    ----------
    config : dict or EnhanceConfig
        Scene keys (:class:`EnhanceConfig`; a parsed TOML file). Unknown keys are errors.
    dem : Dem, optional
        The base DEM, instead of the ``input`` key.
    progress : bool
        Show progress bars (unless the config says ``quiet``).

    Returns
    -------
    Stack
        Layers (coarsest first), footprints, the local frame (origin at the target
        pixel), per-layer crater catalogs (local frame) and ``info`` (seed, parameters,
        crater accounting).

    Examples
    --------
    >>> base = Dem(np.random.default_rng(0).normal(0, 5, (33, 33)), pixel_size_m=100.0)
    >>> s = enhance({"layers": 3, "size": 17, "seed": 1,
    ...              "craters": ["c=0.05,k=-2,dmin=20,dmax=800"]}, dem=base)
    >>> s.shapes, s.pixel_sizes_m(), s.is_consistent()
    ([(17, 17), (17, 17), (17, 17)], [100.0, 50.0, 25.0], True)
    >>> c = s.info["craters"]
    >>> c["drawn"] == sum(c["stamped"]) + sum(c["erased_on_steep_ground"]) + c["rejected"]
    True
    """
    cfg = EnhanceConfig.from_mapping(config)
    show = progress and not cfg.quiet
    if (dem is None) == (cfg.input is None):
        raise ValueError("give the base DEM either as the `input` key or as `dem`, not both"
                         if dem is not None else "no base DEM: give the `input` key")
    if dem is not None and not isinstance(dem, Dem):
        raise TypeError(f"`dem` must be a Dem; got {type(dem).__name__}")
    specs = [craters.parse_layer_spec(s) for s in cfg.craters]
    if cfg.output is not None:
        check_stack_folder(cfg.output, force=cfg.force)
    need = cfg.layers * cfg.size**2 * 8 * 2.5 + (2 * cfg.size + 8) ** 2 * 8 * 2.3
    if need > 0.85 * physical_memory_bytes():
        raise ValueError(f"{cfg.layers} layers of {cfg.size}^2 pixels need about "
                         f"{human_bytes(need)} of memory; this machine has "
                         f"{human_bytes(physical_memory_bytes())}")
    base = dem if dem is not None else read(cfg.input, band=cfg.band,
                                            pixel_size_m=cfg.pixel_size_m,
                                            body_radius_m=cfg.body_radius_m)
    seed = cfg.seed
    if seed is None:
        seed = int(np.random.SeedSequence().entropy % 2**63)
    normalize_rng(seed)
    win0, windows, t0, t_base = _windows(base, cfg.target, cfg.size, cfg.layers)
    layer0 = base.crop(win0)
    unknown = int((~layer0.known).sum())
    if unknown:
        raise ValueError(f"layer 0 (rows {int(win0.row_off)}.., cols {int(win0.col_off)}.. of "
                         f"the base) has {unknown} unknown (NaN) pixels; fill them first "
                         f"(dem.fill_gaps, dem.fill_crater_gaps, `dem fill`)")
    frame = local_frame(layer0, origin=t0)
    a0 = pixel_affine(layer0, frame)
    p0 = grid_pixel_size(a0, "the base DEM")
    geometry = _geometry(cfg.size, windows, p0)
    irregularity = 0.0 if cfg.smooth_craters else 0.02  # craters.stamp_many's default
    reach_radii = craters.DEFAULT_EJECTA_EDGE * (1.0 + irregularity)
    plans, accounting = plan_craters(specs, geometry, min_px=cfg.min_crater_px,
                                     reach_radii=reach_radii, seed=seed)
    rock_specs = [craters.parse_boulder_spec(s) for s in cfg.boulders]
    rock_plans, rock_accounting = (plan_boulders(rock_specs, geometry,
                                                 min_px=cfg.min_boulder_px, seed=seed)
                                   if rock_specs else ([None] * cfg.layers, None))
    rock_shape = craters.BoulderShape()
    fd = cfg.fractal_dimension
    fd_estimated = None
    if fd is None:
        fd_estimated = fractal_fit(layer0).fractal_dimension
        fd = min(3.0, max(2.0, fd_estimated))
    roughness = not cfg.smooth_craters
    arrays: list[np.ndarray] = []
    metas: list[Dem] = []
    stamped: list[np.ndarray] = []
    rocks: list = []
    bar = progress_bar(range(cfg.layers), enabled=show, desc="enhance")
    for k in bar:
        if k == 0:
            meta = layer0
        else:
            rr, cc, w = windows[k - 1]
            parent = metas[k - 1].replace(heights=arrays[k - 1])
            meta = expand(parent, 1, fd, cfg.roughness, Window(cc, rr, w, w), rng=seed)
        z, cat = _stamp_layer(np.array(meta.heights), plans[k], geometry, k,
                              roughness=roughness, seed=seed, progress=False)
        rock = None
        if rock_specs:
            z, rock = _stamp_boulders_layer(z, rock_plans[k], geometry, k, a0, rock_shape)
        arrays.append(np.array(z, dtype=np.float64))
        metas.append(meta)
        stamped.append(cat)
        rocks.append(rock)
        _propagate_up(arrays, windows, k)
    n_stamped = [len(c) for c in stamped]
    accounting["stamped"] = n_stamped
    accounting["erased_on_steep_ground"] = [a - s for a, s in
                                            zip(accounting["assigned"], n_stamped, strict=True)]
    if rock_accounting is not None:
        n_rocks = [0 if r is None else len(r) for r in rocks]
        rock_accounting["stamped"] = n_rocks
        rock_accounting["off_grid"] = [a - s for a, s in
                                       zip(rock_accounting["assigned"], n_rocks, strict=True)]
    params = cfg.to_dict()
    params.update(seed=seed, fractal_dimension=fd, fractal_dimension_estimated=fd_estimated)
    info = {
        "seed": seed,
        "parameters": params,
        "target": {"world": None if cfg.target is None else list(cfg.target),
                   "pixel_in_base": list(t_base), "pixel_in_layer0": list(t0),
                   "world_pixel_centre": [float(v) for v in layer0.xy(*t0)]},
        "layer0_window_in_base": [int(win0.row_off), int(win0.col_off), cfg.size],
        "craters": accounting,
        "boulders": rock_accounting,
        "randomness": "numpy SeedSequence(seed, spawn_key=(1, band)) for the population of "
                      "each diameter band, (2, band) and (3,) for the rejected counts, "
                      "(4, layer) for stamping; the RMD key is default_rng(seed)'s first "
                      "draw",
    }
    layers = []
    for k in range(cfg.layers):
        step = {"layer": k, "craters_stamped": n_stamped[k],
                "synchronised_with_finer_layers": k < cfg.layers - 1}
        if rock_specs:
            step["boulders_stamped"] = len(rocks[k])
        layers.append(metas[k].with_step(arrays[k], "dem.enhance", seed, step))
    catalogs = [_to_local(c, a0, p0) for c in stamped]
    stack = Stack(layers, windows, frame, catalogs, info, rocks if rock_specs else None)
    if cfg.output is not None:
        stack.write(cfg.output, force=cfg.force, progress=show)
    return stack

