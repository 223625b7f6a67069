"""Stamping craters into a 2-D height grid: the primitive that ``dem`` and ``latlong`` reuse.

Grid frame: pixel (row i, column j) has its centre at ``x = j * pixel_size_m``,
``y = i * pixel_size_m`` (metres). For each crater (oldest first):

1. the crater's radial profile: the fresh morphology of the target body
   (:mod:`craters.morphology`: simple bowl to flat floor, central peak, terraces, peak
   ring) evolved by topographic diffusion for the crater's age (:mod:`craters.diffusion`)
   - or to a fixed ``degradation``, the share of the fresh depth removed - as a table of
   heights over [0, ejecta edge];
2. the plane fitted (least squares) to the terrain of the obliterated region
   (r <= R) becomes the crater's base, so craters sit correctly on slopes and on older
   craters; on steep ground the relief is reduced (slope erosion,
   :func:`craters.slope_erosion`) and above ``full_deg`` the crater is erased;
3. inside the (irregular) rim the terrain is replaced by plane + profile; outside, the
   exterior rim and ejecta are added to the terrain, starting from the plane's height
   at the rim (the offset ``plane - terrain`` is sampled at 64 azimuths) and ending on
   the terrain at the ejecta edge; beyond it nothing changes, bit for bit;
4. with roughness, a fractal overlay (2-D gradient-noise fBm, fractal dimension 2.2 by
   default) is added with an amplitude that depends on x = r/R: bowl, wall, ejecta,
   fading linearly to zero at the ejecta edge; the rim radius gets a periodic 1-D
   fractal perturbation (harmonics 2-16, amplitude ~ k^-1.5) of at most
   ``irregularity`` x R.

On more than one numba thread the craters are stamped in parallel waves of craters whose
boxes cannot overlap (:mod:`craters._wave_kernels`): the same bytes as the serial
age-ordered stamp, whatever the thread count.
"""

from __future__ import annotations

import dataclasses
import logging

import numba
import numpy as np

from ._diffusion_kernels import _rim_and_floor, _rim_spectra, _scale_rims
from ._raster_stamp_kernels import _stamp_many_kernel
from ._shared import check_finite, check_positive, check_range, normalize_rng, progress_bar
from ._stamp_kernels import N_RIM, PARALLEL_MIN
from ._wave_kernels import WAVE_MARGIN, _stamp_waves_kernel, _wave_schedule_kernel
from .catalog import make_catalog, sort_oldest_first, validate_catalog
from .diffusion import profile_tables, tau_from_age, tau_from_degradation
from .morphology import EJECTA_EDGE, fresh_morphometry, morphology_class
from .targets import Target, get_target

logger = logging.getLogger(__name__)

__all__ = ["Crater", "Roughness", "StampRequest", "StampingProfiles", "resolve_roughness",
           "rim_perturbations", "rim_perturbations_from_phases", "stamp", "stamp_many",
           "stamp_request", "stamped_after", "stamping_profiles"]

_HARMONICS = np.arange(2, 17)
#: Share of the wall warp a peak-ring basin loses: with the full warp (0.25 R) its ring at
#: half the rim radius came out a lumpy rounded triangle; real rings are near-circular
#: chains of massifs (Baker et al. 2011: ring / rim ~ 0.5 with little scatter).
RING_WARP_CUT = 0.7
_BATCH = 512  # craters per kernel call when a progress bar is shown
# the serial kernel for fewer craters or crater-box pixels than these (or one thread): a
# few ms of work per wave does not pay for its barrier, least of all on a busy machine
WAVE_MIN = 64
WAVE_MIN_PIXELS = 1_000_000


