"""Morphometry of the LCSN crater kernels (Li et al. 2022, eq. 4-5, 7-11, 13-16).

Morphometry (:func:`lcsn_morphometry`): ``H_t`` depth below the datum, ``D_a`` apparent
diameter, ``D_rim`` rim-crest diameter, ``H_rim`` rim height, ``H_c`` central-uplift
height, ``L_d`` width of the outer rim flank (rim crest to its border). Three methods:

``"paper"`` - the formulas exactly as printed. Kinds 1-2 (eq. 4-5): ``H_t = a``;
``D_a`` is 2.5 FWHM (kind 1) or 2 FWHM (kind 2) of the bowl, with the FWHM of
``exp(-b r^(2q))``, ``2 (ln 2 / b)^(1/(2q))``. For kind 1 that is eq. 5's
``5 sqrt(2 ln 2) sigma`` (``sigma = 1/sqrt(2b)``) and, with the unit-area normalisation
``b = pi a^2``, its ``5 sqrt(ln 2) / (sqrt(pi) a)``; eq. 5's expressions in sigma and a
reuse the q = 1 FWHM for kind 2 as well, which is dimensionally wrong for ``b`` in
1/m^4, so kind 2 uses its own FWHM. Kind 3 (eq. 7-11): ``H_rim = kappa - a
exp(-b/gamma)``, ``H_t = a``, ``D_rim = 2/sqrt(gamma)``, ``D_a = 4 sqrt(beta/b) W(x)``,
``L_d = -2 sqrt(beta/b) W(-x) - 1/sqrt(gamma)`` with ``x = sqrt(b/(beta gamma))/2`` and
W the principal branch of Lambert's W (``scipy.special.lambertw``); ``L_d`` is NaN when
``x > 1/e`` (no real W(-x)). Kind 4 (eq. 13-16): ``H_rim = kappa``, ``H_c = a``,
``D_rim = 2/sqrt(gamma)``, ``L_d = sqrt(exp(sqrt(ln(kappa/t)/beta))/gamma) -
1/sqrt(gamma)`` with the paper's border threshold ``t = 0.01`` (``kernel_4 = t``; in
the kernel's height unit, metres here) - NaN when ``kappa <= t``. These are
approximations: eq. 9 puts the crest at the ring's peak, ignoring the Gaussian's slope
there, and eq. 10-11 solve ``kernel_3 = 0`` with Lambert W only under the paper's
simplification ``kappa = a`` ("often we can simplify the evaluation by setting kappa =
a"). Table A.1's fresh craters have ``kappa = 0.22-0.34 a``, and there the printed D_a
is 8-11 % short and L_d 50-60 % long (tests and benchmark).

``"closed"`` (the default) - the same closed forms without those two simplifications:
each printed root is refined by three explicit Newton steps in ``s = ln r`` on the exact
equation (the crest on ``d kernel/ds = 0`` from ``1/sqrt(gamma)``; the datum crossings
of kind 3 on ``ln(kappa L) - ln(a exp(-b r^2)) = 0``, whose value at eq. 10-11's roots
is ``ln(kappa/a)``, so the steps vanish when ``kappa = a``; kind 4's border on
``ln kernel_4 = ln t`` from the farther of eq. 16's root and the Gaussian's own,
``sqrt(ln(a/t)/b)``). Each refined root is then *verified*: it is kept only if the
equation changes sign within 0.5 % of its radius (the right way: rising for D_a,
falling for the outer crossing, the slope falling through 0 at the crest), so a
reported D_rim, D_a or outer crossing is within 0.5 % of a true one; otherwise the
quantity is NaN. ``H_rim`` is the kernel at the refined crest, ``L_d`` the refined
outer crossing minus the refined crest radius (NaN unless it lies beyond the crest).
Without a verified crest, ``D_rim``, ``H_rim`` and ``L_d`` are NaN, and so is kind 3's
``D_a`` (it is also NaN unless the rim rises above the datum: only then must the
profile cross it). A fixed number of steps and checks keeps it a formula (no iteration
to convergence). Measured (``tests/benchmarks/bench_implicit.py`` prints these):
within 1.3e-6 of ``"numeric"`` on the 0 Gyr Table A.1 rows; on 1000 random kernels per
kind with a distinct rim (kappa/a 0.05-2, beta 0.5-20, b/gamma 0.1-10) every finite
closed value exists in the measured profile and is within 0.5 % (D_rim), 0.13 % (D_a)
and 0.4 % (L_d) of it, and closed is NaN where numeric measures for 0.18 % (kind 3) /
0.45 % (kind 4) of the quantities; other seeds give up to 0.2 % (D_a), 1.6 % (L_d, on
a rim barely 5 % of the depth) and 0.9 % NaN. The tests hold looser bounds. ``L_d`` is
a difference of two radii, so near a very low rim its error can exceed 0.5 %. Past
``x > 1/e``, where eq. 11 has no root, closed ``L_d`` is NaN (numeric may measure it).

``"numeric"`` - measured on the profile itself: it is sampled densely (uniform plus
geometric spacing out to where every term is below 1e-16 of its amplitude), and the
features found there are refined with Brent's root finder / bounded minimisation to
machine precision. ``H_t = -min``, ``H_c = kernel(0)``; the rim crest is the interior
local maximum nearest (in ln r) the ring's peak ``1/sqrt(gamma)`` - not the highest: far
out, where the bowl has died away, the ring's tail leaves a local maximum ~1e-20 high
that would outrank a rim below the datum; ``D_a`` is twice the first zero crossing if
it lies inside the crest (kind 3) or 2.5 / 2 times the measured FWHM (kinds 1-2);
``L_d`` is the first crossing of the datum (kind 3) or of ``t`` (kind 4) beyond the
crest, minus the crest radius.

Where a profile has no distinct rim (degraded rows of Table A.1: the rim decays into
the bowl), ``"numeric"`` returns NaN for ``D_rim``, ``H_rim`` and ``L_d`` (no interior
local maximum), NaN for ``D_a`` when the profile does not reach the datum inside the
crest, and NaN for ``L_d`` when the flank never returns to the datum; ``"paper"``
always evaluates its formulas (``H_rim`` can then be <= 0, the formula's way of saying
"no rim").
"""

