"""The detector: from the radiance factor I/F of each pixel to digital numbers.

electrons = I/F x ``flux_e_per_s`` x ``exposure_s`` (the optics, the band and the sun's
distance folded into one flux), blurred by an optional Gaussian PSF, with optional
Poisson photon noise and Gaussian read noise (counter-based per pixel and seed: the
same bytes for any thread count), clipped to the full well, then DN = electrons x
``gain`` x (2^bits - 1) / full well, rounded. ``bits=32`` keeps a float32 image in I/F
units (PSF and noise applied, no clipping or rounding).

Auto-exposure (the default, ``exposure_s=None``) does what a flight camera's exposure
control does: the exposure puts the ``exposure_percentile`` th percentile of the lit
pixels (I/F > 0) at ``exposure_target`` of full scale, so a frame neither clips its
bright slopes nor sits in the bottom fifth of the range (a fixed exposure left the
README frames' lit pixels at 17-20 % of full scale: black in any viewer). The exposure
chosen is recorded with each frame. :func:`display_image` makes the 8-bit sRGB picture
for people from the linear data, which stays as recorded.

Examples
--------
>>> import numpy as np
>>> s = Sensor(exposure_s=0.01, flux_e_per_s=4e6, full_well_e=40000.0, bits=16)
>>> expose(np.array([[0.0, 0.5, 1.0, 2.0]]), s).tolist()
[[0, 32768, 65535, 65535]]
>>> auto = Sensor(flux_e_per_s=4e6, full_well_e=40000.0, exposure_percentile=100.0)
>>> exposure_for(np.array([[0.0, 0.2, 0.4]]), auto)  # the brightest, 0.4, at 0.75 of full
0.01875
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from craters._shared import ParameterError, check_int, check_positive, check_range

__all__ = ["DEFAULT_EXPOSURE_S", "Sensor", "display_image", "expose", "exposure_for"]

#: Exposure of a frame with no lit pixel under auto-exposure, seconds.
DEFAULT_EXPOSURE_S = 0.01


@dataclass(frozen=True, slots=True)
class Sensor:
    """Exposure, gain, bit depth, noise and PSF of a camera's detector (module notes)."""

    exposure_s: float | None = None
    """Exposure time, seconds (> 0); None: auto-exposure (module notes)."""
    flux_e_per_s: float = 1.2e7
    """Photo-electrons per second collected by a pixel that sees I/F = 1 (> 0); the
    default fills the full well at I/F = 0.33 in an exposure of 0.01 s."""
    full_well_e: float = 40000.0
    """Full-well capacity, electrons (> 0)."""
    gain: float = 1.0
    """Gain relative to full well -> full scale (> 0; 2 = twice the DN per electron)."""
    bits: int = 16
    """8 or 16 (integer DN, PNG) or 32 (float32 I/F, TIFF)."""
    photon_noise: bool = False
    """Poisson photon (shot) noise on the electrons."""
    read_noise_e: float = 0.0
    """Gaussian read noise, electrons RMS (>= 0)."""
    psf_sigma_px: float = 0.0
    """Gaussian PSF standard deviation, pixels (0: none), [0, 50]."""
    exposure_percentile: float = 95.0
    """Auto-exposure: the percentile of the lit pixels' I/F placed at the target, [50, 100]."""
    exposure_target: float = 0.75
    """Auto-exposure: where that percentile lands, as a share of full scale, (0, 1]."""

    def __post_init__(self):
        for key in ("exposure_s", "flux_e_per_s", "full_well_e", "gain"):
            if key != "exposure_s" or self.exposure_s is not None:
                object.__setattr__(self, key, check_positive(key, getattr(self, key)))
        object.__setattr__(self, "exposure_percentile",
                           check_range("exposure_percentile", self.exposure_percentile, 50.0,
                                       100.0))
        target = check_range("exposure_target", self.exposure_target, 0.0, 1.0)
        if target == 0.0:
            raise ParameterError("exposure_target", "must be in (0, 1]; got 0")
        object.__setattr__(self, "exposure_target", target)
        bits = check_int("bits", self.bits, 8, 32)
        if bits not in (8, 16, 32):
            raise ParameterError("bits", f"must be 8, 16 or 32; got {bits}")
        object.__setattr__(self, "bits", bits)
        object.__setattr__(self, "photon_noise", bool(self.photon_noise))
        object.__setattr__(self, "read_noise_e",
                           check_positive("read_noise_e", self.read_noise_e, allow_zero=True))
        object.__setattr__(self, "psf_sigma_px",
                           check_range("psf_sigma_px", self.psf_sigma_px, 0.0, 50.0))

    @property
    def electrons_per_reflectance(self) -> float:
        """Electrons of a pixel that sees I/F = 1 (at :data:`DEFAULT_EXPOSURE_S` under
        auto-exposure: :func:`exposure_for` gives a frame's own)."""
        return self.flux_e_per_s * (DEFAULT_EXPOSURE_S if self.exposure_s is None
                                    else self.exposure_s)

    @property
    def dtype(self):
        return {8: np.uint8, 16: np.uint16, 32: np.float32}[self.bits]


