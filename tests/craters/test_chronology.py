"""Production functions, chronologies, equilibrium: coefficients against craterstats'
file, values against craterstats and closed forms, sampling against the laws."""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest
from scipy import stats

import craters
from craters.chronology import (
    CHRONOLOGY_SYSTEMS,
    EQUILIBRIUM_FUNCTIONS,
    cap_at_equilibrium,
    cumulative_density,
    equilibrium_bin_edges,
    equilibrium_caps,
    equilibrium_density,
    formation_ages,
    get_chronology_system,
    sample_pf_diameters,
    saturation_diameter_m,
)

FUNCTIONS = Path(__file__).parents[1] / "data" / "craterstats" / "functions.txt"


def _entries(kind: str) -> dict[str, dict]:
    """``kind={ name='...' coefficients=*[...] range=[...] }`` blocks of functions.txt."""
    text = FUNCTIONS.read_text(encoding="utf-8-sig")
    out = {}
    for block in re.findall(rf"^{kind}=\{{(.*?)^\}}", text, re.S | re.M):
        name = re.search(r"name=['\"](.*?)['\"]\s*$", block, re.M)
        coef = re.search(r"coefficients=\*?\[(.*?)\]", block)
        rng = re.search(r"range=\[(.*?)\]", block)
        if name and coef:
            out[name.group(1)] = {
                "coefficients": [float(v) for v in coef.group(1).split(",")],
                "range": [float(v) for v in rng.group(1).split(",")] if rng else None}
    return out


@pytest.mark.parametrize("key", list(CHRONOLOGY_SYSTEMS))
def test_coefficients_are_craterstats(key):
    system = CHRONOLOGY_SYSTEMS[key]
    pf = _entries("production")[system.production.name]
    cf = _entries("chronology")[system.chronology.name]
    assert list(system.production.coefficients) == pf["coefficients"]
    assert list(system.production.d_range_km) == pf["range"]
    assert list(system.chronology.coefficients) == cf["coefficients"]
    systems = re.findall(r"chronology_system=\{(.*?)\}", FUNCTIONS.read_text("utf-8-sig"), re.S)
    mine = [s for s in systems if re.search(rf"name=['\"]{re.escape(system.title)}['\"]", s)]
    assert len(mine) == 1
    assert f"pf='{system.production.name}'" in mine[0]
    assert f"cf='{system.chronology.name}'" in mine[0]


@pytest.mark.parametrize("key", list(EQUILIBRIUM_FUNCTIONS))
def test_equilibrium_coefficients_are_craterstats(key):
    eq = EQUILIBRIUM_FUNCTIONS[key]
    ref = _entries("equilibrium")[eq.name]
    assert list(eq.coefficients) == ref["coefficients"]
    assert list(eq.d_range_km) == ref["range"]


def test_moon_n1_closed_form():
    """Neukum (1983) / Neukum et al. (2001): N(1 km) = 5.44e-14 (e^(6.93 T) - 1) + 8.38e-4 T."""
    cf = CHRONOLOGY_SYSTEMS["moon"].chronology
    for t in (1.0, 3.8):
        assert float(cf.n1(t)) == pytest.approx(5.44e-14 * math.expm1(6.93 * t) + 8.38e-4 * t,
                                                rel=1e-14)
    assert float(cf.n1(1.0)) == pytest.approx(8.38e-4, rel=1e-6)     # 1 Gyr: the linear term
    assert float(cf.n1(3.8)) == pytest.approx(1.8054e-2, rel=1e-4)   # 3.8 Gyr: 20x that
    t = np.linspace(0.01, 4.5, 50)
    assert np.allclose(cf.age_gyr(cf.n1(t)), t, atol=1e-10)


