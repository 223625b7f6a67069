"""Perlin fBm base shapes (Martin et al. 2014, IV.B)."""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from craters._shared import (
    ParameterError,
    check_finite,
    check_int,
    check_positive,
    normalize_rng,
    progress_bar,
)
from craters._shared.settings import check_declared, declared, setting

from .grid import LatLongGrid

__all__ = ["FBM_PRESETS", "FbmParams", "fbm3", "perlin_fbm", "random_rotation"]

_MAX_OCTAVES = 30
#: Vertices per chunk of :func:`perlin_fbm` (~60 B each while it is computed).
_CHUNK = 1 << 20


def _check_noise_params(octaves, persistence, lacunarity, base):
    """The declared ranges of :class:`FbmParams` and the limits of the noise's numbers."""
    declared_ = declared(FbmParams)
    octaves = declared_["octaves"].check("octaves", octaves)
    persistence = declared_["persistence"].check("persistence", persistence)
    lacunarity = declared_["lacunarity"].check("lacunarity", lacunarity)
    base = check_int("base", base, 0, 255)
    if (octaves - 1) * math.log2(lacunarity) + 10 >= 31:  # in logs: no overflow
        top = 2.0 ** (21 / (octaves - 1))
        raise ParameterError(
            "lacunarity", f"** ({{}} - 1) * 1024 must stay below 2**31 (the noise tiling "
            f"period): lacunarity < {top:.6g} with {octaves} octaves; got {lacunarity!r}",
            see=("octaves",))
    if (octaves - 1) * math.log10(persistence) >= 38:  # the amplitudes' float32 sum
        raise ParameterError(
            "persistence", f"** ({{}} - 1) must stay below 1e38 (the octaves' amplitudes are "
            f"summed in single precision): persistence < {10 ** (38 / (octaves - 1)):.6g} "
            f"with {octaves} octaves; got {persistence!r}", see=("octaves",))
    return octaves, persistence, lacunarity, base


def fbm3(x, y, z, octaves: int = 1, persistence: float = 0.5, lacunarity: float = 2.0,
         base: int = 0) -> np.ndarray:
    """3-D improved Perlin fBm, identical to ``noise.pnoise3`` (vectorised, numba).

    Same permutation table, gradient table, single-precision arithmetic and octave
    normalisation (sum of octaves divided by the sum of their amplitudes) as
    ``noise.pnoise3(x, y, z, octaves, persistence, lacunarity, base=base)``; inputs
    are rounded to float32 as ``pnoise3`` does. ``noise`` reads outside its 512-entry
    table for ``base >= 2``; here the table is periodic, which equals ``noise`` for
    ``base`` 0 and 1 and stays defined up to 255.

    Parameters
    ----------
    x, y, z : array_like
        Coordinates (broadcast together).
    octaves : int
        Number of octaves, 1..30.
    persistence : float
        Amplitude ratio between successive octaves (> 0).
    lacunarity : float
        Frequency ratio between successive octaves (>= 1).
    base : int
        Offset into the permutation table, 0..255.

    Returns
    -------
    float64 array of the broadcast shape, values in about [-1, 1].

    Examples
    --------
    >>> float(fbm3(0.5, 0.25, 0.125, octaves=3))  # noise.pnoise3 gives the same float
    -0.05736129730939865
    """
    octaves, persistence, lacunarity, base = _check_noise_params(
        octaves, persistence, lacunarity, base)
    bx, by, bz = np.broadcast_arrays(np.asarray(x, np.float64), np.asarray(y, np.float64),
                                     np.asarray(z, np.float64))
    shape = bx.shape
    xs = np.ascontiguousarray(bx, dtype=np.float32).ravel()
    ys = np.ascontiguousarray(by, dtype=np.float32).ravel()
    zs = np.ascontiguousarray(bz, dtype=np.float32).ravel()
    if not (np.isfinite(xs).all() and np.isfinite(ys).all() and np.isfinite(zs).all()):
        raise ValueError("`x`, `y`, `z` must be finite (and within float32 range)")
    out = np.empty(xs.shape[0], dtype=np.float64)
    _run_fbm3(xs, ys, zs, octaves, persistence, lacunarity, base, out)
    return out.reshape(shape)


def _run_fbm3(xs, ys, zs, octaves, persistence, lacunarity, base, out):
    """Pick the fast kernel when every |coordinate| <= FAST_LIMIT (same results)."""
    # numba loads here (a scene is described without it: `latlong tile` checks first)
    from ._perlin_kernels import FAST_LIMIT, GRAD3, PERM, _fbm3_fast_kernel, _fbm3_kernel

    fast = xs.size == 0 or max(np.abs(a).max() for a in (xs, ys, zs)) <= FAST_LIMIT
    kernel = _fbm3_fast_kernel if fast else _fbm3_kernel
    kernel(xs, ys, zs, octaves, np.float32(persistence), np.float32(lacunarity), base,
           PERM, GRAD3, out)


def random_rotation(rng=None) -> np.ndarray:
    """A uniformly random 3x3 rotation matrix (QR of a Gaussian matrix, sign-fixed)."""
    rng = normalize_rng(rng)
    q, r = np.linalg.qr(rng.standard_normal((3, 3)))
    q = q * np.sign(np.diag(r))
    if np.linalg.det(q) < 0:
        q[:, 0] = -q[:, 0]
    return q


