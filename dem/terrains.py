"""Roughness of lunar terrain types below a DEM's pixels: the LOLA deviogram.

Rosenburg et al. (2011, "Global surface slopes and roughness of the Moon from the Lunar
Orbiter Laser Altimeter", JGR 116, E02001, doi:10.1029/2010JE003716, Table 2; medians of
along-track LOLA profiles) give per terrain type the median bidirectional slope at a
17 m baseline and the Hurst exponent ``H`` fitted to the deviogram (RMS height
difference against baseline) from 57 m up to its breakover, above which the relief grows
more slowly. The numbers below are Table 2 as cited by a third party (the paper itself
could not be read here; the PGDA product page, pgda.gsfc.nasa.gov/products/70, confirms
the method but lists no regional values).

With Gaussian height differences (median ``|dz|`` = 0.6745 x RMS) the deviogram below
the breakover is

    nu(L) = L0 tan(s0) / 0.6745 * (L / L0)^H        (metres; L0 = 17 m, s0 the slope there)

and :func:`dem.enhance` with ``terrain`` makes every layer's RMD detail follow it
(``tests/benchmarks/measure_rmd_roughness.py`` measures the stack against it).
"""

from __future__ import annotations

import dataclasses
import math

from craters._shared import ParameterError

__all__ = ["TERRAINS", "TerrainRoughness", "terrain_roughness"]

#: Median of the absolute value of a standard Gaussian (median |dz| / RMS dz).
MEDIAN_ABS_GAUSSIAN = 0.6744897501960817


@dataclasses.dataclass(frozen=True, slots=True)
class TerrainRoughness:
    """A terrain type's deviogram below its breakover (Rosenburg et al. 2011, Table 2)."""

    name: str
    """Terrain type."""
    median_slope_deg: float
    """Median bidirectional (point-to-point) slope at :attr:`baseline_m`, degrees."""
    baseline_m: float
    """Baseline of :attr:`median_slope_deg`, metres."""
    hurst: float
    """Hurst exponent of the deviogram from 57 m to the breakover."""
    breakover_m: float
    """Baseline above which the deviogram flattens (another, smaller Hurst exponent)."""

    def relief_m(self, lag_m: float) -> float:
        """RMS height difference at ``lag_m`` metres (the deviogram; exact below the
        breakover, continued with :attr:`hurst` above it).

        Examples
        --------
        >>> round(TERRAINS["highlands"].relief_m(17.0), 3)   # 17 tan(7.5 deg) / 0.6745
        3.318
        """
        nu0 = self.baseline_m * math.tan(math.radians(self.median_slope_deg)) / MEDIAN_ABS_GAUSSIAN
        return nu0 * (lag_m / self.baseline_m) ** self.hurst


#: Terrain types with their deviogram (Rosenburg et al. 2011, Table 2).
TERRAINS = {
    "highlands": TerrainRoughness("highlands", 7.5, 17.0, 0.95, 980.0),
    "maria": TerrainRoughness("maria", 2.0, 17.0, 0.76, 530.0),
}


def terrain_roughness(name: str) -> TerrainRoughness:
    """The :data:`TERRAINS` entry ``name`` (a one-line error naming the choices)."""
    try:
        return TERRAINS[name]
    except (KeyError, TypeError):
        raise ParameterError("terrain", f"must be one of {', '.join(TERRAINS)}; got "
                             f"{name!r}") from None