# craterstats 3.2.1: Productionfn(...).C(D, Chronologyfn(...).a0(T)) per km^2 at D = 0.1, 1,
# 10, 100 km (values outside a function's range left out)
CRATERSTATS_VALUES = {
    ("moon-neukum-1983", 1.0): [2.8352736219e+00, 8.3800005557e-04, 2.1255003334e-06,
                                2.4510556253e-08],
    ("moon-neukum-1983", 3.8): [6.1084780312e+01, 1.8054359516e-02, 4.5793012680e-05,
                                5.2806964819e-07],
    ("moon", 1.0): [2.9050636179e+00, 8.3800005557e-04, 4.6048813801e-06, 5.7816426767e-08],
    ("moon", 3.8): [6.2588376486e+01, 1.8054359516e-02, 9.9210236816e-05, 1.2456306510e-06],
    ("mars", 1.0): [1.7995089911e+00, 4.8750003289e-04, 6.9667602744e-06, 5.1037795743e-08],
    ("mars", 3.8): [3.9327865761e+01, 1.0654203978e-02, 1.5225698466e-04, 1.1154195892e-06],
    ("mars-ivanov-2001", 3.8): [3.2834270056e+01, 8.8950418203e-03, 1.2711716884e-04,
                                9.3124778856e-07],
    ("mercury-strom-neukum-1988", 1.0): [5.7745738233e+00, 1.8180001211e-03,
                                         3.3925865644e-06, 4.7044388504e-08],
    ("mercury", 3.8): [6.8403036749e+01, 2.0731452407e-02, 8.7197887582e-05,
                       1.5985823214e-06],
    ("vesta", 1.0): [2.8802855645e+01, 1.9794856047e-02, 2.0216694472e-04, 4.7717617084e-07],
    ("ceres", 3.8): [2.6293764156e+03, 1.2578969589e+00, 6.0479575074e-03, 7.6330772769e-05],
    ("ida", 1.0): [2.7497902915e+01, 2.4354127049e-02, 2.9893499354e-04, 4.0316376255e-06],
    ("gaspra", 3.8): [1.0420084354e+03, 8.7464340244e-01, 7.9955855387e-03, 1.6491680492e-04],
    ("lutetia", 1.0): [3.6112700809e+01, 3.1546543939e-02, 3.6832676893e-04, 4.4308319482e-06],
    ("phobos-som", 3.8): [2.2092496536e+01, 1.7423535541e-02, 8.9547238121e-05],
    ("phobos-mba", 1.0): [7.6223101658e+01, 6.1939220720e-02, 4.8190325200e-04],
}


@pytest.mark.parametrize(("key", "age"), list(CRATERSTATS_VALUES))
def test_production_function_reproduces_craterstats(key, age):
    want = CRATERSTATS_VALUES[(key, age)]
    d_m = np.array([100.0, 1000.0, 10000.0, 100000.0])[:len(want)]
    got = cumulative_density(key, age, d_m) * 1e6
    np.testing.assert_allclose(got, want, rtol=1e-9)


def test_pf_slope_is_the_log_derivative():
    pf = CHRONOLOGY_SYSTEMS["moon"].production
    d = np.geomspace(0.02, 200.0, 40)
    h = 1e-6
    num = (pf.shape_log10(d * 10**h) - pf.shape_log10(d * 10**-h)) / (2 * h)
    np.testing.assert_allclose(pf.slope(d), num, atol=1e-6)


@pytest.mark.parametrize("key", ["moon", "mars", "vesta"])
def test_sampled_sfd_follows_the_production_function(key):
    """The cumulative count of sampled diameters matches the PF within Poisson error."""
    la = craters.ModelAgeLayer(key, 3.5, 500.0, 50000.0)
    area = 2e4 / la.cumulative_m2(500.0)      # about 20 000 craters
    d, ages = la.draw(area, rng=7)
    for edge in (700.0, 1000.0, 2000.0, 5000.0, 15000.0):
        want = la.expected_count(area, edge, 50000.0)
        got = int((d >= edge).sum())
        assert abs(got - want) < 4.0 * math.sqrt(want) + 1, (edge, got, want)
    assert ages.min() >= 0 and ages.max() <= 3.5


def test_diameters_within_range_and_deterministic():
    a = sample_pf_diameters(5000, "moon", 10.0, 300000.0, rng=3)
    b = sample_pf_diameters(5000, "moon", 10.0, 300000.0, rng=3)
    assert a.min() >= 10.0 and a.max() <= 300000.0 and np.array_equal(a, b)
    ks = stats.kstest(np.log10(sample_pf_diameters(20000, "mars", 1000.0, 30000.0, rng=1)),
                      lambda x: _pf_cdf("mars", 1000.0, 30000.0, 10.0**np.asarray(x)))
    assert ks.pvalue > 1e-3


