"""3-D Gabor noise for surface micro-detail (Li et al. 2020 §3.2; Lagae et al. 2009;
Galerne et al. 2012 "Gabor noise by example").

Sparse convolution: impulses at the points of a 3-D Poisson process (density lambda per
m^3) near the surface, each carrying one Gabor kernel

    g(x) = K exp(-pi a^2 |x|^2) cos(2 pi w . x + phi)

with bandwidth ``a`` (1/m), frequency vector ``w`` (cycles/m) in the tangent plane of the
coarse surface at the impulse (``w = f (cos t east + sin t north)``, east/north the
local frame with north towards +z; ``t`` a fixed orientation or uniform per impulse),
and a uniform random phase ``phi``. A noise is a mixture of *patches* (f, a, t,
variance share): each impulse picks a patch with probability = its share and gets
``K = sqrt(2 V (2 a^2)^(3/2) / lambda)``, so that the point variance of the noise,
``lambda sum_p share_p K_p^2 / 2 (2 a_p^2)^(-3/2)``, equals ``V = amplitude_m^2``.
The kernel is cut where its envelope is below 1e-3. A 2-D section through the 3-D
noise has the power spectrum of the patches (Gaussians of width ``a`` at ``+-w``), so a
fit to a 2-D example carries over to the surface.

By example (:func:`fit_gabor`): the example's periodogram (Hann window) is
block-averaged to at most 96 x 96 frequencies and written, by non-negative least
squares (``scipy.optimize.nnls``), as a sum of Gaussian power patches
``exp(-2 pi |k -+ mu|^2 / a^2)`` over a polar grid of centres ``mu`` (frequency x
orientation, plus one at 0) and a few quantised bandwidths; the non-zero weights
become the patches. Image convention: ``image[i, j]`` is the height at ``x = j``,
``y = i`` pixels; orientations are measured from +x towards +y (east towards north).
"""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np

from craters._shared import (
    check_choice,
    check_int,
    check_positive,
    check_range,
    normalize_rng,
    parse_spec,
)
from craters._shared.files import check_regular_file
from craters.exact import abs2

from . import _kernels as _k
from .grid import VoxelGrid

__all__ = ["GaborNoise", "GaborPatch", "add_gabor", "fit_gabor", "gabor_image",
           "gabor_impulses", "parse_gabor_spec", "power_spectrum", "read_example"]

_EPS = 1e-3
_CUTOFF2 = math.log(1.0 / _EPS) / math.pi  # envelope < EPS beyond r^2 a^2 = this


@dataclasses.dataclass(frozen=True, slots=True)
class GaborPatch:
    """One Gaussian patch of the power spectrum."""

    frequency: float
    """|w|, cycles per metre (>= 0)."""
    bandwidth: float
    """a, 1/m (> 0): envelope exp(-pi a^2 |x|^2); spectrum width."""
    orientation_deg: float | None = None
    """Direction of w from east towards north, degrees; None = uniform per impulse."""
    weight: float = 1.0
    """Share of the variance (relative to the other patches), > 0."""

    def __post_init__(self):
        check_positive("frequency", self.frequency, allow_zero=True)
        check_positive("bandwidth", self.bandwidth)
        if self.orientation_deg is not None:
            check_range("orientation_deg", self.orientation_deg, -360.0, 360.0)
        check_positive("weight", self.weight)


@dataclasses.dataclass(frozen=True, slots=True)
class GaborNoise:
    """A Gabor noise: patches, rms amplitude and impulse density."""

    patches: tuple[GaborPatch, ...]
    """The spectrum's patches (at least one)."""
    amplitude_m: float
    """Root-mean-square height of the noise, metres (>= 0)."""
    density: float = 4.0
    """Impulses per cube of side 1/a (a = the share-weighted mean bandwidth); about
    13.6 x density impulses overlap at every point."""

    def __post_init__(self):
        if not self.patches or not all(isinstance(p, GaborPatch) for p in self.patches):
            raise ValueError("`patches` must be a non-empty tuple of GaborPatch")
        check_positive("amplitude_m", self.amplitude_m, allow_zero=True)
        check_range("density", self.density, 0.1, 1000.0)

    @classmethod
    def single(cls, frequency: float, bandwidth: float, amplitude_m: float, *,
               orientation_deg: float | None = None, density: float = 4.0) -> GaborNoise:
        """One patch: frequency (cycles/m), bandwidth (1/m), orientation (None = any)."""
        return cls((GaborPatch(frequency, bandwidth, orientation_deg),), amplitude_m, density)

    @property
    def shares(self) -> np.ndarray:
        w = np.array([p.weight for p in self.patches])
        return w / w.sum()

    @property
    def impulse_density(self) -> float:
        """Impulses per m^3."""
        a = float(np.dot(self.shares, [p.bandwidth for p in self.patches]))
        return self.density * a**3

    def describe(self) -> dict:
        return {"amplitude_m": self.amplitude_m, "density": self.density,
                "patches": [dataclasses.asdict(p) for p in self.patches]}


