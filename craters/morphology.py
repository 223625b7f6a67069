"""Fresh crater morphology on any target: simple bowls, flat floors, central peaks,
terraced walls and peak rings, continuous in diameter.

Heights are relative to the pre-impact surface as a function of ``x = r / R`` (R = D/2,
rim crest at x = 1), for a fresh crater of rim-crest diameter D on a
:class:`~craters.Target`:

* depth (rim crest to floor) and rim height: the smaller of the body's simple and
  complex power laws (for the Moon Pike 1977: simple 0.196 D^1.010 and 0.036 D^1.014,
  complex 1.044 D^0.301 and 0.236 D^0.399, D in km). The two laws cross near the
  transition (lunar depths at 10.6 km, rims at 21 km), so the minimum is continuous.
* interior, simple: the Fassett & Thomson (2014, JGR Planets 119, 2255, eq. 4) fresh
  lunar profile (a small flat floor r < 0.2 R, a polynomial wall to the crest at 0.98 R),
  rescaled to the depth and rim height; complex: a flat floor out to the floor radius
  (Pike 1977: D_f = 0.187 D^1.249 km, self-similar in D / D_t on other bodies), a wall
  steepest under the rim (``u^1.6`` of the wall coordinate) broken into 1-5 terraces
  (benches and scarps; more on larger craters; stamping makes them and the peak
  irregular: :func:`craters.kernels.warp_x`), a central peak of height
  0.032 D^0.9 km (Hale & Head 1979 as tabulated by cratermaker) and base diameter
  0.22 D (Hale & Head 1979; Pike 1985), which becomes a ring of peaks at half the rim
  diameter above the peak-ring onset (Baker et al. 2011: ring / rim ~ 0.5).
* the complex form replaces the simple one over the transitional range 0.8-1.6 D_t
  (smoothstep in log D): floors widen, peaks and terraces grow in, nothing jumps.
* exterior: the rim falls to McGetchin et al.'s (1973) ejecta thickness 0.14 R^0.74 (r/R)^-3
  (metres, capped at the rim height) with the corrective quadratic that ends it on the
  terrain at the ejecta edge (Martin, Parkes & Dunstan 2014, III; :mod:`craters.profile`).
"""

from __future__ import annotations

import numpy as np

from ._shared import ParameterError
from .targets import Target, get_target

__all__ = ["EJECTA_EDGE", "fresh_morphometry", "fresh_profile", "morphology_class"]

#: Ejecta edge in crater radii: r = 1.5 D, one diameter beyond the rim.
EJECTA_EDGE = 3.0
# Fassett & Thomson (2014) eq. 4: elevation / D against r / R (crest at 0.98 R)
_FT_FLOOR = -0.181
_FT_INNER = (-0.228809953, 0.227533882, 0.083116795, -0.039499407)
_FT_RIM = 0.036822095
_FT_CREST = 0.98
# complex craters (lunar values, self-similar in D / D_t elsewhere)
_FLOOR_LAW = (0.187, 1.249)         # floor diameter, km (Pike 1977)
_PEAK_LAW = (0.032, 0.9)            # central peak height, km (Hale & Head 1979)
_PEAK_BASE = 0.22                   # central peak base diameter / D (Hale & Head 1979)
_RING_X = 0.5                       # peak ring diameter / rim diameter (Baker et al. 2011)
_RING_WIDTH = 0.08                  # peak ring half-width, crater radii
_TRANSITION = (0.8, 1.6)            # transitional range, in D_t
_RING_ONSET = (1.0, 1.3)            # central peak -> peak ring, in D_pr
_MAX_TERRACES = 5


def _smoothstep(t):
    t = np.clip(t, 0.0, 1.0)
    return t * t * (3.0 - 2.0 * t)


def _law(law: tuple[float, float], d_km):
    return law[0] * d_km ** law[1]


def _diameters(diameter_m) -> np.ndarray:
    d = np.asarray(diameter_m, dtype=np.float64)
    if not np.isfinite(d).all() or (d <= 0).any():
        raise ParameterError("diameter_m", "must be finite and > 0")
    return d


