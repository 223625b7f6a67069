r"""Random midpoint displacement (RMD) expansion of DEMs (Martin, Parkes & Dunstan 2014, IV.A).

One level doubles the resolution of a square region of ``W = 2**n + 1`` pixels: the new
grid has ``2 W - 1`` pixels a side, its even pixels are the old pixels (bit for bit),
the (odd, odd) pixels come from the *square* phase (mean of the four diagonal old
pixels) and the remaining pixels from the *diamond* phase (mean of the four axis
neighbours: two old pixels and two square-phase pixels; three on the border), each plus
a Gaussian displacement.

Displacement scale (derivation)
-------------------------------
The terrain is modelled as fractional Brownian motion with Hurst exponent ``H = 3 - F``
(``F`` the fractal dimension): its variogram is

    gamma(l) = E[(z(p + l) - z(p))^2] = sigma^2 (l / R)^(2 H),   sigma = roughness * R,

with ``R`` the input resolution (:mod:`dem.fractal` estimates ``F`` and ``roughness``).
A new point ``c`` has four neighbours ``a_1..a_4`` at distance ``rho`` (a square of side
``rho sqrt 2``, diagonal ``2 rho``) and gets ``z(c) = mean(z(a_k)) + D`` with ``D`` an
independent Gaussian of variance ``s^2``. We ask the new increments to follow the
model, ``E[(z(c) - z(a_1))^2] = gamma(rho)``. Now ``z(c) - z(a_1) = sum_k w_k z(a_k) + D``
with ``w = (-3/4, 1/4, 1/4, 1/4)``; since ``sum w_k = 0``,
``E[(sum w_k z_k)^2] = -1/2 sum_kl w_k w_l gamma(|a_k - a_l|)``, which for this square
is ``gamma(rho sqrt 2) / 4 + gamma(2 rho) / 8 = gamma(rho) (2^(H-2) + 2^(2H-3))``. Hence

    s^2 = gamma(rho) k(H),   k(H) = 1 - 2^(H-2) - 2^(2H-3)

(``k(1) = 0``: a smooth surface needs no displacement; ``k(1/2) = 0.396``;
``k(0) = 0.625``). At expansion level ``L = 1, 2, ...`` the old spacing is
``d = 2^(1-L) R``; the square phase has ``rho = d / sqrt 2`` and the diamond phase
``rho = d / 2``, so

    s_square(L) = sigma sqrt(k(H)) 2^(-(L - 1/2) H),   s_diamond(L) = sigma sqrt(k(H)) 2^(-L H).

Each half step (square -> diamond -> next square) shrinks the scale by
``2^(-H/2) = 2^(-(3-F)/2)``, Peitgen & Saupe's (1988) factor (the paper's eq. 14). The paper's
starting scale (eq. 15, from a height-range factor and the resolution) and its scale
after ``n`` RMD iterations (eq. 16) are replaced by ``sigma``, *measured* on the input at
its own resolution, so the expansion continues the input's roughness across scales. The
independence of ``D`` is an approximation (the neighbours of a new point are not all
model-distributed pairs: two square-phase points share corners); measured on a 17 x 17
seed expanded 7 levels (tests, ``bench_dem.py``): F = 2.2 / 2.5 / 2.8 read 2.29 / 2.56 /
2.75 with :func:`dem.fractal_dimension` (lags 2-8 px) and 2.15 / 2.50 / 2.81 with the
power-spectrum slope (:func:`dem.spectral_fit`), and the variance at the finest lag is
0.82 / 0.98 of ``gamma`` (F = 2.2 / 2.5).

Local amplitude. By default ``sigma`` is not one number but the local relief of the
input, ``sigma(p) = rho(p) R``: the RMS height difference between input pixel ``p`` and
its axis neighbours (:func:`dem.local_roughness`), in metres, interpolated bilinearly
to each new pixel: the terrain model of :mod:`dem.fractal` (one ``H``, amplitude varying in
space). Smooth mare then gets smooth detail and crater walls rough detail, which is
what keeps the slope distribution of a real DEM (a single amplitude makes the median
slope of smooth areas several times too large). An explicit ``roughness`` gives the
paper's uniform scale. ``relief`` carries a coarser ancestor's relief instead (layer 0's
in :func:`dem.enhance`), with the scale continued from that level: expanding one level
at a time with it gives exactly the pixels of one multi-level expansion (tests).

Randomness and tiles
--------------------
The Gaussian of a new pixel is a hash of (seed, level, global pixel index) (see
:attr:`Dem.level` / :attr:`Dem.origin`), and a region is expanded with up to two pixels
of context around it at every level (the DEM's own pixels where they exist). So
expanding a DEM as tiles that share their edge pixels, or expanding a sub-window, gives
exactly the pixels of the whole expansion, for any thread count (the amplitude map is
computed from one more pixel of context, so it agrees too). A tile cut out as its own
:class:`Dem` gives the same pixels when it keeps :data:`CONTEXT_PX` pixels of context
around the region and is given the whole DEM's ``fractal_dimension`` (the default
estimate is per DEM); with a uniform ``roughness`` and a geographic CRS the amplitude
``roughness * resolution_m`` also depends on the crop's centre latitude. A finer layer's even
pixels equal the coarser layer (the layer-stack consistency ``enhance`` relies on).
:func:`dem.expand_to_file` (:mod:`dem.expandfile`) uses this to write results bigger than
memory: tiles of the region, each expanded with its halo, each written into its window of
the output file.
"""

