"""Crater catalogues drawn cell by cell: the craters of any region, the same as the whole
body's there (terrain on demand).

A power-law layer (:class:`craters.CraterLayer`) is split into size bins
``[2**b, 2**(b + 1))`` metres (clipped to the layer's range). Bin ``b`` is drawn per
cell of one level of the cube-sphere hierarchy (:mod:`craters.cells`): a Poisson count
of mean ``area x (N(lo) - N(hi))``, then per crater its diameter (inverse power law),
age (uniform in the layer's range), position (uniform in the cell's solid angle),
rim-shape phases and roughness seed. A model-age layer (:class:`craters.ModelAgeLayer`)
is drawn the same way from its production function and chronology: the bin's density
``N1(T) (S(lo) - S(hi))`` (``S`` the production function's shape, ``N1`` the
chronology), diameters by inverting ``S`` within the bin and formation ages by inverting
``N1`` over [0, T] (``P(age <= t) = N1(t) / N1(T)``), both by bisection in portable
arithmetic; with an ``equilibrium`` cap a saturated bin keeps the equilibrium density
and only the youngest craters (ages drawn from the youngest share ``cap / N`` of the
flux: what the sequential cap keeps, as a density rather than a count per area).
Every number comes from the Philox words of the
counter ``(cell id, layer << 32 | bin + 2**31, crater index, purpose)`` under the key
``(seed, 0x6372617465727300)`` through exact or portable transforms
(:mod:`craters.counter`), so a crater depends on nothing but its own counter: any set of
cells asked in any order, on any core, gives each cell the same craters.

The caller chooses the cells (those that can reach its region) and the level of each
bin (:func:`bin_level`: a function of the bin and the body, never of the region asked),
and gives each cell's area on its surface.

Examples
--------
>>> from craters import CraterLayer
>>> la = CraterLayer(0.5, -2.0, 1.0, 8.0)
>>> bins(la).tolist()
[0, 1, 2]
>>> a = draw_cells(la, 0, seed=1, b=1, level=20, cell_ids=[(20 << 57) | 5], area_m2=[400.0])
>>> bool(((a["diameter_m"] >= 2) & (a["diameter_m"] < 4)).all())
True
"""

from __future__ import annotations

import math

import numpy as np

from ._counter_kernels import _LN10, _age_bisect_kernel, _pf_bisect_kernel
from .boulders import BoulderLayer
from .boulders.placement import MIN_BURIAL
from .cells import cell_parts, cell_points
from .chronology import get_chronology_system, get_equilibrium
from .counter import (
    MAX_POISSON_MEAN,
    philox4x64,
    poisson_from_uniform,
    portable_exp,
    portable_log,
    power_law_from_uniform,
    uniform_from_words,
)
from .layers import CraterLayer, ModelAgeLayer

__all__ = ["CRATER_KEY", "ROCK_FACETS", "ROCK_KEY", "bin_bounds", "bin_level", "bins",
           "draw_cells", "draw_rock_cells", "min_cell_angle"]

#: The second key word of crater draws ("craters\0").
CRATER_KEY = 0x6372617465727300
#: The second key word of rock draws ("rocks\0\0\0").
ROCK_KEY = 0x726F636B73000000
#: Facet planes of a rock (:func:`draw_rock_cells`).
ROCK_FACETS = 6
_BIN_OFFSET = 1 << 31
_COUNT, _MAIN, _RIM, _POSITION = 0, 1, 2, 16  # counter purposes
_RIM_COUNTERS = 4  # 16 words for the 15 rim phases
_ROCK_COUNTERS = 6  # 24 words: 18 for the facets, 3 for elongation, height, burial
_MAX_CANDIDATES = 64  # position candidates per crater (acceptance >= 0.19 a candidate)
_TWO_PI = 2.0 * np.pi
_BISECTIONS = 64  # halvings of a bracket: past the last bit of a double


def _bin_of(d: float) -> int:
    """``b`` with ``2**b <= d < 2**(b + 1)``, exactly (``frexp``)."""
    _, e = np.frexp(d)
    return int(e) - 1


