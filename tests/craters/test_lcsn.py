"""LCSN crater kernels (Li et al. 2022 §3.2-3.3): formulas, morphometry, inverse, presets."""

from __future__ import annotations

import math

import numpy as np
import pytest

import craters
from craters._lcsn_kernels import _lcsn_heights_kernel
from craters.lcsn import MORPH_KEYS, RAW_KEYS

PRESETS = craters.LCSN_PRESETS
NUMERIC_TOL = 0.01  # numeric morphometry vs an independent dense-sampling measurement
CLOSED_TOL = 0.05  # the acceptance bound for the closed forms
FRESH = ["table-a1-300m-0gyr", "table-a1-1km-0gyr", "table-a1-3km-0gyr"]
FIG6 = ["fig6-kernel1", "fig6-kernel2", "fig6-kernel3", "fig6-kernel4"]


def reference_profile(kind, r, p):
    """The kernels written out directly from eq. 3, 6 and 12."""
    with np.errstate(divide="ignore"):
        ring = np.where(r > 0, np.exp(-p.get("beta", 1) * np.log(p.get("gamma", 1) * r**2) ** 2),
                        0.0)
    if kind == 1:
        return -p["a"] * np.exp(-p["b"] * r**2)
    if kind == 2:
        return -p["a"] * np.exp(-p["b"] * r**4)
    return p["kappa"] * ring + (1 if kind == 4 else -1) * p["a"] * np.exp(-p["b"] * r**2)


def dense_measurement(kind, p, threshold=0.01):
    """Morphometry read off 2 million uniform samples: no root finding, no refinement."""
    if kind in (1, 2):
        span = 8.0 * p["b"] ** (-1.0 / (2 * kind))
    else:
        span = 8.0 / math.sqrt(p["gamma"])
    r = np.linspace(0.0, span, 2_000_001)
    h = reference_profile(kind, r, p)

    def first(mask, start=0.0):
        idx = np.flatnonzero(mask[:-1] != mask[1:])
        idx = idx[r[idx] >= start]
        if not idx.size:
            return math.nan
        i = idx[0]  # linear interpolation between the two samples
        return float(r[i] + (r[i + 1] - r[i]) * (0 - h[i]) / (h[i + 1] - h[i])) if (
            h[i + 1] != h[i]) else float(r[i])

    if kind in (1, 2):
        depth = -h.min()
        i = np.flatnonzero(h > -depth / 2)[0]
        half = r[i - 1] + (r[i] - r[i - 1]) * (-depth / 2 - h[i - 1]) / (h[i] - h[i - 1])
        return {"H_t": depth, "D_a": (2.5 if kind == 1 else 2.0) * 2 * half}
    peaks = np.flatnonzero((h[1:-1] > h[:-2]) & (h[1:-1] >= h[2:])) + 1  # the crest: the
    near = np.argmin(np.abs(np.log(r[peaks] * math.sqrt(p["gamma"])))) if peaks.size else 0
    crest = r[peaks[near]] if peaks.size else math.nan  # one nearest the ring's peak
    out = {"D_rim": 2 * crest, "H_rim": h[peaks[near]] if peaks.size else math.nan}
    if kind == 3:
        out["H_t"] = -h.min()
        inner = first(h >= 0)
        out["D_a"] = 2 * inner if inner < crest else math.nan
        out["L_d"] = first(h >= 0, crest) - crest if peaks.size else math.nan
    else:
        out["H_c"] = h[0]
        shifted = h - threshold
        idx = np.flatnonzero((shifted[:-1] >= 0) & (shifted[1:] < 0) & (r[:-1] >= crest))
        out["L_d"] = r[idx[0]] - crest if idx.size else math.nan
    if not peaks.size:
        out["D_rim"] = out["H_rim"] = math.nan
    return out


def rel(a, b):
    return abs(a - b) / abs(b)