from __future__ import annotations

import logging
import math
from typing import NamedTuple

import numpy as np
from affine import Affine

from craters._shared import (
    ParameterError,
    about,
    check_int,
    check_positive,
    check_range,
    progress_bar,
)

from .budget import check_memory_need
from .core import Dem
from .fractal import MAX_ROUGHNESS, expansion_fit, local_msd

__all__ = ["CONTEXT_PX", "RELIEF_MEDIAN_PX", "displacement_scales", "expand", "expansion_sizes",
           "local_relief", "midpoint_factor"]

logger = logging.getLogger(__name__)

#: The window (pixels of layer 0) of the median local relief :func:`dem.enhance`
#: continues in every layer (:func:`local_relief`).
RELIEF_MEDIAN_PX = 5
#: Context pixels a separately cut tile needs around its region to expand exactly like
#: the same region of the whole DEM (level-1 halo plus the amplitude's neighbours).
CONTEXT_PX = 3
# context pixels kept around the region at every level: enough for the border diamond
# pixels of every level to see the same neighbours as in the whole-DEM expansion
HALO_PX = 2
# bytes per output pixel: the output, the previous level, the final crop
BYTES_PER_PIXEL = 8 * 2.3


def expansion_sizes(n_max: int = 12) -> list[int]:
    """The region widths expansion accepts: ``2**n + 1`` for n = 1..n_max."""
    return [2**n + 1 for n in range(1, n_max + 1)]


def midpoint_factor(hurst: float) -> float:
    """k(H) = 1 - 2^(H-2) - 2^(2H-3): displacement variance over gamma(rho) for a midpoint.

    See the module docstring (clipped at 0 for H > 1).
    """
    return max(0.0, 1.0 - 2.0 ** (hurst - 2.0) - 2.0 ** (2.0 * hurst - 3.0))


def displacement_scales(level: int, fractal_dimension: float, sigma_m: float):
    """Standard deviations (square, diamond) of the displacements at expansion ``level``.

    ``sigma_m`` is the RMS height difference (metres) of neighbouring pixels of the input
    (``roughness * resolution_m``); level 1 is the first doubling. See the module
    docstring for the derivation.

    Examples
    --------
    >>> sq, dia = displacement_scales(1, 2.5, 1.0)
    >>> round(sq / dia, 6) == round(2 ** 0.25, 6)   # one half step: 2^((3 - F) / 2)
    True
    """
    level = check_int("level", level, 1)
    hurst = 3.0 - check_range("fractal_dimension", fractal_dimension, 2.0, 3.0)
    base = check_positive("sigma_m", sigma_m, allow_zero=True) * math.sqrt(midpoint_factor(hurst))
    return base * 2.0 ** (-(level - 0.5) * hurst), base * 2.0 ** (-level * hurst)


def _check_dem(dem) -> Dem:
    if not isinstance(dem, Dem):
        raise TypeError(f"`dem` must be a Dem; got {type(dem).__name__}")
    if not dem.known.any():
        raise ValueError("`dem` has no known pixel (all NaN)")
    return dem



