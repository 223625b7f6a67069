"""Fresh-crater morphometry: rim-crest-to-floor depth and rim height against diameter."""

from __future__ import annotations

import dataclasses

import numpy as np

from ._shared import check_choice, check_positive

__all__ = ["MORPHOMETRY_PRESETS", "Morphometry", "fresh_depth", "fresh_rim_height",
           "get_morphometry"]


@dataclasses.dataclass(frozen=True, slots=True)
class Morphometry:
    """Power laws ``depth = a D^b`` and ``rim height = c D^d`` with D in kilometres.

    Results are in kilometres for D in kilometres (the functions below convert metres in
    and out).
    """

    depth_coef: float = 0.196
    """Coefficient of the rim-crest-to-floor depth, km per km^exponent (Pike 1977)."""
    depth_exp: float = 1.010
    """Exponent of the depth law."""
    rim_coef: float = 0.036
    """Coefficient of the rim height above the surroundings (Pike 1977)."""
    rim_exp: float = 1.014
    """Exponent of the rim-height law."""

    def __post_init__(self):
        for name in ("depth_coef", "depth_exp", "rim_coef", "rim_exp"):
            check_positive(name, getattr(self, name))


#: Named parameter sets. ``lunar-simple``: Pike (1977) fresh lunar simple craters,
#: depth 0.196 D^1.010, rim 0.036 D^1.014 (D in km). ``asteroid-fresh``: fresh asteroid
#: craters with d/D = 0.2 (Li et al. 2022 §4.2, after Marchi et al. 2015) and the same
#: rim-to-depth ratio as Pike's lunar craters (0.036 / 0.196).
MORPHOMETRY_PRESETS: dict[str, Morphometry] = {
    "lunar-simple": Morphometry(0.196, 1.010, 0.036, 1.014),
    "asteroid-fresh": Morphometry(0.200, 1.0, 0.200 * 0.036 / 0.196, 1.0),
}


def get_morphometry(morphometry: str | Morphometry | None) -> Morphometry:
    """Resolve a preset name (or None = ``lunar-simple``) to a :class:`Morphometry`."""
    if morphometry is None:
        return MORPHOMETRY_PRESETS["lunar-simple"]
    if isinstance(morphometry, Morphometry):
        return morphometry
    check_choice("morphometry", morphometry, tuple(MORPHOMETRY_PRESETS))
    return MORPHOMETRY_PRESETS[morphometry]


def _diameters(diameter_m) -> np.ndarray:
    d = np.asarray(diameter_m, dtype=np.float64)
    if not np.isfinite(d).all() or (d <= 0).any():
        bad = d[~(np.isfinite(d) & (d > 0))].ravel()[0]
        raise ValueError(f"`diameter_m` must be finite and > 0; got {bad!r}")
    return d


def fresh_depth(diameter_m, morphometry: str | Morphometry | None = None):
    """Rim-crest-to-floor depth H0 of a fresh crater, metres.

    Pike (1977): ``H0 = 0.196 D^1.010`` with D in km (``lunar-simple``).

    Examples
    --------
    >>> round(float(fresh_depth(1000.0)), 3)
    196.0
    """
    m = get_morphometry(morphometry)
    d_km = _diameters(diameter_m) / 1000.0
    return 1000.0 * m.depth_coef * d_km**m.depth_exp


def fresh_rim_height(diameter_m, morphometry: str | Morphometry | None = None):
    """Rim height Hr0 of a fresh crater above the surrounding terrain, metres.

    Pike (1977): ``Hr0 = 0.036 D^1.014`` with D in km (``lunar-simple``).

    Examples
    --------
    >>> round(float(fresh_rim_height(1000.0)), 3)
    36.0
    """
    m = get_morphometry(morphometry)
    d_km = _diameters(diameter_m) / 1000.0
    return 1000.0 * m.rim_coef * d_km**m.rim_exp