# --------------------------------------------------------------------------- kernels
@pytest.mark.parametrize("name", sorted(PRESETS))
def test_kernel_matches_the_equations(name):
    p = PRESETS[name]
    r = np.linspace(0.0, 6.0, 601) * p.morphometry("paper")["D_rim" if p.kind > 2 else "D_a"]
    got = craters.lcsn_kernel(p.kind, r, **p.raw)
    np.testing.assert_allclose(got, reference_profile(p.kind, r, p.raw), rtol=1e-13,
                               atol=1e-15 * p.a)


def compiled(kind, r, raw):
    """The numba definition (``craters.kernels.lcsn_height``) over an array."""
    full = {"kappa": 0.0, "beta": 0.0, "gamma": 0.0, **raw}
    params = np.array([full[k] for k in ("kappa", "beta", "gamma", "a", "b")])
    out = np.empty_like(r)
    _lcsn_heights_kernel(kind, r, params, out)
    return out


@pytest.mark.parametrize("name", sorted(PRESETS))
def test_compiled_kernel_matches_the_equations(name):
    p = PRESETS[name]
    r = np.linspace(0, 4 * p.morphometry("paper")["D_rim" if p.kind > 2 else "D_a"], 999)
    want = reference_profile(p.kind, r, p.raw)
    np.testing.assert_allclose(compiled(p.kind, r, p.raw), want, rtol=1e-13, atol=1e-14 * p.a)
    np.testing.assert_allclose(craters.lcsn_kernel(p.kind, r, **p.raw), want, rtol=1e-13,
                               atol=1e-14 * p.a)


@pytest.mark.parametrize("kind", [1, 2, 3, 4])
def test_numpy_callers_get_the_compiled_bits(kind, rng):
    # one definition of the formulas: craters.lcsn_kernel evaluates the numba one, so the
    # implicit backend's kernels and numpy callers agree bit for bit, any shape of r
    for _ in range(20):
        raw = {"a": rng.uniform(0.01, 100.0), "b": 10.0 ** rng.uniform(-8, 1)}
        if kind > 2:
            raw.update(kappa=rng.uniform(0.0, 2.0) * raw["a"], beta=rng.uniform(0.5, 20.0),
                       gamma=raw["b"] * 10.0 ** rng.uniform(-1, 1))
        raw = {k: raw[k] for k in RAW_KEYS[kind]}
        scale = raw["b"] ** (-1.0 / (2 if kind != 2 else 4))
        r = rng.uniform(0.0, 6.0, 5000) * scale
        assert np.array_equal(compiled(kind, r, raw), craters.lcsn_kernel(kind, r, **raw))
        grid = r[:4000].reshape(40, 100)
        assert np.array_equal(craters.lcsn_kernel(kind, grid, **raw),
                              compiled(kind, r[:4000], raw).reshape(40, 100))


def test_kernel_values():
    k3 = PRESETS["table-a1-300m-0gyr"].raw
    assert craters.lcsn_kernel(3, 0.0, **k3) == -55.1  # L(0) = 0: the floor is -a
    k4 = PRESETS["fig6-kernel4"].raw
    assert craters.lcsn_kernel(4, 0.0, **k4) == pytest.approx(0.2)  # the central uplift
    # the ring peaks at 1/sqrt(gamma) with height kappa
    ring = craters.lcsn_kernel(4, 1 / math.sqrt(k4["gamma"]), **{**k4, "a": 0.0})
    assert ring == pytest.approx(k4["kappa"], rel=1e-14)


# --------------------------------------------------------------------------- morphometry
@pytest.mark.parametrize("name", sorted(PRESETS))
def test_numeric_agrees_with_independent_measurement(name):
    p = PRESETS[name]
    got = p.morphometry("numeric")
    want = dense_measurement(p.kind, p.raw)
    assert set(got) == set(MORPH_KEYS[p.kind])
    for key, value in got.items():
        if math.isnan(want[key]):
            assert math.isnan(value), key
        else:
            assert rel(value, want[key]) < NUMERIC_TOL, (key, value, want[key])


