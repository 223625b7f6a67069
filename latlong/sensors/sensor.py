"""The detector: from the radiance factor I/F of each pixel to digital numbers.

electrons = I/F x ``flux_e_per_s`` x ``exposure_s`` (the optics, the band and the sun's
distance folded into one flux), blurred by an optional Gaussian PSF, with optional
Poisson photon noise and Gaussian read noise (counter-based per pixel and seed: the
same bytes for any thread count), clipped to the full well, then DN = electrons x
``gain`` x (2^bits - 1) / full well, rounded. ``bits=32`` keeps a float32 image in I/F
units (PSF and noise applied, no clipping or rounding).

Examples
--------
>>> import numpy as np
>>> s = Sensor(exposure_s=0.01, flux_e_per_s=4e6, full_well_e=40000.0, bits=16)
>>> expose(np.array([[0.0, 0.5, 1.0, 2.0]]), s).tolist()
[[0, 32768, 65535, 65535]]
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from craters._shared import ParameterError, check_int, check_positive, check_range

from ._render_kernels import _sensor_kernel

__all__ = ["Sensor", "expose"]


@dataclass(frozen=True, slots=True)
class Sensor:
    """Exposure, gain, bit depth, noise and PSF of a camera's detector (module notes)."""

    exposure_s: float = 0.01
    """Exposure time, seconds (> 0)."""
    flux_e_per_s: float = 1.2e7
    """Photo-electrons per second collected by a pixel that sees I/F = 1 (> 0); the
    default fills the full well at I/F = 0.33 in the default exposure."""
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

    def __post_init__(self):
        for key in ("exposure_s", "flux_e_per_s", "full_well_e", "gain"):
            object.__setattr__(self, key, check_positive(key, getattr(self, key)))
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
        """Electrons of a pixel that sees I/F = 1."""
        return self.flux_e_per_s * self.exposure_s

    @property
    def dtype(self):
        return {8: np.uint8, 16: np.uint16, 32: np.float32}[self.bits]


def expose(reflectance, sensor: Sensor | None = None, *, seed: int = 0) -> np.ndarray:
    """The image a :class:`Sensor` records of an (H, W) I/F image (NaN counts as 0)."""
    sensor = Sensor() if sensor is None else sensor
    if not isinstance(sensor, Sensor):
        raise TypeError(f"`sensor` must be a Sensor; got {type(sensor).__name__}")
    seed = check_int("seed", seed, 0, 2**63 - 1)
    img = np.nan_to_num(np.asarray(reflectance, dtype=np.float64), nan=0.0)
    if img.ndim != 2:
        raise ParameterError("reflectance", f"must be an (H, W) image; got shape {img.shape}")
    if sensor.psf_sigma_px > 0:
        from scipy.ndimage import gaussian_filter

        img = gaussian_filter(img, sensor.psf_sigma_px, mode="constant", cval=0.0,
                              truncate=4.0)
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