@dataclasses.dataclass(frozen=True, slots=True)
class Crater:
    """One crater on a 2-D grid (grid frame in the module notes)."""

    x_m: float
    """Centre, metres along the columns."""
    y_m: float
    """Centre, metres along the rows."""
    diameter_m: float
    """Rim-crest diameter, metres."""
    degradation: float = 0.0
    """Share of the fresh depth removed (0 = fresh .. 1 = no relief left; before slope
    erosion)."""
    irregularity: float = 0.02
    """Largest rim-radius perturbation as a fraction of the radius (with roughness)."""

    def __post_init__(self):
        check_finite("x_m", self.x_m)
        check_finite("y_m", self.y_m)
        check_positive("diameter_m", self.diameter_m)
        check_range("degradation", self.degradation, 0.0, 1.0)
        check_range("irregularity", self.irregularity, 0.0, 0.3)


@dataclasses.dataclass(frozen=True, slots=True)
class Roughness:
    """Fractal overlay amplitudes as fractions of the crater's (degraded) depth."""

    bowl: float = 0.03
    """Amplitude on the floor (x <= 0.5)."""
    wall: float = 0.06
    """Amplitude on the wall (0.9 <= x <= 1)."""
    ejecta: float = 0.05
    """Amplitude just outside the rim (x = 1.1), fading linearly to 0 at the edge."""
    fractal_dimension: float = 2.2
    """Fractal dimension of the overlay (octave gain 2^(F - 3))."""
    terraces: float = 1.0
    """Irregularity of complex craters' terraces and central peaks, a factor of the
    default wall warp (:func:`craters._stamp_kernels._warp_x`; 0: concentric terraces)."""

    def __post_init__(self):
        for name in ("bowl", "wall", "ejecta"):
            check_range(name, getattr(self, name), 0.0, 1.0)
        check_range("fractal_dimension", self.fractal_dimension, 2.0, 3.0)
        check_range("terraces", self.terraces, 0.0, 2.0)


_NO_ROUGHNESS = Roughness(0.0, 0.0, 0.0, terraces=0.0)


def rim_perturbations(n: int, irregularity, *, rng=None) -> np.ndarray:
    """Periodic 1-D fractal rim perturbations, (n, 64) relative radius changes.

    Sample k of row c is the perturbation at azimuth ``-pi + 2 pi k / 64``; each row is
    a sum of harmonics 2..16 with amplitudes ~ k^-1.5 and random phases, scaled so that
    its largest magnitude is ``irregularity`` (scalar or per row).
    """
    rng = normalize_rng(rng)
    return rim_perturbations_from_phases(
        rng.uniform(0.0, 2 * np.pi, size=(n, _HARMONICS.size)), irregularity)


