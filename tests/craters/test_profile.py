"""Crater morphology on real bodies and degradation by diffusion, against published laws
and an independent numerical solution."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import craters
from craters import crater_morphometry, fresh_morphometry, radial_profile


def pike_simple(d_km):
    """Pike (1977) fresh lunar simple craters: depth, rim height (km; D in km)."""
    return 0.196 * d_km**1.010, 0.036 * d_km**1.014


def pike_complex(d_km):
    """Pike (1977) fresh lunar complex craters: depth, rim height (km; D in km)."""
    return 1.044 * d_km**0.301, 0.236 * d_km**0.399


@pytest.mark.parametrize("d_km,law", [(0.5, pike_simple), (1.0, pike_simple),
                                      (5.0, pike_simple), (30.0, pike_complex),
                                      (100.0, pike_complex)])
def test_fresh_lunar_craters_follow_pike(d_km, law):
    m = crater_morphometry(d_km * 1000.0, target="moon")  # measured on the profile
    depth, rim = law(d_km)
    assert m["depth_m"] == pytest.approx(1000 * depth, rel=0.10)
    assert m["rim_height_m"] == pytest.approx(1000 * rim, rel=0.10)


def test_no_jump_across_the_transition():
    d = np.geomspace(2e3, 80e3, 400)  # 0.9 % apart, through 0.8-1.6 D_t and both law joins
    x = np.linspace(0.0, 1.5, 4001)
    h = craters.fresh_profile(x, d, "moon")
    depth = h.max(axis=1) - h[:, x <= 1.2].min(axis=1)
    rim = h.max(axis=1)
    for v in (depth, rim):
        step = v[1:] / v[:-1]
        assert (np.abs(step - 1.0) < 0.10).all()
        assert (np.abs(step - 1.0) < 0.02).all()  # in fact smooth


@pytest.mark.parametrize("d_km", [30.0, 100.0])
def test_complex_craters_have_flat_floors_and_central_peaks(d_km):
    d = d_km * 1000.0
    x = np.linspace(0.0, 1.0, 2001)
    h = radial_profile(x, d)
    m = fresh_morphometry(d)
    floor = h.min()
    flat = x[np.abs(h - floor) < 0.005 * float(m["depth_m"])]
    assert flat.max() - flat.min() > 0.15  # a flat floor, > 15 % of the radius wide
    peak = h[x < 0.05].max() - floor
    assert peak > 0.2 * float(m["depth_m"])  # a central peak
    assert craters.morphology_class(d) == "complex"


def test_peak_rings_above_the_onset():
    x = np.linspace(0.0, 1.0, 2001)
    h = radial_profile(x, 400e3)
    floor = h.min()
    ring = x[np.argmax(np.where(x < 0.9, h, -np.inf))]
    assert 0.4 < ring < 0.6 and h[x < 0.1].max() - floor < 0.1 * (h.max() - floor)


@pytest.mark.parametrize("body,low,high,simple,complex_,simple_km", [
    # Garvin, Sakimoto & Frawley 2003 (gridded MOLA): transition ~7 km, fresh simple
    # d = 0.21 D^0.81, complex d = 0.36 D^0.49 (7-100 km); the two cross at 5.4 km
    ("mars", 6e3, 8e3, (0.21, 0.81), (0.36, 0.49), (1.0, 2.0, 4.0)),
    # Pike 1988: transition ~10.3 km, simple d = 0.199 D^0.995, complex 0.353 D^0.496;
    # the depth laws cross at 3.2 km
    ("mercury", 9e3, 12e3, (0.199, 0.995), (0.353, 0.496), (1.0, 2.0, 3.0)),
])
def test_mars_and_mercury_fresh_depths_follow_their_fits(body, low, high, simple, complex_,
                                                         simple_km):
    """Depth measured on the stamped profile within 10 % of the cited fit at three
    diameters of each kind (issue 36)."""
    t = craters.get_target(body)
    assert low <= t.transition_m <= high
    for fit, sizes in ((simple, simple_km), (complex_, (20.0, 50.0, 100.0))):
        for d_km in sizes:
            m = crater_morphometry(d_km * 1000.0, target=body)
            assert m["depth_m"] == pytest.approx(1000 * fit[0] * d_km ** fit[1], rel=0.10)


def test_ceres_fresh_simple_craters_follow_gou_and_complex_ones_join_them():
    """Gou et al. 2018 (Dawn HAMO DTM, craters >= 1 km): fresh simple d/D 0.11 +- 0.04,
    complex craters 0.08 +- 0.04; transition 7.5-12 km (Hiesinger et al. 2016)."""
    t = craters.get_target("ceres")
    assert 7.5e3 <= t.transition_m <= 12e3
    for d_km in (1.0, 3.0, 6.0):
        m = crater_morphometry(d_km * 1000.0, target="ceres")
        assert m["depth_m"] == pytest.approx(0.11 * 1000 * d_km, rel=0.10)
    for d_km in (15.0, 20.0, 30.0):  # inside the measured spread of complex craters
        ratio = crater_morphometry(d_km * 1000.0, target="ceres")["depth_m"] / (d_km * 1e3)
        assert 0.04 <= ratio <= 0.12
    d = np.geomspace(2e3, 60e3, 300)
    depth = fresh_morphometry(d, "ceres")["depth_m"]
    assert (np.abs(depth[1:] / depth[:-1] - 1.0) < 0.02).all()  # no step at the transition


@pytest.mark.parametrize("d_m,ratio", [(40.0, 0.13), (63.0, 0.13), (100.0, 0.1415),
                                       (141.0, 0.15), (283.0, 0.17), (1000.0, 0.196)])
def test_small_fresh_lunar_craters_are_shallower_stopar(d_m, ratio):
    """Stopar et al. 2017 (LROC NAC DTMs): fresh d/D 0.13 at 40-100 m, 0.15 at 100-200 m,
    0.17 at 200-400 m (knots at the bins' geometric centres, log-linear between), Pike
    from 400 m; measured on the profile, rim in proportion."""
    m = crater_morphometry(d_m, target="moon")
    assert m["depth_m"] / d_m == pytest.approx(ratio, rel=0.03)
    pike = 0.036 * (d_m / 1000.0) ** 0.014 / (0.196 * (d_m / 1000.0) ** 0.010)
    assert m["rim_height_m"] / m["depth_m"] == pytest.approx(pike, rel=0.03)


def test_small_depth_knots_are_continuous_and_checked():
    d = np.geomspace(20.0, 2000.0, 800)
    ratio = fresh_morphometry(d, "moon")["depth_m"] / d
    assert np.abs(np.diff(ratio)).max() < 0.002           # no step at 400 m or a knot
    moon = craters.get_target("moon")
    with pytest.raises(ValueError, match="small_depth_ratio.*increasing"):
        dataclasses.replace(moon, small_depth_ratio=((100.0, 0.1), (50.0, 0.12)))
    with pytest.raises(ValueError, match="small_depth_ratio.*must be >= the simple law"):
        dataclasses.replace(moon, small_depth_ratio=((100.0, 0.1), (400.0, 0.15)))


def test_transition_scales_as_one_over_g():
    moon = craters.get_target("moon")
    assert craters.get_target("moon", gravity_m_s2=2 * 1.62).transition_m \
        == pytest.approx(moon.transition_m / 2)
    small = craters.small_body(8000.0, 2670.0)
    assert small.transition_m > 1e6 and craters.morphology_class(50e3, small) == "simple"


def test_small_body_depth_ratio_sets_fresh_depth_and_keeps_rim_share():
    """Bennu's measured d/D = 0.10 (Daly et al. 2020) halves the depth and the rim of the
    default d/D = 0.2 (Marchi et al. 2015); only small bodies take it."""
    default, bennu = craters.small_body(245.0, 1190.0), craters.small_body(245.0, 1190.0, 0.1)
    for d in (2.0, 10.0, 60.0):
        m0 = craters.crater_morphometry(d, target=default)
        m1 = craters.crater_morphometry(d, target=bennu)
        assert m0["depth_m"] / d == pytest.approx(0.2, rel=1e-12)
        assert m1["depth_m"] / d == pytest.approx(0.1, rel=1e-12)
        assert m1["rim_height_m"] / m0["rim_height_m"] == pytest.approx(0.5, rel=1e-12)
    with pytest.raises(ValueError, match="depth_ratio"):
        craters.small_body(245.0, 1190.0, 0.9)
    with pytest.raises(ValueError, match="depth_ratio.*small-body only"):
        craters.get_target("moon", depth_ratio=0.1)


# --------------------------------------------------------------------------- diffusion
def explicit_radial_diffusion(r, h, tau, n_steps=None):
    """Independent reference: explicit finite differences of dh/dt = lap h in polar
    coordinates (dimensionless time tau, r in crater radii), h = 0 at the outer edge."""
    dr = r[1] - r[0]
    dt = 0.2 * dr * dr
    n = int(np.ceil(tau / dt)) if n_steps is None else n_steps
    dt = tau / n
    h = h.copy()
    rm = r[1:-1]
    for _ in range(n):
        lap = np.empty_like(h)
        lap[1:-1] = ((h[2:] - 2 * h[1:-1] + h[:-2]) / dr**2
                     + (h[2:] - h[:-2]) / (2 * dr * rm))
        lap[0] = 4 * (h[1] - h[0]) / dr**2  # symmetric centre: lap = 2 h''
        lap[-1] = 0.0
        h = h + dt * lap
        h[-1] = 0.0
    return h


@pytest.mark.parametrize("age_gyr", [1.0, 3.5])
def test_diffused_1km_crater_matches_an_independent_solution(age_gyr):
    d = 1000.0
    tau = float(craters.tau_from_age(d, age_gyr))
    r = np.linspace(0.0, 6.0, 1201)
    fresh = craters.fresh_profile(r, d)
    ref = explicit_radial_diffusion(r, fresh, tau)
    got = radial_profile(r, d, age_gyr=age_gyr)
    inside = r <= 1.5
    d_ref = ref[inside].max() - ref[r <= 1.2].min()
    d_got = got[inside].max() - got[r <= 1.2].min()
    assert d_got / d == pytest.approx(d_ref / d, rel=0.05)
    assert np.abs(got - ref)[r < 2.5].max() < 0.02 * d_ref
    # and the stamping tables agree with the exact solve
    tab = craters.profile_tables([d], [tau])[0]
    xt = np.linspace(0.0, 3.0, tab.size)
    assert (tab.max() - tab[xt <= 1.2].min()) == pytest.approx(d_got, rel=0.02)


def test_old_craters_are_shallow_and_rimless_and_degradation_one_is_flat():
    fresh = crater_morphometry(1000.0)
    old = crater_morphometry(1000.0, age_gyr=3.5)
    assert old["depth_diameter"] < 0.7 * fresh["depth_diameter"]
    assert old["rim_height_m"] < 0.5 * fresh["rim_height_m"]
    gone = radial_profile(np.linspace(0, 3, 601), 1000.0, degradation=1.0)
    relief = np.ptp(craters.fresh_profile(np.linspace(0, 3, 601), 1000.0))
    assert np.ptp(gone) < 0.01 * relief
    half = crater_morphometry(1000.0, degradation=0.5)
    assert half["degradation"] == pytest.approx(0.5, abs=0.02)


def test_diffusion_keeps_volume_and_smooths():
    """The Hankel-space solve conserves the profile's volume (2 pi int h r dr) while the
    relief is far from the domain edge, and never sharpens."""
    from craters.diffusion import diffuse_profiles, diffusion_nodes

    r = diffusion_nodes()
    h = craters.fresh_profile(r, 1000.0)
    out = diffuse_profiles(h[None], [0.02])[0]
    vol = np.trapezoid(h * r, r)
    assert np.trapezoid(out * r, r) == pytest.approx(vol, abs=1e-3 * np.abs(h * r).max())
    assert np.ptp(out) < np.ptp(h)


def test_kappa_scaling_of_fassett_and_thomson():
    assert float(craters.kappa_m2_yr(1000.0)) == pytest.approx(5.5e-6)
    assert float(craters.kappa_m2_yr(10_000.0)) == pytest.approx(5.5e-6 * 10**0.9)


@pytest.mark.parametrize("kw,match", [({"age_gyr": -1.0}, "age_gyr"),
                                      ({"degradation": 1.5}, "degradation"),
                                      ({"age_gyr": 1.0, "degradation": 0.2}, "degradation")])
def test_bad_states(kw, match):
    with pytest.raises(ValueError, match=match):
        radial_profile([0.0], 1000.0, **kw)


def test_small_body_depth_exponent_makes_larger_craters_shallower():
    t = craters.small_body(245.0, 1190.0, 0.118, 0.756)
    for d, want in ((10.0, 0.118), (40.0, 0.118 * 4.0 ** -0.244), (2.5, 0.118 * 4.0 ** 0.244)):
        assert float(fresh_morphometry(d, t)["depth_m"]) / d == pytest.approx(want, rel=1e-9)
    with pytest.raises(ValueError, match="depth_exponent.*small-body only"):
        craters.get_target("moon", depth_exponent=0.8)
    with pytest.raises(ValueError, match="depth_exponent"):
        craters.small_body(245.0, 1190.0, 0.1, 2.0)