def _pf_cdf(key, lo, hi, d):
    n = cumulative_density(key, 1.0, np.array([lo, hi]))
    return (n[0] - cumulative_density(key, 1.0, d)) / (n[0] - n[1])


@pytest.mark.parametrize("age", [1.0, 3.8])
def test_formation_ages_follow_the_flux(age):
    """P(age <= t) = N1(t) / N1(T): most craters of an old surface are almost as old."""
    cf = CHRONOLOGY_SYSTEMS["moon"].chronology
    a = formation_ages(40000, "moon", age, rng=2)
    ks = stats.kstest(a, lambda t: cf.n1(np.asarray(t)) / cf.n1(age))
    assert ks.pvalue > 1e-3
    if age == 3.8:   # 73 % of the craters of a 3.8 Gyr surface formed before 3.5 Gyr ago
        want = 1 - float(cf.n1(3.5) / cf.n1(3.8))
        assert want == pytest.approx(0.7345, abs=1e-3)
        assert (a > 3.5).mean() == pytest.approx(want, abs=0.01)
    else:            # 1 Gyr: nearly constant flux, ages nearly uniform
        assert a.mean() == pytest.approx(0.5, abs=0.01)


def test_saturation_diameter():
    ds = saturation_diameter_m("moon", 3.8, "trask")
    assert 300.0 < ds < 600.0
    assert float(cumulative_density("moon", 3.8, ds)) == pytest.approx(
        float(equilibrium_density("trask", ds)), rel=1e-9)
    ages = [0.5, 1.0, 2.0, 3.0, 3.8, 4.2]
    sat = [saturation_diameter_m("moon", t, "hartmann") for t in ages]
    assert all(a < b for a, b in zip(sat, sat[1:], strict=False))   # older: saturated larger
    assert saturation_diameter_m("moon", 1e-4, "trask") is None       # 100 kyr: nowhere


def test_caps_only_where_saturated_and_unbiased():
    edges, caps = equilibrium_caps("moon", 3.8, "trask", 1e9, 100.0, 2000.0, rng=1)
    centres = np.sqrt(edges[:-1] * edges[1:])
    ds = saturation_diameter_m("moon", 3.8, "trask")
    # incremental saturation (ΔN_pf > ΔN_eq per bin) starts a little above the cumulative
    # crossing: the production function is steeper than the equilibrium
    assert (caps[centres < ds] >= 0).all() and (caps[centres > 2.0 * ds] == -1).all()
    pf = cumulative_density("moon", 3.8, edges)
    eqd = equilibrium_density("trask", edges)
    assert np.array_equal(caps >= 0, pf[:-1] - pf[1:] > eqd[:-1] - eqd[1:])
    eq = equilibrium_density("trask", edges) * 1e9
    want = eq[:-1] - eq[1:]
    assert np.all(np.abs(caps[caps >= 0] - want[caps >= 0]) < 1)
    # on a small area the cap is below one crater a bin: rounded at random, unbiased
    draws = np.array([equilibrium_caps("moon", 3.8, "trask", 1e5, 100.0, 200.0, rng=s)[1]
                      for s in range(2000)])
    eq = equilibrium_density("trask", edges[:1]) * 1e5
    small = equilibrium_density("trask", equilibrium_bin_edges(100.0, 200.0)) * 1e5
    np.testing.assert_allclose(draws.mean(axis=0), small[:-1] - small[1:], atol=0.05)


def test_cap_keeps_the_youngest_up_to_the_cap():
    rng = np.random.default_rng(5)
    d = 10.0 ** rng.uniform(2.0, 3.0, 20000)
    a = rng.uniform(0.0, 3.8, 20000)
    edges = equilibrium_bin_edges(100.0, 1000.0)
    caps = rng.integers(-1, 3000, len(edges) - 1)
    keep = cap_at_equilibrium(d, a, edges, caps)
    for b in range(len(caps)):
        inb = (d >= edges[b]) & (d < edges[b + 1])
        n_keep = int((keep & inb).sum())
        assert n_keep == (inb.sum() if caps[b] < 0 else min(int(inb.sum()), int(caps[b])))
        if 0 < n_keep < inb.sum():      # the removed are all older than the kept
            assert a[keep & inb].max() <= a[~keep & inb].min()