@pytest.mark.parametrize("name", FRESH)
def test_closed_forms_on_fresh_table_rows(name):
    """The acceptance asks for 5 % (CLOSED_TOL); measured: below 1e-5 for every quantity
    (asserted 1e-4, twenty times inside the 0.5 % verification window)."""
    p = PRESETS[name]
    closed, numeric = p.morphometry("closed"), p.morphometry("numeric")
    assert closed["H_t"] == numeric["H_t"] == p.a
    for key, value in closed.items():
        if math.isnan(numeric[key]):
            assert math.isnan(value), key  # 1 km: the flank never returns to the datum
        else:
            assert rel(value, numeric[key]) < 1e-4 < CLOSED_TOL, (key, value, numeric[key])


@pytest.mark.parametrize("name", FRESH)
def test_printed_forms_on_fresh_table_rows(name):
    """As printed, eq. 9-11 put the crest at 1/sqrt(gamma) and assume kappa = a: D_a
    8-11 % short, L_d ~50 % long on Table A.1 (kappa = 0.22-0.34 a), D_rim 2-4 % short,
    H_rim 1-5.3 % low (measured)."""
    p = PRESETS[name]
    printed, numeric = p.morphometry("paper"), p.morphometry("numeric")
    assert printed["D_rim"] == pytest.approx(2 / math.sqrt(p.gamma))
    assert printed["H_rim"] == pytest.approx(p.kappa - p.a * math.exp(-p.b / p.gamma))
    assert printed["H_t"] == p.a
    assert 0.02 < rel(printed["D_rim"], numeric["D_rim"]) < 0.04
    assert 0.01 < rel(printed["H_rim"], numeric["H_rim"]) < 0.053
    assert 0.08 < rel(printed["D_a"], numeric["D_a"]) < 0.11
    if math.isfinite(numeric["L_d"]):
        assert 0.5 < rel(printed["L_d"], numeric["L_d"]) < 0.53


# Measured closed-form errors of the degraded rows (golden values, not bounds in
# principle): the shallow 1 Gyr 300 m rim (17 cm) has L_d 1.4 % long; 1 km at 3 Gyr keeps
# a 6 cm crest that three steps from 1/sqrt(gamma) do not reach within 0.5 %, so closed
# declines it (NaN) while numeric measures it.
TABLE_GOLDEN_TOL = {"table-a1-300m-1gyr": 0.015, "table-a1-1km-2gyr": 3e-4}
CLOSED_DECLINES = {"table-a1-1km-3gyr": {"D_a", "D_rim", "H_rim"}}


@pytest.mark.parametrize("name", [k for k in PRESETS if k.startswith("table-a1")])
def test_closed_forms_on_every_table_row(name):
    p = PRESETS[name]
    closed, numeric = p.morphometry("closed"), p.morphometry("numeric")
    declined = CLOSED_DECLINES.get(name, set())
    for key, value in closed.items():
        if key in declined:
            assert math.isnan(value) and math.isfinite(numeric[key]), key
            continue
        assert math.isnan(value) == math.isnan(numeric[key]), key
        if math.isfinite(value):
            tol = TABLE_GOLDEN_TOL.get(name, 1e-4)
            assert rel(value, numeric[key]) < tol, (key, value, numeric[key])


@pytest.mark.parametrize("name", FIG6)
def test_closed_forms_on_fig6_cases(name):
    p = PRESETS[name]
    closed, numeric = p.morphometry("closed"), p.morphometry("numeric")
    for key, value in closed.items():
        if math.isnan(numeric[key]):
            assert math.isnan(value), key  # fig6-kernel3: the flank never returns to 0
        else:
            assert rel(value, numeric[key]) < CLOSED_TOL, (key, value, numeric[key])