def _region(dem: Dem, region) -> tuple[int, int, int]:
    """(row_off, col_off, width) of a valid square 2^n + 1 region."""
    allowed = ", ".join(map(str, expansion_sizes(12))) + ", ..."
    if region is None:
        rows, cols = dem.shape
        if rows != cols or rows < 3 or (rows - 1) & (rows - 2):
            raise ParameterError(
                "region", f"is needed (or a cropped DEM): the DEM is {rows} x {cols} pixels "
                f"and expansion needs a square region of W = 2^n + 1 pixels ({allowed})")
        return 0, 0, rows
    win = dem.window(region)
    h, w = int(win.height), int(win.width)
    if h != w or h < 3 or (h - 1) & (h - 2):
        raise ParameterError("region", f"is {h} x {w} pixels; expansion needs a square of "
                             f"W = 2^n + 1 pixels ({allowed})")
    return int(win.row_off), int(win.col_off), h


def expand(dem: Dem, levels: int = 1, fractal_dimension: float | None = None,
           roughness: float | None = None, region=None, rng=None, *,
           relief: Dem | None = None, progress: bool = False) -> Dem:
    """Double the resolution of a square region ``levels`` times by RMD (diamond-square).

    A region of ``W = 2^n + 1`` pixels becomes ``(W - 1) 2^levels + 1`` pixels; its
    pixels are kept exactly (``out.heights[::2**levels, ::2**levels]`` equals the region),
    new pixel centres fall on the old ones, and the new pixel size is the old one over
    ``2^levels``. Displacements follow fBm with fractal dimension ``fractal_dimension``;
    their amplitude is the input's relief at its finest scale (see the module
    docstring). Defaults come from the input DEM itself, so the expansion continues its
    statistics: F from :func:`dem.expansion_fit` of the *whole* DEM (clipped to
    [2, 3]; 0.1-0.3 below its fractal dimension, which is what reproduces real terrain
    below the pixel, see there) and, without ``roughness``, the local roughness of each input pixel
    (:func:`dem.local_roughness`, interpolated bilinearly), so rough areas get rough
    detail and smooth areas smooth detail. A ``roughness`` value makes it uniform (the
    paper's single scale).

    Parameters
    ----------
    dem : Dem
    levels : int
        Number of doublings, 1..16.
    fractal_dimension : float, optional
        F in [2, 3] (H = 3 - F).
    roughness : float, optional
        Uniform RMS slope between neighbouring input pixels (m/m, >= 0; 0 = smooth
        diamond-square interpolation). Default: local, from the input.
    region : tuple, str, rasterio Window or BoundingBox, optional
        The square to expand: ``(row, col, size)`` in pixels or ``(left, bottom, right,
        top)`` in CRS units (the pixels whose centres lie inside), as a tuple or the same
        text (``"0,0,257"``, as ``dem expand --region`` takes it; see
        :func:`dem.core.parse_region`). Default: the whole DEM, which must then be a
        2^n + 1 square. Pixels around it are used as context for its border.
    rng : int, numpy.random.Generator or None
        Seed of the counter-based randomness. Give the same *int* to get the same pixels
        from separate calls (tiles).
    relief : Dem, optional
        The local relief to continue instead of the input's own (metres, RMS height
        difference of neighbouring pixels of ``relief``, :func:`local_relief`): a
        coarser ancestor of ``dem`` on the same lattice (its :attr:`Dem.level` at most
        ``dem``'s, covering the region), scaled down by ``2^(-H)`` per level between
        them as fBm continues. :func:`dem.enhance` passes layer 0's, so every layer
        continues the *source* DEM's roughness: re-estimating it on each expanded
        layer reads the large-scale slope of crater walls as relief and feeds it back
        (steep ground got 4.8x the fine detail of flat ground, issue 36). Not with
        ``roughness``.
    progress : bool
        Show a progress bar over the levels.

    Returns
    -------
    Dem
        The expanded region, with its transform, level, origin and history tags.

    Examples
    --------
    >>> d = Dem(np.arange(25.0).reshape(5, 5), pixel_size_m=8.0)
    >>> e = expand(d, 2, fractal_dimension=2.3, roughness=0.1, rng=1)
    >>> e.shape, e.pixel_size_m, bool((e.heights[::4, ::4] == d.heights).all())
    ((17, 17), (2.0, 2.0), True)
    """
    plan = plan_expansion(dem, levels, fractal_dimension, roughness, region, rng, relief)
    check_memory_need((plan.side + 4 * HALO_PX) ** 2 * BYTES_PER_PIXEL,
                      f"expanding {plan.width} x {plan.width} pixels {levels} levels (to "
                      f"{plan.side} x {plan.side} pixels)",
                      "dem.expand_to_file writes it tile by tile", share=0.85)
    heights = expand_tile(dem, plan, plan.r0, plan.c0, plan.width, progress=progress)
    return dem.with_step(heights, "dem.expand", plan.seed, plan.params,
                         transform=plan.transform, pixel_size_m=plan.pixel_size_m,
                         level=dem.level + plan.levels, origin=plan.origin)


