"""The three kinds of crater-counting functions, as frozen records that evaluate
themselves (the forms craterstats uses; Michael & Neukum 2010, Michael 2013):

* :class:`ProductionFunction`: the shape of the size-frequency distribution of new
  craters, the 11-degree polynomial ``log10 N(>D) = a0 + sum_{j=1..11} a_j (log10 D)^j``
  (D in km, N per km^2) of Neukum (1983) and Neukum, Ivanov & Hartmann (2001) and their
  successors, valid on ``d_range_km``. ``a0`` only sets the density at D = 1 km, which
  the chronology gives, so it is kept for the record and ignored (as by craterstats):
  ``N(>D, T) = N1(T) 10^(sum_{j>=1} a_j (log10 D)^j)``.
* :class:`ChronologyFunction`: ``N1(T) = c0 (exp(c1 T) - 1) + c2 T^2 + c3 T``, the
  cumulative density of craters >= 1 km (per km^2) on a surface of age T (Gyr); its
  derivative is the impact rate (Neukum 1983; Neukum et al. 2001 eq. 5).
* :class:`EquilibriumFunction`: ``log10 N_eq(>D) = b0 + b1 log10 D`` (D in km, N per
  km^2), the density at which new craters erase as many as they add (Trask 1966;
  Hartmann 1984).

Everything here is in craterstats' units (km, km^2, Gyr); the metre-based functions of
:mod:`craters.chronology.sampling` convert at the boundary.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from .._shared import ParameterError, check_positive

__all__ = ["ChronologyFunction", "EquilibriumFunction", "ProductionFunction"]


@dataclasses.dataclass(frozen=True, slots=True)
class ProductionFunction:
    """A polynomial production function (module notes). D in km, N per km^2."""

    name: str
    """Its name in craterstats' ``functions.txt`` (e.g. ``Moon, Neukum et al. (2001)``)."""
    coefficients: tuple[float, ...]
    """a0 .. a11 of ``log10 N(>D) = sum a_j (log10 D)^j``; a0 (the density at D = 1 km
    of one particular age) is ignored in favour of the chronology."""
    d_range_km: tuple[float, float]
    """Diameters (km) on which the polynomial is valid."""
    reference: str
    """The paper(s) the coefficients come from."""

    def __post_init__(self):
        if len(self.coefficients) != 12 or not all(map(math.isfinite, self.coefficients)):
            raise ParameterError("coefficients", f"must be 12 finite numbers a0..a11; got "
                                 f"{self.coefficients!r}")
        lo, hi = self.d_range_km
        check_positive("d_range_km", lo)
        if not hi > lo:
            raise ParameterError("d_range_km", f"must be (low, high) with low < high; got "
                                 f"{self.d_range_km!r}")

    def shape_log10(self, d_km) -> np.ndarray:
        """``sum_{j>=1} a_j (log10 D)^j``: log10 of N(>D) / N(>1 km)."""
        x = np.log10(np.asarray(d_km, dtype=np.float64))
        # Horner, highest power first, without a0
        out = np.zeros_like(x)
        for a in self.coefficients[:0:-1]:
            out = (out + a) * x
        return out

    def cumulative_km2(self, d_km, n1_km2: float) -> np.ndarray:
        """N(>D) per km^2 for diameters ``d_km`` on a surface with ``N(>1 km) = n1_km2``."""
        return n1_km2 * 10.0 ** self.shape_log10(d_km)

    def slope(self, d_km) -> np.ndarray:
        """Local log-log slope ``d log10 N / d log10 D`` (the cumulative exponent)."""
        x = np.log10(np.asarray(d_km, dtype=np.float64))
        out = np.zeros_like(x)
        for j in range(len(self.coefficients) - 1, 0, -1):
            out = out * x + j * self.coefficients[j]
        return out


@dataclasses.dataclass(frozen=True, slots=True)
class ChronologyFunction:
    """``N1(T) = c0 (exp(c1 T) - 1) + c2 T^2 + c3 T`` per km^2, T in Gyr (module notes)."""

    name: str
    """Its name in craterstats' ``functions.txt``."""
    coefficients: tuple[float, float, float, float]
    """c0 (km^-2), c1 (Gyr^-1), c2 (km^-2 Gyr^-2), c3 (km^-2 Gyr^-1)."""
    reference: str
    """The paper(s) the coefficients come from."""
    t_max_gyr: float = 4.5
    """Oldest age the chronology is used for, Gyr (the oldest lunar crust, ~4.5 Gyr;
    the exponential term means nothing before the bodies formed)."""

    def __post_init__(self):
        if len(self.coefficients) != 4 or not all(map(math.isfinite, self.coefficients)):
            raise ParameterError("coefficients", f"must be 4 finite numbers c0..c3; got "
                                 f"{self.coefficients!r}")
        check_positive("t_max_gyr", self.t_max_gyr)

    def n1(self, t_gyr) -> np.ndarray:
        """Cumulative density of craters >= 1 km (per km^2) on a surface of age ``t_gyr``."""
        c0, c1, c2, c3 = self.coefficients
        t = np.asarray(t_gyr, dtype=np.float64)
        return c0 * np.expm1(c1 * t) + c2 * t * t + c3 * t

    def rate(self, t_gyr) -> np.ndarray:
        """The impact rate dN1/dT (km^-2 Gyr^-1) at ``t_gyr`` before present."""
        c0, c1, c2, c3 = self.coefficients
        t = np.asarray(t_gyr, dtype=np.float64)
        return c0 * c1 * np.exp(c1 * t) + 2.0 * c2 * t + c3

    def age_gyr(self, n1_km2) -> np.ndarray:
        """The model age (Gyr) of a surface whose N(>1 km) is ``n1_km2`` (the inverse of
        :meth:`n1`; Newton's method from a tabulated start, to 1e-12 Gyr)."""
        target = np.asarray(n1_km2, dtype=np.float64)
        grid = np.linspace(0.0, self.t_max_gyr, 4097)
        t = np.interp(target, self.n1(grid), grid)
        return _newton(self, t, target)


def _newton(cf: ChronologyFunction, t: np.ndarray, target: np.ndarray) -> np.ndarray:
    """Solve ``cf.n1(t) = target`` by Newton steps from ``t`` (N1 is increasing and
    convex, so from a tabulated start it converges in a few steps)."""
    for _ in range(6):
        t = t - (cf.n1(t) - target) / cf.rate(t)
    return np.maximum(t, 0.0)


@dataclasses.dataclass(frozen=True, slots=True)
class EquilibriumFunction:
    """``log10 N_eq(>D) = b0 + b1 log10 D`` per km^2, D in km (module notes)."""

    name: str
    """Its name in craterstats' ``functions.txt``."""
    coefficients: tuple[float, float]
    """b0 and b1."""
    d_range_km: tuple[float, float]
    """Diameters (km) on which it is given."""
    reference: str
    """The paper it comes from."""

    def cumulative_km2(self, d_km) -> np.ndarray:
        """Equilibrium N(>D) per km^2 at diameters ``d_km``."""
        b0, b1 = self.coefficients
        return 10.0 ** (b0 + b1 * np.log10(np.asarray(d_km, dtype=np.float64)))
