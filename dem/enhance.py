r"""Multi-resolution enhancement of a DEM around a site (Martin, Parkes & Dunstan 2014, IV.A).

:func:`enhance` builds a :class:`dem.Stack` of ``layers`` square layers of ``size`` =
2^n + 1 pixels, described by a :class:`dem.EnhanceConfig`: layer 0 is the
``size``-square window of the base DEM around the target, and layer k is
:func:`dem.expand` (one RMD doubling) of the ``(size + 1) / 2``-square footprint of layer
k - 1 centred on the target, so each layer is 2x finer than the last. Every layer's RMD
detail continues the relief of layer 0 (the source DEM; the median over
:data:`dem.expansion.RELIEF_MEDIAN_PX` pixels of its local relief, scaled by ``2^(-H)``
per level), not the relief re-estimated on the layer above: that reads the slopes of
crater walls as roughness and fed it back layer after layer (issue 36: steep ground had
4.8x the fine detail of flat ground). With ``terrain`` (:mod:`dem.terrains`) the detail
instead follows that terrain's LOLA deviogram (Rosenburg et al. 2011), the same
everywhere, each layer filling what its parent lacks (:func:`terrain_relief_m`). Without
a ``target`` the site is landing-like (:func:`dem.planning.landing_site`).

Consistency (exact)
-------------------
Expansion keeps a parent's pixels as the even pixels of the child (bit for bit). Craters
break that, so after stamping the craters of layer k the stack is re-synchronised
upwards: for j = k-1 .. 0, ``layer[j][footprint] = layer[j+1][::2, ::2]``
(:func:`dem.stack.propagate_up`). A crater of layer k never touches layer k's border
pixels (the containment rule of the plan), so the change stays strictly inside each
coarser footprint and the coarser layers stay continuous; at the end
``Stack.is_consistent()`` holds exactly (and for the float32 GeoTIFFs too). Layer k+1 is
expanded only after layer k's craters are in.

Boulders (``boulders``, ``min_boulder_px``) are planned the same way (by diameter band,
each into the finest layer that holds its whole footprint and resolves it) and, in each
layer, placed on the ground after that layer's craters and stamped as a heightfield
maximum (:func:`dem.stamp_boulders`). What finer layers add later -- RMD detail at odd
pixels, their own boulders (a maximum again) and their smaller craters -- is superposed
on everything, so a younger small crater of a finer layer can dent a coarser layer's
boulder; the synchronisation carries that up like any crater.

Stamping frames: crater positions are drawn in the *layer-0 grid frame* (metres, pixel
(i, j) of layer 0 at (j p0, i p0)); layer k's grid frame is the same frame shifted by
its offset, so no rounding enters. Catalogs are in the stack's local frame
(:mod:`dem.frame`, origin at the target pixel); the files add world coordinates.

Randomness: one ``seed`` feeds everything through ``numpy.random.SeedSequence(seed,
spawn_key=...)`` streams (:func:`dem.planning.seed_stream`: one per diameter band for the
populations, one per layer for stamping, one per count) and the counter-based expansion
key, so the same seed gives the same bytes whatever the thread count.
"""

from __future__ import annotations

import dataclasses
import logging
import math
from typing import NamedTuple

import numpy as np
from rasterio.windows import Window

import craters
from craters._shared import ParameterError, progress_bar

from .boulders import place_boulders
from .budget import check_memory_need
from .config import EnhanceConfig, SourceCraterLayer
from .core import Dem
from .craterdensity import CraterDensity, crater_density
from .expansion import RELIEF_MEDIAN_PX, expand, local_relief, midpoint_factor
from .fractal import expansion_fit
from .frame import LocalFrame, crater_target, grid_pixel_size, local_frame, pixel_affine
from .io import read
from .planning import (
    LANDING_SLOPE_LIMIT_DEG,
    STREAM_STAMP,
    StackGeometry,
    landing_site,
    layer_windows,
    plan_boulders,
    plan_craters,
    seed_stream,
    stack_geometry,
)
from .stack import Stack, propagate_up
from .terrains import MEDIAN_ABS_GAUSSIAN, TerrainRoughness, terrain_roughness