def _checked(reflectance, sensor) -> tuple[np.ndarray, Sensor]:
    sensor = Sensor() if sensor is None else sensor
    if not isinstance(sensor, Sensor):
        raise TypeError(f"`sensor` must be a Sensor; got {type(sensor).__name__}")
    img = np.nan_to_num(np.asarray(reflectance, dtype=np.float64), nan=0.0)
    if img.ndim not in (2, 3):
        raise ParameterError("reflectance", f"must be an (H, W) or (H, W, bands) image; got "
                             f"shape {img.shape}")
    return img, sensor


def exposure_for(reflectance, sensor: Sensor | None = None) -> float:
    """The exposure (s) a :class:`Sensor` takes of an (H, W) I/F image (or (H, W, bands):
    one exposure for all bands, from all their lit pixels): its own
    ``exposure_s``, or under auto-exposure the one that puts the lit pixels' (I/F > 0)
    ``exposure_percentile`` th percentile at ``exposure_target`` of full scale
    (:data:`DEFAULT_EXPOSURE_S` when nothing is lit). The percentile is taken before the
    PSF and the noise, so the same scene gets the same exposure whatever the seed."""
    img, sensor = _checked(reflectance, sensor)
    if sensor.exposure_s is not None:
        return sensor.exposure_s
    lit = img[img > 0.0]
    level = float(np.percentile(lit, sensor.exposure_percentile)) if len(lit) else 0.0
    if not 0.0 < level < np.inf:
        return DEFAULT_EXPOSURE_S
    electrons = sensor.exposure_target * sensor.full_well_e / sensor.gain
    exposure = electrons / (sensor.flux_e_per_s * level)
    return exposure if 0.0 < exposure < np.inf else DEFAULT_EXPOSURE_S


def display_image(image: np.ndarray, *, white_percentile: float = 95.0,
                  white_level: float = 0.75) -> np.ndarray:
    """The 8-bit sRGB picture (IEC 61966-2-1 transfer curve) of a recorded image for
    people: an integer image's DN over its full scale; a float (I/F) image scaled so its
    lit pixels' ``white_percentile`` th percentile lands at ``white_level``, as
    auto-exposure would. Clipped to [0, 1] before the curve."""
    a = np.asarray(image)
    if np.issubdtype(a.dtype, np.integer):
        v = a.astype(np.float64) / float(np.iinfo(a.dtype).max)
    else:
        v = np.nan_to_num(a.astype(np.float64), nan=0.0)
        lit = v[v > 0.0]
        level = float(np.percentile(lit, white_percentile)) if len(lit) else 0.0
        v = v * (white_level / level) if 0.0 < level < np.inf else v
    v = np.clip(v, 0.0, 1.0)
    srgb = np.where(v <= 0.0031308, 12.92 * v, 1.055 * v ** (1.0 / 2.4) - 0.055)
    return np.round(255.0 * srgb).astype(np.uint8)


def expose(reflectance, sensor: Sensor | None = None, *, seed: int = 0) -> np.ndarray:
    """The image a :class:`Sensor` records of an (H, W) I/F image (NaN counts as 0), at
    :func:`exposure_for` of it; an (H, W, bands) image band by band (the PSF within each
    band; the noise keyed by the pixel and the band)."""
    from ._render_kernels import _sensor_kernel  # numba loads here
    img, sensor = _checked(reflectance, sensor)
    seed = check_int("seed", seed, 0, 2**63 - 1)
    if sensor.exposure_s is None:
        sensor = replace(sensor, exposure_s=exposure_for(img, sensor))
    if sensor.psf_sigma_px > 0:
        from scipy.ndimage import gaussian_filter

        sigma = sensor.psf_sigma_px if img.ndim == 2 else (sensor.psf_sigma_px,) * 2 + (0.0,)
        img = gaussian_filter(img, sigma, mode="constant", cval=0.0, truncate=4.0)
    electrons = np.ascontiguousarray(img.ravel() * sensor.electrons_per_reflectance)
    quantize = sensor.bits != 32
    if quantize:
        max_dn = float(2**sensor.bits - 1)
        full_well, gain = sensor.full_well_e, sensor.gain * max_dn / sensor.full_well_e
    else:  # float32 I/F: no full well, no rounding
        max_dn, full_well, gain = np.inf, np.inf, 1.0 / sensor.electrons_per_reflectance
    out = np.empty(electrons.shape)
    _sensor_kernel(electrons, seed, sensor.photon_noise, sensor.read_noise_e, full_well,
                   gain, max_dn, quantize, out)
    return out.reshape(img.shape).astype(sensor.dtype)