class ExpansionPlan(NamedTuple):
    """An expansion's settings, made once for the whole region (:func:`plan_expansion`)."""

    r0: int
    c0: int
    width: int
    levels: int
    side: int
    fractal_dimension: float
    key: int
    seed: int | None
    params: dict
    uniform_m: float | None
    """The uniform amplitude (roughness x resolution), None for the local one."""
    relief: Dem | None
    """The carried local relief (metres at its own level), None for the input's own."""
    fallback_m: float
    """The local amplitude where a pixel has no known neighbour."""
    transform: Affine
    pixel_size_m: tuple | None
    origin: tuple[int, int]


def expansion_extent(dem: Dem, levels, region) -> tuple[int, tuple[int, int, int], int]:
    """(levels, (row_off, col_off, width) of the region, side of the output in pixels),
    checked: what an output's size is known from before any estimate (``dem expand``
    refuses an output too large for its disk before scipy and numba load, < 1 s)."""
    with about("levels"):
        levels = check_int("levels", levels, 1, 16)
    r0, c0, width = _region(_check_dem(dem), region)
    return levels, (r0, c0, width), (width - 1) * 2**levels + 1


def plan_expansion(dem: Dem, levels, fractal_dimension, roughness, region, rng,
          relief: Dem | None = None) -> ExpansionPlan:
    """Check the arguments and make the estimates of the whole DEM (expand's parameters)."""
    from ._rng_kernels import key_from_rng  # numba: loaded where it runs

    dem = _check_dem(dem)
    levels, (r0, c0, width), side = expansion_extent(dem, levels, region)
    block = dem.heights[r0:r0 + width, c0:c0 + width]
    unknown = int(np.isnan(block).sum())
    if unknown:
        raise ValueError(f"the region has {unknown} unknown (NaN) pixels; fill them first "
                         f"(dem.fill_gaps, `dem fill`)")
    if fractal_dimension is not None:
        with about("fractal_dimension"):
            fractal_dimension = check_range("fractal_dimension", fractal_dimension, 2.0, 3.0)
    if roughness is not None:
        with about("roughness"):
            roughness = check_range("roughness", roughness, 0.0, MAX_ROUGHNESS)
    params: dict = {"levels": levels, "region": [r0, c0, width],
                    "input_resolution_m": dem.resolution_m}
    fit = None
    if fractal_dimension is None or roughness is None:
        fit = expansion_fit(dem)
    if fractal_dimension is None:
        assert fit is not None  # fitted above
        fractal_dimension = min(3.0, max(2.0, fit.fractal_dimension))
        params["fractal_dimension_estimated"] = fit.fractal_dimension
    params["fractal_dimension"] = fractal_dimension
    if relief is not None:
        relief = _check_relief(relief, dem, roughness, (r0, c0, width))
        params["relief_level"] = relief.level
    resolution = dem.resolution_m
    if roughness is None:
        assert fit is not None  # fitted above
        uniform, fallback = None, fit.roughness * resolution
        params["roughness"] = "local"
        params["roughness_rms"] = fit.roughness
    else:
        uniform, fallback = roughness * resolution, 0.0
        params["roughness"] = roughness
    with about("rng"):
        key, seed = key_from_rng(rng)
    params["key"] = key
    scale = 0.5**levels
    shift = 0.5 - scale / 2.0  # keeps pixel centres: new (0, 0) on old (r0, c0)
    transform = (dem.transform @ Affine.translation(c0 + shift, r0 + shift)
                 @ Affine.scale(scale))
    px = None if dem.crs is not None else tuple(v * scale for v in dem.pixel_size_m)
    origin = ((dem.origin[0] + r0) * 2**levels, (dem.origin[1] + c0) * 2**levels)
    return ExpansionPlan(r0, c0, width, levels, side, fractal_dimension, key, seed, params, uniform,
                 relief, fallback, transform, px, origin)


