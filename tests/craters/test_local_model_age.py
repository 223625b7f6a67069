"""Model-age layers drawn cell by cell (craters.local, terrain on demand): the production
function's sizes, the chronology's ages, the model age recovered from the counts, the
equilibrium cap, and the same craters in a cell whatever else is drawn."""

from __future__ import annotations

import numpy as np
import pytest

from craters import ModelAgeLayer
from craters.cells import cell_ids, cell_solid_angle
from craters.chronology import (
    cumulative_density,
    formation_ages,
    get_chronology_system,
    sample_pf_diameters,
)
from craters.local import bins, draw_cells

MOON_M = 1737400.0


def _cells(level, n, face=2):
    i, j = np.meshgrid(np.arange(n) + 7, np.arange(n) + 11)
    ids = cell_ids(level, np.full(i.size, face), i.ravel(), j.ravel())
    return ids, cell_solid_angle(level, face, i.ravel(), j.ravel()) * MOON_M**2


def _draw(layer, ids, area, seed=3, level=11):
    got = [draw_cells(layer, 0, seed=seed, b=int(b), level=level, cell_ids=ids, area_m2=area)
           for b in bins(layer)]
    return {k: np.concatenate([g[k] for g in got]) for k in got[0]}


@pytest.fixture(scope="module")
def drawn():
    layer = ModelAgeLayer("moon", 3.8, 100.0, 2000.0)
    ids, area = _cells(11, 30)
    return layer, ids, area, _draw(layer, ids, area)


def test_model_age_cells_draw_the_production_function_and_the_chronology(drawn):
    layer, _, area, got = drawn
    d, age = got["diameter_m"], got["age_gyr"]
    expected = area.sum() * float(cumulative_density("moon", 3.8, 100.0)
                                  - cumulative_density("moon", 3.8, 2000.0))
    assert abs(len(d) - expected) < 4.0 * np.sqrt(expected)  # ~34 000 craters
    assert ((d >= 100.0) & (d < 2000.0)).all() and ((age >= 0.0) & (age <= 3.8)).all()
    # the same distributions as the sequential draws (two-sample KS, 4 sigma-ish bound)
    from scipy.stats import ks_2samp

    bound = 1.95 * np.sqrt(1.0 / len(d) + 1.0 / 200_000)
    assert ks_2samp(d, sample_pf_diameters(200_000, "moon", 100.0, 2000.0, rng=1)).statistic \
        < bound
    assert ks_2samp(age, formation_ages(200_000, "moon", 3.8, rng=1)).statistic < bound
    # the model age back from the count >= 100 m: N1 = N(>100 m) / S(100 m)
    system = get_chronology_system("moon")
    n1 = len(d) / (area.sum() * 1e-6) / (10.0 ** float(system.production.shape_log10(0.1))
                                         - 10.0 ** float(system.production.shape_log10(2.0)))
    fit = float(system.chronology.age_gyr(n1))
    sigma = 1.0 / np.sqrt(len(d)) / float(system.chronology.rate(3.8) / system.chronology.n1(3.8))
    assert abs(fit - 3.8) < 4.0 * sigma  # sigma ~ 0.0008 Gyr


def test_a_model_age_cell_draws_the_same_craters_whatever_else_is_drawn(drawn):
    layer, ids, area, every = drawn
    pick = np.array([3, 450, 899])
    some = _draw(layer, ids[pick[::-1]], area[pick[::-1]])
    for c in ids[pick]:
        a, b = every["cell"] == c, some["cell"] == c
        assert a.sum() > 0
        for key in ("unit", "diameter_m", "age_gyr", "id"):
            assert every[key][a].tobytes() == some[key][b].tobytes()


def test_the_equilibrium_cap_keeps_the_equilibrium_density_of_the_youngest():
    capped = ModelAgeLayer("moon", 3.8, 100.0, 2000.0, equilibrium="trask")
    ids, area = _cells(11, 30)
    got = _draw(capped, ids, area)
    d, age = got["diameter_m"], got["age_gyr"]
    # saturated below ~420 m: the equilibrium count there; above it the production count
    from craters.chronology import equilibrium_density

    small = (d >= 128.0) & (d < 256.0)
    want = area.sum() * float(equilibrium_density("trask", 128.0)
                              - equilibrium_density("trask", 256.0))
    assert abs(small.sum() - want) < 4.0 * np.sqrt(want)
    # the survivors are the young ones; the large craters keep the chronology's ages
    large = d >= 600.0
    assert large.sum() > 30
    assert np.median(age[small]) < 2.0 < np.median(age[large])


def _bisect_reference(f, target, a, b, increasing):
    """The pure-numpy bisection the compiled kernels replace (craters.local until stop 54)."""
    lo = np.full(target.shape, float(a))
    hi = np.full(target.shape, float(b))
    for _ in range(64):
        mid = 0.5 * (lo + hi)
        below = (f(mid) < target) if increasing else (f(mid) > target)
        lo = np.where(below, mid, lo)
        hi = np.where(below, hi, mid)
    return 0.5 * (lo + hi)


@pytest.mark.parametrize("npf", ["moon", "mars", "gaspra", "vesta"])
def test_the_compiled_bisections_are_the_numpy_ones_byte_for_byte(npf):
    """Sizes and ages of a model-age bin come from 64 halvings (numba kernels since the
    per-element numpy loop cost 0.075 s of a 1 cm tile): the same bytes as the numpy
    reference over the portable exp/log, from both ends of each bracket to the middle."""
    import math

    from craters.local import _model_age_draws, _n1, _p10, _pf_shape

    layer = ModelAgeLayer(npf, 3.5, 100.0, 20000.0)
    rng = np.random.default_rng(5)
    u = np.concatenate([[0.0, 1e-17, 0.5, 1.0 - 2**-53], rng.random(300)])
    u_age = np.concatenate([[0.0, 1e-17, 0.5, 1.0 - 2**-53], rng.random(300)])
    for lo, hi in ((100.0, 200.0), (163.84, 327.68), (5000.0, 20000.0)):
        d, ages = _model_age_draws(layer, lo, hi, 0.8, u, u_age)
        s = _pf_shape(layer, np.array([lo, hi]))
        x = _bisect_reference(lambda v: _pf_shape(layer, _p10(v) * 1e3),
                              s[0] - u * (s[0] - s[1]), math.log10(lo * 1e-3),
                              math.log10(hi * 1e-3), increasing=False)
        want_d = np.clip(_p10(x) * 1e3, lo, np.nextafter(hi, 0.0))
        n_t = float(_n1(layer, np.array([3.5]))[0])
        want_age = np.clip(_bisect_reference(lambda t: _n1(layer, t), u_age * 0.8 * n_t, 0.0,
                                             3.5, increasing=True), 0.0, 3.5)
        assert d.tobytes() == want_d.tobytes()
        assert ages.tobytes() == want_age.tobytes()
        assert (d >= lo).all() and (d < hi).all() and (np.diff(np.sort(ages)) >= 0).all()
