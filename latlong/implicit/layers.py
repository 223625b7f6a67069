"""LCSN crater layers on the multi-level grid (step 4 of
:func:`latlong.implicit.implicit_surface`; Li 2022 §3.1, eq. 2, §4.1).

The multi-level grid has cells of ``cell_m / 2^l`` at level l (each cell holds 2^3
cells of the next level); a layer uses the finest level whose cells hold its largest
crater. Every cell of that level that the coarse surface passes through (a triangle of
the base mesh has its centroid in it) receives one impulse with the layer's
probability, at a uniform random point of the surface inside the cell (a Poisson point
conditioned on the cell); its diameter is drawn by inversion sampling in
[d_min, d_max] (Li 2022 eq. 17-21, :func:`craters.sample_power_law_diameters`). The
layer's kernel (:mod:`craters.lcsn`) is scaled self-similarly to that diameter
(rim-crest diameter, or apparent diameter for kernels without a rim), its heights times
the layer weight omega (eq. 2) and optionally set to a random depth/diameter ratio.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from typing import Any

import numpy as np

import craters as _craters
from craters._shared import check_positive, check_range, parse_spec

__all__ = ["CraterShape", "LcsnLayer", "draw_impulses", "largest_height", "layer_levels",
           "measure_shape", "parse_lcsn_spec"]

_KERNEL_EPS = 1e-3  # a kernel's support: where it has fallen below this share of its extreme


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


_SPEC: dict[str, Callable[[str], Any]] = {
    "kernel": str, "d_min_m": float, "d_max_m": float, "exponent": float,
    "probability": float, "weight": float, "depth_ratio": _ratio_range}
_OLD_KEYS = {"dmin": "d_min_m", "dmax": "d_max_m", "B": "exponent", "p": "probability",
             "w": "weight", "hd": "depth_ratio"}


def parse_lcsn_spec(spec: str) -> LcsnLayer:
    """Parse ``kernel=NAME,d_min_m=500,d_max_m=1000[,exponent=3,probability=0.5,weight=1,
    depth_ratio=0.15:0.25]``: the fields of :class:`LcsnLayer` (metres).

    Examples
    --------
    >>> parse_lcsn_spec("kernel=table-a1-1km-0gyr,d_min_m=500,d_max_m=1000,"
    ...                 "depth_ratio=0.1:0.2").depth_ratio
    (0.1, 0.2)
    """
    values = parse_spec(spec, _SPEC, ("kernel", "d_min_m", "d_max_m"), "LCSN layer",
                        renamed=_OLD_KEYS)
    try:
        return LcsnLayer(**values)
    except (ValueError, TypeError) as exc:
        raise ValueError(f"LCSN layer {spec!r}: {exc}") from None


_KIND_NAMES = {1: "simple", 2: "flat-floored", 3: "fresh", 4: "complex"}


@dataclasses.dataclass(frozen=True)
class CraterShape:
    """A layer's reference kernel, measured once: what scaling needs."""

    kind: int
    """LCSN kind 1-4."""
    raw: dict
    """Raw parameters of the reference kernel (:func:`craters.lcsn_kernel`)."""
    diameter: float
    """D_rim, or D_a without a rim (or the nominal 2/sqrt(gamma)), metres."""
    morph: dict
    """Its measured morphometry (``"numeric"``), metres."""
    support: float
    """Radius beyond which it is dropped, metres of the reference kernel."""
    amplitude: float
    """Largest |kernel|, metres."""
    depth: float
    """H_t (kinds 1-3) or H_c (kind 4), metres."""


def measure_shape(params: _craters.LcsnParams) -> CraterShape:
    """Measure a layer's reference kernel once: diameter to scale by, support (where
    |kernel| falls below 1e-3 of its extreme, over the last 80 % of the radius), height."""
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
    return CraterShape(kind, raw, d, morph, reach / 0.8, amp, depth)


def largest_height(shape: CraterShape, la: LcsnLayer) -> float:
    """The largest |height| (m) one crater of the layer can add: at d_max_m, weighted."""
    ratio = la.depth_ratio[1] * shape.diameter / shape.depth if la.depth_ratio else 1.0
    return shape.amplitude * la.d_max_m / shape.diameter * la.weight * ratio