__all__ = ["Run", "enhance", "finish", "layer_step", "layers_of", "prepare", "stack_info"]

logger = logging.getLogger(__name__)

#: Largest source area (pixels) the crater density of a ``source`` layer is measured on.
_DENSITY_MAX_PX = 1_100_000


# --------------------------------------------------------------------------- stamping
def _stamp_boulders_layer(z, cat, geometry: StackGeometry, k: int, a0, shape):
    """Place and stamp layer k's boulders (layer-0 grid positions); returns the heights
    and the placed catalog in the local frame."""
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
    h, _, placed = place_boulders(z, geometry.pixel_m(k), m, t, local, shape=shape)
    return h, placed


def below_source(layers, source_px: float | None, pixel_m: float) -> tuple:
    """The crater layers limited to diameters below ``source_px`` source pixels (layers
    entirely above the limit are dropped; None keeps them all)."""
    if source_px is None:
        return tuple(layers)
    cap = source_px * pixel_m
    return tuple(dataclasses.replace(la, d_max_m=min(la.d_max_m, cap)) for la in layers
                 if la.d_min_m < cap)


def _with_source_density(cfg, base: Dem, win0, p0: float):
    """The crater layers with each :class:`~dem.config.SourceCraterLayer` made a power law
    at the source's measured crater density (the whole base when it has at most
    ``_DENSITY_MAX_PX`` pixels, else a window of that many around layer 0); and the
    measurement (None without such a layer)."""
    if not any(isinstance(la, SourceCraterLayer) for la in cfg.crater_layers):
        return cfg.crater_layers, None
    src = base
    if base.shape[0] * base.shape[1] > _DENSITY_MAX_PX:
        side = int(math.isqrt(_DENSITY_MAX_PX))
        r = max(0, min(base.shape[0] - side, int(win0.row_off) + cfg.size // 2 - side // 2))
        c = max(0, min(base.shape[1] - side, int(win0.col_off) + cfg.size // 2 - side // 2))
        src = base.crop(Window(c, r, min(side, base.shape[1]), min(side, base.shape[0])))
    density = crater_density(src)
    if density is None:
        raise ParameterError("craters", "'source': the source DEM shows too few craters of 6 "
                             "pixels and up (fewer than 3 found) to measure their density; "
                             "give a crater layer (c=..,k=.. or npf=..) instead")
    # up to what the source resolves: source_crater_px of its pixels, else (no limit
    # asked) the smallest crater the density was measured on
    d_max = cfg.source_crater_px * p0 if cfg.source_crater_px else density.d_lo_m
    layers = tuple(la.layer(density.c, density.k, max(d_max, la.d_min_m * 1.0001))
                   if isinstance(la, SourceCraterLayer) else la for la in cfg.crater_layers)
    logger.info("source crater density: N(>D) = %.4g D^%g per m^2 from %d craters of %.4g-%.4g "
                "m on %.4g km^2", density.c, density.k, density.count, density.d_lo_m,
                density.d_hi_m, density.area_m2 / 1e6)
    return layers, density


def _stamp_layer(z: np.ndarray, cat: np.ndarray, geometry: StackGeometry, k: int, *,
                 roughness: bool, seed: int, progress: bool, target):
    """Stamp layer k's craters (layer-0 grid frame positions) into a copy of ``z``."""
    if len(cat) == 0:
        return z, cat
    r, c = geometry.offsets[k]
    p0 = geometry.pixel0_m
    names = cat.dtype.names
    assert names is not None  # a catalog: a structured array
    cols = {name: cat[name] for name in names}
    cols["x_m"] = cat["x_m"] - c * p0
    cols["y_m"] = cat["y_m"] - r * p0
    grid = craters.make_catalog(**cols)
    h, stamped = craters.stamp_many(z, geometry.pixel_m(k), grid, roughness=roughness,
                                    target=target, rng=seed_stream(seed, STREAM_STAMP, k),
                                    progress=progress, return_catalog=True)
    # back to layer-0 grid positions, exactly as planned
    order = np.argsort(cat["index"])
    pos = order[np.searchsorted(cat["index"], stamped["index"], sorter=order)]
    stamped["x_m"] = cat["x_m"][pos]
    stamped["y_m"] = cat["y_m"][pos]
    return h, stamped


def _to_local(cat: np.ndarray, a0, p0: float) -> np.ndarray:
    """Catalog positions: layer-0 grid frame -> local frame (pixel affine ``a0``)."""
    u, v = cat["x_m"] / p0, cat["y_m"] / p0
    names = cat.dtype.names
    assert names is not None  # a catalog: a structured array
    cols = {name: cat[name] for name in names}
    cols["x_m"] = a0.a * u + a0.b * v + a0.c
    cols["y_m"] = a0.d * u + a0.e * v + a0.f
    return craters.make_catalog(**cols)


def enhance(config, *, dem: Dem | None = None, progress: bool = False) -> Stack:
    """Build a multi-resolution stack with craters (and boulders) per layer.

    See the module notes for the algorithm and how the layers are kept consistent, and
    :mod:`dem.planning` for the crater split. Nothing is written: save the stack with
    :meth:`Stack.write`.

    Parameters
    ----------
    config : EnhanceConfig or dict
        The stack's description (a dict is made into an :class:`EnhanceConfig`; unknown
        keys are errors).
    dem : Dem, optional
        The base DEM, instead of the config's ``input`` file.
    progress : bool
        Show a progress bar over the layers.

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
    ...              "craters": ["c=0.05,k=-2,d_min_m=20,d_max_m=800"]}, dem=base)
    >>> s.shapes, s.pixel_sizes_m(), s.is_consistent()
    ([(17, 17), (17, 17), (17, 17)], [100.0, 50.0, 25.0], True)
    >>> c = s.info["craters"]
    >>> c["drawn"] == (sum(c["stamped"]) + sum(c["erased_on_steep_ground"])
    ...                + sum(c["erased_by_younger_crater"]) + c["rejected"])
    True
    """
    run = prepare(config, dem)
    arrays: list[np.ndarray] = []
    metas: list[Dem] = []
    stamped: list[np.ndarray] = []
    rocks: list = []
    for k, meta, z, cat, rock in layers_of(run, progress=progress):
        arrays.append(z)
        metas.append(meta)
        stamped.append(cat)
        rocks.append(rock)
        propagate_up(arrays, run.windows, k)
    info = stack_info(run, stamped, rocks)
    layers = [metas[k].with_step(arrays[k], "dem.enhance", run.seed, layer_step(run, k, stamped,
                                                                              rocks))
              for k in range(run.cfg.layers)]
    return finish(run, layers, stamped, rocks, info)


class Run(NamedTuple):
    """A stack's settings and plan, made once before its layers (:func:`prepare`)."""

    cfg: EnhanceConfig
    seed: int
    layer0: Dem
    win0: Window
    windows: list
    t0: tuple
    t_base: tuple
    frame: LocalFrame
    a0: object
    p0: float
    geometry: StackGeometry
    target: object
    plans: list
    accounting: dict
    rock_plans: list
    rock_accounting: dict | None
    source_density: CraterDensity | None
    fd: float
    fd_estimated: float | None
    relief: Dem | None
    """Layer 0's local relief (the median over :data:`RELIEF_MEDIAN_PX` pixels), which
    every layer's expansion continues (None with a uniform ``roughness``)."""
    terrain: TerrainRoughness | None
    """The terrain whose deviogram the layers follow (:func:`terrain_relief_m`)."""
    site_choice: str
    """How the site was chosen (the manifest's ``target.chosen``)."""


def prepare(config, dem: Dem | None = None, *, layers_held: int | None = None) -> Run:
    """Check a stack's description, read the base, plan the layers, craters and boulders.

    ``layers_held``: how many layer-sized arrays the run keeps at once (default: every
    layer, as :func:`enhance`), for the up-front memory check.
    """
    cfg = EnhanceConfig.from_mapping(config)
    if (dem is None) == (cfg.input is None):
        raise ValueError("give the base DEM either as the `input` key or as `dem`, not both"
                         if dem is not None else "no base DEM: give the `input` key")
    if dem is not None and not isinstance(dem, Dem):
        raise TypeError(f"`dem` must be a Dem; got {type(dem).__name__}")
    held = cfg.layers * 2.5 if layers_held is None else layers_held
    need = held * cfg.size**2 * 8 + (2 * cfg.size + 8) ** 2 * 8 * 2.3
    check_memory_need(need, f"a stack of {cfg.layers} layers of {cfg.size}^2 pixels",
                      share=0.85)
    base = dem if dem is not None else read(cfg.input, band=cfg.band,
                                            pixel_size_m=cfg.pixel_size_m,
                                            body_radius_m=cfg.body_radius_m, body=cfg.body,
                                            crs=cfg.crs)
    seed = cfg.seed  # checked by the config
    if seed is None:
        entropy = np.random.SeedSequence().entropy
        assert isinstance(entropy, int)  # a fresh SeedSequence's own
        seed = int(entropy % 2**63)
    site = None if cfg.target is not None else landing_site(base, cfg.size)
    win0, windows, t0, t_base = layer_windows(base, cfg.target, cfg.size, cfg.layers,
                                              site_px=None if site is None else site[0])
    layer0 = base.crop(win0)
    unknown = int((~layer0.known).sum())
    if unknown:
        raise ValueError(f"layer 0 (rows {int(win0.row_off)}.., cols {int(win0.col_off)}.. of "
                         f"the base) has {unknown} unknown (NaN) pixels; fill them first "
                         f"(dem.fill_gaps, dem.fill_crater_gaps, `dem fill`)")
    frame = local_frame(layer0, origin=t0)
    a0 = pixel_affine(layer0, frame)
    p0 = grid_pixel_size(a0, "the base DEM")
    geometry = stack_geometry(cfg.size, windows, p0)
    target = crater_target(base, cfg.body, cfg.gravity_m_s2)
    irregularity = 0.0 if cfg.smooth_craters else 0.02  # craters.stamp_many's default
    reach_radii = craters.DEFAULT_EJECTA_EDGE * (1.0 + irregularity)
    crater_layers, source_density = _with_source_density(cfg, base, win0, p0)
    crater_layers = below_source(crater_layers, cfg.source_crater_px, p0)
    plans, accounting = plan_craters(crater_layers, geometry, min_px=cfg.min_crater_px,
                                     reach_radii=reach_radii, seed=seed)
    rock_plans, rock_accounting = (plan_boulders(cfg.boulder_layers, geometry,
                                                 min_px=cfg.min_boulder_px, seed=seed)
                                   if cfg.boulder_layers else ([None] * cfg.layers, None))
    fd = cfg.fractal_dimension
    fd_estimated = None
    terrain = None if cfg.terrain is None else terrain_roughness(cfg.terrain)
    if terrain is not None:
        fd = 3.0 - terrain.hurst
    elif fd is None:
        fd_estimated = expansion_fit(layer0).fractal_dimension
        fd = min(3.0, max(2.0, fd_estimated))
    relief = (local_relief(layer0, median_px=RELIEF_MEDIAN_PX) if cfg.roughness is None
              else None)
    return Run(cfg, seed, layer0, win0, windows, t0, t_base, frame, a0, p0, geometry, target,
               plans, accounting, rock_plans, rock_accounting, source_density, fd,
               fd_estimated, relief, terrain, _site_choice(site))


def terrain_target_m(terrain, pixel_m: float, source_pixel_m: float,
                     source_relief_m: float) -> float:
    """RMS height difference a stack on ``terrain`` should have at lag ``pixel_m``: the
    deviogram ``nu`` below the breakover; between the source's pixel and the breakover
    (where the real deviogram flattens) the log-linear interpolation from the source's
    own median relief to ``nu(breakover)``."""
    b = terrain.breakover_m
    if pixel_m <= b or source_pixel_m <= b or source_relief_m <= 0.0:
        return terrain.relief_m(pixel_m)
    t = math.log(pixel_m / source_pixel_m) / math.log(b / source_pixel_m)
    return math.exp((1.0 - t) * math.log(source_relief_m) + t * math.log(terrain.relief_m(b)))


def robust_relief_m(z: np.ndarray, diagonal: bool = False) -> float:
    """RMS height difference of neighbouring pixels (axis or diagonal) from the median
    ``|dz|`` (Gaussian: median = 0.6745 RMS), robust to the walls of resolved craters."""
    if diagonal:
        d = np.concatenate([(z[1:, 1:] - z[:-1, :-1]).ravel(), (z[1:, :-1] - z[:-1, 1:]).ravel()])
    else:
        d = np.concatenate([(z[:, 1:] - z[:, :-1]).ravel(), (z[1:] - z[:-1]).ravel()])
    d = np.abs(d[np.isfinite(d)])
    return float(np.median(d)) / MEDIAN_ABS_GAUSSIAN if d.size else 0.0


def terrain_relief_m(run: Run, k: int, parent: Dem) -> float:
    """The uniform relief (metres on layer 0's grid) that makes layer k's RMD bring the
    stack to its ``terrain``'s deviogram (:mod:`dem.terrains`).

    A square-phase pixel at distance ``rho = d / sqrt 2`` from four parent pixels (``d``
    the parent's pixel) differs from one of them by ``sum w z + D`` whose variance is
    ``gamma(d) / 4 + gamma(d sqrt 2) / 8 + s^2`` (:mod:`dem.expansion`). With the parent's
    *measured* ``gamma`` (robust, over the part being expanded: one number, so the detail
    does not follow local slopes) the displacement fills the deficit to the target,
    ``s^2 = nu(rho)^2 - gamma(d) / 4 - gamma(d sqrt 2) / 8`` (at least a tenth of the fBm
    value ``k(H) nu(rho)^2``): a parent smoother than the terrain at its scale (the LOLA
    gridded source is) gets the difference at once, a rougher one little more. The
    terrain type is what the user claims for the site, so its detail is the same
    everywhere (the source's own relief map, kept without ``terrain``, made the site's
    560 m slopes 28 % lower: the site is a smooth spot of the source).
    """
    terrain, relief = run.terrain, run.relief
    assert terrain is not None and relief is not None  # a terrain run's (prepare)
    rr, cc, w = run.windows[k - 1]
    d = parent.resolution_m
    target = terrain_target_m(terrain, d / math.sqrt(2.0), relief.resolution_m,
                              float(np.median(relief.heights)))
    z = parent.heights[rr:rr + w, cc:cc + w]
    g_axis = robust_relief_m(z) ** 2
    g_diag = robust_relief_m(z, diagonal=True) ** 2
    k_h = midpoint_factor(terrain.hurst)
    s2 = max(target**2 - g_axis / 4.0 - g_diag / 8.0, 0.1 * k_h * target**2)
    # the square phase's scale per metre of relief on layer 0's grid (dem.expand)
    unit = math.sqrt(k_h) * 2.0 ** (-(k - 0.5) * terrain.hurst)
    return math.sqrt(s2) / unit


def layers_of(run: Run, *, progress: bool = False):
    """The layers of a stack one after the other: ``(k, meta, heights, craters,
    boulders)``, layer k with its own craters and boulders, not yet synchronised with the
    finer layers (:func:`dem.stack.propagate_up`); only the previous layer is kept."""
    cfg = run.cfg
    rock_shape = craters.BoulderShape()
    prev: tuple[Dem, np.ndarray] | None = None
    meta: Dem | None
    z: np.ndarray | None
    for k in progress_bar(range(cfg.layers), enabled=progress, desc="enhance"):
        if k == 0:
            meta = run.layer0
        else:
            rr, cc, w = run.windows[k - 1]
            assert prev is not None  # k > 0: the previous layer's
            parent = prev[0].replace(heights=prev[1])
            relief = run.relief
            if relief is not None and run.terrain is not None:
                relief = relief.replace(heights=np.full(relief.shape,
                                                        terrain_relief_m(run, k, parent)))
            prev = meta = z = None  # the caller may drop them too: only the copy is held
            meta = expand(parent, 1, run.fd, cfg.roughness, Window(cc, rr, w, w), rng=run.seed,
                          relief=relief)
            del parent
        z, cat = _stamp_layer(np.array(meta.heights), run.plans[k], run.geometry, k,
                              roughness=not cfg.smooth_craters, seed=run.seed, progress=False,
                              target=run.target)
        rock = None
        if cfg.boulder_layers:
            z, rock = _stamp_boulders_layer(z, run.rock_plans[k], run.geometry, k, run.a0,
                                            rock_shape)
        z = np.asarray(z, dtype=np.float64)  # a fresh array already (the stamped copy)
        yield k, meta, z, cat, rock
        prev = (meta, z)


def layer_step(run: Run, k: int, stamped, rocks) -> dict:
    """The ``dem.enhance`` step recorded in layer k's history."""
    step = {"layer": k, "craters_stamped": len(stamped[k]),
            "synchronised_with_finer_layers": k < run.cfg.layers - 1}
    if run.cfg.boulder_layers:
        step["boulders_stamped"] = len(rocks[k])
    return step


def stack_info(run: Run, stamped, rocks) -> dict:
    """The stack's ``info`` (seed, parameters, target, crater and boulder accounting)."""
    cfg = run.cfg
    accounting = run.accounting
    n_stamped = [len(c) for c in stamped]
    accounting["stamped"] = n_stamped
    accounting["erased_on_steep_ground"] = [
        a - e - s for a, e, s in zip(accounting["assigned"],
                                     accounting["erased_by_younger_crater"], n_stamped,
                                     strict=True)]
    rock_accounting = run.rock_accounting
    if rock_accounting is not None:
        n_rocks = [0 if r is None else len(r) for r in rocks]
        rock_accounting["stamped"] = n_rocks
        rock_accounting["off_grid"] = [a - s for a, s in
                                       zip(rock_accounting["assigned"], n_rocks, strict=True)]
    params = cfg.to_dict()
    params.update(seed=run.seed, fractal_dimension=run.fd,
                  fractal_dimension_estimated=run.fd_estimated)
    density = run.source_density
    win0 = run.win0
    return {
        "seed": run.seed,
        "parameters": params,
        "target": {"world": None if cfg.target is None else list(cfg.target),
                   "chosen": run.site_choice,
                   "pixel_in_base": list(run.t_base), "pixel_in_layer0": list(run.t0),
                   "world_pixel_centre": [float(v) for v in run.layer0.xy(*run.t0)]},
        "layer0_window_in_base": [int(win0.row_off), int(win0.col_off), cfg.size],
        "craters": accounting,
        "source_crater_density": None if density is None else {
            "c": density.c, "k": density.k, "count": density.count,
            "area_m2": density.area_m2, "d_lo_m": density.d_lo_m,
            "d_hi_m": density.d_hi_m},
        "boulders": rock_accounting,
        "randomness": "numpy SeedSequence(seed, spawn_key=(1, band)) for the population of "
                      "each diameter band, (2, band) and (3,) for the rejected counts, "
                      "(4, layer) for stamping; the RMD key is default_rng(seed)'s first "
                      "draw",
    }


def _site_choice(site) -> str:
    """How the site was chosen: given, or :func:`dem.planning.landing_site`'s ``site``
    (its pixel and the steepest slope around it)."""
    if site is None:
        return "given"
    worst = site[1]
    if worst <= LANDING_SLOPE_LIMIT_DEG:
        return (f"landing-like: nearest the base's centre with 3 x 3 Horn slopes <= "
                f"{LANDING_SLOPE_LIMIT_DEG:g} deg at the base's pixels (steepest there "
                f"{worst:.2f} deg)")
    return (f"landing-like: no pixel near the base's centre has 3 x 3 Horn slopes <= "
            f"{LANDING_SLOPE_LIMIT_DEG:g} deg; the gentlest (steepest there {worst:.2f} deg)")


def finish(run: Run, layers, stamped, rocks, info) -> Stack:
    """The :class:`Stack` of the finished ``layers`` (catalogs to the local frame)."""
    catalogs = [_to_local(c, run.a0, run.p0) for c in stamped]
    return Stack(layers, run.windows, run.frame, catalogs, info,
                 rocks if run.cfg.boulder_layers else None)