def parse_gabor_spec(spec: str) -> GaborNoise:
    """Parse ``frequency=0.01,bandwidth=0.005,amplitude_m=2[,orientation_deg=30,density=4]``
    (cycles/m, 1/m, m, degrees): the arguments of :meth:`GaborNoise.single`.

    Examples
    --------
    >>> spec = "frequency=0.02,bandwidth=0.01,amplitude_m=1.5"
    >>> parse_gabor_spec(spec).patches[0].orientation_deg is None
    True
    """
    items = {"frequency": float, "bandwidth": float, "amplitude_m": float,
             "orientation_deg": float, "density": float}
    values = parse_spec(spec, items, ("frequency", "bandwidth", "amplitude_m"), "Gabor spec",
                        renamed={"f": "frequency", "bw": "bandwidth", "amp": "amplitude_m",
                                 "orient": "orientation_deg"})
    try:
        return GaborNoise.single(**values)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"Gabor spec {spec!r}: {exc}") from None


_MAX_CELLS = 5e8  # cells listed (a million at a time) for one noise
_MAX_IMPULSES = 3e7  # impulses of one noise (~100 B each, plus the grid work)


# --------------------------------------------------------------------------- impulses
def _draw(noise: GaborNoise, lo, hi, rng, keep=None):
    """Poisson impulses in the boxes of side s covering [lo, hi] (optionally filtered)."""
    a_min = min(p.bandwidth for p in noise.patches)
    s = math.sqrt(_CUTOFF2) / a_min  # the widest kernel's cut-off radius
    n_cells = np.maximum(np.ceil((np.asarray(hi) - np.asarray(lo)) / s).astype(np.int64), 1)
    total = int(np.prod(n_cells.astype(float)))
    lam = noise.impulse_density
    if total > _MAX_CELLS:
        raise ValueError(f"Gabor noise: bandwidth {a_min:.3g} 1/m makes {total:.3g} cells of "
                         f"{s:.3g} m over the region (limit {_MAX_CELLS:.0e}); lower the "
                         "bandwidth (wider impulses)")
    corners = []
    for start in range(0, total, 1 << 20):  # listed a million cells at a time
        k, j, i = np.unravel_index(np.arange(start, min(start + (1 << 20), total)),
                                   n_cells[::-1])
        corner = np.asarray(lo) + np.stack([i, j, k], axis=1) * s
        corners.append(corner if keep is None else corner[keep(corner + 0.5 * s, s)])
    corner = np.concatenate(corners)
    expected = lam * s**3 * len(corner)
    if expected > _MAX_IMPULSES:
        raise ValueError(f"Gabor noise: about {expected:.3g} impulses (limit "
                         f"{_MAX_IMPULSES:.0e}); lower the bandwidth or the density")
    counts = rng.poisson(lam * s**3, len(corner))
    n = int(counts.sum())
    pos = np.repeat(corner, counts, axis=0) + rng.random((n, 3)) * s
    shares = noise.shares
    which = rng.choice(len(shares), n, p=shares) if len(shares) > 1 else np.zeros(n, np.int64)
    phase = rng.random(n) * 2.0 * math.pi
    theta = rng.random(n) * 2.0 * math.pi
    freq = np.array([p.frequency for p in noise.patches])[which]
    band = np.array([p.bandwidth for p in noise.patches])[which]
    fixed = np.array([math.nan if p.orientation_deg is None else math.radians(p.orientation_deg)
                      for p in noise.patches])[which]
    theta = np.where(np.isnan(fixed), theta, fixed)
    var = noise.amplitude_m**2
    amp = np.sqrt(2.0 * var * (2.0 * band**2) ** 1.5 / lam)
    return {"pos": np.ascontiguousarray(pos), "env": band, "amp": amp, "phase": phase,
            "freq": freq, "theta": theta, "cutoff2": _CUTOFF2,
            "reach": math.sqrt(_CUTOFF2) / band}