from __future__ import annotations

import math

import numpy as np

from .._shared import check_choice, check_positive
from .kernel import BORDER_THRESHOLD, RAW_KEYS, check_kind, check_raw, kernel_heights

__all__ = ["METHODS", "lcsn_morphometry", "morphometry_closed", "morphometry_numeric",
           "morphometry_paper"]

_LN2 = math.log(2.0)
METHODS = ("closed", "paper", "numeric")


# --------------------------------------------------------------------------- closed forms
def _lambertw(x: float) -> float:
    from scipy.special import lambertw

    if x < -1.0 / math.e:
        return math.nan
    return float(lambertw(x, 0).real)


def morphometry_paper(kind: int, p: dict, threshold: float) -> dict:
    """The closed forms exactly as printed (eq. 4-5, 7-11, 13-16; module notes)."""
    if kind in (1, 2):
        q = kind
        fwhm = 2.0 * (_LN2 / p["b"]) ** (1.0 / (2 * q))
        return {"H_t": p["a"], "D_a": (2.5 if q == 1 else 2.0) * fwhm}
    kappa, beta, gamma, a, b = (p[k] for k in RAW_KEYS[kind])
    r_rim = 1.0 / math.sqrt(gamma)
    if kind == 3:
        out = {"H_t": a, "D_a": math.nan, "D_rim": 2.0 * r_rim,
               "H_rim": kappa - a * math.exp(-b / gamma), "L_d": math.nan}
        if beta * gamma > 0.0:  # else it underflowed, and eq. 10-11 divide by it
            x = 0.5 * math.sqrt(b / (beta * gamma))
            s = math.sqrt(beta / b)
            w_out = _lambertw(-x)
            out["D_a"] = 4.0 * s * _lambertw(x)
            if math.isfinite(w_out):
                out["L_d"] = -2.0 * s * w_out - r_rim
        return out
    l_d = math.nan
    if kappa > threshold:
        try:
            l_d = math.sqrt(math.exp(math.sqrt(math.log(kappa / threshold) / beta)) / gamma
                            ) - r_rim
        except OverflowError:  # the ring is so wide (tiny beta) that r overflows a float
            l_d = math.nan
    return {"H_c": a, "D_rim": 2.0 * r_rim, "H_rim": kappa, "L_d": l_d}