def _check_relief(relief, dem: Dem, roughness, region) -> Dem:
    """``relief`` checked against ``dem`` and its region (see :func:`expand`)."""
    if not isinstance(relief, Dem):
        raise TypeError(f"`relief` must be a dem.Dem; got {type(relief).__name__}")
    if roughness is not None:
        raise ValueError("give `relief` or `roughness`, not both")
    if relief.level > dem.level:
        raise ValueError(f"`relief` must be at the level of the DEM or coarser (<= "
                         f"{dem.level}); got level {relief.level}")
    if not np.isfinite(relief.heights).all() or (relief.heights < 0).any():
        raise ValueError("`relief` must be finite and >= 0 metres everywhere")
    step = 2 ** (dem.level - relief.level)
    r0, c0, width = region
    lo = [(dem.origin[i] + (r0, c0)[i]) / step - relief.origin[i] for i in (0, 1)]
    hi = [v + (width - 1) / step for v in lo]
    if min(lo) < 0 or hi[0] > relief.shape[0] - 1 or hi[1] > relief.shape[1] - 1:
        raise ValueError("`relief` does not cover the region to expand (it must be an "
                         "ancestor of the DEM on the same lattice: dem.local_relief of a "
                         "coarser layer it was expanded from)")
    return relief


def local_relief(dem: Dem, *, median_px: int = 1) -> Dem:
    """The local relief of each pixel (metres): RMS height difference to its known axis
    neighbours, what :func:`expand` scales its displacements by (``local_roughness``
    times the resolution; a pixel with no known neighbour gets the DEM's RMS value).

    ``median_px`` > 1 (odd) takes the median of that value over a ``median_px`` square
    around each pixel instead: the relief of the *terrain* there, robust to the few
    pixels of a resolved landform in the window. A crater wall a few pixels wide reads
    as relief because of its slope, not its roughness; :func:`dem.enhance` uses
    :data:`RELIEF_MEDIAN_PX` so the detail below the pixel does not follow the
    resolved slopes (issue 36; ``tests/benchmarks/measure_rmd_roughness.py``).

    Examples
    --------
    >>> d = Dem(np.array([[0.0, 1.0, 2.0], [0.0, 1.0, 2.0]]), pixel_size_m=1.0)
    >>> local_relief(d).heights.round(3).tolist()
    [[0.707, 0.816, 0.707], [0.707, 0.816, 0.707]]
    """
    dem = _check_dem(dem)
    with about("median_px"):
        median_px = check_int("median_px", median_px, 1)
    if median_px % 2 == 0:
        raise ValueError(f"`median_px` must be odd; got {median_px}")
    rows, cols = dem.shape
    amp, _, _ = _local_amplitude(dem, 0, 0, max(rows, cols), math.nan)
    amp = amp[:rows, :cols]
    finite = np.isfinite(amp)
    amp[~finite] = float(np.sqrt(np.mean(amp[finite] ** 2))) if finite.any() else 0.0
    if median_px > 1:
        from scipy.ndimage import median_filter  # loaded where it runs: see expansion_extent

        amp = median_filter(amp, median_px, mode="nearest")
    return dem.replace(heights=amp)


def expand_tile(dem: Dem, plan: ExpansionPlan, r0: int, c0: int, width: int, *,
                 progress: bool = False) -> np.ndarray:
    """The expansion of the square ``(r0, c0, width)`` of ``dem`` with ``plan``'s settings
    (the same pixels as that part of the whole region's expansion)."""
    coarser = 0
    if plan.relief is not None:
        coarser = dem.level - plan.relief.level
        amp = np.ascontiguousarray(plan.relief.heights)
        amp_r0, amp_c0 = plan.relief.origin
    elif plan.uniform_m is None:
        amp, amp_r0, amp_c0 = _local_amplitude(dem, r0, c0, width, plan.fallback_m)
    else:
        amp = np.full((1, 1), plan.uniform_m)
        amp_r0, amp_c0 = dem.origin[0] + r0, dem.origin[1] + c0
    return _expand_region(dem.heights, (r0, c0, width), dem.origin, dem.level, plan.levels,
                          plan.key, plan.fractal_dimension, amp, (amp_r0, amp_c0),
                          amp_coarser=coarser, progress=progress)