def _frames(normals: np.ndarray):
    """Local (east, north) unit vectors for outward normals; north towards +z (towards
    +x at the poles, where |n_z| > 0.999)."""
    n = normals / np.maximum(np.linalg.norm(normals, axis=1, keepdims=True), 1e-300)
    ref = np.zeros_like(n)
    polar = np.abs(n[:, 2]) > 0.999
    ref[~polar, 2] = 1.0
    ref[polar, 0] = 1.0
    north = ref - (ref * n).sum(axis=1, keepdims=True) * n
    north /= np.linalg.norm(north, axis=1, keepdims=True)
    return np.cross(north, n), north


def _waves(d: dict, east: np.ndarray, north: np.ndarray) -> np.ndarray:
    """Frequency vectors f (cos t east + sin t north) of the impulses."""
    c, s = np.cos(d["theta"])[:, None], np.sin(d["theta"])[:, None]
    return np.ascontiguousarray(d["freq"][:, None] * (c * east + s * north))


def gabor_impulses(noise: GaborNoise, base: np.ndarray, grid: VoxelGrid, reach_m: float,
                   rng) -> dict:
    """Impulses within reach_m (+ the kernel radius) of the coarse surface ``base``
    (signed distance on ``grid``, metres), with tangent frames from its gradient.
    ``rng``: a Generator. Returns arrays for :func:`add_gabor` (``pos``, ``wave``,
    ``env``, ``amp``, ``phase``, ``reach``) and ``cutoff2``."""
    rho = math.sqrt(_CUTOFF2) / min(p.bandwidth for p in noise.patches)
    inner = base > -(reach_m + rho)
    # the index box of ``inner`` from its projections (np.argwhere would list most of
    # the grid's points)
    ends = [np.flatnonzero(inner.any(axis=tuple(a for a in range(3) if a != axis)))
            for axis in range(3)]
    if not ends[0].size:
        raise ValueError("no grid point lies near the coarse surface")
    lo = grid.origin + np.array([e[0] for e in ends])[::-1] * grid.h
    hi = grid.origin + np.array([e[-1] for e in ends])[::-1] * grid.h

    def keep(centres, s):
        return np.abs(grid.sample(base, centres)) < reach_m + rho + s * math.sqrt(3) / 2

    d = _draw(noise, lo, hi, rng, keep)
    normals = -grid.gradient(base, d["pos"]) if len(d["pos"]) else np.zeros((0, 3))
    d["wave"] = _waves(d, *_frames(normals))
    return d


def add_gabor(impulses: dict, grid: VoxelGrid, base: np.ndarray, band_m: float,
              out: np.ndarray) -> None:
    """Add the impulses' Gabor kernels (:func:`gabor_impulses`) to ``out`` (a field on
    ``grid``) at the grid points where ``|base| < band_m``."""
    d = impulses
    lo_i, hi_i = grid.index_boxes(d["pos"], d["reach"])
    nbins, offsets, items, active = grid.bins(lo_i, hi_i)
    _k._gabor_grid_kernel(grid.origin, grid.h, active, grid.bin_size, nbins, offsets, items,
                          lo_i, hi_i, d["pos"], d["wave"], d["env"], d["amp"], d["phase"],
                          d["cutoff2"], base, band_m, out)


def gabor_image(noise: GaborNoise, shape, pixel_m: float, *, rng=None) -> np.ndarray:
    """A plane section (z = 0, normal +z, east = +x, north = +y) of the 3-D noise,
    sampled at ``shape`` = (rows, cols) pixels of ``pixel_m`` metres (image[i, j] at
    x = j, y = i pixels). Metres.

    Examples
    --------
    >>> img = gabor_image(GaborNoise.single(0.05, 0.02, 1.0), (64, 64), 1.0, rng=0)
    >>> img.shape, bool(0.5 < img.std() < 1.5)
    ((64, 64), True)
    """
    if not isinstance(noise, GaborNoise):
        raise TypeError(f"`noise` must be a GaborNoise; got {type(noise).__name__}")
    ny, nx = (check_int("shape", v, 1, 1 << 14) for v in shape)
    pixel_m = check_positive("pixel_m", pixel_m)
    rng = normalize_rng(rng)
    rho = math.sqrt(_CUTOFF2) / min(p.bandwidth for p in noise.patches)
    lo = np.array([-rho, -rho, -rho])
    hi = np.array([(nx - 1) * pixel_m + rho, (ny - 1) * pixel_m + rho, rho])
    d = _draw(noise, lo, hi, rng)
    n = len(d["pos"])
    d["wave"] = _waves(d, np.tile([1.0, 0.0, 0.0], (n, 1)), np.tile([0.0, 1.0, 0.0], (n, 1)))
    grid = VoxelGrid(np.zeros(3), pixel_m, (1, ny, nx))
    out = np.zeros((1, ny, nx))
    if len(d["pos"]):
        add_gabor(d, grid, np.zeros_like(out), np.inf, out)
    return out[0]


