"""Crater degradation as topographic diffusion (Fassett & Thomson 2014).

A crater of age T is its fresh profile (:mod:`craters.morphology`) evolved by the
diffusion equation dh/dt = kappa lap(h) for the time T: the rim, the profile's shortest
wavelength, goes first; the bowl shallows; an old crater is a shallow rimless dimple and
in the limit no relief is left. Lunar diffusivity (Fassett & Thomson 2014, JGR Planets
119, 2255; the D-scaling of Fassett & Thomson 2015): kappa = 5.5e-6 m^2/yr at D = 1 km,
times (D / 1 km)^0.9 (:class:`~craters.Target` holds it per body).

The radial problem is solved exactly (no time stepping) in Hankel space: an
axisymmetric profile h(r) has the transform H(k) and ``h(r, t) = int H(k) exp(-kappa k^2 t)
J0(k r) k dk``. On the quasi-discrete Hankel transform of Guizar-Sicairos & Gutierrez-Vega
(2004, JOSA A 21, 53) - nodes at the zeros of J0 out to ``DOMAIN`` crater radii, where the
profile is held at 0, an orthogonal symmetric matrix - the evolution is two matrix
products with a diagonal in between, in the dimensionless time tau = kappa t / R^2.

Stamping needs the profile at every pixel of thousands of craters, so profiles are made
on a grid of (log D, log tau) nodes (3 % in D, 12 % in tau), once per target and shared
by every crater that falls between the nodes (bilinear in log D and log tau): "cached per
D and kappa t". A crater with tau below ``TAU_FRESH`` is evaluated fresh, exactly.

``degradation`` in the catalogs is what this leaves of the fresh depth,
``1 - depth(tau) / depth(0)`` (0 fresh ... 1 gone); a layer that fixes it (an explicit
override) gets the tau that removes that share of its depth, and ``degradation = 1``
leaves no relief at all.
"""

from __future__ import annotations

import functools
import math

import numpy as np

from ._diffusion_kernels import _blend_tables
from ._shared import ParameterError
from .exact import matmul
from .morphology import EJECTA_EDGE, fresh_morphometry, fresh_profile
from .targets import Target, get_target

__all__ = ["DOMAIN", "N_TABLE", "TAU_FRESH", "diffuse_profiles", "diffusion_age_gyr",
           "kappa_m2_yr", "profile_tables", "tau_from_age", "tau_from_degradation"]

#: Radius of the diffusion domain, in crater radii (the profile is 0 beyond).
DOMAIN = 6.0
#: Quasi-discrete Hankel transform nodes.
N_NODES = 256
#: Samples of a stamping table over [0, ejecta edge].
N_TABLE = 256
#: Below this tau = kappa t / R^2 a crater is stamped fresh (its rim has moved less
#: than a hundredth of a radius).
TAU_FRESH = 1e-5
_TAU_MAX = 30.0
_D_STEP = 1.03
_TAU_STEP = 1.12
SECONDS_PER_YEAR = 365.25 * 86400.0


def kappa_m2_yr(diameter_m, target: str | Target = "moon") -> np.ndarray:
    """Topographic diffusivity of craters of ``diameter_m`` on ``target``, m^2/yr.

    Examples
    --------
    >>> float(kappa_m2_yr(1000.0))
    5.5e-06
    """
    t = get_target(target)
    d = np.asarray(diameter_m, dtype=np.float64)
    return t.kappa_1km_m2_yr * (d / 1000.0) ** t.kappa_exponent