def test_fig6_caption_values():
    m1 = PRESETS["fig6-kernel1"].morphometry("numeric")
    assert m1["D_a"] == pytest.approx(5 * math.sqrt(math.log(2)) / math.sqrt(math.pi))
    m2 = PRESETS["fig6-kernel2"].morphometry("numeric")
    assert m2["D_a"] == pytest.approx(4 * math.sqrt(math.log(2)) / math.sqrt(math.pi))
    m3 = PRESETS["fig6-kernel3"].morphometry("numeric")
    assert [m3[k] for k in ("H_t", "D_a", "D_rim", "H_rim")] == pytest.approx(
        [1.0, 1.31, 2.0, 0.309], rel=1e-9)
    m4 = PRESETS["fig6-kernel4"].morphometry("numeric")
    assert [m4[k] for k in ("H_c", "D_rim", "H_rim")] == pytest.approx([0.2, 2.0, 0.471],
                                                                      rel=1e-9)


@pytest.mark.parametrize("method", ["paper", "closed"])
@pytest.mark.parametrize("beta,gamma,b", [(5.0, 1.0, 0.7), (0.5, 4.0, 1.5), (7.0, 4.5e-7, 9e-7)])
def test_eq10_eq11_are_exact_when_kappa_equals_a(beta, gamma, b, method):
    """With kappa = a the Lambert-W roots are exact and the refinement leaves them."""
    raw = {"kappa": 3.0, "beta": beta, "gamma": gamma, "a": 3.0, "b": b}
    closed = craters.lcsn_morphometry(3, method, **raw)
    numeric = craters.lcsn_morphometry(3, "numeric", **raw)
    assert closed["D_a"] == pytest.approx(numeric["D_a"], rel=1e-9)
    if math.isfinite(numeric["L_d"]):  # compare the outer zero crossing itself
        crest = 1 / math.sqrt(gamma) if method == "paper" else closed["D_rim"] / 2
        outer_numeric = numeric["L_d"] + numeric["D_rim"] / 2
        assert closed["L_d"] + crest == pytest.approx(outer_numeric, rel=1e-9)


def random_kernels(rng, kind, n):
    """``n`` kernels with a distinct rim (kind 3: at least 5 % of the depth), log-uniform
    in kappa/a 0.05-2, beta 0.5-20, b/gamma 0.1-10, and their measured morphometry."""
    out = []
    while len(out) < n:
        raw = {"kappa": 10 ** rng.uniform(math.log10(0.05), math.log10(2.0)),
               "beta": 10 ** rng.uniform(math.log10(0.5), math.log10(20.0)), "gamma": 1.0,
               "a": 1.0, "b": 10 ** rng.uniform(-1.0, 1.0)}
        numeric = craters.lcsn_morphometry(kind, "numeric", **raw)
        if kind == 4 and math.isfinite(numeric["H_rim"]) or (
                kind == 3 and numeric["H_rim"] > 0.05 * numeric["H_t"]):
            out.append((raw, numeric))
    return out


@pytest.mark.parametrize("kind", [3, 4])
def test_closed_forms_on_random_kernels(kind):
    """Away from Table A.1 (300 kernels per kind). Every finite closed value exists in the
    measured profile and is within the 0.5 % verification window (radii; H_rim at the
    refined crest closer still), L_d within 7 %; closed declines (NaN) where numeric
    measures for under 2 % of the quantities. Measured (1000 per kind, other seeds):
    worst D_rim 0.5 %, D_a 0.07 %, L_d 1.6 %; declined 0.3 % (kind 3) / 0.5 % (kind 4,
    mostly an uplift wider than the rim). The printed forms' median error is ~10 %."""
    rng = np.random.default_rng(kind)
    worst, paper_worst, declined, total = [], [], 0, 0
    for raw, numeric in random_kernels(rng, kind, 300):
        closed = craters.lcsn_morphometry(kind, **raw)
        printed = craters.lcsn_morphometry(kind, "paper", **raw)
        errs = []
        for key, value in closed.items():
            if math.isfinite(value):
                assert math.isfinite(numeric[key]), (key, raw, closed, numeric)
                errs.append(rel(value, numeric[key]))
                bound = 0.07 if key == "L_d" else 0.0051
                assert rel(value, numeric[key]) < bound, (key, raw, value, numeric[key])
            elif math.isfinite(numeric[key]):
                declined += 1
            total += math.isfinite(numeric[key])
        worst.append(max(errs))
        paper_worst.append(max(rel(printed[k], numeric[k]) for k in numeric
                               if math.isfinite(printed[k]) and math.isfinite(numeric[k])))
    assert np.median(worst) < 1e-5
    assert declined < 0.02 * total, (declined, total)
    assert np.median(paper_worst) > 0.05


