"""Morphometry, degradation curves and the radial profile (closed forms, properties)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import craters
from craters._stamp_kernels import _degradation_factors, _profile_kernel

STEP = 1e-4
X = np.arange(0.0, 3.2, STEP)


@pytest.mark.parametrize("d_km", [0.01, 1.0, 10.0])
def test_pike_1977(d_km):
    # H0 = 0.196 D^1.010, Hr0 = 0.036 D^1.014, D in km, converted to metres
    assert craters.fresh_depth(d_km * 1000) == pytest.approx(1000 * 0.196 * d_km**1.010)
    assert craters.fresh_rim_height(d_km * 1000) == pytest.approx(1000 * 0.036 * d_km**1.014)
    if d_km == 1.0:
        assert craters.fresh_depth(1000.0) == pytest.approx(196.0)
        assert craters.fresh_rim_height(1000.0) == pytest.approx(36.0)


def test_asteroid_preset_and_custom_laws():
    assert craters.fresh_depth(500.0, "asteroid-fresh") == pytest.approx(100.0)
    m = craters.Morphometry(0.1, 1.0, 0.02, 1.0)
    assert craters.fresh_rim_height(2000.0, m) == pytest.approx(40.0)
    with pytest.raises(ValueError, match="morphometry"):
        craters.fresh_depth(10.0, "martian")
    with pytest.raises(ValueError, match="diameter_m"):
        craters.fresh_depth([10.0, -1.0])
    with pytest.raises(ValueError, match="diameter_m"):
        craters.fresh_depth(np.nan)


def test_degradation_curves():
    d = np.linspace(0, 1, 101)
    f_h, f_r = craters.degradation_factors(d)
    assert f_h[0] == f_r[0] == 1.0
    assert f_r[-1] == pytest.approx(0.0, abs=1e-15) and f_h[-1] == pytest.approx(0.25)
    assert (np.diff(f_h) < 0).all() and (np.diff(f_r) < 0).all()
    assert (f_r[1:-1] < f_h[1:-1]).all()  # the rim decays faster than the depth
    for v in (0.0, 0.3, 0.77, 1.0):  # the numba scalar version is the same curve
        got = _degradation_factors(v, 3.0, 1.5, 0.25)
        want = craters.degradation_factors(v)
        assert np.allclose(got, [float(want[0]), float(want[1])], rtol=0, atol=1e-15)
    with pytest.raises(ValueError, match="degradation"):
        craters.degradation_factors(1.2)


def test_degradation_from_age():
    # T_b = T_x (D_b / D_x)^P, normalised by the baseline lifetime
    d = craters.degradation_from_age(250.0, 1.0, baseline_diameter_m=1000.0,
                                     baseline_lifetime_gyr=20.0, exponent=1.0)
    assert d == pytest.approx(1.0 * 4.0 / 20.0)
    assert craters.degradation_from_age(1000.0, 0.0) == 0.0
    assert craters.degradation_from_age(10.0, 3.0) == 1.0
    older = craters.degradation_from_age(500.0, [0.5, 1.0, 2.0])
    assert (np.diff(older) > 0).all()
    with pytest.raises(ValueError, match="age_gyr"):
        craters.degradation_from_age(10.0, -1.0)


def test_slope_erosion():
    assert craters.slope_erosion(0.2, 10.0) == 0.2
    assert craters.slope_erosion(0.2, 50.0) == 1.0
    assert craters.slope_erosion(0.0, 32.5) == pytest.approx(0.5)
    with pytest.raises(ValueError, match="full_deg"):
        craters.slope_erosion(0.1, 10.0, onset_deg=30.0, full_deg=20.0)


def test_fresh_profile_closed_form():
    h = craters.radial_profile(X, 1000.0)
    i_rim = int(round(1.0 / STEP))
    assert h[0] == pytest.approx(36.0 - 196.0, rel=1e-3)  # floor = Hr0 - H0
    assert h[i_rim] == pytest.approx(36.0, rel=1e-3)  # rim crest height Hr0
    assert np.argmax(h) == i_rim  # sharp rim at x = 1
    assert (h[X >= 3.0] == 0).all()  # ejecta ends at r = 1.5 D
    # the bowl is the paper's parabola Hr - H + H x^2 (fresh: alpha = 1)
    inside = X <= 1
    assert np.allclose(h[inside], 36.0 - 196.0 + 196.0 * X[inside] ** 2, rtol=0, atol=0.2)
    # McGetchin thickness dominates far out: h ~ E0 x^-3 plus the corrective function
    p = craters.profile_params(1000.0)
    assert p.ejecta_m == pytest.approx(0.14 * 500.0**0.74, rel=1e-9)


@pytest.mark.parametrize("deg", [0.1, 0.2, 0.4, 0.6, 0.8, 1.0])
def test_degraded_profile_has_no_kinks(deg):
    h = craters.radial_profile(X, 1000.0, deg)
    slope = np.diff(h) / STEP
    # C1: the slope changes by a tiny amount between samples everywhere, including the
    # joins alpha, 1, beta and the ejecta edge (a kink would jump by ~ the depth)
    p = craters.profile_params(1000.0, deg)
    assert np.abs(np.diff(slope)).max() < 0.01 * max(p.depth_m, 1.0)
    assert p.alpha < 1.0 < p.beta
    assert np.argmax(h) == int(round(1.0 / STEP)) or deg == 1.0


def test_depth_and_rim_fall_with_degradation():
    degs = np.linspace(0.1, 1.0, 10)
    depth, rim = [], []
    for d in degs:
        h = craters.radial_profile(X, 1000.0, d)
        rim.append(h.max())
        depth.append(h.max() - h.min())
    assert (np.diff(depth) <= 1e-9).all() and (np.diff(rim) <= 1e-9).all()
    assert depth[-1] < 0.5 * depth[0] and rim[-1] < 0.05 * rim[0]
    # fully degraded: a shallow rimless depression
    h = craters.radial_profile(X, 1000.0, 1.0)
    assert h.max() <= 1e-12 and h.min() == pytest.approx(-0.25 * 196.0, rel=1e-3)


@settings(max_examples=40, deadline=None)
@given(st.floats(1.0, 50_000.0), st.floats(0.0, 1.0), st.floats(-50.0, 50.0))
def test_profile_properties(diameter, deg, delta):
    h = craters.radial_profile(X[::10], diameter, deg, rim_offset_m=delta)
    p = craters.profile_params(diameter, deg)
    assert np.isfinite(h).all()
    assert h[0] == pytest.approx(p.rim_height_m - p.depth_m, abs=1e-9 * diameter)
    assert (h[X[::10] >= 3.0] == 0).all()
    # the exterior starts at the rim value (plus the plane/terrain offset)
    outer = craters.radial_profile([1.0 + 1e-9], diameter, deg, rim_offset_m=delta)
    assert outer[0] == pytest.approx(p.rim_height_m + delta, abs=1e-6 * max(diameter, 1))
    if delta == 0:  # on flat ground the ejecta is never below the terrain
        assert h[X[::10] > 1].min() >= -1e-9 * diameter


@pytest.mark.parametrize("deg", [0.0, 0.35, 1.0])
@pytest.mark.parametrize("delta", [0.0, -3.0, 7.5])
def test_numba_profile_matches_numpy(deg, delta):
    x = np.linspace(0, 3.5, 3001)
    out = np.empty_like(x)
    _profile_kernel(x, 800.0, deg, np.array([0.196, 1.010, 0.036, 1.014]),
                    np.array([3.0, 1.5, 0.25]), 3.0, delta, out)
    want = craters.radial_profile(x, 800.0, deg, rim_offset_m=delta)
    assert np.allclose(out, want, rtol=0, atol=1e-9)


@pytest.mark.parametrize("kw,match", [({"diameter_m": -5.0}, "diameter_m"),
                                      ({"diameter_m": math.nan}, "diameter_m"),
                                      ({"degradation": 1.5}, "degradation"),
                                      ({"degradation": -0.1}, "degradation")])
def test_bad_profile_input(kw, match):
    args = {"diameter_m": 100.0, "degradation": 0.0} | kw
    with pytest.raises(ValueError, match=match):
        craters.radial_profile([0.5], **args)
    with pytest.raises(ValueError, match="`x`"):
        craters.radial_profile([-1.0], 100.0)
