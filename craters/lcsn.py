"""Locally controlled spot-noise (LCSN) crater kernels of Li et al. (2022, §3.2-3.3).

Four radial kernels, ``r`` the distance from the impulse in metres, heights in metres
(positive up, the surrounding terrain at 0):

* ``kernel_1(r) = -a exp(-b r^2)``  simple bowl (a Gaussian, eq. 3 with q = 1)
* ``kernel_2(r) = -a exp(-b r^4)``  simple crater with a flat floor (eq. 3, q = 2)
* ``kernel_3(r) = kappa L(r) - a exp(-b r^2)``  fresh crater with a rim (eq. 6)
* ``kernel_4(r) = kappa L(r) + a exp(-b r^2)``  complex crater, central uplift (eq. 12)

with the log-normal ring ``L(r) = exp(-beta (ln(gamma r^2))^2)`` (``L(0) = 0``), which
peaks at ``r = 1/sqrt(gamma)``. All raw parameters are >= 0: ``a`` is the depth of the
bowl (kinds 1-3) or the height of the uplift (kind 4), ``kappa`` the ring height; ``b``
is in 1/m^2 (1/m^4 for kind 2), ``gamma`` in 1/m^2, ``beta`` is dimensionless. The
Gaussian term is ``exp(-b r^2)`` in kernels 3 and 4: eq. 7, eq. 10 and Table A.1 need
it (with ``exp(-b r^4)``, as the extracted eq. 6 reads, Table A.1's 300 m crater would
have a 10 m wide bowl).

Morphometry (:func:`lcsn_morphometry`): ``H_t`` depth below the datum, ``D_a`` apparent
diameter, ``D_rim`` rim-crest diameter, ``H_rim`` rim height, ``H_c`` central-uplift
height, ``L_d`` width of the outer rim flank (rim crest to its border). Two methods:

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

Table A.1 (kernel_3 fits of Fassett & Thomson's degradation of 300 m, 1 km and 3 km
craters at 0-3 Gyr) lists ``a`` as a negative number: it is the signed coefficient of
the Gaussian in ``kappa L + a exp(-b r^2)``, so the bowl depth is ``-a``. Read that
way the 0 Gyr rows are realistic fresh craters (d/D 0.18-0.19, rim height 0.032-0.037
D); read as eq. 6's ``a`` they would be domes. :data:`LCSN_PRESETS` stores ``a = -a_table``.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from ._shared import check_choice, check_finite, check_positive

__all__ = ["LCSN_PRESETS", "LcsnParams", "lcsn_degrade", "lcsn_kernel", "lcsn_morphometry",
           "lcsn_raw", "lcsn_scaled"]

#: Raw parameters of each kind, in the order the numba kernels take them.
RAW_KEYS = {1: ("a", "b"), 2: ("a", "b"), 3: ("kappa", "beta", "gamma", "a", "b"),
            4: ("kappa", "beta", "gamma", "a", "b")}
#: Morphometric parameters of each kind.
MORPH_KEYS = {1: ("H_t", "D_a"), 2: ("H_t", "D_a"),
              3: ("H_t", "D_a", "D_rim", "H_rim", "L_d"), 4: ("H_c", "D_rim", "H_rim", "L_d")}
BORDER_THRESHOLD = 0.01  # eq. 16: kernel_4 = 0.01 marks the border of a complex crater
_LN2 = math.log(2.0)
_METHODS = ("closed", "paper", "numeric")


# --------------------------------------------------------------------------- validation
def _kind(kind) -> int:
    if isinstance(kind, bool) or not isinstance(kind, int | float | np.integer) or (
            kind not in RAW_KEYS):
        raise ValueError(f"`kind` must be 1, 2, 3 or 4; got {kind!r}")
    return int(kind)


def _raw(kind: int, raw: dict) -> dict:
    """Check the raw parameters of ``kind``: the right names, finite, in range."""
    keys = RAW_KEYS[kind]
    for name in raw:
        if name not in keys:
            raise ValueError(f"`{name}` does not apply to kind {kind}; its parameters are "
                             f"{', '.join(keys)}")
    out = {}
    for name in keys:
        if name not in raw:
            raise ValueError(f"`{name}` is required for kind {kind} ({', '.join(keys)})")
        value = check_finite(name, raw[name])
        if name in ("b", "beta", "gamma") and value <= 0:
            raise ValueError(f"`{name}` must be > 0; got {value!r}")
        if name == "a" and value < 0:
            raise ValueError(f"`a` must be >= 0 (the bowl depth or uplift height, metres); got "
                             f"{value!r} (Table A.1 lists a negated: pass -a)")
        if name == "kappa" and value < 0:
            raise ValueError(f"`kappa` must be >= 0 (the ring height, metres); got {value!r}")
        out[name] = value
    if kind in (1, 2) and out["a"] == 0:
        raise ValueError("`a` must be > 0 for kinds 1 and 2 (the bowl depth, metres); got 0.0")
    return out


def _ring(r, beta, gamma):
    """The log-normal ring L(r) = exp(-beta (ln(gamma r^2))^2), 0 at r = 0."""
    r = np.asarray(r, dtype=np.float64)
    out = np.zeros_like(r)
    pos = r > 0
    lg = np.log(gamma * r[pos] * r[pos])
    out[pos] = np.exp(-beta * lg * lg)
    return out


def _profile(kind: int, r, p: dict) -> np.ndarray:
    r = np.asarray(r, dtype=np.float64)
    if kind == 1:
        return -p["a"] * np.exp(-p["b"] * r * r)
    if kind == 2:
        return -p["a"] * np.exp(-p["b"] * (r * r) ** 2)
    sign = -1.0 if kind == 3 else 1.0
    return p["kappa"] * _ring(r, p["beta"], p["gamma"]) + sign * p["a"] * np.exp(-p["b"] * r * r)


# --------------------------------------------------------------------------- kernels
def lcsn_kernel(kind: int, r, **raw) -> np.ndarray:
    """Height (metres) of LCSN crater kernel ``kind`` at distance ``r`` (metres).

    Parameters
    ----------
    kind : {1, 2, 3, 4}
        Simple bowl, flat-floored simple crater, fresh crater with rim, complex crater
        with central uplift (module notes).
    r : array_like
        Distances from the impulse, metres, finite and >= 0.
    **raw
        ``a, b`` (kinds 1-2) or ``kappa, beta, gamma, a, b`` (kinds 3-4), all >= 0.

    Examples
    --------
    >>> float(lcsn_kernel(3, 0.0, kappa=16.3, beta=5.0, gamma=4.2e-5, a=55.1, b=9e-5))
    -55.1
    >>> round(float(lcsn_kernel(1, 1.0, a=2.0, b=math.log(2))), 12)
    -1.0
    """
    kind = _kind(kind)
    p = _raw(kind, raw)
    r = np.asarray(r, dtype=np.float64)
    if not np.isfinite(r).all() or (r < 0).any():
        raise ValueError("`r` must be finite and >= 0 (distances in metres)")
    return _profile(kind, r, p)


# --------------------------------------------------------------------------- closed forms
def _lambertw(x: float) -> float:
    from scipy.special import lambertw

    if x < -1.0 / math.e:
        return math.nan
    return float(lambertw(x, 0).real)


def _paper(kind: int, p: dict, threshold: float) -> dict:
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


def _closed(kind: int, p: dict, threshold: float) -> dict:
    """The printed closed forms with their simplifications removed (module notes)."""
    if kind in (1, 2):
        return _paper(kind, p, threshold)  # eq. 4-5 are exact
    printed = _paper(kind, p, threshold)
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


def _numeric(kind: int, p: dict, threshold: float) -> dict:
    def f(x):
        return _profile(kind, np.asarray(x, dtype=np.float64), p)

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
    kind = _kind(kind)
    check_choice("method", method, _METHODS)
    threshold = check_positive("threshold", threshold)
    p = _raw(kind, raw)
    return {"closed": _closed, "paper": _paper, "numeric": _numeric}[method](kind, p, threshold)


# --------------------------------------------------------------------------- inverse
def _morph(kind: int, morph: dict) -> dict:
    keys = MORPH_KEYS[kind]
    for name in morph:
        if name not in keys:
            raise ValueError(f"`{name}` does not apply to kind {kind}; its morphometric "
                             f"parameters are {', '.join(keys)}")
    need = [k for k in keys if k != "L_d"]
    out = {}
    for name in need:
        if name not in morph:
            raise ValueError(f"`{name}` is required for kind {kind}")
        out[name] = check_positive(name, morph[name])
    if "L_d" in morph:
        out["L_d"] = check_positive("L_d", morph["L_d"])
    return out


def _b_from_da(d_a: float, beta: float, gamma: float) -> float:
    """Invert eq. 10 for b: D_a falls from D_rim (b -> 0) to 0 (b -> inf)."""
    from scipy.optimize import brentq

    def g(log_b):
        b = math.exp(log_b)
        return _paper(3, {"kappa": 0.0, "beta": beta, "gamma": gamma, "a": 0.0, "b": b},
                      1.0)["D_a"] - d_a

    return math.exp(brentq(g, math.log(gamma) - 40.0, math.log(gamma) + 40.0, xtol=1e-14))


def _paper_inverse(kind: int, m: dict, beta, b, threshold: float) -> dict:
    if kind in (1, 2):
        q = kind
        fwhm = m["D_a"] / (2.5 if q == 1 else 2.0)
        return {"a": m["H_t"], "b": _LN2 / (fwhm / 2.0) ** (2 * q)}
    gamma = 4.0 / m["D_rim"] ** 2
    r_rim = 0.5 * m["D_rim"]
    if kind == 3:
        if m["D_a"] >= m["D_rim"]:
            raise ValueError(f"`D_a` must be < D_rim ({m['D_rim']!r}) for kind 3 (eq. 10); "
                             f"got {m['D_a']!r}")
        if beta is None:  # numeric inverse from L_d: start from Table A.1's usual beta
            beta = 5.0
        b = _b_from_da(m["D_a"], beta, gamma)
        a = m["H_t"]
        return {"kappa": m["H_rim"] + a * math.exp(-b / gamma), "beta": beta, "gamma": gamma,
                "a": a, "b": b}
    kappa = m["H_rim"]
    if "L_d" in m:
        if kappa <= threshold:
            raise ValueError(f"`H_rim` must be > threshold ({threshold!r}) to give L_d")
        beta = math.log(kappa / threshold) / math.log((m["L_d"] + r_rim) ** 2 * gamma) ** 2
    return {"kappa": kappa, "beta": beta, "gamma": gamma, "a": m["H_c"], "b": b}


def lcsn_raw(kind: int, method: str = "closed", *, beta: float | None = None,
             b: float | None = None, threshold: float = BORDER_THRESHOLD, **morph) -> dict:
    """Raw kernel parameters from morphometric ones: the inverse of :func:`lcsn_morphometry`.

    Kinds 1-2 need ``H_t, D_a``. Kind 3 needs ``H_t, D_a, D_rim, H_rim`` and ``beta``:
    eq. 10-11 depend on b and beta only through b/beta, so the closed ``L_d`` follows
    from D_a and D_rim and cannot fix beta; the measured ``L_d`` can, so
    ``method="numeric"`` also accepts ``L_d`` instead of ``beta``. Kind 4 needs
    ``H_c, D_rim, H_rim``, ``b`` (the uplift's width, which no closed form involves) and
    either ``L_d`` or ``beta``. ``method="paper"`` inverts the printed formulas in
    closed form; ``"closed"`` and ``"numeric"`` start there and solve (least squares in
    log-parameters) until the refined closed-form (``"closed"``) or the *measured*
    (``"numeric"``) morphometry of the result equals the targets to ``_INVERSE_TOL``
    (relative, 1e-8), raising ValueError if the fit finds none. The answer need not be
    unique: at small beta (kind 3, beta < ~1) or when the uplift rather than the ring
    sets the border (kind 4, b < gamma), different kernels share a morphometry, and the
    one returned is the fit's, started from the printed forms' inverse.

    Examples
    --------
    >>> raw = lcsn_raw(1, H_t=1.0, D_a=5 * math.sqrt(math.log(2) / math.pi))
    >>> round(raw["b"], 12) == round(math.pi, 12)  # the unit-area Gaussian of Fig. 6
    True
    >>> p = lcsn_raw(3, "numeric", beta=5.0, H_t=1.0, D_a=1.31, D_rim=2.0, H_rim=0.309)
    >>> {k: round(v, 4) for k, v in p.items()}
    {'kappa': 0.309, 'beta': 5.0, 'gamma': 1.0001, 'a': 1.0, 'b': 11.0821}
    """
    kind = _kind(kind)
    check_choice("method", method, _METHODS)
    threshold = check_positive("threshold", threshold)
    m = _morph(kind, morph)
    if kind in (1, 2):
        if beta is not None or b is not None:
            raise ValueError(f"`beta` and `b` do not apply to the inverse of kind {kind}")
    else:
        if kind == 3 and method != "numeric" and ("L_d" in m or beta is None):
            raise ValueError(f"kind 3 needs `beta` and no `L_d` for method={method!r} (eq. "
                             "10-11 fix only b/beta); give `L_d` with method='numeric'")
        if ("L_d" in m) == (beta is not None):
            raise ValueError(f"kind {kind} needs exactly one of `L_d` or `beta`")
        if beta is not None:
            beta = check_positive("beta", beta)
        if kind == 4:
            if b is None:
                raise ValueError("kind 4 needs `b` (1/m^2), the width of the central uplift")
            b = check_positive("b", b)
        elif b is not None:
            raise ValueError("`b` follows from D_a for kind 3; do not give it")
    beyond = (f"the morphometry {morph!r} is beyond what the kind-{kind} formulas can "
              "evaluate in float64 (b or gamma would overflow or underflow: use lengths in "
              "metres between about 1e-70 and 1e70)")
    try:
        raw = _paper_inverse(kind, m, beta, b, threshold)
        if not (method == "paper" or kind in (1, 2) and method == "closed"):  # eq. 4-5 exact
            raw = _solve_inverse(kind, m, raw, beta, b, threshold, method)
    except (OverflowError, ZeroDivisionError):
        raise ValueError(beyond) from None
    if not all(math.isfinite(v) and v > 0.0 for v in raw.values()):  # b = inf, gamma = 0 ...
        raise ValueError(beyond)
    return raw


_INVERSE_TOL = 1e-8  # relative; flat directions (see lcsn_raw) stop the fit near 1e-9


def _solve_inverse(kind, m, start, beta, b, threshold, method) -> dict:
    from scipy.optimize import least_squares

    measure, what = (_closed, "closed-form") if method == "closed" else (_numeric, "measured")

    free = [k for k in RAW_KEYS[kind]
            if not ((k == "beta" and beta is not None) or (k == "b" and kind == 4))]
    targets = list(m)
    scale = np.array([abs(m[k]) for k in targets])

    def unpack(z):
        raw = dict(start)
        raw.update({k: math.exp(min(v, 700.0)) for k, v in zip(free, z, strict=True)})
        return raw

    def resid(z):
        try:
            got = measure(kind, _raw(kind, unpack(z)), threshold)
        except (ValueError, OverflowError, ZeroDivisionError):  # e.g. beta < 1e-4 (numeric)
            return np.full(len(targets), 10.0)
        vals = np.array([got[k] for k in targets])
        bad = ~np.isfinite(vals)
        vals[bad] = 10.0 * scale[bad]  # a feature that vanished: far from the target
        return (vals - np.array([m[k] for k in targets])) / scale

    z0 = np.array([math.log(max(start[k], 1e-300)) for k in free])
    err = math.inf
    if np.isfinite(z0).all():
        res = least_squares(resid, z0, xtol=1e-15, ftol=1e-15, gtol=1e-15, max_nfev=400)
        err = float(np.max(np.abs(resid(res.x))))
    if err > _INVERSE_TOL:
        raise ValueError(f"found no kind-{kind} kernel with the {what} morphometry "
                         f"{ {k: m[k] for k in targets} } (closest: relative error {err:.2g}; "
                         f"the fit starts from the printed forms' inverse)")
    return unpack(res.x)


# --------------------------------------------------------------------------- degradation
def lcsn_degrade(kind: int, alpha, *, relative: bool = False, **raw) -> dict:
    """Apply a degradation vector (Li 2022 §3.3) and return the new raw parameters.

    Kinds 3-4: ``alpha = (d_kappa, d_gamma, d_a)``; kinds 1-2: ``alpha = d_a`` (a number
    or a 1-tuple). The deltas are added (``kappa + d_kappa``, ...): the paper's vectors
    are negative (a lower rim, a wider rim as gamma falls, a shallower bowl).
    ``relative=True`` reads them as fractions (``kappa (1 + d_kappa)``), as in §4.2's
    "each Gyr alpha = (-0.1 kappa, -0.1 gamma, -0.1 a)". ValueError if a parameter would
    leave its range.

    Examples
    --------
    >>> p = LCSN_PRESETS["fig6-kernel3"].raw
    >>> q = lcsn_degrade(3, (-0.3, -0.4, -0.25), relative=True, **p)   # Fig. 8, fresh
    >>> round(lcsn_morphometry(3, **q)["D_rim"], 3)   # 2 / sqrt(gamma - 0.4 gamma)
    2.582
    """
    kind = _kind(kind)
    p = _raw(kind, raw)
    names = ("a",) if kind in (1, 2) else ("kappa", "gamma", "a")
    vec = np.atleast_1d(np.asarray(alpha, dtype=np.float64))
    if vec.shape != (len(names),) or not np.isfinite(vec).all():
        want = "d_a" if kind in (1, 2) else "(d_kappa, d_gamma, d_a)"
        raise ValueError(f"`alpha` must be {want} (finite) for kind {kind}; got {alpha!r}")
    out = dict(p)
    for name, d in zip(names, vec.tolist(), strict=True):
        out[name] = p[name] * (1.0 + d) if relative else p[name] + d
    for name in names:
        if out[name] < 0 or (name == "gamma" and out[name] <= 0) or (
                name == "a" and kind in (1, 2) and out[name] <= 0):
            raise ValueError(f"`alpha` takes {name} out of range: {p[name]!r} -> {out[name]!r}")
    return out


def lcsn_scaled(kind: int, factor: float, **raw) -> dict:
    """The same crater shape ``factor`` times larger (lengths and heights; d/D kept).

    ``a, kappa`` times factor; ``b`` (kinds 1, 3, 4) and ``gamma`` divided by factor^2,
    ``b`` of kind 2 by factor^4; ``beta`` unchanged. Every morphometric length and
    height scales by ``factor`` (kind 4's ``L_d`` only if the threshold scales too).
    """
    kind = _kind(kind)
    p = _raw(kind, raw)
    s = check_positive("factor", factor)
    out = dict(p)
    out["a"] = p["a"] * s
    out["b"] = p["b"] / s ** (4 if kind == 2 else 2)
    if kind in (3, 4):
        out["kappa"] = p["kappa"] * s
        out["gamma"] = p["gamma"] / (s * s)
    return out


# --------------------------------------------------------------------------- presets
@dataclasses.dataclass(frozen=True, slots=True)
class LcsnParams:
    """A named LCSN kernel: its kind and raw parameters (metres; see the module notes)."""

    kind: int
    """1 simple bowl, 2 flat-floored, 3 fresh with rim, 4 complex with central uplift."""
    a: float
    """Bowl depth (kinds 1-3) or uplift height (kind 4), >= 0, metres."""
    b: float
    """Width of the Gaussian term, 1/m^2 (kind 2: 1/m^4), > 0."""
    kappa: float = 0.0
    """Ring (rim) height, metres, >= 0 (kinds 3-4)."""
    beta: float = 0.0
    """Ring sharpness, dimensionless, > 0 (kinds 3-4)."""
    gamma: float = 0.0
    """Ring position: the ring peaks at r = 1/sqrt(gamma); 1/m^2, > 0 (kinds 3-4)."""
    description: str = ""
    """Where the numbers come from."""

    def __post_init__(self):
        _raw(_kind(self.kind), self.raw)

    @property
    def raw(self) -> dict:
        """The raw parameters as keyword arguments of :func:`lcsn_kernel`."""
        return {k: getattr(self, k) for k in RAW_KEYS[self.kind]}

    def morphometry(self, method: str = "closed") -> dict:
        """:func:`lcsn_morphometry` of this kernel."""
        return lcsn_morphometry(self.kind, method, **self.raw)


def _table_rows() -> dict[str, LcsnParams]:
    rows = {  # diameter, age: kappa, beta, gamma, a (as printed, signed), b
        ("300m", 0): (16.3, 5.0, 0.000042, -55.1, 0.00009),
        ("300m", 1): (1.5, 5.0, 0.000042, -8.1, 0.00007),
        ("300m", 2): (0.7, 5.0, 0.000042, -5.1, 0.00005),
        ("300m", 3): (0.0, 5.0, 0.000042, -2.4, 0.00003),
        ("1km", 0): (40.3, 5.0, 0.0000045, -180.1, 0.000016),
        ("1km", 1): (15.3, 5.0, 0.0000045, -142.1, 0.000016),
        ("1km", 2): (3.3, 5.0, 0.0000045, -120.1, 0.000016),
        ("1km", 3): (1.3, 5.0, 0.0000045, -110.1, 0.000016),
        ("3km", 0): (190.3, 7.0, 0.00000045, -563.1, 0.00000088),
        ("3km", 1): (175.3, 5.5, 0.00000045, -558.1, 0.00000088),
        ("3km", 2): (172.3, 5.2, 0.00000045, -553.1, 0.00000088),
        ("3km", 3): (169.3, 4.9, 0.00000045, -548.1, 0.00000088),
    }
    return {f"table-a1-{d}-{age}gyr": LcsnParams(
        3, a=-a, b=b, kappa=k, beta=bt, gamma=g,
        description=f"Li et al. 2022 Table A.1, {d} crater at {age} Gyr (Fassett & Thomson "
                    f"2014 degradation); printed a = {a} (signed), bowl depth {-a} m")
        for (d, age), (k, bt, g, a, b) in rows.items()}


#: Named kernels. ``table-a1-<D>-<age>gyr``: the twelve kernel_3 rows of Li et al. 2022
#: Table A.1 (metres; ``a = -a_table``). ``fig6-kernel<k>``: the normalised profiles of
#: Fig. 6, rebuilt from the caption's morphometry: kernel 1 the unit-area Gaussian
#: (``H_t = 1``, ``D_a = 5 sqrt(ln 2/pi)``: b = pi); kernel 2 ``H_t = 1``,
#: ``D_a = 4 sqrt(ln 2/pi)`` (b = pi^2/ln 2); kernel 3 ``H_t = 1, D_a = 1.31,
#: D_rim = 2, H_rim = 0.309`` measured, with Table A.1's usual beta = 5
#: (``lcsn_raw(3, "numeric", beta=5, ...)``); kernel 4 ``H_c = 0.2, D_rim = 2,
#: H_rim = 0.471`` measured, with kernel 3's beta and b (the caption gives neither).
LCSN_PRESETS: dict[str, LcsnParams] = {
    **_table_rows(),
    "fig6-kernel1": LcsnParams(1, a=1.0, b=math.pi,
                               description="Li 2022 Fig. 6 simple crater 1 (normalised)"),
    "fig6-kernel2": LcsnParams(2, a=1.0, b=math.pi**2 / _LN2,
                               description="Li 2022 Fig. 6 simple crater 2 (normalised)"),
    "fig6-kernel3": LcsnParams(3, a=1.0, b=11.08212495520453, kappa=0.3090153895909925,
                               beta=5.0, gamma=1.0000551840631648,
                               description="Li 2022 Fig. 6 fresh crater (normalised)"),
    "fig6-kernel4": LcsnParams(4, a=0.2, b=11.08212495520453, kappa=0.4709969231460819,
                               beta=5.0, gamma=0.9999927643928281,
                               description="Li 2022 Fig. 6 complex crater (normalised)"),
}