@pytest.mark.parametrize("kind", [3, 4])
def test_closed_forms_never_raise(kind):
    """Over 9-12 decades of every raw parameter the formulas give numbers or NaN (a Newton
    step that runs away, an overflowing radius), never an exception or a length <= 0."""
    rng = np.random.default_rng(kind)
    for _ in range(1500):
        raw = {"kappa": 10 ** rng.uniform(-6, 4) * (rng.random() > 0.05),
               "beta": 10 ** rng.uniform(-7, 2), "gamma": 10 ** rng.uniform(-9, 3),
               "a": 10 ** rng.uniform(-6, 4) * (rng.random() > 0.05),
               "b": 10 ** rng.uniform(-9, 3)}
        for method in ("closed", "paper"):
            out = craters.lcsn_morphometry(kind, method, **raw)
            for key in ("D_a", "D_rim", "L_d"):
                if key in out:
                    assert math.isnan(out[key]) or out[key] > 0, (method, raw, out)


def dlnr(f, s, h=1e-4):
    """First and second derivative of f(e^s) by central differences."""
    return ((f(math.exp(s + h)) - f(math.exp(s - h))) / (2 * h),
            (f(math.exp(s + h)) - 2 * f(math.exp(s)) + f(math.exp(s - h))) / h**2)


@pytest.mark.parametrize("name", ["table-a1-300m-0gyr", "table-a1-3km-1gyr", "fig6-kernel4"])
def test_refinement_matches_a_plain_newton_reference(name):
    """The closed forms' steps written out independently from the profile itself: three
    Newton steps in s = ln r with derivatives by finite differences, from 1/sqrt(gamma)
    (crest), eq. 10's root (D_a, kind 3) and eq. 16's root (border, kind 4)."""
    p = PRESETS[name]
    printed, closed = p.morphometry("paper"), p.morphometry()

    def f(r):
        return float(reference_profile(p.kind, np.array(r), p.raw))

    s = math.log(0.5 * printed["D_rim"])
    for _ in range(3):
        d1, d2 = dlnr(f, s)
        s -= d1 / d2
    assert closed["D_rim"] == pytest.approx(2 * math.exp(s), rel=1e-6)
    crest = s
    if p.kind == 3:
        s = math.log(0.5 * printed["D_a"])
        g = lambda r: math.log(p.kappa / p.a) - p.beta * math.log(p.gamma * r * r) ** 2 + (  # noqa: E731
            p.b * r * r)
        for _ in range(3):
            s -= g(math.exp(s)) / dlnr(g, s)[0]
        assert closed["D_a"] == pytest.approx(2 * math.exp(s), rel=1e-6)
    else:
        s = math.log(printed["L_d"] + 0.5 * printed["D_rim"])
        for _ in range(3):
            s -= (math.log(f(math.exp(s))) - math.log(0.01)) / dlnr(
                lambda r: math.log(f(r)), s)[0]
        assert closed["L_d"] == pytest.approx(math.exp(s) - math.exp(crest), rel=1e-6)