# --------------------------------------------------------------------------- by example
def read_example(path) -> tuple[np.ndarray, bool]:
    """An example for :func:`fit_gabor`: ``.npy`` (a 2-D array of heights, metres) or a
    picture (``.png``, ``.jpg``, ``.tif``: grey levels 0-1). Returns (image, is_heights).
    """
    path = Path(path)
    check_regular_file(path, "example")
    suffix = path.suffix.lower()
    if suffix == ".npy":
        try:
            image = np.load(path, allow_pickle=False)
        except (ValueError, OSError) as exc:
            raise ValueError(f"cannot read example {str(path)!r}: {exc}") from None
        heights = True
    elif suffix in (".png", ".jpg", ".jpeg", ".tif", ".tiff"):
        from PIL import Image, UnidentifiedImageError

        try:
            with Image.open(path) as im:
                image = np.asarray(im.convert("F"), dtype=np.float64) / 255.0
        except (UnidentifiedImageError, OSError) as exc:
            raise ValueError(f"cannot read example {str(path)!r}: {exc}") from None
        heights = False
    else:
        raise ValueError(f"example {str(path)!r}: unknown format {suffix!r}; allowed: .npy "
                         ".png .jpg .tif")
    image = np.asarray(image, dtype=np.float64)
    if image.ndim != 2:
        raise ValueError(f"example {str(path)!r} must be a 2-D array; got shape {image.shape}")
    return image, heights


def power_spectrum(image, pixel_m: float):
    """Periodogram of a 2-D height image (mean removed, Hann window), centred.

    Returns ``(power, fx, fy)``: ``power[i, j]`` (m^2 per frequency cell, summing to the
    windowed variance) at ``(fx[j], fy[i])`` cycles per metre.
    """
    z = np.asarray(image, dtype=np.float64)
    if z.ndim != 2 or min(z.shape) < 16:
        raise ValueError(f"`image` must be a 2-D array of at least 16 x 16; got shape {z.shape}")
    if not np.isfinite(z).all():
        raise ValueError("`image` must be finite (fill gaps first)")
    pixel_m = check_positive("pixel_m", pixel_m)
    ny, nx = z.shape
    w = np.outer(np.hanning(ny), np.hanning(nx))
    f = np.fft.fft2((z - z.mean()) * w)
    power = np.fft.fftshift(abs2(f)) / (w**2).sum() / z.size
    fx = np.fft.fftshift(np.fft.fftfreq(nx, pixel_m))
    fy = np.fft.fftshift(np.fft.fftfreq(ny, pixel_m))
    return power, fx, fy


