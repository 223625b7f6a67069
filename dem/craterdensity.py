r"""Crater counts on a DEM: a simple detector, the crater density it implies, and the
diameter below which a DEM no longer resolves craters.

Detector (:func:`detect_craters`): a crater is a bowl whose rim stands above its floor
all around. For radii ``R`` from ``min_diameter_px / 2`` up, a quarter octave apart,
the means of the heights over the floor (disc of ``R / 2``) and over the rim (annulus
``0.8 R .. 1.2 R``, and the first two angular harmonics of the rim) are computed everywhere by FFT
convolution (unknown pixels left out; positions whose discs are less than 95 % known
are skipped). A candidate is a position and radius where

* the rim-to-floor depth exceeds the median of that difference over the whole DEM at
  that radius by 4 robust standard deviations (1.4826 median absolute deviations): a
  bowl deeper than the terrain's own,
* that depth is at least 1 % of the diameter (large complex lunar craters have about
  2 %, Pike 1977) and the rim stands above the floor by half of it all around (its
  mean less the amplitudes of its first two angular harmonics: a crater on a slope
  tilts its rim, a trough or a valley has a two-fold one),
* the depth is the largest within ``R / 2`` and over the neighbouring radii (the
  floor-to-rim difference peaks when the annulus sits on the rim crest).

Overlapping candidates of similar size (centres closer than half the larger radius,
radii within a factor 1.6) keep the deeper one (relative to the diameter).

Measured (``tests/benchmarks/bench_craterdensity.py``; 250 craters stamped by
``craters.stamp_many`` with rough rims and the fractal overlay into five 384 x 384 fBm
scenes of F = 2.3 whose RMS neighbour slope, 0.085, is the LOLA crop's): a crater counts
as found when a detection lies within 0.3 radii + 1 px with its diameter within 25 %.
Degradation 0-0.6: 65 % found at 4-5 px, 53 % at 5-6 px, 96 % at 6-8 px, 97-100 %
above; degradation 0.6-0.9: 15 % at 4-5 px, 48 % at 6-8 px, 75 % at 8-12 px, 84 % at
12-24 px, 93 % above. The fBm alone gives 0-2 false craters per scene (147 000 px). On
the LOLA crop (257 x 257) it finds 147 craters of 4-64 px (30-490 km) in 0.4 s.

Density (:func:`crater_density`): ``n`` craters with diameters in ``[d_lo, d_hi]``
(default from :data:`COMPLETE_CRATER_PX` = 6 px, where the detector misses almost none
but the most degraded) over the known area ``A`` give the cumulative power law
``N(>D) = c D^k`` (D in metres, N per m^2, the craters package's convention) with ``k``
the equilibrium slope -2 (Trask 1966; a crater-saturated surface) unless given or
fitted, ``c = n / (A (d_lo^k - d_hi^k))``. Degraded and overlapping craters that the
detector misses make it a lower bound: 0.6 of the truth for a dense population
(c = 0.05 with k = -2, ages 0-3.5 Gyr) in the tests. The LOLA crop reads c = 0.055 from
6 px (45 km; 100 craters, N(>45 km) = 2.6e-5 per km^2), 70 % of Trask's equilibrium; a
fitted exponent would be -2.34.
:meth:`CraterDensity.layer` turns it into a :class:`craters.CraterLayer` for stamping.
Trask's lunar equilibrium, for scale, is ``c = 10^-1.1 = 0.079`` with ``k = -2``
(craterstats' ``functions.txt``).

Resolution (:func:`resolved_diameter_m`): a DEM resolves its craters down to
:data:`RESOLVED_CRATER_PX` = 4 pixels across (a floor pixel with a rim pixel on each
side and the walls between; the value ``dem enhance`` keeps its synthetic craters
under). The detector finds about 60 % of the moderately degraded craters of 4-6 px,
nearly all from 6 px, and under half below 4 px (45 % at 3-4 px, none when degraded):
below 4 px a crater is lost in the pixels, so synthetic craters belong there and the
real ones above.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from craters import CraterLayer, fit_power_law_exponent, make_catalog
from craters._shared import about, check_positive, check_range

from .core import Dem

__all__ = ["COMPLETE_CRATER_PX", "RESOLVED_CRATER_PX", "CraterDensity", "crater_density",
           "detect_craters", "resolved_diameter_m"]

#: Smallest crater a DEM resolves, in its pixels (see the module docstring); the same as
#: ``dem enhance``'s ``source_crater_px`` default.
RESOLVED_CRATER_PX = 4.0
#: Smallest diameter (pixels) :func:`crater_density` counts: the detector finds nearly
#: every moderately degraded crater from there (96 %, see the module docstring).
COMPLETE_CRATER_PX = 6.0
#: Shallowest crater counted: rim-minus-floor depth over diameter (complex lunar craters
#: of 300 km have about 0.02, Pike 1977; degraded ones less).
DEPTH_RATIO_MIN = 0.01
#: A candidate's rim-minus-floor difference must exceed the median of the whole DEM's at
#: its radius by this many robust standard deviations (1.4826 MAD).
SIGNIFICANCE = 4.0
#: Radii step of the detector (a quarter octave).
_RADIUS_STEP = 2.0**0.25
# a position is measured when this share of its floor and rim pixels is known
_COVERAGE = 0.95
# fewest craters for a fitted exponent (fewer: the equilibrium slope -2)
_FIT_MIN = 30
#: Exponent of the cumulative law by default: the equilibrium slope (Trask 1966).
EQUILIBRIUM_SLOPE = -2.0


def resolved_diameter_m(dem: Dem, pixels: float = RESOLVED_CRATER_PX) -> float:
    """Smallest crater diameter (metres) the DEM resolves: ``pixels`` x its resolution.

    Synthetic craters added to a real DEM should stay below it (above it the DEM's
    own craters are the truth).

    Examples
    --------
    >>> resolved_diameter_m(Dem(np.zeros((4, 4)), pixel_size_m=100.0))
    400.0
    """
    if not isinstance(dem, Dem):
        raise TypeError(f"`dem` must be a Dem; got {type(dem).__name__}")
    with about("pixels"):
        pixels = check_positive("pixels", pixels)
    return float(pixels * dem.resolution_m)


def _kernels(radius: float):
    """Floor disc and rim annulus (masks), and the rim's first two angular harmonics
    (cos, sin of 1 and 2 times the azimuth over the annulus), on an odd square."""
    half = int(math.ceil(1.2 * radius)) + 1
    yy, xx = np.mgrid[-half:half + 1, -half:half + 1].astype(np.float64)
    r = np.hypot(yy, xx)
    floor = r <= max(0.5 * radius, 0.75)
    rim = (r >= 0.8 * radius) & (r <= max(1.2 * radius, 0.8 * radius + 1.0))
    angle = np.arctan2(yy, xx)
    harmonics = [np.where(rim, f(m * angle), 0.0) for m in (1, 2) for f in (np.cos, np.sin)]
    return floor, rim, harmonics


def _convolve(data_f, kernel, shape, fshape):
    """``data`` (given by its rfft over ``fshape``) correlated with a centred ``kernel``."""
    kh, kw = kernel.shape
    out = np.fft.irfft2(data_f * np.fft.rfft2(kernel.astype(np.float64), fshape), fshape)
    return out[kh // 2:kh // 2 + shape[0], kw // 2:kw // 2 + shape[1]]


def _means(z0_f, known_f, shape, kernel, fshape):
    """Mean of the known heights under ``kernel`` centred on every pixel, and coverage."""
    total = _convolve(z0_f, kernel, shape, fshape)
    count = _convolve(known_f, kernel, shape, fshape)
    with np.errstate(invalid="ignore", divide="ignore"):
        mean = np.where(count > 0.5, total / np.maximum(count, 1e-9), np.nan)
    return mean, count / float(kernel.sum())


def detect_craters(dem: Dem, *, min_diameter_px: float = RESOLVED_CRATER_PX,
                   max_diameter_px: float | None = None,
                   depth_ratio_min: float = DEPTH_RATIO_MIN,
                   significance: float = SIGNIFICANCE) -> np.ndarray:
    """Craters of ``dem`` by the rim-over-floor detector of the module docstring.

    Returns a crater catalog (:func:`craters.make_catalog`) with ``x_m, y_m`` (from
    the centre of pixel (0, 0), along columns and rows, in the DEM's pixel sizes),
    ``diameter_m``, ``depth_m`` (rim mean minus floor mean), ``col``, ``row`` (pixel
    coordinates) and ``score`` (depth over diameter), deepest first. Diameters run from
    ``min_diameter_px`` to ``max_diameter_px`` (default: a quarter of the shorter side).

    Examples
    --------
    >>> import craters
    >>> flat = np.zeros((120, 120))
    >>> cat = craters.make_catalog(x_m=[600.0], y_m=[600.0], diameter_m=[200.0])
    >>> z = craters.stamp_many(flat, 10.0, cat, roughness=False)
    >>> found = detect_craters(Dem(z, pixel_size_m=10.0))
    >>> len(found), bool(abs(found["diameter_m"][0] - 200.0) < 40.0)
    (1, True)
    """
    if not isinstance(dem, Dem):
        raise TypeError(f"`dem` must be a Dem; got {type(dem).__name__}")
    with about("min_diameter_px"):
        d_lo = check_range("min_diameter_px", min_diameter_px, 3.0, None)
    d_hi = min(dem.shape) / 4.0 if max_diameter_px is None else max_diameter_px
    with about("max_diameter_px"):
        d_hi = check_range("max_diameter_px", d_hi, d_lo, None)
    with about("depth_ratio_min"):
        ratio_min = check_range("depth_ratio_min", depth_ratio_min, 0.0, 1.0)
    z = dem.heights
    known = np.isfinite(z)
    dx, dy = dem.pixel_size_m
    pixel = math.sqrt(dx * dy)
    n_r = int(math.floor(math.log(d_hi / d_lo) / math.log(_RADIUS_STEP))) + 1
    # one radius below and one above the range: a crater outside it peaks there, not on
    # the range's first or last radius
    radii = 0.5 * d_lo * _RADIUS_STEP ** np.arange(-1, max(n_r, 1) + 1)
    pad = int(math.ceil(1.2 * radii[-1])) + 2
    from scipy.fft import next_fast_len

    fshape = (next_fast_len(z.shape[0] + 2 * pad, True),
              next_fast_len(z.shape[1] + 2 * pad, True))
    z0_f = np.fft.rfft2(np.where(known, z, 0.0), fshape)
    known_f = np.fft.rfft2(known.astype(np.float64), fshape)
    scores = np.full((len(radii), *z.shape), -np.inf)  # depth where a candidate
    for j, radius in enumerate(radii):
        floor, rim, harmonics = _kernels(radius)
        f_mean, f_cov = _means(z0_f, known_f, z.shape, floor, fshape)
        r_mean, r_cov = _means(z0_f, known_f, z.shape, rim, fshape)
        depth = r_mean - f_mean
        ok = (f_cov >= _COVERAGE) & (r_cov >= _COVERAGE) & known
        # the rim's lowest point is at least r_mean - |a1| - |a2|: it must stand half the
        # depth above the floor (the heights' harmonics over the known rim pixels)
        n_rim = np.maximum(r_cov * float(rim.sum()), 1.0)
        a1, b1, a2, b2 = (2.0 * _convolve(z0_f, h, z.shape, fshape) / n_rim
                          for h in harmonics)
        ok &= np.hypot(a1, b1) + np.hypot(a2, b2) <= 0.5 * depth
        ok &= depth >= ratio_min * 2.0 * radius * pixel
        valid = np.isfinite(depth) & (f_cov >= _COVERAGE) & (r_cov >= _COVERAGE)
        if valid.any():  # the terrain's own rim-minus-floor scatter at this radius
            dv = depth[valid]
            spread = 1.4826 * float(np.median(np.abs(dv - np.median(dv))))
            ok &= depth >= float(np.median(dv)) + significance * spread
        scores[j] = np.where(ok, depth, -np.inf)
    return _select(scores, radii, dx, dy, pixel)


def _select(scores, radii, dx, dy, pixel) -> np.ndarray:
    """Local maxima of the depth over space (within R / 2) and radius (the rim crest
    gives the deepest rim-to-floor difference); overlapping similar ones out."""
    from scipy import ndimage

    picks = []
    for j, radius in enumerate(radii[1:-1], 1):
        s = scores[j]
        if not np.isfinite(s).any():
            continue
        size = 2 * max(int(radius // 2), 1) + 1
        local = ndimage.maximum_filter(s, size=size, mode="constant", cval=-np.inf)
        peak = np.isfinite(s) & (s >= local)
        peak &= (s >= scores[j - 1]) & (s >= scores[j + 1])
        for r, c in zip(*np.nonzero(peak), strict=True):
            ratio = float(s[r, c]) / (2.0 * radius * pixel)
            picks.append((ratio, float(radius), int(r), int(c), float(s[r, c])))
    picks.sort(key=lambda p: (-p[0], -p[1], p[2], p[3]))
    kept: list[tuple] = []
    for p in picks:
        if all(math.hypot(p[2] - q[2], p[3] - q[3]) >= 0.5 * max(p[1], q[1])
               or max(p[1], q[1]) / min(p[1], q[1]) > 1.6 for q in kept):
            kept.append(p)
    rows = np.array([p[2] for p in kept], dtype=np.float64)
    cols = np.array([p[3] for p in kept], dtype=np.float64)
    return make_catalog(x_m=cols * dx, y_m=rows * dy,
                        diameter_m=np.array([2.0 * p[1] * pixel for p in kept]),
                        depth_m=np.array([p[4] for p in kept]), col=cols, row=rows,
                        score=np.array([p[0] for p in kept]))


@dataclasses.dataclass(frozen=True, slots=True)
class CraterDensity:
    """A measured cumulative crater density ``N(>D) = c D^k`` (D in metres, N per m^2)."""

    c: float
    """Coefficient (N per m^2 at D = 1 m; dimensionless when k = -2)."""
    k: float
    """Exponent (< 0): -2 (equilibrium) or as given, or fitted (:attr:`k_fitted`)."""
    count: int
    """Craters counted in [:attr:`d_lo_m`, :attr:`d_hi_m`]."""
    area_m2: float
    """Area counted over (the known pixels), m^2."""
    d_lo_m: float
    """Smallest diameter counted (the detection limit), metres."""
    d_hi_m: float
    """Largest diameter searched, metres."""
    k_fitted: bool
    """Whether :attr:`k` was fitted (else the equilibrium slope)."""

    @property
    def n_1km_per_km2(self) -> float:
        """N(>1 km) per km^2, the number crater chronologies use (extrapolated when 1 km
        lies outside the counted range)."""
        return self.c * 1000.0**self.k * 1e6

    def layer(self, d_min_m: float, d_max_m: float, **kwargs) -> CraterLayer:
        """The same law as a :class:`craters.CraterLayer` between two diameters."""
        return CraterLayer(self.c, self.k, d_min_m, d_max_m, **kwargs)


def crater_density(dem: Dem, *, min_diameter_px: float = COMPLETE_CRATER_PX,
                   max_diameter_px: float | None = None,
                   depth_ratio_min: float = DEPTH_RATIO_MIN,
                   exponent: float | None = EQUILIBRIUM_SLOPE) -> CraterDensity | None:
    """The crater density of ``dem``'s known terrain from :func:`detect_craters`.

    ``exponent`` fixes ``k`` (default -2, the equilibrium slope); None fits it by
    maximum likelihood when 30 or more craters are counted (the detector's completeness
    changes with size, which biases that fit: 4-6 px craters in a dense population are
    found more often than 6-12 px ones). None is returned when fewer than 3 craters are
    found (no density can be claimed). See the module docstring for the law and its
    limits (a lower bound: shallow and overlapping craters are missed). The detector runs
    from ``min_diameter_px`` itself: its radii are a quarter octave apart from there, so
    a run from another start would put the cut between different radii.

    Examples
    --------
    >>> crater_density(Dem(np.zeros((64, 64)), pixel_size_m=1.0)) is None
    True
    """
    found = detect_craters(dem, min_diameter_px=min_diameter_px,
                           max_diameter_px=max_diameter_px, depth_ratio_min=depth_ratio_min)
    pixel = math.sqrt(dem.pixel_size_m[0] * dem.pixel_size_m[1])
    d_lo = min_diameter_px * pixel
    d_hi = (min(dem.shape) / 4.0 if max_diameter_px is None else max_diameter_px) * pixel
    d = found["diameter_m"]
    d = d[(d >= d_lo) & (d <= d_hi)]
    if d.size < 3 or d_hi <= d_lo:
        return None
    area = float(dem.known.sum()) * dem.pixel_size_m[0] * dem.pixel_size_m[1]
    k, fitted = (EQUILIBRIUM_SLOPE if exponent is None else float(exponent)), False
    if exponent is None and d.size >= _FIT_MIN:
        k = min(-1.0, max(-4.0, fit_power_law_exponent(d, d_lo, d_hi)))
        fitted = True
    if k >= 0:
        raise ValueError(f"`exponent` must be < 0; got {exponent!r}")
    c = d.size / (area * (d_lo**k - d_hi**k))
    return CraterDensity(c, k, int(d.size), area, d_lo, d_hi, fitted)