def test_degraded_rows_without_a_rim():
    p = PRESETS["table-a1-300m-3gyr"]  # kappa = 0: a bare Gaussian, never reaches 0
    numeric = p.morphometry("numeric")
    assert numeric["H_t"] == pytest.approx(2.4)
    assert all(math.isnan(numeric[k]) for k in ("D_a", "D_rim", "H_rim", "L_d"))
    printed = p.morphometry("paper")
    assert printed["H_rim"] < 0 and math.isfinite(printed["D_a"])  # formulas still evaluate
    closed = p.morphometry("closed")  # no maximum, so no rim and no datum crossing
    assert all(math.isnan(closed[k]) for k in ("D_a", "D_rim", "H_rim", "L_d"))
    # 1 km at 2 Gyr: a crest survives (1.17 m) though eq. 7 says -0.13 m
    m = PRESETS["table-a1-1km-2gyr"].morphometry("numeric")
    assert m["H_rim"] == pytest.approx(1.1664, abs=1e-4)
    assert PRESETS["table-a1-1km-2gyr"].morphometry("paper")["H_rim"] < 0
    assert PRESETS["table-a1-1km-2gyr"].morphometry()["H_rim"] == pytest.approx(1.1664,
                                                                                abs=1e-3)


def test_rim_below_the_datum_and_the_ring_tail():
    """A rim 0.32 below the datum: far out, where the bowl has died away, the ring's
    tail leaves a local maximum ~1e-21 high. The crest is the maximum nearest the ring's
    peak (not that speck), and with the rim under the datum there is no D_a or L_d."""
    raw = {"kappa": 0.405, "beta": 1.756, "gamma": 1.0, "a": 1.0, "b": 0.29}
    r = np.geomspace(1.0, 40.0, 20001)
    h = craters.lcsn_kernel(3, r, **raw)
    tail = r[np.flatnonzero((h[1:-1] > h[:-2]) & (h[1:-1] >= h[2:])) + 1]
    assert tail.max() > 10 and h.max() < 1e-15  # the speck exists
    for method in ("numeric", "closed"):
        m = craters.lcsn_morphometry(3, method, **raw)
        assert m["D_rim"] == pytest.approx(2.19207, abs=1e-5)
        assert m["H_rim"] == pytest.approx(-0.32406, abs=1e-5)
        assert math.isnan(m["D_a"]) and math.isnan(m["L_d"])


@pytest.mark.parametrize("call", [
    lambda: craters.lcsn_raw(3, beta=5.0, H_t=1e160, D_a=1e160, D_rim=2e160, H_rim=1e159),
    lambda: craters.lcsn_raw(2, H_t=1.0, D_a=1e80),
    lambda: craters.lcsn_raw(1, "closed", H_t=1.0, D_a=1e-160),
])
def test_extreme_scales_are_a_value_error(call):
    with pytest.raises(ValueError, match="beyond what the kind-"):
        call()


def test_table_a1_goldens():
    """The measured 0 Gyr profiles: realistic fresh craters (d/D ~ 0.19, rim ~0.035 D)."""
    for name, d_rim, h_rim, d_a in (("table-a1-300m-0gyr", 321.1266, 10.3790, 268.0006),
                                    ("table-a1-1km-0gyr", 962.3778, 35.5294, 766.7536),
                                    ("table-a1-3km-0gyr", 3066.8167, 114.9845, 2630.9317)):
        m = PRESETS[name].morphometry("numeric")
        assert [m["D_rim"], m["H_rim"], m["D_a"]] == pytest.approx([d_rim, h_rim, d_a],
                                                                   abs=1e-3)
        assert 0.17 < m["H_t"] / m["D_rim"] < 0.19
        assert 0.03 < m["H_rim"] / m["D_rim"] < 0.04


# --------------------------------------------------------------------------- inverse
@pytest.mark.parametrize("method", ["closed", "paper"])
@pytest.mark.parametrize("name", [*FRESH, *FIG6])
def test_inverse_round_trip(name, method):
    p = PRESETS[name]
    closed = p.morphometry(method)
    extra = {}
    if p.kind == 3:
        extra = {"beta": p.beta}
        closed.pop("L_d")
    elif p.kind == 4:
        extra = {"b": p.b}
    raw = craters.lcsn_raw(p.kind, method, **extra, **closed)
    for key, value in p.raw.items():
        assert raw[key] == pytest.approx(value, rel=1e-9), key


