"""Poisson faulting base shapes (Martin, Parkes, Dunstan & Rowell 2014, IV.A)."""

from __future__ import annotations

import dataclasses
import logging

import numpy as np

from craters._shared import ParameterError, check_int, check_positive, normalize_rng, progress_bar
from craters._shared.settings import check_declared, setting

from .grid import LatLongGrid
from .smoothing import check_smooth_width, smooth

__all__ = [
    "FAULTING_PRESETS",
    "FaultingParams",
    "apply_faults",
    "area_mean",
    "poisson_faulting",
    "random_faults",
    "two_phase_faulting",
]

logger = logging.getLogger(__name__)

# faults per kernel call when a progress bar is shown (the result does not depend on it)
_CHUNK = 2000


def _check_grid(grid) -> LatLongGrid:
    if not isinstance(grid, LatLongGrid):
        raise TypeError(f"`grid` must be a LatLongGrid; got {type(grid).__name__}")
    return grid


def area_mean(grid: LatLongGrid, values) -> float:
    """Area-weighted mean of a per-vertex field over the sphere."""
    w = grid.vertex_areas()
    from craters.exact import dot

    return dot(w, values) / float(w.sum())


def apply_faults(grid: LatLongGrid, normals, heights, *, progress: bool = False) -> np.ndarray:
    """Sum of fault offsets at every vertex: ``h_i = sum_f heights[f] [u_i . n_f > 0]``.

    Exact (the sign test is the definition) and computed ring by ring in
    O(F * M + N): on each latitude ring a fault's half-space is one arc of longitude
    with closed-form ends (DESIGN §4), accumulated in a difference array.

    Parameters
    ----------
    grid : LatLongGrid
    normals : (F, 3) array_like
        Fault plane normals (any non-zero length; only the direction matters).
    heights : (F,) array_like
        Fault offsets in metres.
    progress : bool
        Show a progress bar over chunks of faults.

    Returns
    -------
    (N,) float64 array of heights in metres.

    Examples
    --------
    >>> g = LatLongGrid(4)
    >>> h = apply_faults(g, [[0.0, 0.0, 1.0]], [2.0])
    >>> float(h[0]), float(h[-1])   # north pole raised, south pole not
    (2.0, 0.0)
    """
    grid = _check_grid(grid)
    normals = np.ascontiguousarray(normals, dtype=np.float64)
    heights = np.ascontiguousarray(heights, dtype=np.float64)
    if normals.ndim != 2 or normals.shape[1] != 3:
        raise ValueError(f"`normals` must have shape (F, 3); got {normals.shape}")
    if heights.shape != (normals.shape[0],):
        raise ValueError(f"`heights` must have shape ({normals.shape[0]},); got {heights.shape}")
    if not (np.isfinite(normals).all() and np.isfinite(heights).all()):
        raise ValueError("`normals` and `heights` must be finite")
    if normals.shape[0] and (np.abs(normals).max(axis=1) == 0).any():
        raise ValueError("`normals` must be non-zero vectors")
    out = np.zeros(grid.n_vertices, dtype=np.float64)
    if normals.shape[0] == 0:
        return out
    lon0 = np.arctan2(normals[:, 1], normals[:, 0])
    horiz = np.hypot(normals[:, 0], normals[:, 1])
    colat = grid.ring_colatitudes()
    ring_cos = np.ascontiguousarray(np.cos(colat))
    ring_sin = np.ascontiguousarray(np.sin(colat))
    ring_cos[0], ring_cos[-1] = 1.0, -1.0
    ring_sin[0] = ring_sin[-1] = 0.0
    unit = grid.unit_vectors()
    offs = grid.ring_offsets()
    n = normals.shape[0]
    chunk = _CHUNK if progress else n
    bar = progress_bar(range(0, n, chunk), enabled=progress, desc="faults")
    from ._fault_kernels import _apply_faults_kernel  # numba loads here

    for s in bar:
        e = min(s + chunk, n)
        _apply_faults_kernel(offs, ring_cos, ring_sin, unit, normals[s:e], lon0[s:e],
                             horiz[s:e], heights[s:e], out)
    return out


def random_faults(n_faults: int, max_fault_m: float, *, rng=None):
    """Draw ``n_faults`` random faults: uniform unit normals and Gaussian offsets.

    Normals are normalised standard-normal 3-vectors (uniform on the sphere). Offsets
    are ``max_fault_m * g / 3`` with ``g`` a standard normal truncated to |g| <= 3 (by
    redrawing), so ``max_fault_m`` is the largest possible offset and the standard
    deviation is about a third of it.

    Returns
    -------
    normals : (F, 3) float64, heights : (F,) float64 (metres)
    """
    n_faults = check_int("n_faults", n_faults, 0, 100_000_000)
    max_fault_m = check_positive("max_fault_m", max_fault_m, allow_zero=True)
    rng = normalize_rng(rng)
    normals = rng.standard_normal((n_faults, 3))
    norm = np.linalg.norm(normals, axis=1)
    bad = norm < 1e-12
    while bad.any():  # vanishingly rare: redraw degenerate directions
        normals[bad] = rng.standard_normal((int(bad.sum()), 3))
        norm = np.linalg.norm(normals, axis=1)
        bad = norm < 1e-12
    normals /= norm[:, None]
    g = rng.standard_normal(n_faults)
    out = np.abs(g) > 3.0
    while out.any():
        g[out] = rng.standard_normal(int(out.sum()))
        out = np.abs(g) > 3.0
    return normals, max_fault_m * g / 3.0


