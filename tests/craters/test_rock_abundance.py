"""Golombek & Rapp's rock-abundance model as boulder layers (craters.boulders.abundance)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import quad

import craters
import dem
from craters.boulders.abundance import (
    golombek_cumulative_area,
    golombek_cumulative_number,
    golombek_q,
    parse_golombek_spec,
)


@pytest.mark.parametrize("k", [0.02, 0.1, 0.3])
def test_q_and_the_area_law_are_the_published_forms(k):
    # F_k(D) = k exp(-q D), q = 1.79 + 0.152 / k (Golombek et al. 2003's quotation)
    assert golombek_q(k) == pytest.approx(1.79 + 0.152 / k)
    assert golombek_cumulative_area(0.0, k) == pytest.approx(k)
    assert golombek_cumulative_area(1.0, k) == pytest.approx(k * math.exp(-golombek_q(k)))


@pytest.mark.parametrize("k", [0.02, 0.1, 0.3])
@pytest.mark.parametrize("d", [0.05, 0.3, 1.5])
def test_number_density_is_the_area_law_per_rock_area(k, d):
    # N(D) = int_D^inf (-dF/dx) / (pi x^2 / 4) dx, by quadrature
    q = golombek_q(k)
    want, _ = quad(lambda x: k * q * math.exp(-q * x) / (math.pi * x * x / 4.0), d, np.inf)
    assert golombek_cumulative_number(d, k) == pytest.approx(want, rel=1e-8)


def test_layers_hold_the_model_count_in_every_bin():
    layers = craters.golombek_layers(0.1, 0.1, 3.0, bins_per_octave=2, burial_max=0.3)
    assert len(layers) == 10 and all(la.burial_max == 0.3 for la in layers)
    assert layers[0].d_min_m == 0.1 and layers[-1].d_max_m == 3.0
    for a, b in zip(layers[:-1], layers[1:], strict=True):
        assert a.d_max_m == b.d_min_m
    for la in layers:
        for d in (la.d_min_m, la.d_max_m):
            assert la.c * d**la.k == pytest.approx(golombek_cumulative_number(d, 0.1), rel=1e-12)


def test_a_drawn_population_covers_the_model_area():
    # catalogue area of rocks >= D over a 100 m square (about 18 000 rocks)
    flat = dem.Dem(np.zeros((101, 101)), pixel_size_m=1.0)
    cat = dem.boulder_population(flat, "golombek,k=0.1,d_min_m=0.1,d_max_m=2", rng=4)
    for d in (0.1, 0.2, 0.4):
        got = (np.pi / 4 * cat["diameter_m"][cat["diameter_m"] >= d] ** 2).sum() / 100.0**2
        want = golombek_cumulative_area(d, 0.1) - golombek_cumulative_area(2.0, 0.1)
        assert got == pytest.approx(want, rel=0.1), d


@pytest.mark.parametrize("spec,match", [
    ("golombek,k=0.1,d_min_m=1", "missing d_max_m"),
    ("golombek,k=2,d_min_m=0.1,d_max_m=1", "`k`"),
    ("golombek,k=0.1,d_min_m=1,d_max_m=0.5", "d_min_m"),
    ("golombek,k=0.1,d_min_m=0.1,d_max_m=1,c=3", "unknown item"),
    ("golumbek,k=0.1,d_min_m=0.1,d_max_m=1", "starts with 'golombek,'"),
])
def test_bad_specs(spec, match):
    with pytest.raises(ValueError, match=match):
        parse_golombek_spec(spec)


def test_specs_in_stacks_and_scenes():
    cfg = dem.EnhanceConfig(layers=2, size=17, boulders=["golombek,k=0.05,d_min_m=0.25,d_max_m=1",
                                                         "c=0.01,k=-3,d_min_m=1,d_max_m=2"])
    assert len(cfg.boulder_layers) == 5
    import latlong

    scene = latlong.Scene.from_settings({"boulders": ["golombek,k=0.05,d_min_m=0.25,d_max_m=1"]})
    assert len(scene.boulders.layers) == 4