@pytest.mark.parametrize("kind", [3, 4])
def test_closed_inverse_on_random_kernels(kind):
    """lcsn_raw(kind, "closed") on 80 random kernels' closed morphometry: a kernel with
    that morphometry to 1e-8, or a ValueError naming the closest error - never another
    exception. Measured (300 per kind): 2 % (kind 3) and 5 % (kind 4) ValueErrors; the
    kernel returned is not always the original (flat directions, see lcsn_raw)."""
    rng = np.random.default_rng(10 + kind)
    failed = tried = 0
    for raw, _ in random_kernels(rng, kind, 80):
        m = {k: v for k, v in craters.lcsn_morphometry(kind, **raw).items()
             if math.isfinite(v)}
        if "D_rim" not in m or kind == 3 and "D_a" not in m:
            continue
        extra = {"b": raw["b"]}
        if kind == 3 or tried % 2:  # kind 4: every other one gives L_d instead of beta
            m.pop("L_d", None)
            extra = {"beta": raw["beta"]} if kind == 3 else {**extra, "beta": raw["beta"]}
        elif "L_d" not in m:
            continue
        tried += 1
        try:
            got = craters.lcsn_raw(kind, **extra, **m)
        except ValueError as exc:
            assert "closest: relative error" in str(exc)
            failed += 1
            continue
        again = craters.lcsn_morphometry(kind, **got)
        assert all(rel(again[k], m[k]) <= 1e-8 for k in m), (raw, got, m, again)
    assert tried > 50 and failed <= 0.1 * tried, (failed, tried)


@pytest.mark.parametrize("name", ["table-a1-300m-0gyr", "table-a1-3km-0gyr", "fig6-kernel4"])
def test_numeric_inverse_recovers_the_kernel(name):
    p = PRESETS[name]
    m = p.morphometry("numeric")
    extra = {"beta": p.beta} if p.kind == 3 else {"b": p.b}
    if p.kind == 3:
        m.pop("L_d")
    raw = craters.lcsn_raw(p.kind, "numeric", **extra, **m)
    for key, value in p.raw.items():
        assert raw[key] == pytest.approx(value, rel=1e-6), key


def test_inverse_with_l_d():
    p = PRESETS["table-a1-3km-0gyr"]  # beta = 7: the measured L_d pins it
    raw = craters.lcsn_raw(3, "numeric", **p.morphometry("numeric"))
    assert raw["beta"] == pytest.approx(p.beta, rel=1e-6)
    k4 = PRESETS["fig6-kernel4"]
    raw4 = craters.lcsn_raw(4, b=k4.b, **k4.morphometry())
    assert raw4["beta"] == pytest.approx(k4.beta, rel=1e-9)


# --------------------------------------------------------------------------- degradation
def test_degradation_vector_fig8():
    p = PRESETS["fig6-kernel3"].raw
    q = craters.lcsn_degrade(3, (-0.3, -0.4, -0.25), relative=True, **p)
    assert q["kappa"] == pytest.approx(0.7 * p["kappa"])
    assert q["a"] == pytest.approx(0.75)
    m0, m1 = (craters.lcsn_morphometry(3, "numeric", **x) for x in (p, q))
    assert m1["D_rim"] > m0["D_rim"] and m1["H_rim"] < m0["H_rim"] and m1["H_t"] < m0["H_t"]
    absolute = craters.lcsn_degrade(3, (-0.05, -0.2, -0.1), **PRESETS["fig6-kernel4"].raw)
    assert absolute["gamma"] == pytest.approx(PRESETS["fig6-kernel4"].gamma - 0.2)
    simple = craters.lcsn_degrade(1, -0.6, **PRESETS["fig6-kernel1"].raw)
    assert simple["a"] == pytest.approx(0.4) and simple["b"] == math.pi