def fresh_morphometry(diameter_m, target: str | Target = "moon") -> dict[str, np.ndarray]:
    """Fresh-crater dimensions on ``target`` (module notes), metres unless noted.

    Returns ``depth_m`` (rim crest to floor), ``rim_height_m``, ``floor_diameter_m``
    (0 for a bowl), ``peak_height_m`` (central peak or peak ring above the floor),
    ``peak_diameter_m`` (base of the central peak), ``complex`` (0 simple ... 1 complex),
    ``ring`` (0 central peak ... 1 peak ring) and ``terraces`` (a real number; its
    integer part is the number of full terraces).

    Examples
    --------
    >>> m = fresh_morphometry([1000.0, 100_000.0], "moon")
    >>> [round(float(v)) for v in m["depth_m"]], [round(float(v)) for v in m["complex"]]
    ([196, 4175], [0, 1])
    """
    t = get_target(target)
    d = _diameters(diameter_m)
    d_km = d / 1000.0
    dt_km = t.transition_m / 1000.0
    scale = dt_km / 15.0  # self-similar carry-over of the lunar complex-crater laws
    depth = 1000.0 * np.minimum(_law(t.simple_depth, d_km), _law(t.complex_depth, d_km))
    rim = 1000.0 * np.minimum(_law(t.simple_rim, d_km), _law(t.complex_rim, d_km))
    if t.small_depth_ratio:  # small craters measured shallower (Target.small_depth_ratio)
        kd, kr = np.array(t.small_depth_ratio, dtype=np.float64).T
        ratio = np.interp(np.log(d), np.log(kd), kr)
        shallow = np.where(d < kd[-1], np.minimum(depth, d * ratio), depth)
        rim = rim * (shallow / depth)
        depth = shallow
    lo, hi = _TRANSITION
    w = _smoothstep(np.log(d / (lo * t.transition_m)) / np.log(hi / lo))
    q = _smoothstep(np.log(d / (_RING_ONSET[0] * t.peak_ring_m))
                    / np.log(_RING_ONSET[1] / _RING_ONSET[0]))
    floor = np.minimum(0.8, _FLOOR_LAW[0] * scale ** (1 - _FLOOR_LAW[1])
                       * d_km ** (_FLOOR_LAW[1] - 1.0))
    peak = 1000.0 * _PEAK_LAW[0] * scale ** (1 - _PEAK_LAW[1]) * d_km ** _PEAK_LAW[1]
    peak = np.minimum(peak, 0.6 * depth) * w
    span = np.log(t.peak_ring_m / t.transition_m)
    terr = np.clip(1.0 + (_MAX_TERRACES - 1) * np.log(np.maximum(d / t.transition_m, 1.0))
                   / span, 1.0, _MAX_TERRACES) * w
    return {"depth_m": depth, "rim_height_m": rim, "floor_diameter_m": w * floor * d,
            "peak_height_m": peak, "peak_diameter_m": w * (1.0 - q) * _PEAK_BASE * d,
            "complex": w, "ring": q * w, "terraces": terr}


def morphology_class(diameter_m, target: str | Target = "moon") -> np.ndarray:
    """``simple``, ``transitional``, ``complex`` or ``peak-ring`` for each diameter.

    Examples
    --------
    >>> morphology_class([1e3, 15e3, 60e3, 300e3]).tolist()
    ['simple', 'transitional', 'complex', 'peak-ring']
    """
    m = fresh_morphometry(diameter_m, target)
    out = np.where(m["complex"] < 0.05, "simple",
                   np.where(m["complex"] < 0.95, "transitional", "complex")).astype("<U12")
    out[(m["ring"] >= 0.5)] = "peak-ring"
    return out


def _simple_shape(x):
    """Fassett & Thomson's fresh interior normalised to 0 (floor) ... 1 (crest at x = 1)."""
    r = _FT_CREST * np.asarray(x)
    p = np.polynomial.polynomial.polyval(r, _FT_INNER)
    p = np.where(r < 0.2, _FT_FLOOR, p)
    return np.clip((p - _FT_FLOOR) / (_FT_RIM - _FT_FLOOR), 0.0, 1.0)


def _stairs(u, n):
    """``n`` (integer >= 1) benches and scarps mapping [0, 1] onto [0, 1]."""
    v = u * n
    k = np.minimum(np.floor(v), n - 1)
    return (k + _smoothstep((v - k - 0.55) / 0.45)) / n