def diffusion_age_gyr(age_gyr, target: str | Target = "moon") -> np.ndarray:
    """The time a crater of age ``age_gyr`` has diffused for at the calibrated rate, Gyr.

    Topographic diffusion on an airless body is impact gardening, so its rate follows
    the impact flux (Fassett & Thomson 2014 measured kappa as the mean over mare surfaces
    of ~3.5 Gyr, the flux of which was not constant). With a target's
    ``flux_clock`` the time counts impacts, not years: ``T_c N1(T) / N1(T_c)``, N1 the
    chronology's cumulative density of craters >= 1 km and T_c the
    ``kappa_calibration_gyr`` the diffusivity was measured at. A crater of 3.5 Gyr
    diffuses exactly ``kappa T`` as before; younger ones less (the flux was lower), one of
    3.9 Gyr 6.9x as long (the late heavy flux): 40-100 km craters of 3.9 Gyr keep 0.92 of
    their fresh depth (median) and of 4.2 Gyr 0.77, against 0.95 for Nectarian and 0.60
    for pre-Nectarian craters measured on LOLA (``measure_old_craters_lola.py``); a
    constant rate left both at 0.96. Without a clock, ``age_gyr`` itself.

    Examples
    --------
    >>> [round(float(v), 2) for v in diffusion_age_gyr([1.0, 3.5, 3.9])]
    [0.61, 3.5, 24.1]
    """
    t = get_target(target)
    age = np.asarray(age_gyr, dtype=np.float64)
    if (age < 0).any() or not np.isfinite(age).all():
        raise ParameterError("age_gyr", "must be finite and >= 0")
    if t.flux_clock is None:
        return age
    from .chronology import get_chronology_system  # here: the chronology tables are large

    n1 = get_chronology_system(t.flux_clock).chronology.n1
    return t.kappa_calibration_gyr * np.asarray(n1(age)) / float(n1(t.kappa_calibration_gyr))


def tau_from_age(diameter_m, age_gyr, target: str | Target = "moon") -> np.ndarray:
    """Dimensionless diffusion time ``kappa(D) T' / R^2`` of craters of age ``age_gyr``,
    ``T'`` the flux-paced time :func:`diffusion_age_gyr`.

    Examples
    --------
    >>> round(float(tau_from_age(1000.0, 3.5)), 4)
    0.077
    """
    d = np.asarray(diameter_m, dtype=np.float64)
    return kappa_m2_yr(d, target) * diffusion_age_gyr(age_gyr, target) * 1e9 / (0.5 * d) ** 2


@functools.lru_cache(maxsize=4)
def _qdht(n: int, domain: float):
    """Nodes (crater radii), wavenumbers (1/radii) and the orthogonal transform matrix."""
    from scipy.special import j0, j1, jn_zeros  # here: importing scipy loads argparse

    alpha = jn_zeros(0, n + 1)
    s = alpha[-1]
    a = alpha[:-1]
    j1a = np.abs(j1(a))
    t = 2.0 * j0(np.outer(a, a) / s) / (np.outer(j1a, j1a) * s)
    r = a * domain / s
    k = a / domain
    scale = domain / j1a  # f(r_n) times this is the transform's own vector
    return r, k, t, scale


def diffuse_profiles(profiles: np.ndarray, tau) -> np.ndarray:
    """Evolve axisymmetric profiles sampled at the transform's nodes by dimensionless
    times ``tau`` (one per row; module notes). Rows are heights at
    ``diffusion_nodes()``; the result is at the same nodes."""
    r, k, t, scale = _qdht(N_NODES, DOMAIN)
    tau = np.asarray(tau, dtype=np.float64).reshape(-1, 1)
    spec = matmul(profiles * scale, t.T)
    spec *= np.exp(-(k[None, :] ** 2) * tau)
    return matmul(spec, t.T) / scale


def diffusion_nodes() -> np.ndarray:
    """Radii (in crater radii) where :func:`diffuse_profiles` samples a profile."""
    return _qdht(N_NODES, DOMAIN)[0]


def _taper(x, xe):
    """1 inside, falling smoothly to 0 over the outer fifth of the ejecta span."""
    t = np.clip((xe - x) / (0.2 * (xe - 1.0)), 0.0, 1.0)
    return t * t * (3.0 - 2.0 * t)