_NEWTON_STEPS = 3  # explicit refinements of the printed roots (module notes)


def _terms(kind: int, p: dict, s: float):
    """Ring and Gaussian terms of kernel 3/4 and their first two derivatives in s = ln r.

    Returns ``(ring, ring', ring'', gauss, gauss', gauss'')``, the Gaussian term signed
    (``-a exp(-b r^2)`` for kind 3, ``+a ...`` for kind 4).
    """
    t = s + 0.5 * math.log(p["gamma"])  # ln(r sqrt(gamma)): 0 at the ring's peak
    four_beta = 4.0 * p["beta"]
    ring = p["kappa"] * math.exp(-four_beta * t * t)
    e = p["b"] * math.exp(2.0 * s)
    gauss = (-1.0 if kind == 3 else 1.0) * p["a"] * math.exp(-e)
    return (ring, -2.0 * four_beta * t * ring,
            (4.0 * four_beta * four_beta * t * t - 2.0 * four_beta) * ring,
            gauss, -2.0 * e * gauss, (4.0 * e * e - 4.0 * e) * gauss)


_MAX_LN_R = 300.0  # |ln r| beyond this (r outside 1e-130 ... 1e130 m): a step ran away


def _newton(step, s: float) -> float:
    """``_NEWTON_STEPS`` explicit Newton steps ``s - g/g'``; NaN if one is undefined."""
    for _ in range(_NEWTON_STEPS):
        try:
            s = step(s)
        except (ZeroDivisionError, OverflowError, ValueError):  # g' = 0, e^s, log(0)
            return math.nan
        if not abs(s) <= _MAX_LN_R:  # also NaN
            return math.nan
    return s


_VERIFY = math.log1p(0.005)  # a refined root is kept if its sign change is within 0.5 %


def _kernel_at(kind: int, p: dict, s: float) -> float:
    ring, _, _, gauss, _, _ = _terms(kind, p, s)
    return ring + gauss


def _slope_at(kind: int, p: dict, s: float) -> float:
    _, ring1, _, _, gauss1, _ = _terms(kind, p, s)
    return ring1 + gauss1


def _verified(g, s: float, rising: bool) -> float:
    """``s`` if ``g`` changes sign (upward or downward) between ``s -+ _VERIFY``, else NaN.

    The check makes every refined root a proven one: a root of ``g`` lies within 0.5 %
    (in radius) of the value returned.
    """
    if not math.isfinite(s):
        return math.nan
    try:
        lo, hi = g(s - _VERIFY), g(s + _VERIFY)
    except (OverflowError, ValueError, ZeroDivisionError):
        return math.nan
    return s if ((lo < 0.0 < hi) if rising else (lo > 0.0 > hi)) else math.nan


def _crest_closed(kind: int, p: dict) -> float:
    """ln of the crest radius: eq. 9's 1/sqrt(gamma) refined and verified, else NaN."""
    def step(s):
        _, r1, r2, _, g1, g2 = _terms(kind, p, s)
        curvature = r2 + g2
        return s - (r1 + g1) / curvature if curvature < 0 else math.nan

    s = _newton(step, -0.5 * math.log(p["gamma"]))
    return _verified(lambda x: _slope_at(kind, p, x), s, rising=False)


def _beyond(s_out: float, s_crest: float) -> float:
    """Flank width e^s_out - e^s_crest; NaN unless the crossing lies beyond the crest."""
    return math.exp(s_out) - math.exp(s_crest) if s_out > s_crest else math.nan