def poisson_faulting(grid: LatLongGrid, n_faults: int, max_fault_m: float, *, rng=None,
                     progress: bool = False) -> np.ndarray:
    """Heights (metres) from ``n_faults`` random faults, area-weighted mean removed.

    See :func:`random_faults` for the fault distribution and :func:`apply_faults` for
    the (exact, O(F M + N)) evaluation.

    Examples
    --------
    >>> h = poisson_faulting(LatLongGrid(8), 100, 1.0, rng=0)
    >>> h.shape, abs(area_mean(LatLongGrid(8), h)) < 1e-12
    ((386,), True)
    """
    grid = _check_grid(grid)
    normals, heights = random_faults(n_faults, max_fault_m, rng=rng)
    h = apply_faults(grid, normals, heights, progress=progress)
    h -= area_mean(grid, h)
    return h


@dataclasses.dataclass(frozen=True, slots=True)
class FaultingParams:
    """Parameters of two-phase Poisson faulting (Martin et al. 2014, IV.A)."""

    n_faults_1: int = setting(1000, "phase-1 fault count", key="faults_1",
                              range=(0, 100_000_000))
    """Faults in phase 1 (large faults: the overall lumpy form)."""
    max_fault_1_m: float = setting(5.0, "largest phase-1 fault offset", unit="m", range=">=0")
    """Largest phase-1 fault offset, metres."""
    smooth_width_m: float = setting(20.0, "smoothing filter width (Gaussian FWHM)", unit="m",
                                    range=">=0")
    """Smoothing filter width between the phases (Gaussian FWHM, metres on the body)."""
    smooth_passes: int = setting(3, "smoothing passes", range=(0, 1000))
    """Number of smoothing passes (0 = no smoothing)."""
    n_faults_2: int = setting(20000, "phase-2 fault count", key="faults_2",
                              range=(0, 100_000_000))
    """Faults in phase 2 (small faults: surface roughness)."""
    max_fault_2_m: float = setting(0.03, "largest phase-2 fault offset", unit="m", range=">=0")
    """Largest phase-2 fault offset, metres."""
    stretch: tuple[float, float, float] = (1.0, 1.0, 1.0)
    """Final stretch of the body along x, y, z (applied by :class:`~latlong.Body`; in a
    :class:`~latlong.Scene` the body's stretch, which this one gives by default)."""
    name = "faulting"  # the base shape's name in a scene (not a field)

    def __post_init__(self):
        check_declared(self)
        if isinstance(self.stretch, str) or len(self.stretch) != 3:
            raise ParameterError("stretch", f"must have three factors; got {self.stretch!r}")
        object.__setattr__(self, "stretch",
                           tuple(check_positive("stretch", v) for v in self.stretch))


#: Named parameter sets, both stretched 2x along x. ``paper``: the asteroid of Martin
#: 2014 IV.A (the CLI gives these presets a 100 m radius); ``fig4``: the three stages of
#: Fig. 4 (500 faults <= 0.5 m in phase 2).
FAULTING_PRESETS: dict[str, FaultingParams] = {
    "paper": FaultingParams(1000, 5.0, 20.0, 3, 20000, 0.03, (2.0, 1.0, 1.0)),
    "fig4": FaultingParams(1000, 5.0, 20.0, 3, 500, 0.5, (2.0, 1.0, 1.0)),
}


def two_phase_faulting(grid: LatLongGrid, radius_m: float, params: FaultingParams | None = None,
                       *, rng=None, progress: bool = False) -> np.ndarray:
    """Two-phase Poisson faulting: large faults, smoothing, small faults.

    Phase 1 applies ``params.n_faults_1`` faults of at most ``max_fault_1_m``; the
    result is smoothed ``smooth_passes`` times with a geodesic Gaussian of FWHM
    ``smooth_width_m`` on a sphere of ``radius_m``; phase 2 adds ``n_faults_2`` faults of
    at most ``max_fault_2_m``. Returns heights in metres with zero area-weighted mean;
    the final stretch ``params.stretch`` is a property of the body:
    ``Body.from_heights(grid, radius_m, h, stretch=params.stretch)``.

    Examples
    --------
    >>> p = FaultingParams(50, 2.0, 10.0, 1, 50, 0.1)
    >>> h = two_phase_faulting(LatLongGrid(8), 50.0, p, rng=1)
    >>> h.shape
    (386,)
    """
    grid = _check_grid(grid)
    radius_m = check_positive("radius_m", radius_m)
    params = FAULTING_PRESETS["paper"] if params is None else params
    if not isinstance(params, FaultingParams):
        raise TypeError(f"`params` must be a FaultingParams; got {type(params).__name__}")
    if params.smooth_passes:
        check_smooth_width(params.smooth_width_m, radius_m, params.smooth_passes,
                           "smooth_width_m")
    rng = normalize_rng(rng)
    h = poisson_faulting(grid, params.n_faults_1, params.max_fault_1_m, rng=rng,
                         progress=progress)
    if params.smooth_passes and params.smooth_width_m > 0:
        h = smooth(grid, h, params.smooth_width_m, radius_m=radius_m,
                   passes=params.smooth_passes)
    h += poisson_faulting(grid, params.n_faults_2, params.max_fault_2_m, rng=rng,
                          progress=progress)
    return h