@functools.lru_cache(maxsize=4)
def _to_table(xe: float) -> np.ndarray:
    """(N_NODES, N_TABLE): a spectrum (the transform's own vector) to the table's heights,
    times the edge taper: the Fourier-Bessel series of the transform evaluated at the
    table's radii, ``h(x) = sum_m 2 J0(k_m x) F_m / (|J1(a_m)| S DOMAIN)`` (equal to the
    inverse transform at its nodes, and smooth between them: linear resampling from the
    nodes, 0.023 radii apart, left slope steps that showed as rings in low-sun close-ups
    of worn craters)."""
    from scipy.special import j0, j1, jn_zeros

    alpha = jn_zeros(0, N_NODES + 1)
    s, a = alpha[-1], alpha[:-1]
    k = a / DOMAIN
    x = np.linspace(0.0, xe, N_TABLE)
    m = 2.0 * j0(np.outer(k, x)) / (np.abs(j1(a)) * s * DOMAIN)[:, None]
    return np.ascontiguousarray(m * _taper(x, xe)[None, :])


def _node_tables(target: Target, d_nodes: np.ndarray, tau_nodes: np.ndarray, xe: float,
                 rows_d: np.ndarray | None = None, rows_tau: np.ndarray | None = None):
    """Diffused profiles divided by each node's fresh depth, as float32 shapes that the
    stamping interpolates between nodes: (len(d), len(tau), N_TABLE) for every pair, or,
    given ``rows_d`` / ``rows_tau`` (indices into ``d_nodes`` / ``tau_nodes``), only those
    pairs, (len(rows_d), N_TABLE)."""
    r, k, t, scale = _qdht(N_NODES, DOMAIN)
    fresh = fresh_profile(r, d_nodes, target, ejecta_edge=xe)            # (nd, N)
    fresh /= fresh_morphometry(d_nodes, target)["depth_m"][:, None]
    spec = matmul(fresh * scale, t.T)                                     # (nd, N)
    decay = np.exp(-np.outer(tau_nodes, k**2))                            # (nt, N)
    if rows_d is None:
        nd, nt = len(d_nodes), len(tau_nodes)
        evolved = matmul((spec[:, None, :] * decay[None]).reshape(nd * nt, -1), _to_table(xe))
        return evolved.reshape(nd, nt, -1).astype(np.float32)
    return matmul(spec[rows_d] * decay[rows_tau], _to_table(xe)).astype(np.float32)