def morphometry_closed(kind: int, p: dict, threshold: float) -> dict:
    """The printed closed forms with their simplifications removed (module notes)."""
    if kind in (1, 2):
        return morphometry_paper(kind, p, threshold)  # eq. 4-5 are exact
    printed = morphometry_paper(kind, p, threshold)
    s_crest = _crest_closed(kind, p)
    out = dict(printed, D_rim=math.nan, H_rim=math.nan, L_d=math.nan)
    if not math.isfinite(s_crest):  # no rim: no datum crossing or border is defined
        if kind == 3:
            out["D_a"] = math.nan
        return out
    out.update(D_rim=2.0 * math.exp(s_crest), H_rim=_kernel_at(kind, p, s_crest))
    kappa, beta, gamma, a, b = (p[k] for k in RAW_KEYS[kind])
    s_ring = -0.5 * math.log(gamma)

    def kernel_minus(level):
        return lambda s: _kernel_at(kind, p, s) - level

    if kind == 3:
        def step(s):  # kernel_3 = 0  <=>  ln(kappa L) - ln(a G) = 0
            t = s - s_ring
            e = b * math.exp(2.0 * s)
            return s - (math.log(kappa / a) - 4.0 * beta * t * t + e) / (-8.0 * beta * t + 2.0 * e)

        if not out["H_rim"] > 0.0:  # f(0) = -a < 0: the crossing exists iff the rim is up
            out["D_a"] = math.nan
            return out
        s_in = _verified(kernel_minus(0.0), _newton(step, math.log(0.5 * printed["D_a"])),
                         rising=True)
        out["D_a"] = 2.0 * math.exp(s_in) if s_in < s_crest else math.nan
        if math.isfinite(printed["L_d"]):
            s_out = _newton(step, math.log(printed["L_d"] + 0.5 * printed["D_rim"]))
            out["L_d"] = _beyond(_verified(kernel_minus(0.0), s_out, rising=False), s_crest)
        return out

    def step4(s):  # kernel_4 = threshold, in logarithms
        ring, r1, _, gauss, g1, _ = _terms(kind, p, s)
        return s - (math.log(ring + gauss) - math.log(threshold)) * (ring + gauss) / (r1 + g1)

    # both terms are >= 0, so the border lies beyond where either alone falls to t
    starts = [math.log(printed["L_d"] + 0.5 * printed["D_rim"])] if math.isfinite(
        printed["L_d"]) else []
    if a > threshold:
        starts.append(0.5 * math.log(math.log(a / threshold) / b))
    if starts:
        s_out = _verified(kernel_minus(threshold), _newton(step4, max(starts)), rising=False)
        out["L_d"] = _beyond(s_out, s_crest)
    return out


# --------------------------------------------------------------------------- numeric
def _sample_radii(kind: int, p: dict) -> np.ndarray:
    """Radii (m) covering the whole profile: out to where every term is < 1e-16."""
    if kind in (1, 2):
        scale = p["b"] ** (-1.0 / (2 * kind))
        r_max = 8.0 * scale  # exp(-64) (kind 1), exp(-4096) (kind 2)
        lo = scale
    else:
        r_rim = 1.0 / math.sqrt(p["gamma"])
        spread = 0.5 * math.sqrt(37.0 / p["beta"])  # L < 1e-16 beyond r_rim e^spread
        if spread > 300.0:
            raise ValueError(f"`beta` must be >= {37.0 / 600.0**2:.2g} for the numeric method "
                             f"(the ring spreads over e^{spread:.0f} rim radii); got {p['beta']!r}")
        ring = r_rim * math.exp(spread)
        r_max = max(ring, 7.0 / math.sqrt(p["b"]), 4.0 * r_rim)
        lo = min(r_rim, 1.0 / math.sqrt(p["b"]))
    uniform = np.linspace(0.0, r_max, 16385)
    geometric = np.geomspace(lo * 1e-4, r_max, 8193)
    return np.unique(np.concatenate([uniform, geometric]))


def _crest(f, r: np.ndarray, h: np.ndarray, ring: float) -> float:
    """Radius of the interior local maximum nearest (in ln r) the ring's peak, or NaN."""
    from scipy.optimize import minimize_scalar

    interior = np.flatnonzero((h[1:-1] > h[:-2]) & (h[1:-1] >= h[2:])) + 1
    if not interior.size:
        return math.nan
    i = int(interior[np.argmin(np.abs(np.log(r[interior] / ring)))])
    res = minimize_scalar(lambda x: -float(f(x)), bounds=(r[i - 1], r[i + 1]),
                          method="bounded", options={"xatol": 1e-12 * r[i + 1]})
    return float(res.x) if float(f(res.x)) >= h[i] else float(r[i])


