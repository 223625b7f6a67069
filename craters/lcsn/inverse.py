"""Raw LCSN kernel parameters from morphometric ones: the inverse of
:func:`craters.lcsn_morphometry`."""

from __future__ import annotations

import math

import numpy as np

from .._shared import check_choice, check_positive
from .kernel import BORDER_THRESHOLD, MORPH_KEYS, RAW_KEYS, check_kind, check_names, check_raw
from .morphometry import METHODS, morphometry_closed, morphometry_numeric, morphometry_paper

__all__ = ["lcsn_raw"]

_LN2 = math.log(2.0)


# --------------------------------------------------------------------------- inverse
def _morph(kind: int, morph: dict) -> dict:
    keys = MORPH_KEYS[kind]
    need = [k for k in keys if k != "L_d"]
    check_names(kind, morph, keys, "morphometric parameters", need)
    out = {}
    for name in need:
        out[name] = check_positive(name, morph[name])
    if "L_d" in morph:
        out["L_d"] = check_positive("L_d", morph["L_d"])
    return out


def _b_from_da(d_a: float, beta: float, gamma: float) -> float:
    """Invert eq. 10 for b: D_a falls from D_rim (b -> 0) to 0 (b -> inf)."""
    from scipy.optimize import brentq

    def g(log_b):
        b = math.exp(log_b)
        return morphometry_paper(3, {"kappa": 0.0, "beta": beta, "gamma": gamma, "a": 0.0, "b": b},
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
    kind = check_kind(kind)
    check_choice("method", method, METHODS)
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

    measure, what = ((morphometry_closed, "closed-form") if method == "closed" else
                     (morphometry_numeric, "measured"))

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
            got = measure(kind, check_raw(kind, unpack(z)), threshold)
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