def test_equilibrium_draw_equals_draw_all_then_cap():
    """The order-statistics draw (survivors only) has the distribution of drawing every
    produced crater and removing the oldest beyond the cap."""
    la = craters.ModelAgeLayer("moon", 3.8, 100.0, 200.0, equilibrium="trask")
    plain = craters.ModelAgeLayer("moon", 3.8, 100.0, 200.0)
    area = 1e7
    fast = [la.draw(area, rng=s) for s in range(40)]
    slow = []
    for s in range(40):
        d, a = plain.draw(area, rng=1000 + s)
        edges, caps = equilibrium_caps("moon", 3.8, "trask", area, 100.0, 200.0, rng=s)
        keep = cap_at_equilibrium(d, a, edges, caps)
        slow.append((d[keep], a[keep]))
    n_fast = np.array([len(d) for d, _ in fast])
    n_slow = np.array([len(d) for d, _ in slow])
    assert n_fast.mean() == pytest.approx(n_slow.mean(), rel=0.01)
    assert n_fast.mean() == pytest.approx(la.expected_count(area), rel=0.01)
    assert n_fast.mean() < 0.2 * plain.expected_count(area)       # saturated: most erased
    ks = stats.ks_2samp(np.concatenate([a for _, a in fast]),
                        np.concatenate([a for _, a in slow]))
    assert ks.pvalue > 1e-3
    ks = stats.ks_2samp(np.concatenate([d for d, _ in fast]),
                        np.concatenate([d for d, _ in slow]))
    assert ks.pvalue > 1e-3


def test_expected_count_with_equilibrium_is_the_survivors():
    la = craters.ModelAgeLayer("moon", 3.8, 100.0, 2000.0, equilibrium="hartmann")
    area = 5e7
    counts = [len(la.draw(area, rng=s)[0]) for s in range(30)]
    assert np.mean(counts) == pytest.approx(la.expected_count(area), rel=0.01)
    plain = craters.ModelAgeLayer("moon", 3.8, 100.0, 2000.0)
    assert la.expected_count(area) < plain.expected_count(area)
    # above the saturation diameter the cap takes nothing, whatever the area
    big = craters.ModelAgeLayer("moon", 3.8, 1000.0, 2000.0, equilibrium="hartmann")
    assert big.saturation_diameter_m < 1000.0
    for area in (5e5, 5e7, 5e9):
        assert big.expected_count(area) == pytest.approx(
            craters.ModelAgeLayer("moon", 3.8, 1000.0, 2000.0).expected_count(area), rel=1e-9)


def test_systems_lookup():
    assert get_chronology_system("mars").title == "Mars, Neukum-Ivanov (2001)"
    assert get_chronology_system("mars").chronology.name == "Mars, Hartmann & Neukum (2001)"
    assert get_chronology_system("moon").d_range_m == (10.0, 300000.0)
    with pytest.raises(ValueError, match="`npf` must be one of moon"):
        get_chronology_system("pluto")


def test_expected_survivors_equal_scipy_stats_poisson():
    """The Poisson tails from scipy.special (no scipy.stats import) give the same numbers
    as scipy.stats.poisson, caps below 2 and lambda = 0 included."""
    from scipy.stats import poisson

    from craters.chronology.sampling import expected_survivors

    rng = np.random.default_rng(1)
    lam = np.concatenate([rng.uniform(0, 50, 300), [0.0, 1e-9, 1e4, 3.0]])
    want = np.concatenate([rng.uniform(0, 60, 300), [0.0, 2.5, 3e3, 0.4]])
    lo = np.floor(want)
    f = want - lo

    def e_min(c):
        return lam * poisson.cdf(c - 2, lam) + c * poisson.sf(c - 1, lam)

    np.testing.assert_array_equal(expected_survivors(lam, want),
                                  (1 - f) * e_min(lo) + f * e_min(lo + 1))