def bins(layer: CraterLayer | ModelAgeLayer | BoulderLayer) -> np.ndarray:
    """The size bins ``b`` (int64) of a layer: ``[2**b, 2**(b + 1))`` meets
    ``[d_min_m, d_max_m)``."""
    if not isinstance(layer, CraterLayer | ModelAgeLayer | BoulderLayer):
        raise TypeError("terrain on demand draws crater layers (craters.CraterLayer, "
                        "craters.ModelAgeLayer) and boulder layers (craters.BoulderLayer); "
                        f"got {type(layer).__name__}")
    lo = _bin_of(layer.d_min_m)
    hi = _bin_of(layer.d_max_m)
    if np.ldexp(1.0, hi) == layer.d_max_m:
        hi -= 1  # d_max is a bin edge: the bin above it is empty
    return np.arange(lo, hi + 1, dtype=np.int64)


def bin_bounds(layer: CraterLayer | ModelAgeLayer | BoulderLayer, b: int) -> tuple[float, float]:
    """``(lo, hi)`` metres: bin ``b`` clipped to the layer's range."""
    return max(float(np.ldexp(1.0, int(b))), layer.d_min_m), \
        min(float(np.ldexp(1.0, int(b) + 1)), layer.d_max_m)


def min_cell_angle(level: int) -> float:
    """A lower bound of the angular width (radians) of every cell of ``level``: the
    gnomonic scale ``sqrt(1 + v^2) / (1 + u^2 + v^2)`` is smallest (sqrt(2) / 3 > 0.47)
    at a face's corners."""
    return 0.47 * 2.0 ** (1 - int(level))


def bin_level(halo_rad: float, max_level: int = 27) -> int:
    """The deepest level whose cells are all at least ``halo_rad`` wide (0 if none), so
    that the craters within ``halo_rad`` of a point lie in its cell or the 8 around it."""
    if not halo_rad > 0:
        raise ValueError(f"`halo_rad` must be > 0; got {halo_rad!r}")
    level = 0
    while level < max_level and min_cell_angle(level + 1) >= halo_rad:
        level += 1
    return level


def _pow(x: np.ndarray, k: float) -> np.ndarray:
    """x ** k, the same bytes everywhere (portable exp and log)."""
    return portable_exp(k * portable_log(x))


def _words(cells: np.ndarray, tag: int, index: np.ndarray, purpose: int, seed: int,
           key: int = CRATER_KEY):
    counters = np.empty((len(cells), 4), dtype=np.uint64)
    counters[:, 0] = cells
    counters[:, 1] = np.uint64(tag)
    counters[:, 2] = index.astype(np.uint64)
    counters[:, 3] = np.uint64(purpose)
    return philox4x64(counters, [seed, key])


def _p10(y) -> np.ndarray:
    """10 ** y, portably."""
    return portable_exp(np.asarray(y, dtype=np.float64) * _LN10)


def _pf_shape(layer: ModelAgeLayer, d_m) -> np.ndarray:
    """N(>D) / N(>1 km) of the layer's production function at ``d_m`` metres, portably
    (the polynomial in log10 D_km by Horner, without a0)."""
    x = portable_log(np.asarray(d_m, dtype=np.float64) * 1e-3) / _LN10
    out = np.zeros_like(x)
    for a in get_chronology_system(layer.npf).production.coefficients[:0:-1]:
        out = (out + a) * x
    return _p10(out)


def _n1(layer: ModelAgeLayer, t_gyr) -> np.ndarray:
    """N(>1 km) per km^2 of the layer's chronology at ``t_gyr``, portably."""
    c0, c1, c2, c3 = get_chronology_system(layer.npf).chronology.coefficients
    t = np.asarray(t_gyr, dtype=np.float64)
    return c0 * (portable_exp(c1 * t) - 1.0) + c2 * t * t + c3 * t