@dataclasses.dataclass(frozen=True, slots=True)
class FbmParams:
    """Parameters of a Perlin fBm base shape sampled on the unit sphere."""

    frequency: float = setting(1.5, "first-octave frequency on the unit sphere", range=">0")
    """Frequency of the first octave on the unit sphere (cycles per unit length)."""
    octaves: int = setting(10, "number of octaves", range=(1, _MAX_OCTAVES))
    """Number of octaves."""
    persistence: float = setting(0.5, "amplitude ratio per octave", range=">0")
    """Amplitude ratio between successive octaves."""
    lacunarity: float = setting(1.75, "frequency ratio per octave", range=(1.0, None))
    """Frequency ratio between successive octaves."""
    amplitude: float = setting(0.4, "fBm height scale as a fraction of the body radius "
                               "(--amplitude-m, in metres, wins)", range=">=0")
    """Height scale as a fraction of the body radius: heights = amplitude * R * fbm."""
    amplitude_m: float | None = setting(None, "fBm height scale", unit="m", range=">=0",
                                        default_text="the preset's fraction of the radius")
    """Height scale in metres, instead of ``amplitude`` x the radius (a
    :class:`~latlong.Scene` sets it from ``amplitude`` when it is None)."""
    name = "fbm"  # the base shape's name in a scene (not a field)

    def __post_init__(self):
        check_declared(self)
        _check_noise_params(self.octaves, self.persistence, self.lacunarity, 0)


#: The three parameter sets of Martin 2014, Fig. 5 (10 octaves each).
FBM_PRESETS: dict[str, FbmParams] = {
    "fig5a": FbmParams(1.5, 10, 0.5, 1.75),
    "fig5b": FbmParams(2.5, 10, 0.5, 1.5),
    "fig5c": FbmParams(4.0, 10, 0.3, 2.5),
}


def perlin_fbm(grid: LatLongGrid, frequency: float, octaves: int, persistence: float,
               lacunarity: float, amplitude_m: float, *, rng=None, out=None,
               progress: bool = False) -> np.ndarray:
    """Heights (metres) from 3-D Perlin fBm sampled on the unit sphere.

    Each vertex direction ``u`` is rotated by a random rotation, scaled by
    ``frequency`` and shifted by a random offset in [0, 256)^3 (both from ``rng``), and
    ``amplitude_m * fbm3(...)`` is its height. Computed in bounded chunks of vertices
    straight into the result: besides it, the memory used does not grow with the grid.

    Parameters
    ----------
    out : (N,) float64 array, optional
        Written in place and returned (C-contiguous, one value per vertex).
    progress : bool
        A progress bar (log lines off a terminal) over the chunks.

    Examples
    --------
    >>> h = perlin_fbm(LatLongGrid(8), 1.5, 4, 0.5, 2.0, 10.0, rng=0)
    >>> h.shape, bool(np.abs(h).max() <= 10.0)
    ((386,), True)
    """
    if not isinstance(grid, LatLongGrid):
        raise TypeError(f"`grid` must be a LatLongGrid; got {type(grid).__name__}")
    frequency = check_positive("frequency", frequency)
    amplitude_m = check_finite("amplitude_m", amplitude_m)
    octaves, persistence, lacunarity, _ = _check_noise_params(octaves, persistence,
                                                              lacunarity, 0)
    if math.log2(frequency + 256) + (octaves - 1) * math.log2(lacunarity) >= 31:
        top = 2.0 ** 31 / lacunarity ** (octaves - 1) - 256
        raise ParameterError(
            "frequency", f"(+ 256, the random offset) * {{}} ** ({{}} - 1) must stay below "
            f"2**31 (the noise tiling period): frequency < {top:.6g} with lacunarity "
            f"{lacunarity:g} and {octaves} octaves; got "
            f"{frequency!r}", see=("lacunarity", "octaves"))
    if out is None:
        out = np.empty(grid.n_vertices, dtype=np.float64)
    elif not (isinstance(out, np.ndarray) and out.dtype == np.float64
              and out.shape == (grid.n_vertices,) and out.flags.c_contiguous
              and out.flags.writeable):
        raise ValueError(f"`out` must be a writeable C-contiguous float64 array of shape "
                         f"({grid.n_vertices},)")
    rng = normalize_rng(rng)
    rot = random_rotation(rng)
    offset = rng.uniform(0.0, 256.0, size=3)
    # per vertex, so the chunking never changes a value: chunks bound the memory
    for s in progress_bar(range(0, grid.n_vertices, _CHUNK), enabled=progress,
                          desc="base fbm"):
        # explicit sums, not BLAS, so the rounding never depends on the thread count
        uc = grid.unit_vectors_range(s, s + _CHUNK)
        xs, ys, zs = (
            ((uc[:, 0] * rot[a, 0] + uc[:, 1] * rot[a, 1] + uc[:, 2] * rot[a, 2]) * frequency
             + offset[a]).astype(np.float32)
            for a in range(3)
        )
        del uc
        block = out[s:s + _CHUNK]
        _run_fbm3(xs, ys, zs, octaves, persistence, lacunarity, 0, block)
        block *= amplitude_m
    return out