def _terraced(u, n):
    """Wall coordinate u in [0, 1] with ``n`` (real) terraces, blended between the whole
    numbers around it so that the wall changes continuously with the crater's size."""
    n = np.maximum(n, 1.0)
    lo = np.floor(n)
    f = n - lo
    return (1.0 - f) * _stairs(u, lo) + f * _stairs(u, lo + 1.0)


def _exterior(x, rim, e0, xe):
    """Rim to the ejecta edge: McGetchin thickness plus the corrective quadratic that
    meets the rim (value ``rim`` at x = 1) and ends on the terrain at ``xe``."""
    length = xe - 1.0
    c0 = -e0 * xe**-3.0
    c1 = -3.0 * e0 * xe**-4.0
    c2 = (rim - e0 - c0 - c1 * length) / (length * length)
    u = xe - x
    return e0 * x**-3.0 + c0 + c1 * u + c2 * u * u


def fresh_profile(x, diameter_m, target: str | Target = "moon", *,
                  ejecta_edge: float = EJECTA_EDGE) -> np.ndarray:
    """Heights (metres) of fresh craters at ``x = r / R`` (module notes).

    ``diameter_m`` may be an array: the result has shape ``(len(diameter_m), len(x))``
    (or ``(len(x),)`` for one diameter); 0 at and beyond the ejecta edge.

    Examples
    --------
    >>> h = fresh_profile([0.0, 1.0, 3.0], 1000.0)
    >>> [round(float(v), 1) for v in h]
    [-160.0, 36.0, 0.0]
    """
    t = get_target(target)
    x = np.asarray(x, dtype=np.float64)
    if not np.isfinite(x).all() or (x < 0).any():
        raise ParameterError("x", "must be finite and >= 0 (radii)")
    d = _diameters(diameter_m)
    scalar = d.ndim == 0
    d = np.atleast_1d(d)
    if d.size * x.size > _BLOCK:  # rows in blocks: the temporaries stay in cache (x4-10)
        step = max(1, _BLOCK // max(x.size, 1))
        h = np.concatenate([_fresh_rows(x, d[s:s + step], t, ejecta_edge)
                            for s in range(0, d.size, step)])
    else:
        h = _fresh_rows(x, d, t, ejecta_edge)
    return h[0] if scalar else h


_BLOCK = 1 << 16  # elements per block of fresh_profile's (crater, x) temporaries


def _fresh_rows(x: np.ndarray, d: np.ndarray, t: Target, ejecta_edge: float) -> np.ndarray:
    """fresh_profile of the 1-D diameters ``d``: (len(d), len(x))."""
    m = fresh_morphometry(d, t)
    col = {k: v[:, None] for k, v in m.items()}
    xx = x[None, :]
    depth, rim = col["depth_m"], col["rim_height_m"]
    w = col["complex"]
    # interior: simple bowl blended into the complex floor, wall and terraces
    xf = col["floor_diameter_m"] / np.maximum(w, 1e-12) / d[:, None]
    u = np.clip((xx - xf) / np.maximum(1.0 - xf, 1e-9), 0.0, 1.0)
    n_terr = col["terraces"] / np.maximum(w, 1e-12)
    terrace_share = 0.6
    uu = (1.0 - terrace_share) * u + terrace_share * _terraced(u, n_terr)
    shape = (1.0 - w) * _simple_shape(np.minimum(xx, 1.0)) + w * uu**1.6
    inner = rim - depth + depth * shape
    # central peak / peak ring on the floor
    q = col["ring"] / np.maximum(w, 1e-12)
    xp = _PEAK_BASE  # base radius of the peak, in crater radii (base diameter 0.22 D)
    tpk = np.clip(xx / xp, 0.0, 1.0)
    bump = (1.0 - tpk**2) ** 2
    ring = np.exp(-(((xx - _RING_X) / _RING_WIDTH) ** 2))
    inner = inner + col["peak_height_m"] * ((1.0 - q) * bump + q * ring)
    # exterior: ejecta from the rim to the edge
    radius = 0.5 * d[:, None]
    e0 = np.minimum(0.14 * radius**0.74, rim)  # McGetchin et al. 1973, metres
    outer = _exterior(np.maximum(xx, 1.0), rim, e0, ejecta_edge)
    return np.where(xx <= 1.0, inner, np.where(xx < ejecta_edge, outer, 0.0))
