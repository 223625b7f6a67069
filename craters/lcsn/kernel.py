"""The four LCSN crater kernels of Li et al. (2022, §3.2-3.3), their parameters,
degradation and scaling.

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

The formulas are written once, in numba (:mod:`craters._lcsn_kernels`; for kernels of
other packages ``craters.kernels.lcsn_height``); :func:`lcsn_kernel` evaluates them
through it.
"""

from __future__ import annotations

import numpy as np

from .._lcsn_kernels import _lcsn_heights_kernel
from .._shared import check_finite, check_positive

__all__ = ["BORDER_THRESHOLD", "MORPH_KEYS", "RAW_KEYS", "check_kind", "check_names",
           "check_raw", "kernel_heights", "lcsn_degrade", "lcsn_kernel", "lcsn_scaled"]

#: Raw parameters of each kind, in the order the numba kernels take them.
RAW_KEYS = {1: ("a", "b"), 2: ("a", "b"), 3: ("kappa", "beta", "gamma", "a", "b"),
            4: ("kappa", "beta", "gamma", "a", "b")}
#: Morphometric parameters of each kind.
MORPH_KEYS = {1: ("H_t", "D_a"), 2: ("H_t", "D_a"),
              3: ("H_t", "D_a", "D_rim", "H_rim", "L_d"), 4: ("H_c", "D_rim", "H_rim", "L_d")}
BORDER_THRESHOLD = 0.01  # eq. 16: kernel_4 = 0.01 marks the border of a complex crater


# --------------------------------------------------------------------------- validation
def check_kind(kind) -> int:
    """``kind`` as an int after checking it is 1, 2, 3 or 4 (ValueError otherwise)."""
    if isinstance(kind, bool) or not isinstance(kind, int | float | np.integer) or (
            kind not in RAW_KEYS):
        raise ValueError(f"`kind` must be 1, 2, 3 or 4; got {kind!r}")
    return int(kind)


def check_names(kind: int, given, keys, what: str, required) -> None:
    """Every name of ``given`` is one of ``keys`` (the ``what`` of ``kind``) and every
    name of ``required`` is given."""
    for name in given:
        if name not in keys:
            raise ValueError(f"`{name}` does not apply to kind {kind}; its {what} are "
                             f"{', '.join(keys)}")
    for name in required:
        if name not in given:
            raise ValueError(f"`{name}` is required for kind {kind} ({', '.join(keys)})")


def check_raw(kind: int, raw: dict) -> dict:
    """Check the raw parameters of ``kind``: the right names, finite, in range."""
    keys = RAW_KEYS[kind]
    check_names(kind, raw, keys, "parameters", keys)
    out = {}
    for name in keys:
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


def kernel_heights(kind: int, r, p: dict) -> np.ndarray:
    """Heights (metres) of kernel ``kind`` at distances ``r`` (metres) for raw parameters
    ``p`` already checked by :func:`check_raw`; no validation (:func:`lcsn_kernel` is the
    checked form). Evaluated by the one definition of the formulas,
    ``craters.kernels.lcsn_height`` (numba), so numpy callers and compiled kernels get
    the same bits."""
    r = np.asarray(r, dtype=np.float64)
    flat = np.ascontiguousarray(r).reshape(-1)
    params = np.array([p.get(k, 0.0) for k in ("kappa", "beta", "gamma", "a", "b")])
    out = np.empty_like(flat)
    _lcsn_heights_kernel(int(kind), flat, params, out)
    return out.reshape(r.shape)


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
    >>> import math
    >>> round(float(lcsn_kernel(1, 1.0, a=2.0, b=math.log(2))), 12)
    -1.0
    """
    kind = check_kind(kind)
    p = check_raw(kind, raw)
    r = np.asarray(r, dtype=np.float64)
    if not np.isfinite(r).all() or (r < 0).any():
        raise ValueError("`r` must be finite and >= 0 (distances in metres)")
    return kernel_heights(kind, r, p)


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
    >>> from craters import LCSN_PRESETS, lcsn_morphometry
    >>> p = LCSN_PRESETS["fig6-kernel3"].raw
    >>> q = lcsn_degrade(3, (-0.3, -0.4, -0.25), relative=True, **p)   # Fig. 8, fresh
    >>> round(lcsn_morphometry(3, **q)["D_rim"], 3)   # 2 / sqrt(gamma - 0.4 gamma)
    2.582
    """
    kind = check_kind(kind)
    p = check_raw(kind, raw)
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
    kind = check_kind(kind)
    p = check_raw(kind, raw)
    s = check_positive("factor", factor)
    out = dict(p)
    out["a"] = p["a"] * s
    out["b"] = p["b"] / s ** (4 if kind == 2 else 2)
    if kind in (3, 4):
        out["kappa"] = p["kappa"] * s
        out["gamma"] = p["gamma"] / (s * s)
    return out
