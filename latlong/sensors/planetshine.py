"""Planetshine: a planet lit by the sun, seen from the surface as a second, extended
light (earthshine on the Moon's night side, Mars-shine on Phobos).

The planet is a sphere of angular radius theta seen in ``direction`` (body frame, towards
its centre) scattering sunlight as a Lambert sphere of geometric albedo p. Its
irradiance at the surface, relative to the sun's on a facet facing each of them, is

    E_planet / E_sun = p (sin theta)^2 Phi(alpha),
    Phi(alpha) = (sin alpha + (pi - alpha) cos alpha) / pi,

with alpha the planet's phase angle (sun - planet - surface: cos alpha = -s . d for a
sun direction s and planet direction d, the sun being much farther than the planet) and
Phi the Lambert sphere's phase law (Russell 1916; 1 when full, 0 when new): the limit
far from the planet (an integral over the sphere's surface seen from 60 radii, the
Moon's distance from the Earth, is 1.2 % brighter when full, 2 % fainter at alpha = 90
deg and 7 % at 135 deg: ``tests/latlong/test_sensors_planetshine.py``). The defaults are the
Earth seen from the Moon: theta = 0.95 deg (6371 km at 384 400 km) and p = 0.20, a
Lambert sphere of the Earth's Bond albedo 0.30 (p = 2/3 of it): the full Earth gives
5.5e-5 of the sun's irradiance, 0.075 W/m^2 of the 1361 W/m^2 at 1 au -- half of the
0.15 W/m^2 near zero phase that Glenar et al. 2019 model for the Earth's reflected plus
thermal light at the Moon, with the two of comparable size. The
renderer shades the planet's light with the surface's reflectance model and casts its
shadows like the sun's (over the planet's disk with ``soft_shadow_samples``, the disk
taken as uniformly bright); the light it sends to the surface is not bounced again.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from craters._shared import ParameterError, check_range

from .camera import unit_direction

__all__ = ["Planet", "lambert_sphere_phase"]


def lambert_sphere_phase(alpha_rad) -> np.ndarray:
    """Phi(alpha) of a Lambert sphere (module notes), alpha in radians, [0, pi]."""
    a = np.clip(np.asarray(alpha_rad, dtype=np.float64), 0.0, math.pi)
    return (np.sin(a) + (math.pi - a) * np.cos(a)) / math.pi


@dataclass(frozen=True, slots=True)
class Planet:
    """The planet that shines on the surface (module notes)."""

    direction: np.ndarray
    """(3,) direction from the surface towards the planet's centre, body frame (normalised;
    a zero vector is an error)."""
    angular_radius_deg: float = 0.95
    """Angular radius of the planet's disk, degrees, (0, 60] (default: the Earth from the
    Moon, 6371 km at 384 400 km)."""
    geometric_albedo: float = 0.2
    """Geometric albedo of the planet, [0, 1] (default: the Earth as a Lambert sphere of
    Bond albedo 0.30)."""

    def __post_init__(self):
        d = unit_direction("planet_direction", self.direction)
        object.__setattr__(self, "direction", d)
        r = check_range("planet_angular_radius_deg", self.angular_radius_deg, 0.0, 60.0)
        if r == 0.0:
            raise ParameterError("planet_angular_radius_deg", "must be > 0 and <= 60; got 0")
        object.__setattr__(self, "angular_radius_deg", r)
        object.__setattr__(self, "geometric_albedo", check_range(
            "planet_geometric_albedo", self.geometric_albedo, 0.0, 1.0))

    def phase_deg(self, sun_direction) -> float:
        """The planet's phase angle, degrees: 0 full, 180 new."""
        s = np.asarray(sun_direction, dtype=np.float64)
        cos_a = -float(self.direction @ s) / float(np.linalg.norm(s))
        return math.degrees(math.acos(min(1.0, max(-1.0, cos_a))))

    def irradiance_ratio(self, sun_direction) -> float:
        """Its irradiance on a facet facing it over the sun's on a facet facing the sun."""
        sin_t = math.sin(math.radians(self.angular_radius_deg))
        phase = float(lambert_sphere_phase(math.radians(self.phase_deg(sun_direction))))
        return self.geometric_albedo * sin_t * sin_t * phase

