"""Reflectance models (latlong.sensors.photometry) against numpy references."""

from __future__ import annotations

import numpy as np
import pytest

from craters._shared import ParameterError
from latlong.sensors.photometry import (
    HAPKE_PRESETS,
    Hapke,
    Lambert,
    LommelSeeliger,
    LunarLambert,
    radiance_factor,
    reflectance_model,
)


def random_geometry(rng, n):
    """cos i, cos e, cos g of random normals, sun and view directions (all lit, seen)."""
    def unit(k):
        v = rng.normal(size=(k, 3))
        return v / np.linalg.norm(v, axis=1, keepdims=True)

    nrm, sun, view = unit(4 * n), unit(4 * n), unit(4 * n)
    mu0 = np.einsum("ij,ij->i", nrm, sun)
    mu = np.einsum("ij,ij->i", nrm, view)
    ok = (mu0 > 1e-3) & (mu > 1e-3)
    return mu0[ok][:n], mu[ok][:n], np.einsum("ij,ij->i", sun, view)[ok][:n]


def numpy_hapke(mu0, mu, cos_g, m: Hapke):
    """Reference: Hapke (1984, 1986, 2002, 2008) written out in numpy."""
    w, xi, b0, h, k = m.w, m.xi, m.b0, m.h, m.porosity_k
    tt = np.tan(np.radians(m.theta_bar_deg))
    i, e, g = np.arccos(mu0), np.arccos(mu), np.arccos(np.clip(cos_g, -1, 1))
    with np.errstate(divide="ignore", invalid="ignore"):
        cos_psi = np.clip((cos_g - mu0 * mu) / (np.sin(i) * np.sin(e)), -1, 1)
    cos_psi = np.where(np.sin(i) * np.sin(e) > 1e-12, cos_psi, 1.0)
    psi = np.arccos(cos_psi)
    if tt > 0:
        chi = 1 / np.sqrt(1 + np.pi * tt**2)
        with np.errstate(divide="ignore"):
            e1 = lambda x: np.exp(-2 / (np.pi * tt * np.tan(x)))  # noqa: E731
            e2 = lambda x: np.exp(-1 / (np.pi * tt**2 * np.tan(x) ** 2))  # noqa: E731
            eta = lambda x: chi * (np.cos(x) + np.sin(x) * tt * e2(x) / (2 - e1(x)))  # noqa: E731
        s2 = np.sin(psi / 2) ** 2
        f = np.exp(-2 * np.tan(np.minimum(psi / 2, np.pi / 2 - 1e-9)))
        le = i <= e
        d1 = 2 - e1(e) - psi / np.pi * e1(i)
        d2 = 2 - e1(i) - psi / np.pi * e1(e)
        mu0e = np.where(le, chi * (mu0 + np.sin(i) * tt * (cos_psi * e2(e) + s2 * e2(i)) / d1),
                        chi * (mu0 + np.sin(i) * tt * (e2(i) - s2 * e2(e)) / d2))
        mue = np.where(le, chi * (mu + np.sin(e) * tt * (e2(e) - s2 * e2(i)) / d1),
                       chi * (mu + np.sin(e) * tt * (cos_psi * e2(i) + s2 * e2(e)) / d2))
        last = np.where(le, mu0 / eta(i), mu / eta(e))
        s = mue / eta(e) * mu0 / eta(i) * chi / (1 - f + f * chi * last)
    else:
        mu0e, mue, s = mu0, mu, 1.0

    def hfun(x):
        x = x / k
        gam = np.sqrt(1 - w)
        r0 = (1 - gam) / (1 + gam)
        return 1 / (1 - w * x * (r0 + (1 - 2 * r0 * x) / 2 * np.log((1 + x) / x)))

    p = (1 - xi**2) / (1 + 2 * xi * cos_g + xi**2) ** 1.5
    bsh = b0 / (1 + np.tan(g / 2) / h)
    z = np.tan(g / 2) / m.hc if m.hc > 0 else np.zeros_like(g)
    with np.errstate(divide="ignore", invalid="ignore"):
        bcb = np.where(z > 1e-8, m.bc0 * (1 + (1 - np.exp(-z)) / z) / (2 * (1 + z) ** 2), m.bc0)
    return k * w / 4 * mu0e / (mu0e + mue) * (p * (1 + bsh) + hfun(mu0e) * hfun(mue) - 1) * (
        1 + bcb) * s