class _Cache:
    """Diffused shapes of one target on the (log D, log tau) node grid, made on demand:
    per D node, the tau nodes up to the largest one a crater has needed."""

    def __init__(self, target: Target, xe: float):
        self.target, self.xe = target, xe
        self.tau_nodes = np.exp(np.arange(math.log(TAU_FRESH), math.log(_TAU_MAX)
                                          + math.log(_TAU_STEP), math.log(_TAU_STEP)))
        self.rows: dict[int, np.ndarray] = {}  # D node index -> (n_tau, N_TABLE)
        self.done: dict[int, int] = {}  # D node index -> tau nodes made so far

    def stack(self, idx: np.ndarray, upto: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(shapes of the D nodes ``idx`` stacked, position of each idx in the stack),
        each with at least its tau nodes below ``upto`` (same length as idx) made."""
        need = np.unique(idx)
        top = np.zeros(len(need), dtype=np.int64)
        np.maximum.at(top, np.searchsorted(need, idx), upto)
        rows_d, rows_tau, owners = [], [], []
        for slot, (i, hi) in enumerate(zip(need.tolist(), top.tolist(), strict=True)):
            lo = self.done.get(i, 0)
            if hi > lo:
                rows_d.append(np.full(hi - lo, slot))
                rows_tau.append(np.arange(lo, hi))
                owners.append((i, lo, hi))
        if owners:
            made = _node_tables(self.target, _D_STEP ** need.astype(np.float64),
                                self.tau_nodes, self.xe, np.concatenate(rows_d),
                                np.concatenate(rows_tau))
            at = 0
            for i, lo, hi in owners:
                if i not in self.rows:
                    self.rows[i] = np.zeros((len(self.tau_nodes), N_TABLE), np.float32)
                self.rows[i][lo:hi] = made[at:at + hi - lo]
                self.done[i] = hi
                at += hi - lo
        return np.stack([self.rows[int(i)] for i in need]), np.searchsorted(need, idx)


@functools.lru_cache(maxsize=16)
def _cache(target: Target, xe: float) -> _Cache:
    return _Cache(target, xe)


def profile_tables(diameter_m, tau, target: str | Target = "moon", *,
                   ejecta_edge: float = EJECTA_EDGE) -> np.ndarray:
    """Stamping tables: heights (metres, relative to the pre-impact surface) of each
    crater at ``N_TABLE`` radii evenly over [0, ejecta_edge] (crater radii), fresh or
    diffused by ``tau`` (module notes). Returns (n, N_TABLE) float64.

    Examples
    --------
    >>> tab = profile_tables([1000.0, 1000.0], [0.0, 0.05])
    >>> depth = tab.max(axis=1) - tab.min(axis=1)
    >>> round(float(depth[0])), bool(depth[1] < depth[0])
    (196, True)
    """
    t = get_target(target)
    d = np.atleast_1d(np.asarray(diameter_m, dtype=np.float64))
    tau = np.broadcast_to(np.asarray(tau, dtype=np.float64), d.shape)
    if not np.isfinite(tau).all() or (tau < 0).any():
        raise ParameterError("tau", "must be finite and >= 0")
    x = np.linspace(0.0, ejecta_edge, N_TABLE)
    out = np.zeros((len(d), N_TABLE))
    fresh = tau < TAU_FRESH
    if fresh.any():
        out[fresh] = fresh_profile(x, d[fresh], t, ejecta_edge=ejecta_edge)
    old = np.flatnonzero(~fresh & (tau < _TAU_MAX))  # beyond _TAU_MAX: no relief left
    if len(old):
        cache = _cache(t, float(ejecta_edge))
        ld = np.log(d[old]) / math.log(_D_STEP)
        i0 = np.floor(ld).astype(np.int64)
        fd = ld - i0
        lt = np.log(tau[old] / TAU_FRESH) / math.log(_TAU_STEP)
        j0 = np.clip(np.floor(lt).astype(np.int64), 0, len(cache.tau_nodes) - 2)
        ft = np.clip(lt - j0, 0.0, 1.0)
        upto = np.minimum(j0 + 2, len(cache.tau_nodes))
        stack, pos = cache.stack(np.concatenate([i0, i0 + 1]), np.concatenate([upto, upto]))
        a, b = pos[:len(old)], pos[len(old):]
        _blend_tables(stack, a, b, j0, fd, ft, fresh_morphometry(d[old], t)["depth_m"], old,
                      out)
    return out


def tau_from_degradation(diameter_m, degradation, target: str | Target = "moon", *,
                         ejecta_edge: float = EJECTA_EDGE) -> np.ndarray:
    """The tau at which craters of ``diameter_m`` keep ``1 - degradation`` of their fresh
    depth (``degradation = 1``: the largest tau, no relief)."""
    t = get_target(target)
    d = np.atleast_1d(np.asarray(diameter_m, dtype=np.float64))
    deg = np.broadcast_to(np.asarray(degradation, dtype=np.float64), d.shape)
    if not np.isfinite(deg).all() or (deg < 0).any() or (deg > 1).any():
        raise ParameterError("degradation", "must be in [0, 1]")
    taus = np.concatenate([[0.0], np.exp(np.linspace(math.log(TAU_FRESH),
                                                       math.log(_TAU_MAX * 0.99), 160))])
    out = np.empty(len(d))
    for k, (dk, gk) in enumerate(zip(d.tolist(), deg.tolist(), strict=True)):
        if gk <= 0.0:
            out[k] = 0.0
            continue
        if gk >= 1.0:
            out[k] = _TAU_MAX
            continue
        tabs = profile_tables(np.full(len(taus), dk), taus, t, ejecta_edge=ejecta_edge)
        depth = tabs.max(axis=1) - tabs.min(axis=1)
        kept = depth / depth[0]
        out[k] = float(np.interp(1.0 - gk, kept[::-1], taus[::-1]))
    return out