def layer_levels(layers, cell_m: float) -> list[int]:
    """The grid level of each layer: the finest whose cells (cell_m / 2^level) hold its
    largest crater."""
    levels = []
    for la in layers:
        level = int(math.floor(math.log2(cell_m / la.d_max_m) + 1e-12))
        if level < 0:
            raise ValueError(f"`cell_m` = {cell_m:g} m is smaller than a layer's d_max_m "
                             f"({la.d_max_m:g} m): level-0 cells must hold the largest crater")
        levels.append(level)
    return levels


def draw_impulses(layers, shapes, levels, cell_m, base_verts, base_faces, surface, rng):
    """Draw every layer's impulses on the base surface (module notes).

    Returns the kernel arrays (``centers, normals, kinds, params, support, zhalf,
    amplitude``; ``params`` rows kappa, beta, gamma, a, b scaled and weighted) and the
    catalog columns. ``surface.normals(points)`` gives the normals at the impulses
    (the :class:`Metaballs`, or the coarse field on its grid).
    """
    a, b, c = (base_verts[base_faces[:, k]] for k in range(3))
    centroid = (a + b + c) / 3.0
    area = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1)
    lo = base_verts.min(axis=0)
    parts = []
    for idx, (la, shape, level) in enumerate(zip(layers, shapes, levels, strict=True)):
        cell = cell_m / 2**level
        key3 = np.floor((centroid - lo) / cell).astype(np.int64)
        pos = _points_in_cells(key3, (a, b, c), area, la.probability, rng)
        n = len(pos)
        diam = (_craters.sample_power_law_diameters(n, la.d_min_m, la.d_max_m, la.exponent,
                                                    rng=rng) if n else np.zeros(0))
        if la.depth_ratio is not None:
            ratio = rng.uniform(la.depth_ratio[0], la.depth_ratio[1], n)
            hscale = ratio * shape.diameter / shape.depth
        else:
            hscale = np.ones(n)
        hscale = hscale * la.weight
        parts.append((idx, level, shape, pos, diam, hscale))
    out, cat_cols = _kernel_rows(parts)
    normals = surface.normals(out["centers"]) if len(out["centers"]) else np.zeros((0, 3))
    out["normals"] = np.ascontiguousarray(normals)
    return out, cat_cols


def _points_in_cells(key3, triangles, area, probability, rng):
    """Each cell of the level (``key3``: the (i, j, k) cell of each triangle's centroid)
    is chosen with ``probability`` and gets a uniform random point of the surface inside
    it (a triangle by area, then a point of the triangle): (n, 3) metres."""
    a, b, c = triangles
    dims = key3.max(axis=0) + 1
    key = (key3[:, 2] * dims[1] + key3[:, 1]) * dims[0] + key3[:, 0]
    order = np.argsort(key, kind="stable")
    cells, start = np.unique(key[order], return_index=True)
    end = np.append(start[1:], len(order))
    chosen = np.flatnonzero(rng.random(len(cells)) < probability)
    n = len(chosen)
    cum = np.cumsum(area[order])
    before = np.where(start[chosen] > 0, cum[start[chosen] - 1], 0.0)
    target = before + rng.random(n) * (cum[end[chosen] - 1] - before)
    tri = order[np.minimum(np.searchsorted(cum, target, side="right"), end[chosen] - 1)]
    u, v = rng.random(n), rng.random(n)
    flip = u + v > 1
    u[flip], v[flip] = 1 - u[flip], 1 - v[flip]
    return a[tri] + u[:, None] * (b[tri] - a[tri]) + v[:, None] * (c[tri] - a[tri])


def _kernel_rows(parts):
    """The drawn craters as kernel rows (each layer's reference kernel scaled to the
    diameter, heights times ``hscale``) and catalog columns, in layer order."""
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
    cat_cols = {k: np.concatenate(v) if v else np.zeros(0) for k, v in cols.items()}
    return out, cat_cols