def _local_amplitude(dem: Dem, r0: int, c0: int, width: int, fallback: float):
    """Local relief sqrt(m(p)) (metres) around the region and its lattice origin.

    NaN (no known neighbour) becomes ``fallback`` metres.

    Covers the region plus the context any level can reach, computed from one more
    pixel of the DEM so that every value equals the whole-DEM value (tiles agree).
    """
    rows, cols = dem.shape
    m = HALO_PX + 1
    a_r, a_c = max(r0 - m, 0), max(c0 - m, 0)
    b_r, b_c = min(r0 + width + m, rows), min(c0 + width + m, cols)
    e_r, e_c = max(a_r - 1, 0), max(a_c - 1, 0)
    z = dem.heights[e_r:min(b_r + 1, rows), e_c:min(b_c + 1, cols)]
    msd = local_msd(z)[a_r - e_r:a_r - e_r + b_r - a_r, a_c - e_c:a_c - e_c + b_c - a_c]
    amp = np.sqrt(msd)
    amp[~np.isfinite(amp)] = fallback
    return (np.ascontiguousarray(amp), dem.origin[0] + a_r, dem.origin[1] + a_c)


def _expand_region(z: np.ndarray, region, origin, level0: int, levels: int, key: int,
                   fractal_dimension: float, amp: np.ndarray, amp_origin, *,
                   amp_coarser: int = 0, progress: bool = False) -> np.ndarray:
    """Expand ``z[region]`` ``levels`` times with ``HALO_PX`` context pixels per level.

    ``region`` is (row_off, col_off, width) in ``z``; ``origin`` the lattice index of
    ``z[0, 0]`` at ``level0``; ``amp`` the displacement amplitude in metres on the
    grid ``amp_coarser`` levels above ``level0``, its pixel (0, 0) at lattice index
    ``amp_origin`` there. Returns the expanded region only.
    """
    from ._expand_kernels import _expand_kernel  # numba: loaded where it runs

    r0, c0, width = region
    rows, cols = z.shape
    a_r, a_c = max(r0 - HALO_PX, 0), max(c0 - HALO_PX, 0)
    b_r, b_c = min(r0 + width + HALO_PX, rows), min(c0 + width + HALO_PX, cols)
    arr = np.ascontiguousarray(z[a_r:b_r, a_c:b_c], dtype=np.float64)
    org = (origin[0] + a_r, origin[1] + a_c)
    reg = (r0 - a_r, c0 - a_c, width)
    for lev in progress_bar(range(1, levels + 1), enabled=progress, desc="expand"):
        # levels from the amplitude's grid: the scale carries 2^(-H) per level from there
        sd_sq, sd_dia = displacement_scales(lev + amp_coarser, fractal_dimension, 1.0)
        out = np.empty((2 * arr.shape[0] - 1, 2 * arr.shape[1] - 1), dtype=np.float64)
        org = (2 * org[0], 2 * org[1])
        _expand_kernel(arr, key, level0 + lev, org[0], org[1], sd_sq, sd_dia, amp,
                       float(amp_origin[0]), float(amp_origin[1]), 0.5**(lev + amp_coarser), out)
        reg = (2 * reg[0], 2 * reg[1], 2 * reg[2] - 1)
        if lev == levels:
            return np.ascontiguousarray(out[reg[0]:reg[0] + reg[2], reg[1]:reg[1] + reg[2]])
        a_r, a_c = max(reg[0] - HALO_PX, 0), max(reg[1] - HALO_PX, 0)
        b_r = min(reg[0] + reg[2] + HALO_PX, out.shape[0])
        b_c = min(reg[1] + reg[2] + HALO_PX, out.shape[1])
        arr = out[a_r:b_r, a_c:b_c]
        if a_r or a_c or b_r < out.shape[0] or b_c < out.shape[1]:
            arr = np.ascontiguousarray(arr)
        org = (org[0] + a_r, org[1] + a_c)
        reg = (reg[0] - a_r, reg[1] - a_c, reg[2])
    raise AssertionError("unreachable")  # pragma: no cover