def _bin_density(layer, lo: float, hi: float) -> tuple[float, float]:
    """(craters per m^2 in [lo, hi), the youngest share of the flux they come from)."""
    if not isinstance(layer, ModelAgeLayer):
        return layer.c * float(_pow(np.array([lo]), layer.k)[0]
                               - _pow(np.array([hi]), layer.k)[0]), 1.0
    s = _pf_shape(layer, np.array([lo, hi]))
    density = float(_n1(layer, np.array([layer.age_gyr]))[0]) * float(s[0] - s[1]) * 1e-6
    if layer.equilibrium is None or not density > 0:
        return density, 1.0
    b0, b1 = get_equilibrium(layer.equilibrium).coefficients
    e = _p10(b0 + b1 * portable_log(np.array([lo, hi]) * 1e-3) / _LN10)
    cap = float(e[0] - e[1]) * 1e-6
    return (cap, cap / density) if cap < density else (density, 1.0)


def _model_age_draws(layer: ModelAgeLayer, lo: float, hi: float, share: float,
                     u_d: np.ndarray, u_age: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Diameters in [lo, hi) and formation ages of a model-age layer's bin from uniforms."""
    s = _pf_shape(layer, np.array([lo, hi]))
    target = np.ascontiguousarray(s[0] - u_d * (s[0] - s[1]))
    system = get_chronology_system(layer.npf)
    x = np.empty_like(target)  # halvings over _pf_shape(layer, 10**v km), compiled
    _pf_bisect_kernel(np.array(system.production.coefficients[:0:-1], dtype=np.float64),
                      target, math.log10(lo * 1e-3), math.log10(hi * 1e-3), _BISECTIONS, x)
    d = np.clip(_p10(x) * 1e3, lo, np.nextafter(hi, 0.0))
    age = layer.age_gyr
    n_t = float(_n1(layer, np.array([age]))[0])
    ages = np.empty_like(target)  # halvings over _n1(layer, t), compiled
    c0, c1, c2, c3 = (float(c) for c in system.chronology.coefficients)
    _age_bisect_kernel(c0, c1, c2, c3, np.ascontiguousarray(u_age * share * n_t), 0.0,
                       float(age), _BISECTIONS, ages)
    return d, np.clip(ages, 0.0, age)


def _counted(layer, layer_index: int, seed: int, b: int, cell_ids, area_m2, key: int):
    """The cells' Poisson counts of bin ``b``: (tag, cell of each draw, index in its cell,
    (lo, hi) metres, the youngest share of the flux the draws come from)."""
    seed = int(seed)
    if not 0 <= seed < 2**64:
        raise ValueError(f"`seed` must be in [0, 2**64); got {seed}")
    cells = np.ascontiguousarray(np.asarray(cell_ids, dtype=np.uint64).ravel())
    area = np.asarray(area_m2, dtype=np.float64).ravel()
    if area.shape != cells.shape:
        raise ValueError(f"`area_m2` must have one value per cell ({len(cells)}); got "
                         f"{area.shape}")
    lo, hi = bin_bounds(layer, b)
    tag = (int(layer_index) << 32) | (int(b) + _BIN_OFFSET)
    density, share = _bin_density(layer, lo, hi)
    mean = area * density
    # a mean beyond what one inversion holds is the sum of `parts` Poisson counts of
    # mean / parts (exactly Poisson), the j-th from counter index j (j = 0: the one draw)
    parts = np.maximum(1, np.ceil(mean / MAX_POISSON_MEAN)).astype(np.int64)
    if (parts == 1).all():
        zero = np.zeros(len(cells), dtype=np.int64)
        u = uniform_from_words(_words(cells, tag, zero, _COUNT, seed, key)[:, 0])
        counts = poisson_from_uniform(u, mean)
    else:
        rep = np.repeat(np.arange(len(cells)), parts)
        j = np.arange(len(rep), dtype=np.int64) - np.repeat(np.cumsum(parts) - parts, parts)
        u = uniform_from_words(_words(cells[rep], tag, j, _COUNT, seed, key)[:, 0])
        sub = poisson_from_uniform(u, (mean / parts)[rep])
        counts = np.add.reduceat(sub, np.cumsum(parts) - parts) if len(rep) else sub
    cell = np.repeat(cells, counts)
    # each draw's index within its cell: 0, 1, .. counts - 1, cell after cell
    index = np.arange(len(cell), dtype=np.int64) - np.repeat(np.cumsum(counts) - counts,
                                                             counts)
    return tag, cell, index, (lo, hi), share


def draw_cells(layer: CraterLayer | ModelAgeLayer, layer_index: int, *, seed: int, b: int,
               level: int, cell_ids, area_m2) -> dict:
    """The craters of size bin ``b`` of ``layer`` in the given cells (ids of ``level``).

    Parameters
    ----------
    layer, layer_index : CraterLayer, int
        The layer and its place in the scene (part of every counter).
    seed : int
        The scene's seed, in [0, 2**64).
    area_m2 : (n,) floats
        Each cell's area on the body's surface (m^2): the Poisson mean of its count is
        ``area x (N(lo) - N(hi))``.

    Returns
    -------
    dict of arrays, one entry per crater, cell by cell in the order given and by index
    within a cell: ``unit`` (n, 3) direction of the centre, ``diameter_m``, ``age_gyr``,
    ``rim_phases`` (n, 15), ``seed`` (uint64 roughness seed), ``id`` (uint64), ``cell``
    (uint64), ``index``.
    """
    tag, cell, index, (lo, hi), share = _counted(layer, layer_index, int(seed), b,
                                                 cell_ids, area_m2, CRATER_KEY)
    seed = int(seed)
    n = len(cell)
    main = _words(cell, tag, index, _MAIN, seed)
    um = uniform_from_words(main)
    if isinstance(layer, ModelAgeLayer):
        diameter, age = _model_age_draws(layer, lo, hi, share, um[:, 0], um[:, 1])
    else:
        diameter = power_law_from_uniform(um[:, 0], lo, hi, layer.k) if n else np.zeros(0)
        age = layer.age_min_gyr + um[:, 1] * (layer.age_max_gyr - layer.age_min_gyr)
    rim = np.concatenate([uniform_from_words(_words(cell, tag, index, _RIM + r, seed))
                          for r in range(_RIM_COUNTERS)], axis=1)[:, :15] * _TWO_PI
    unit = _positions(cell, tag, index, seed)
    return {"unit": unit, "diameter_m": diameter, "age_gyr": age, "rim_phases": rim,
            "seed": main[:, 2] >> np.uint64(1), "id": main[:, 3], "cell": cell,
            "index": index}


def draw_rock_cells(layer: BoulderLayer, layer_index: int, *, seed: int, b: int, level: int,
                    cell_ids, area_m2, elongation: float = 1.4, flatten: float = 0.6) -> dict:
    """The rocks of size bin ``b`` of a boulder ``layer`` in the given cells (ids of
    ``level``): as :func:`draw_cells` (the same counts, diameters and positions, under
    the key :data:`ROCK_KEY`), and each rock's shape in its own frame:

    - ``azimuth_rad`` of its long axis, uniform;
    - ``elongation`` (long / short axis of its footprint), uniform in [1, ``elongation``];
    - ``height_m``: ``flatten`` x diameter x a uniform factor in [0.7, 1.3];
    - ``burial_frac`` of that height below the ground, uniform in [MIN_BURIAL,
      ``layer.burial_max``];
    - ``facets`` (n, ROCK_FACETS, 3): the planes cutting the ellipsoid into an angular
      block, each (direction of its downhill normal in radians, offset, slope), in units
      of the half-height and the footprint's semi-axes: the first half cut the top
      (offset 0.6-0.95, slope 0.2-1), the others the sides (offset 1-1.5, slope 1.5-3),
      which makes the footprint a polygon.

    Returns ``unit``, ``diameter_m``, those, ``seed`` (uint64), ``id`` (uint64),
    ``cell``, ``index``.
    """
    tag, cell, index, (lo, hi), _ = _counted(layer, layer_index, int(seed), b, cell_ids,
                                             area_m2, ROCK_KEY)
    seed = int(seed)
    n = len(cell)
    main = _words(cell, tag, index, _MAIN, seed, ROCK_KEY)
    um = uniform_from_words(main)
    diameter = power_law_from_uniform(um[:, 0], lo, hi, layer.k) if n else np.zeros(0)
    shape = np.concatenate([uniform_from_words(_words(cell, tag, index, _RIM + r, seed,
                                                      ROCK_KEY))
                            for r in range(_ROCK_COUNTERS)], axis=1)
    facets = shape[:, :3 * ROCK_FACETS].reshape(n, ROCK_FACETS, 3)
    top = np.arange(ROCK_FACETS) < ROCK_FACETS // 2
    facets = np.stack([facets[..., 0] * _TWO_PI,
                       np.where(top, 0.6 + 0.35 * facets[..., 1], 1.0 + 0.5 * facets[..., 1]),
                       np.where(top, 0.2 + 0.8 * facets[..., 2], 1.5 + 1.5 * facets[..., 2])],
                      axis=-1)
    extra = shape[:, 3 * ROCK_FACETS:]
    unit = _positions(cell, tag, index, seed, ROCK_KEY)
    return {"unit": unit, "diameter_m": diameter,
            "azimuth_rad": um[:, 1] * _TWO_PI,
            "elongation": 1.0 + (float(elongation) - 1.0) * extra[:, 0],
            "height_m": float(flatten) * diameter * (0.7 + 0.6 * extra[:, 1]),
            "burial_frac": MIN_BURIAL + (layer.burial_max - MIN_BURIAL) * extra[:, 2],
            "facets": facets, "seed": main[:, 2] >> np.uint64(1), "id": main[:, 3],
            "cell": cell, "index": index}


def _positions(cell: np.ndarray, tag: int, index: np.ndarray, seed: int,
               key: int = CRATER_KEY) -> np.ndarray:
    """Uniform directions in each crater's cell: candidates uniform in the cell's
    tangent-plane square, accepted with probability J / J_max (J = (1 + u^2 + v^2)^-1.5,
    the gnomonic area element); the last candidate if none of 64 is (never seen: at
    least 0.19 of the candidates pass, in a level-0 cell)."""
    n = len(cell)
    level, face, i, j = cell_parts(cell)
    scale = 2.0 / np.left_shift(1, level).astype(np.float64)
    u0 = -1.0 + i * scale
    v0 = -1.0 + j * scale
    near_u = np.minimum(np.abs(u0), np.abs(u0 + scale)) * ((u0 > 0) | (u0 + scale < 0))
    near_v = np.minimum(np.abs(v0), np.abs(v0 + scale)) * ((v0 > 0) | (v0 + scale < 0))
    s_max = 1.0 + near_u * near_u + near_v * near_v  # J_max = s_max ** -1.5
    fu = np.zeros(n)
    fv = np.zeros(n)
    todo = np.arange(n)
    for k in range(_MAX_CANDIDATES):
        if not len(todo):
            break
        w = uniform_from_words(_words(cell[todo], tag, index[todo], _POSITION + k, seed, key))
        uu = u0[todo] + w[:, 0] * scale[todo]
        vv = v0[todo] + w[:, 1] * scale[todo]
        s = 1.0 + uu * uu + vv * vv
        # accept when w2 < J / J_max = (s_max / s) ** 1.5
        ratio = s_max[todo] / s
        ok = w[:, 2] < ratio * np.sqrt(ratio)
        if k == _MAX_CANDIDATES - 1:
            ok[:] = True
        fu[todo[ok]] = w[ok, 0]
        fv[todo[ok]] = w[ok, 1]
        todo = todo[~ok]
    return _cell_point(level, face, i, j, fu, fv) if n else np.zeros((0, 3))


def _cell_point(level, face, i, j, fu, fv) -> np.ndarray:
    """:func:`craters.cells.cell_points` for per-point levels."""
    out = np.empty((len(level), 3))
    for lv in np.unique(level):
        sel = level == lv
        out[sel] = cell_points(int(lv), face[sel], i[sel], j[sel], fu[sel], fv[sel])
    return out