def _block_mean(a: np.ndarray, n_max: int):
    ny, nx = a.shape
    by, bx = -(-ny // n_max), -(-nx // n_max)  # block sizes
    ny2, nx2 = (ny // by) * by, (nx // bx) * bx
    return a[:ny2, :nx2].reshape(ny2 // by, by, nx2 // bx, bx).mean(axis=(1, 3)), by, bx


def fit_gabor(image, pixel_m: float, *, amplitude_m: float | None = None,
              n_frequencies: int = 24, n_orientations: int = 12, n_bandwidths: int = 3,
              density: float = 4.0, max_patches: int = 1000,
              weighting: str = "relative") -> GaborNoise:
    """Gabor noise whose spectrum fits the power spectrum of a 2-D example (module notes).

    Parameters
    ----------
    image : (rows, cols) array
        Example heights (or grey levels), finite, at least 16 x 16.
    pixel_m : float
        Pixel size, metres: sets the frequencies in cycles per metre.
    amplitude_m : float, optional
        rms of the noise, metres (default: the example's standard deviation, i.e. the
        image is heights in metres).
    n_frequencies, n_orientations, n_bandwidths : int
        The dictionary: patch centres at ``k / n_frequencies`` of the Nyquist frequency
        (k = 1..n) times ``n_orientations`` directions over 180 degrees, plus one at 0;
        bandwidths 0.5, 1, 2, ... times the frequency step.
    max_patches : int
        Keep at most this many patches (largest variance shares).
    weighting : {"relative", "linear"}
        Least squares on the power itself (``"linear"``, Galerne et al.'s (2012) choice: the
        strongest part of the spectrum dominates) or relative to a smoothed periodogram
        (``"relative"``: every frequency counts, so the weak high frequencies of a
        power-law terrain are kept).

    Examples
    --------
    >>> truth = GaborNoise.single(0.08, 0.02, 1.0, orientation_deg=30.0, density=8.0)
    >>> img = gabor_image(truth, (128, 128), 1.0, rng=1)
    >>> fit = fit_gabor(img, 1.0)
    >>> top = max(fit.patches, key=lambda p: p.weight)
    >>> round(top.frequency, 2), round(top.orientation_deg)
    (0.08, 30)
    """
    from scipy.optimize import nnls

    n_frequencies = check_int("n_frequencies", n_frequencies, 1, 64)
    n_orientations = check_int("n_orientations", n_orientations, 1, 64)
    n_bandwidths = check_int("n_bandwidths", n_bandwidths, 1, 6)
    max_patches = check_int("max_patches", max_patches, 1, 10_000)
    check_choice("weighting", weighting, ("relative", "linear"))
    power, fx, fy = power_spectrum(image, pixel_m)
    if not power.max() > 0:
        raise ValueError("`image` has no variance to fit")
    rms = float(np.std(np.asarray(image, dtype=np.float64)))
    amplitude_m = rms if amplitude_m is None else check_positive("amplitude_m", amplitude_m,
                                                                 allow_zero=True)
    p_small, by, bx = _block_mean(power, 96)
    # the dictionary is averaged over the same blocks of frequencies (a patch narrower
    # than a block is otherwise misread)
    fxb = fx[:p_small.shape[1] * bx].reshape(-1, bx)
    fyb = fy[:p_small.shape[0] * by].reshape(-1, by)
    A, meta = _patch_dictionary(fxb, fyb, 0.5 / pixel_m, n_frequencies, n_orientations,
                                n_bandwidths)
    target = p_small.ravel()
    if weighting == "relative":  # each frequency cell counts by its relative error
        from scipy.ndimage import gaussian_filter

        scale = np.maximum(gaussian_filter(p_small, 1.5).ravel(), 1e-12 * target.max())
        A, target = A / scale[:, None], target / scale
    w, _ = nnls(A, target, maxiter=50 * A.shape[1])
    return GaborNoise(_largest_patches(w, meta, max_patches), amplitude_m, density)


def _patch_dictionary(fxb, fyb, nyquist, n_frequencies, n_orientations, n_bandwidths):
    """The least-squares dictionary of :func:`fit_gabor`: one column per Gaussian power
    patch (both lobes at +-mu), block-averaged like the periodogram (``fxb``, ``fyb``:
    the frequencies of each block, cycles/m), and the ``(mu_x, mu_y, a)`` of each."""
    step = nyquist / n_frequencies
    centres = [(0.0, 0.0)]
    for fk in range(1, n_frequencies + 1):
        for m in range(n_orientations):
            t = math.pi * m / n_orientations
            centres.append((fk * step * math.cos(t), fk * step * math.sin(t)))
    bands = [step * 2.0 ** (b - 1) for b in range(n_bandwidths)]
    cols, meta = [], []
    for a in bands:
        c = 2 * math.pi / a**2
        for mx, my in centres:
            # Gaussians are separable: the block mean is the outer product of 1-D means
            g = np.outer(np.exp(-c * (fyb - my) ** 2).mean(1), np.exp(-c * (fxb - mx) ** 2).mean(1))
            if mx or my:
                g += np.outer(np.exp(-c * (fyb + my) ** 2).mean(1),
                              np.exp(-c * (fxb + mx) ** 2).mean(1))
            cols.append(g.ravel())
            meta.append((mx, my, a))
    return np.stack(cols, axis=1), meta


def _largest_patches(w, meta, max_patches) -> tuple[GaborPatch, ...]:
    """The patches of the non-negative weights ``w`` of the dictionary ``meta``, largest
    variance share first, at most ``max_patches``, none below 1e-6 of the largest."""
    # variance of each patch: integral of its power over the plane (two lobes)
    share = np.array([wt * a * a / 2 * (2 if (mx or my) else 1)
                      for wt, (mx, my, a) in zip(w, meta, strict=True)])
    if not (share > 0).any():
        raise ValueError("`image` has no variance to fit")
    order = np.argsort(-share, kind="stable")
    order = order[share[order] > 1e-6 * share[order[0]]][:max_patches]
    patches = []
    for idx in order:
        mx, my, a = meta[idx]
        f = math.hypot(mx, my)
        patches.append(GaborPatch(f, a, math.degrees(math.atan2(my, mx)) if f else None,
                                  float(share[idx])))
    return tuple(patches)
