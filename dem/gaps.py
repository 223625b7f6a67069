"""Outside-in fractal gap filling of DEMs (Martin et al., lunar paper IV.B)."""

from __future__ import annotations

import math

import numpy as np

from craters._shared import about, check_positive

from ._fill_kernels import _fill_gaps_kernel
from ._rng_kernels import key_from_rng
from .core import Dem
from .expansion import midpoint_factor
from .fractal import expansion_fit

__all__ = ["fill_gaps"]


def _step_lengths(dem: Dem) -> np.ndarray:
    """Length of one step in each of the 8 directions, in units of the resolution."""
    dx, dy = dem.pixel_size_m
    r = dem.resolution_m
    diag = math.hypot(dx, dy) / r
    return np.array([diag, dy / r, diag, dx / r, dx / r, diag, dy / r, diag], dtype=np.float64)


def _fill(dem: Dem, sigma_m: float, key: int) -> tuple[np.ndarray, np.ndarray, int]:
    """Filled heights, the wave number of each filled pixel (-1 = known), wave count."""
    z = np.array(dem.heights, dtype=np.float64, copy=True)
    order = np.empty(z.shape, dtype=np.int32)
    n_waves = _fill_gaps_kernel(z, key, dem.level, dem.origin[0], dem.origin[1], sigma_m,
                                _step_lengths(dem), order)
    return z, order, int(n_waves)


def fill_gaps(dem: Dem, roughness: float | None = None, *, rng=None) -> Dem:
    """Fill the unknown (NaN) pixels of ``dem`` with fractal terrain, outside in.

    The paper's algorithm, in waves: all unknown pixels that have the most known
    8-neighbours are filled at once, then the counts are updated and the next wave
    starts, so holes close from their rims inwards. A filled pixel is the
    inverse-distance-weighted average of the nearest known pixel (original or already
    filled) along each of the 8 directions (distances in metres) plus a Gaussian times
    ``roughness * resolution_m``. Known pixels are returned bit for bit. The Gaussian
    of a pixel is keyed by (seed, level, global pixel index), so the result is
    deterministic for an int seed. Work is proportional to the number of unknown pixels
    times the length of the rays across the holes (no global sort).

    Parameters
    ----------
    dem : Dem
        Must have at least one known pixel.
    roughness : float, optional
        Noise scale (m/m, >= 0): the Gaussian's standard deviation is
        ``roughness * resolution_m``. Default: from the known terrain's fBm fit, the
        RMS neighbour slope ``rho`` and Hurst exponent ``H`` (:func:`dem.expansion_fit`):
        ``rho * sqrt(k(H))``, the displacement a midpoint one pixel from its neighbours
        needs to get the known terrain's one-pixel increments (the derivation in
        :mod:`dem.expansion`, ``k(H) = 1 - 2^(H-2) - 2^(2H-3)``).
    rng : int, numpy.random.Generator or None
        Seed of the counter-based randomness.

    Returns
    -------
    Dem
        Without NaN; its history tags record the step.

    Examples
    --------
    >>> z = np.arange(25.0).reshape(5, 5)
    >>> z[1:3, 1:4] = np.nan
    >>> f = fill_gaps(Dem(z, pixel_size_m=1.0), roughness=0.0)
    >>> bool(np.isfinite(f.heights).all()), float(f.heights[0, 0])
    (True, 0.0)
    """
    if not isinstance(dem, Dem):
        raise TypeError(f"`dem` must be a Dem; got {type(dem).__name__}")
    if not dem.known.any():
        raise ValueError("`dem` has no known pixel (all NaN): there is nothing to fill from")
    estimated = roughness is None
    if roughness is None:
        roughness = _known_roughness(dem)
    with about("roughness"):
        roughness = check_positive("roughness", roughness, allow_zero=True)
    with about("rng"):
        key, seed = key_from_rng(rng)
    z, _, n_waves = _fill(dem, roughness * dem.resolution_m, key)
    params = {"roughness": roughness, "estimated": estimated, "key": key,
              "filled_pixels": int((~dem.known).sum()), "waves": n_waves}
    return dem.with_step(z, "dem.fill_gaps", seed, params)


def _known_roughness(dem: Dem) -> float:
    """Default noise scale: ``rho sqrt(k(H))`` of the known terrain (0 if not estimable)."""
    try:
        fit = expansion_fit(dem)
    except ValueError:
        return 0.0
    if not math.isfinite(fit.roughness):
        return 0.0
    return fit.roughness * math.sqrt(midpoint_factor(min(1.0, max(0.0, fit.hurst))))