def rim_perturbations_from_phases(phases, irregularity) -> np.ndarray:
    """:func:`rim_perturbations` of given phases (n, 15) in [0, 2 pi) of the harmonics
    2..16 (row c depends only on ``phases[c]``: for craters drawn from counter words)."""
    phases = np.ascontiguousarray(phases, dtype=np.float64)
    n = phases.shape[0]
    irr = np.broadcast_to(np.asarray(irregularity, dtype=np.float64), (n,))
    amps = _HARMONICS.astype(float) ** -1.5
    # sum_k a_k cos(k theta + phi_k) at theta = -pi + 2 pi j / 64, by an inverse real FFT:
    # the shift by -pi is the factor (-1)^k
    spec = np.zeros((n, N_RIM // 2 + 1), dtype=np.complex128)
    _rim_spectra(phases, (N_RIM / 2) * amps, (-1.0) ** _HARMONICS, _HARMONICS, spec)
    rho = np.fft.irfft(spec, n=N_RIM, axis=1)
    out = np.empty_like(rho)
    _scale_rims(rho, np.ascontiguousarray(irr), out)
    return out


def _check_heights(heights) -> np.ndarray:
    h = np.asarray(heights)
    if h.ndim != 2 or h.size == 0:
        raise ValueError(f"`heights` must be a non-empty 2-D array; got shape {h.shape}")
    h = np.array(h, dtype=np.float64, order="C", copy=True)
    if not np.isfinite(h).all():
        raise ValueError("`heights` must be finite (fill gaps first)")
    return h


def resolve_roughness(roughness) -> tuple[Roughness, bool]:
    """``(overlay amplitudes, irregular rims?)`` for ``roughness`` = True, False/None or a
    :class:`Roughness` (False: no overlay and circular rims, the ideal crater)."""
    if roughness is True:
        return Roughness(), True
    if roughness is False or roughness is None:
        return _NO_ROUGHNESS, False
    if isinstance(roughness, Roughness):
        return roughness, True
    raise TypeError(f"`roughness` must be True, False or a Roughness; got {roughness!r}")


@dataclasses.dataclass(frozen=True)
class StampRequest:
    """A crater catalog and the stamping options shared by every surface (a height grid,
    :func:`stamp_many`; a lat/long body, :func:`latlong.stamp_craters`; a mesh,
    :func:`latlong.mesh.stamp_mesh_craters`), checked once by :func:`stamp_request`."""

    catalog: np.ndarray
    """The catalog, validated, oldest first."""
    roughness: Roughness
    """Overlay amplitudes (zero without roughness)."""
    irregularity: float
    """Largest rim-radius perturbation used (0 without roughness: circular rims)."""
    ejecta_edge: float
    """Ejecta edge in crater radii."""
    slope_erosion: bool
    """Less relief on steep ground."""
    onset_deg: float
    """Slope where the relief starts to shrink, degrees."""
    full_deg: float
    """Slope of no relief (the crater is erased), degrees."""

    @property
    def rough_array(self) -> np.ndarray:
        """Bowl, wall and ejecta amplitudes: the kernels' ``rough``."""
        return np.array([self.roughness.bowl, self.roughness.wall, self.roughness.ejecta])

    def warps(self, prof: StampingProfiles) -> np.ndarray:
        """Each crater's wall warp (the kernels' ``warps``) with this request's roughness
        (0 without roughness: ideal craters)."""
        return prof.warps(self.roughness.terraces)

    @property
    def gain(self) -> float:
        """The overlay's octave gain, 2^(F - 3)."""
        return 2.0 ** (self.roughness.fractal_dimension - 3.0)

    def draws(self, n: int, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
        """The random part of stamping ``n`` craters, in this order: rim perturbations
        (n, 64) and overlay seeds (n,) uint64, from the Generator ``rng``."""
        rim_tabs = rim_perturbations(n, self.irregularity, rng=rng)
        return rim_tabs, rng.integers(0, 2**63, size=n, dtype=np.uint64)


def stamp_request(catalog, *, columns: tuple[str, ...], onto: str, roughness=True,
                  irregularity: float = 0.02, ejecta_edge: float = EJECTA_EDGE,
                  slope_erosion: bool = True, onset_deg: float = 20.0,
                  full_deg: float = 45.0) -> StampRequest:
    """Check a stamping request once (see :func:`stamp_many` for the options): the catalog
    validated and sorted oldest first, with the position ``columns`` stamping ``onto``
    (``"a grid"``, ``"a body"``, ``"a mesh"``) needs; ``ValueError``/``TypeError``
    naming the parameter otherwise."""
    cat = sort_oldest_first(validate_catalog(catalog))
    fields = cat.dtype.names
    assert fields is not None  # validate_catalog: a structured array
    missing = [c for c in columns if c not in fields]
    if missing:
        raise ValueError(f"`catalog` needs {', '.join(columns)} columns to stamp on {onto}; "
                         f"it has no {missing[0]!r}")
    rough, irregular = resolve_roughness(roughness)
    irregularity = check_range("irregularity", irregularity, 0.0, 0.3)
    ejecta_edge = check_range("ejecta_edge", ejecta_edge, 1.5, 20.0)
    onset = check_range("onset_deg", onset_deg, 0.0, 90.0)
    full = check_range("full_deg", full_deg, 0.0, 90.0)
    if slope_erosion and full <= onset:
        raise ValueError(f"`full_deg` must be > onset_deg ({onset}); got {full}")
    return StampRequest(cat, rough, irregularity if irregular else 0.0, ejecta_edge,
                        bool(slope_erosion), onset, full)


@dataclasses.dataclass(frozen=True)
class StampingProfiles:
    """What the stamping kernels need per crater, and what the catalog reports."""

    tables: np.ndarray
    """(n, N_TABLE) heights (metres) over [0, ejecta edge] radii, relative to the plane."""
    depth_m: np.ndarray
    """Rim crest to floor of each table (before slope erosion)."""
    rim_height_m: np.ndarray
    """Rim crest above the surroundings of each table."""
    fresh_depth_m: np.ndarray
    """The fresh crater's depth."""
    tau: np.ndarray
    """Dimensionless diffusion time kappa t / R^2."""
    warp_share: np.ndarray
    """The share of the wall warp a crater gets (:meth:`warps`): 0 simple .. 1 complex
    (:func:`craters.fresh_morphometry`'s ``complex``), less on peak-ring basins
    (``complex - RING_WARP_CUT * ring``: their ring stays a ring)."""
    extra: dict
    """Catalog columns: morphology, floor_diameter_m, peak_height_m, kappa_t_m2."""

    def warps(self, terraces: float) -> np.ndarray:
        """Each crater's wall warp (the kernels' ``warps``, :func:`craters.kernels.warp_x`)
        for the ``terraces`` factor of a :class:`Roughness`."""
        return np.ascontiguousarray(self.warp_share * terraces)


def stamping_profiles(catalog, target: str | Target = "moon", *,
                      ejecta_edge: float = EJECTA_EDGE) -> StampingProfiles:
    """Profile tables of a catalog's craters on ``target`` (module notes, step 1).

    A crater's degradation comes from its age by diffusion when its ``degradation`` is
    NaN (what :func:`craters.population` writes for layers that do not fix it), else the
    given share of the fresh depth is removed (an explicit override; 1 = no relief).
    """
    t = get_target(target)
    cat = np.asarray(catalog)
    names = cat.dtype.names
    d = np.ascontiguousarray(cat["diameter_m"], dtype=np.float64)
    assert names is not None  # cat["diameter_m"] read a field: a structured array
    n = len(d)
    age = cat["age_gyr"] if "age_gyr" in names else np.zeros(n)
    deg = cat["degradation"] if "degradation" in names else np.zeros(n)
    from_age = np.isnan(deg)
    tau = np.zeros(n)
    if from_age.any():
        tau[from_age] = tau_from_age(d[from_age], age[from_age], t)
    if (~from_age).any():
        tau[~from_age] = tau_from_degradation(d[~from_age], deg[~from_age], t,
                                              ejecta_edge=ejecta_edge)
    tabs = np.ascontiguousarray(profile_tables(d, tau, t, ejecta_edge=ejecta_edge))
    rim, floor = np.empty(n), np.empty(n)
    _rim_and_floor(tabs, min(int(np.ceil(1.5 / ejecta_edge * tabs.shape[1])), tabs.shape[1]),
                   min(int(np.ceil(1.2 / ejecta_edge * tabs.shape[1])), tabs.shape[1]),
                   rim, floor)
    fresh = fresh_morphometry(d, t)
    peak = np.where(fresh["complex"] > 0, fresh["peak_height_m"], 0.0)
    kappa_t = tau * (0.5 * d) ** 2
    extra = {"morphology": morphology_class(d, t), "floor_diameter_m": fresh["floor_diameter_m"],
             "peak_height_m": peak, "kappa_t_m2": kappa_t}
    warp = fresh["complex"] - RING_WARP_CUT * fresh["ring"]
    return StampingProfiles(tabs, rim - floor, rim, fresh["depth_m"], tau,
                            np.ascontiguousarray(warp, dtype=np.float64), extra)


def stamp_many(heights, pixel_size_m: float, catalog, *, roughness=True,
               target: str | Target = "moon", ejecta_edge: float = EJECTA_EDGE,
               irregularity: float = 0.02, slope_erosion: bool = True,
               onset_deg: float = 20.0, full_deg: float = 45.0, rng=None,
               progress: bool = False, return_catalog: bool = False):
    """Stamp a catalog of craters (oldest first) into a copy of ``heights``.

    Parameters
    ----------
    heights : (rows, cols) array_like
        Terrain heights in metres (finite); not modified.
    pixel_size_m : float
        Pixel size in metres.
    catalog : structured array
        Columns ``x_m, y_m, diameter_m`` and optionally ``age_gyr`` (stamping order:
        oldest first, and the diffusion time; default 0) and ``degradation`` (NaN: from
        the age; else the share of the fresh depth removed), see :mod:`craters.catalog`.
    roughness : bool or Roughness
        Fractal overlay and irregular rims (True: defaults; False: the ideal crater).
    target : str or Target
        The body (:data:`craters.TARGETS`): crater morphology and diffusivity.
    ejecta_edge : float
        Ejecta edge in crater radii.
    irregularity : float
        Largest rim-radius perturbation as a fraction of the radius (with roughness).
    slope_erosion, onset_deg, full_deg
        Less relief on steep ground (see :func:`craters.slope_erosion`).
    rng
        Seed or Generator for rim shapes and overlay seeds.
    return_catalog : bool
        Also return the catalog of the craters stamped (in stamping order; craters that
        fell on ground steeper than ``full_deg`` are erased by mass wasting, not stamped,
        and left out) with the as-stamped ``degradation`` (share of the fresh depth
        removed, slope erosion included), ``rim_radius_m``, ``depth_m``,
        ``rim_height_m``, ``slope_deg``, ``seed``, ``morphology`` (simple, transitional,
        complex, peak-ring), ``floor_diameter_m``, ``peak_height_m`` (fresh) and
        ``kappa_t_m2`` (diffusivity x time).

    Returns
    -------
    new heights (float64), and the stamped catalog if ``return_catalog``.
    """
    h = _check_heights(heights)
    pixel = check_positive("pixel_size_m", pixel_size_m)
    req = stamp_request(catalog, columns=("x_m", "y_m"), onto="a grid", roughness=roughness,
                        irregularity=irregularity, ejecta_edge=ejecta_edge,
                        slope_erosion=slope_erosion, onset_deg=onset_deg, full_deg=full_deg)
    cat, ejecta_edge, onset, full = req.catalog, req.ejecta_edge, req.onset_deg, req.full_deg
    rng = normalize_rng(rng)
    n = len(cat)
    names = cat.dtype.names
    assert names is not None  # stamp_request validated the catalog: a structured array
    prof = stamping_profiles(cat, target, ejecta_edge=ejecta_edge)
    rim_tabs, seeds = req.draws(n, rng)
    cx = np.ascontiguousarray(cat["x_m"] / pixel, dtype=np.float64)
    cy = np.ascontiguousarray(cat["y_m"] / pixel, dtype=np.float64)
    diam = np.ascontiguousarray(cat["diameter_m"], dtype=np.float64)
    scale, slope = np.ones(n), np.zeros(n)
    erased = np.zeros(n, dtype=np.bool_)
    rough_arr, gain = req.rough_array, req.gain
    _stamp_all((h, pixel, cx, cy, diam, prof.tables, prof.depth_m, req.warps(prof), rim_tabs,
                seeds, ejecta_edge, bool(slope_erosion), onset, full, rough_arr, gain, scale,
                slope, erased), progress)
    if erased.any():
        logger.info("%d of %d craters fell on ground steeper than %g deg and were erased",
                    int(erased.sum()), n, full)
    if not return_catalog:
        return h
    cols = {k: cat[k] for k in names}
    cols.update(as_stamped(prof, scale, diam), slope_deg=slope, seed=seeds)
    return h, make_catalog(**cols)[~erased]


def _stamp_all(args: tuple, progress: bool) -> None:
    """Run the stamping kernel on ``args`` (its arguments, full arrays): in parallel waves
    when there are threads and enough craters and pixels to pay for them, else the
    serial kernel (in batches of :data:`_BATCH` craters behind a progress bar)."""
    (h, pixel, cx, cy, diam, tables, depth, warps, rim_tabs, seeds, ejecta_edge, erosion, onset,
     full, rough, gain, scale, slope, erased) = args
    n = len(cx)
    if numba.get_num_threads() > 1 and n >= WAVE_MIN:
        reach = _crater_reach_px(pixel, diam, rim_tabs, ejecta_edge)
        cost = _box_pixels(h.shape[0], cy, reach) * _box_pixels(h.shape[1], cx, reach)
        if cost.sum() >= WAVE_MIN_PIXELS:
            _stamp_in_waves(args, reach, cost, progress)
            return
    step = _BATCH if progress else max(n, 1)
    for s in progress_bar(range(0, n, step), enabled=progress, desc="craters"):
        e = min(s + step, n)
        _stamp_many_kernel(h, pixel, cx[s:e], cy[s:e], diam[s:e], tables[s:e], depth[s:e],
                           warps[s:e], rim_tabs[s:e], seeds[s:e], ejecta_edge, erosion, onset,
                           full, rough, gain, scale[s:e], slope[s:e], erased[s:e])


def _crater_reach_px(pixel_size_m: float, diameter_m, rim_tabs, ejecta_edge: float) -> np.ndarray:
    """Reach of each crater in pixels: ejecta edge x largest rim radius, plus one pixel
    (the half-width of the box :func:`stamp_many` reads and writes)."""
    rho = np.maximum(rim_tabs.max(axis=1, initial=0.0), 0.0)
    return ejecta_edge * (0.5 * np.asarray(diameter_m)) * (1.0 + rho) / pixel_size_m + 1.0


def _wave_schedule(shape, cy, cx, reach) -> tuple[np.ndarray, int, int]:
    """Parallel waves of craters stamped in the given order on a raster of ``shape``:
    ``(wave per crater, number of waves, cell size in pixels)``.

    Centres ``cy, cx`` and ``reach`` in pixels (:func:`_crater_reach_px`). A crater's wave
    is one more than the latest wave of the earlier craters whose boxes (plus a margin)
    share a cell with its own (:mod:`craters._wave_kernels`), so craters of one wave never
    overlap and each comes after every earlier crater it overlaps. Cells: a quarter of
    the median box side (at least 4 pixels, at most 4 M cells in all): small craters touch
    about 25 cells, and craters that share a cell without overlapping (a later wave than
    needed) are few: 10 000 craters of 8-200 m on 4097^2 pixels take 28 waves (42 with
    cells of the median box, 26 with exact box overlaps) for a schedule of a few ms.
    """
    ny, nx = int(shape[0]), int(shape[1])
    n = len(cy)
    side = 2.0 * np.median(reach) + 2 * WAVE_MARGIN + 1 if n else 16.0
    cell = int(max(side / 4.0, 4.0, np.ceil(np.sqrt(ny * nx / 4.0e6))))
    wave = np.zeros(n, dtype=np.int64)
    n_waves = _wave_schedule_kernel(ny, nx, np.ascontiguousarray(cy, dtype=np.float64),
                                    np.ascontiguousarray(cx, dtype=np.float64),
                                    np.ascontiguousarray(reach, dtype=np.float64), cell, wave)
    return wave, int(n_waves), cell


def _box_pixels(n: int, c: np.ndarray, reach: np.ndarray) -> np.ndarray:
    """Pixels along one axis of the crater boxes (``_crater_box``), 0 off the raster."""
    lo = np.maximum(np.floor(c - reach), 0.0)
    hi = np.minimum(np.ceil(c + reach), n - 1.0)
    return np.maximum(hi - lo + 1.0, 0.0)


def _stamp_in_waves(args, reach, cost, progress: bool) -> None:
    """Stamp in parallel waves (:mod:`craters._wave_kernels`): the serial kernel's heights
    and outputs, bit for bit. ``args``: the serial kernel's arguments (full arrays);
    ``reach`` (:func:`_crater_reach_px`) and ``cost`` (box pixels) per crater."""
    h, cx, cy = args[0], args[2], args[3]
    n = len(cx)
    wave, n_waves, cell = _wave_schedule(h.shape, cy, cx, reach)
    alone = cost >= PARALLEL_MIN
    order = np.lexsort((-cost, wave))  # by wave, the costliest first
    starts = np.searchsorted(wave[order], np.arange(n_waves + 1))
    chunks = np.linspace(0, n_waves, min(n_waves, 100 if progress else 1) + 1).astype(int)
    bar = progress_bar(total=n, enabled=progress, desc="craters")
    try:
        for w0, w1 in zip(chunks[:-1], chunks[1:], strict=True):
            _stamp_waves_kernel(order, starts[w0:w1 + 1], alone, numba.get_num_threads(),
                                *args)
            bar.update(int(starts[w1] - starts[w0]))
    finally:
        bar.close()
    logger.debug("%d craters in %d waves (cells of %d px; %d waves of one; %d craters of "
                 ">= %d px alone)", n, n_waves, cell, int((np.diff(starts) == 1).sum()),
                 int(alone.sum()), PARALLEL_MIN)


def as_stamped(prof: StampingProfiles, scale: np.ndarray, diameter_m: np.ndarray) -> dict:
    """The catalog columns of craters stamped from ``prof`` with slope-erosion factors
    ``scale``: degradation (share of the fresh depth removed), rim radius, depth, rim
    height and the morphology columns."""
    depth = prof.depth_m * scale
    degradation = np.clip(1.0 - depth / prof.fresh_depth_m, 0.0, 1.0)
    return {"degradation": degradation, "rim_radius_m": diameter_m / 2.0, "depth_m": depth,
            "rim_height_m": prof.rim_height_m * scale, **prof.extra}


def stamped_after(previous, stamped: np.ndarray) -> np.ndarray:
    """A surface's crater catalog after stamping: its ``previous`` craters (if any) then
    the ``stamped`` ones, or only the stamped ones when the previous catalog has other
    columns (logged)."""
    if previous is None or not len(previous):
        return stamped
    try:
        return np.concatenate([previous, stamped.astype(previous.dtype)])
    except (TypeError, ValueError):
        logger.warning("previous crater catalog has other columns; keeping only the new")
        return stamped


def stamp(heights, pixel_size_m: float, crater: Crater, *, roughness=True, rng=None,
          **kwargs) -> np.ndarray:
    """Stamp one :class:`Crater` into a copy of ``heights`` (see :func:`stamp_many`).

    Examples
    --------
    >>> h = stamp(np.zeros((101, 101)), 20.0, Crater(1000.0, 1000.0, 1000.0),
    ...           roughness=False)
    >>> round(float(h[50, 50]), 1), round(float(h.max()), 1)
    (-160.0, 36.1)
    """
    if not isinstance(crater, Crater):
        raise TypeError(f"`crater` must be a Crater; got {type(crater).__name__}")
    cat = make_catalog(x_m=[crater.x_m], y_m=[crater.y_m], diameter_m=[crater.diameter_m],
                       degradation=[crater.degradation])
    return stamp_many(heights, pixel_size_m, cat, roughness=roughness, rng=rng,
                      irregularity=crater.irregularity, **kwargs)