def _crossing(f, r: np.ndarray, h: np.ndarray, level: float, start: float,
              falling: bool) -> float:
    """First radius > start where the profile crosses ``level`` (falling or rising)."""
    from scipy.optimize import brentq

    above = h >= level
    idx = np.flatnonzero((r[:-1] >= start) & (above[:-1] != above[1:]) &
                         (above[:-1] if falling else ~above[:-1]))
    if not idx.size:
        return math.nan
    i = int(idx[0])
    try:
        return float(brentq(lambda x: float(f(x)) - level, r[i], r[i + 1],
                            xtol=1e-14 * r[i + 1], rtol=1e-15))
    except RuntimeError:  # no convergence at extreme scales (e.g. a < 1e-169 m)
        return math.nan


def morphometry_numeric(kind: int, p: dict, threshold: float) -> dict:
    def f(x):
        return kernel_heights(kind, np.asarray(x, dtype=np.float64), p)

    r = _sample_radii(kind, p)
    h = f(r)
    if kind in (1, 2):
        depth = -float(h[0])
        half = _crossing(f, r, h, -0.5 * depth, 0.0, falling=False)
        return {"H_t": depth, "D_a": (2.5 if kind == 1 else 2.0) * 2.0 * half}
    crest = _crest(f, r, h, 1.0 / math.sqrt(p["gamma"]))
    rim = {"D_rim": 2.0 * crest, "H_rim": float(f(crest))} if math.isfinite(crest) else {
        "D_rim": math.nan, "H_rim": math.nan}
    if kind == 3:
        depth = -float(h.min())  # at r = 0: kappa L >= 0 and -a exp(-b r^2) rises
        zero = _crossing(f, r, h, 0.0, 0.0, falling=False)
        out = math.nan
        if math.isfinite(crest):
            out = _crossing(f, r, h, 0.0, crest, falling=True) - crest
        zero = zero if zero < crest else math.nan  # the bowl's edge lies inside the rim
        return {"H_t": depth, "D_a": 2.0 * zero, **rim, "L_d": out}
    out = math.nan
    if math.isfinite(crest):
        out = _crossing(f, r, h, threshold, crest, falling=True) - crest
    return {"H_c": float(h[0]), **rim, "L_d": out}


def lcsn_morphometry(kind: int, method: str = "closed", *, threshold: float = BORDER_THRESHOLD,
                     **raw) -> dict:
    """Morphometric parameters of an LCSN kernel (metres), closed-form or measured.

    Parameters
    ----------
    kind : {1, 2, 3, 4}
    method : {"closed", "paper", "numeric"}
        ``"closed"``: the paper's formulas (eq. 4-5, 7-11, 13-16) with the roots of eq.
        9-11 and 16 refined by three explicit Newton steps, which removes their kappa = a
        simplification; ``"paper"``: the formulas exactly as printed; ``"numeric"``: a
        measurement of the profile (module notes; NaN where a feature does not exist).
    threshold : float
        Kernel value (metres) marking the outer border of a complex crater, kind 4's
        ``L_d`` (eq. 16 uses 0.01).
    **raw
        The kernel's raw parameters (:func:`lcsn_kernel`).

    Returns
    -------
    dict
        ``H_t, D_a`` (kinds 1-2); ``H_t, D_a, D_rim, H_rim, L_d`` (kind 3);
        ``H_c, D_rim, H_rim, L_d`` (kind 4).

    Examples
    --------
    >>> from craters import LCSN_PRESETS
    >>> p = LCSN_PRESETS["table-a1-1km-0gyr"].raw
    >>> printed = lcsn_morphometry(3, "paper", **p)
    >>> round(printed["D_rim"], 1), round(printed["H_rim"], 2), round(printed["D_a"], 1)
    (942.8, 35.16, 691.9)
    >>> closed = lcsn_morphometry(3, **p)
    >>> round(closed["D_rim"], 1), round(closed["H_rim"], 2), round(closed["D_a"], 1)
    (962.4, 35.53, 766.7)
    >>> m = lcsn_morphometry(3, "numeric", **p)
    >>> round(m["D_rim"], 1), round(m["H_rim"], 2), round(m["H_t"], 1)
    (962.4, 35.53, 180.1)
    """
    kind = check_kind(kind)
    check_choice("method", method, METHODS)
    threshold = check_positive("threshold", threshold)
    p = check_raw(kind, raw)
    measure = {"closed": morphometry_closed, "paper": morphometry_paper,
               "numeric": morphometry_numeric}[method]
    return measure(kind, p, threshold)