def test_scaled_shapes_scale_every_measure():
    p = PRESETS["table-a1-1km-0gyr"]
    m0 = p.morphometry("numeric")
    m1 = craters.lcsn_morphometry(3, "numeric", **craters.lcsn_scaled(3, 0.1, **p.raw))
    for key in ("H_t", "D_a", "D_rim", "H_rim"):
        assert m1[key] == pytest.approx(0.1 * m0[key], rel=1e-9)
    k2 = craters.lcsn_scaled(2, 3.0, **PRESETS["fig6-kernel2"].raw)
    assert craters.lcsn_morphometry(2, **k2)["D_a"] == pytest.approx(3 * 1.8789, rel=1e-4)


# --------------------------------------------------------------------------- errors
@pytest.mark.parametrize("call,match", [
    (lambda: craters.lcsn_kernel(5, 1.0, a=1.0, b=1.0), "`kind`"),
    (lambda: craters.lcsn_kernel(1.5, 1.0, a=1.0, b=1.0), "`kind`"),
    (lambda: craters.lcsn_kernel(3, 1.0, a=55.1, b=1.0, beta=5.0, gamma=1.0), "`kappa`"),
    (lambda: craters.lcsn_kernel(1, 1.0, a=1.0, b=1.0, gamma=2.0), "`gamma`"),
    (lambda: craters.lcsn_kernel(3, 1.0, kappa=1.0, beta=5.0, gamma=1.0, a=-55.1, b=1.0),
     "Table A.1"),
    (lambda: craters.lcsn_kernel(1, 1.0, a=1.0, b=0.0), "`b`"),
    (lambda: craters.lcsn_kernel(1, 1.0, a=1.0, b=math.inf), "`b`"),
    (lambda: craters.lcsn_kernel(1, -1.0, a=1.0, b=1.0), "`r`"),
    (lambda: craters.lcsn_morphometry(1, "exact", a=1.0, b=1.0), "`method`"),
    (lambda: craters.lcsn_morphometry(4, threshold=0, **PRESETS["fig6-kernel4"].raw),
     "`threshold`"),
    (lambda: craters.lcsn_raw(3, H_t=1.0, D_a=1.0, D_rim=2.0, H_rim=0.3), "`beta`"),
    (lambda: craters.lcsn_raw(3, "numeric", H_t=1.0, D_a=1.0, D_rim=2.0, H_rim=0.3),
     "`L_d` or `beta`"),
    (lambda: craters.lcsn_raw(3, beta=5.0, H_t=1.0, D_a=3.0, D_rim=2.0, H_rim=0.3), "`D_a`"),
    (lambda: craters.lcsn_raw(4, beta=5.0, H_c=0.2, D_rim=2.0, H_rim=0.4), "`b`"),
    (lambda: craters.lcsn_raw(1, H_t=1.0, D_rim=2.0), "`D_rim`"),
    (lambda: craters.lcsn_raw(1, H_t=-1.0, D_a=2.0), "`H_t`"),
    (lambda: craters.lcsn_degrade(3, (-0.1, -2.0, 0.0), **PRESETS["fig6-kernel3"].raw),
     "`alpha`"),
    (lambda: craters.lcsn_degrade(3, (-0.1, 0.0), **PRESETS["fig6-kernel3"].raw), "`alpha`"),
    (lambda: craters.lcsn_scaled(1, 0.0, a=1.0, b=1.0), "`factor`"),
    (lambda: craters.LcsnParams(3, a=1.0, b=1.0), "`beta`"),
    (lambda: craters.lcsn_morphometry(3, "numeric", kappa=1.0, beta=1e-5, gamma=1.0, a=1.0,
                                      b=1.0), "`beta` must be >= 0.0001"),  # was OverflowError
])
def test_bad_input_names_the_parameter(call, match):
    with pytest.raises(ValueError, match=match):
        call()


def test_unreachable_numeric_inverse():
    with pytest.raises(ValueError, match="found no kind-3 kernel"):
        craters.lcsn_raw(3, "numeric", beta=5.0, H_t=1.0, D_a=1.99, D_rim=2.0, H_rim=0.001)