@pytest.mark.parametrize("model", [*HAPKE_PRESETS.values(),
                                   Hapke(0.6, 0.2, 0.5, 0.1, 0.0, bc0=0.4, hc=0.03,
                                         porosity_k=1.4)])
def test_hapke_matches_numpy(rng, model):
    mu0, mu, cg = random_geometry(rng, 3000)
    np.testing.assert_allclose(radiance_factor(model, mu0, mu, cg),
                               numpy_hapke(mu0, mu, cg, model), rtol=1e-10)


def test_simple_models_match_numpy(rng):
    mu0, mu, cg = random_geometry(rng, 2000)
    g = np.degrees(np.arccos(cg))
    np.testing.assert_allclose(radiance_factor(Lambert(0.3), mu0, mu, cg), 0.3 * mu0)
    np.testing.assert_allclose(radiance_factor(LommelSeeliger(0.2), mu0, mu, cg),
                               0.4 * mu0 / (mu0 + mu))
    lg = 1 - 0.019 * g + 2.42e-4 * g**2 - 1.46e-6 * g**3
    np.testing.assert_allclose(radiance_factor(LunarLambert(0.1), mu0, mu, cg),
                               0.1 * (2 * lg * mu0 / (mu0 + mu) + (1 - lg) * mu0), rtol=1e-12)


def test_limits_and_unlit():
    # unlit or unseen points are black
    for model in (Lambert(), LommelSeeliger(), LunarLambert(), HAPKE_PRESETS["moon"]):
        out = radiance_factor(model, [-0.1, 0.5, 0.0], [0.5, -0.2, 0.5], [0.3, 0.3, 0.3])
        assert (out == 0).all()
    # lunar-Lambert at zero phase is Lommel-Seeliger; with L = 0 it is Lambert
    assert np.isclose(radiance_factor(LunarLambert(0.1), 0.7, 0.7, 1.0)[0],
                      radiance_factor(LommelSeeliger(0.1), 0.7, 0.7, 1.0)[0])
    assert np.isclose(radiance_factor(LunarLambert(0.1, (-1 / 90, 0, 0)), 0.3, 0.6,
                                      np.cos(np.radians(90)))[0], 0.1 * 0.3)
    # Hapke without roughness, opposition or multiple scattering -> Lommel-Seeliger w/8
    dark = Hapke(w=1e-6, xi=0.0, b0=0.0, h=0.1, theta_bar_deg=0.0)
    mu0, mu, cg = np.array([0.9, 0.4]), np.array([0.5, 0.8]), np.array([0.2, 0.6])
    np.testing.assert_allclose(radiance_factor(dark, mu0, mu, cg),
                               radiance_factor(LommelSeeliger(1e-6 / 8), mu0, mu, cg),
                               rtol=1e-5)
    # the opposition surge: brighter towards zero phase at the same i, e
    m = HAPKE_PRESETS["c-type"]
    near, far = radiance_factor(m, [0.8, 0.8], [0.8, 0.8], [1.0, np.cos(np.radians(10))])
    assert near > 1.3 * far


def test_model_by_name():
    assert reflectance_model("lambert", albedo=0.2) == Lambert(0.2)
    assert reflectance_model("hapke", preset="moon") is HAPKE_PRESETS["moon"]
    assert reflectance_model("hapke") is HAPKE_PRESETS["s-type"]
    with pytest.raises(ParameterError, match="reflectance"):
        reflectance_model("phong")
    with pytest.raises(ParameterError, match="preset"):
        reflectance_model("hapke", preset="x-type")
    with pytest.raises(ParameterError, match="albedo"):
        Lambert(-0.1)
    with pytest.raises(ParameterError, match="h"):
        Hapke(h=0.0)
    with pytest.raises(TypeError, match="model"):
        radiance_factor("lambert", 1, 1, 1)
