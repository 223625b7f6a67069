"""Crater layers: power-law and model-age records, their specs, tables and one interface;
populations of model-age layers; .scc and Robbins-column catalogs."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

import craters
from craters import CraterLayer, ModelAgeLayer, as_crater_layer, parse_layer_spec, population
from craters._shared import ParameterError

SAMPLE_SCC = Path(__file__).parents[1] / "data" / "craterstats" / "c7_Michael-et-al-2021.scc"


def _old_population(layer: CraterLayer, area: float, rng) -> tuple:
    """The power-law draw as it was before model-age layers (issue 21): its stream."""
    rng = np.random.default_rng(rng)
    mean = area * layer.c * (layer.d_min_m**layer.k - layer.d_max_m**layer.k)
    n = int(rng.poisson(mean))
    d = craters.sample_power_law_diameters(n, layer.d_min_m, layer.d_max_m, -layer.k, rng=rng)
    age = rng.uniform(layer.age_min_gyr, layer.age_max_gyr, n)
    lat, lon = craters.uniform_sphere_directions(n, rng=rng)
    return d, age, lat, lon


def test_power_law_stream_unchanged():
    layer = CraterLayer(0.5, -2.0, 5.0, 800.0, 1.0, 3.0)
    area = 4 * np.pi * 500.0**2
    d, age, lat, lon = _old_population(layer, area, 42)
    cat = population([layer], area_m2=area, rng=42)
    order = np.argsort(-age, kind="stable")
    for name, want in (("diameter_m", d), ("age_gyr", age), ("lat_deg", lat), ("lon_deg", lon)):
        assert np.array_equal(cat[name], want[order]), name


@pytest.mark.parametrize("layer", [CraterLayer(0.5, -2.0, 5.0, 800.0),
                                   ModelAgeLayer("moon", 3.8, 500.0, 20000.0),
                                   ModelAgeLayer("mars", 1.0, 500.0, 20000.0, "hartmann")])
def test_one_interface(layer):
    area = 1e4 / float(layer.cumulative_m2(layer.d_min_m))
    assert layer.expected_count(area) == pytest.approx(
        layer.expected_count(area, layer.d_min_m, 2000.0)
        + layer.expected_count(area, 2000.0, layer.d_max_m), rel=1e-9)
    n = layer.cumulative_m2(np.array([layer.d_min_m, layer.d_max_m]))
    assert n[0] > n[1] > 0
    d = layer.sample_diameters(100, rng=1)
    a = layer.sample_ages(100, rng=1)
    assert d.shape == a.shape == (100,) and (d >= layer.d_min_m).all()
    d, a = layer.draw(area, rng=2)
    assert len(d) == len(a)


def test_model_age_population_catalog():
    la = ModelAgeLayer("moon", 3.8, 1000.0, 20000.0, kind="mare")
    cat = population([la, CraterLayer(1e-3, -2.0, 100.0, 1000.0)], area_m2=2e10, rng=3)
    mine = cat[cat["layer"] == 0]
    assert abs(len(mine) - la.expected_count(2e10)) < 4 * np.sqrt(la.expected_count(2e10))
    assert (np.diff(cat["age_gyr"]) <= 0).all()   # oldest first, both layers
    assert mine["age_gyr"].max() <= 3.8 and set(mine["kind"]) == {"mare"}
    assert np.isnan(mine["degradation"]).all()  # from the age, by diffusion when stamped
    planar = population(la, x_range_m=(0, 1e5), y_range_m=(0, 2e5), rng=3)
    assert planar.dtype.names[:2] == ("x_m", "y_m") and len(planar) > 100


def test_equilibrium_population_is_capped():
    la = ModelAgeLayer("moon", 3.8, 100.0, 5000.0, equilibrium="trask")
    area = 3e8
    cat = population(la, area_m2=area, rng=1)
    ds = la.saturation_diameter_m
    for d in (150.0, 250.0):
        assert d < ds
        n_cum = (cat["diameter_m"] >= d).sum() / area
        eq = float(craters.chronology.equilibrium_density("trask", d))
        pf = float(la.cumulative_m2(d))
        assert n_cum < 1.1 * eq < pf       # below equilibrium, far below production
    assert ModelAgeLayer("moon", 3.8, 100.0, 5000.0).saturation_diameter_m is None


@pytest.mark.parametrize(("spec", "kind"), [
    ("c=0.5,k=-2,d_min_m=2,d_max_m=50", CraterLayer),
    ("npf=moon,age_gyr=3.8,d_min_m=1000,d_max_m=20000", ModelAgeLayer),
    ("npf=ceres,age_gyr=0.5,d_min_m=100,d_max_m=2000,equilibrium=hartmann,kind=ice",
     ModelAgeLayer),
])
def test_specs_and_tables_make_the_same_record(spec, kind):
    layer = parse_layer_spec(spec)
    assert type(layer) is kind
    table = {k: (v if k in ("npf", "kind", "equilibrium") else float(v))
             for k, v in (item.split("=") for item in spec.split(","))}
    assert as_crater_layer(table) == layer == as_crater_layer(layer)
    assert as_crater_layer(spec) == layer


@pytest.mark.parametrize(("spec", "name", "needle"), [
    ("npf=moon,c=0.5,age_gyr=3.8,d_min_m=1000,d_max_m=20000", "c", "does not go with npf"),
    ("npf=moon,k=-2,age_gyr=3.8,d_min_m=1000,d_max_m=20000", "k", "does not go with npf"),
    ("npf=moon,age_max_gyr=3,age_gyr=3.8,d_min_m=1000,d_max_m=20000", "age_max_gyr",
     "does not go with npf"),
    ("c=0.5,k=-2,age_gyr=3.8,d_min_m=1000,d_max_m=20000", "age_gyr", "needs npf"),
    ("c=0.5,k=-2,equilibrium=trask,d_min_m=1000,d_max_m=20000", "equilibrium", "needs npf"),
    ("npf=pluto,age_gyr=3.8,d_min_m=1000,d_max_m=20000", "npf", "must be one of moon"),
    ("npf=moon,age_gyr=0,d_min_m=1000,d_max_m=20000", "age_gyr", "(0, 4.5]"),
    ("npf=moon,age_gyr=-1,d_min_m=1000,d_max_m=20000", "age_gyr", "(0, 4.5]"),
    ("npf=moon,age_gyr=4.6,d_min_m=1000,d_max_m=20000", "age_gyr", "(0, 4.5]"),
    ("npf=moon,age_gyr=3,d_min_m=1,d_max_m=20000", "d_min_m", "[10, 300000] m"),
    ("npf=mars,age_gyr=3,d_min_m=1000,d_max_m=400000", "d_max_m", "[15, 362000] m"),
    ("npf=moon,age_gyr=3,d_min_m=2000,d_max_m=1000", "d_min_m", "must be < d_max_m"),
    ("npf=moon,age_gyr=3,d_min_m=1000,d_max_m=2000,equilibrium=x", "equilibrium",
     "trask, hartmann"),
])
def test_bad_layer_specs(spec, name, needle):
    with pytest.raises(ParameterError) as info:
        parse_layer_spec(spec)
    assert info.value.name == name and needle in str(info.value)
    assert "\n" not in str(info.value) and spec in str(info.value)


def test_bad_tables_and_records():
    with pytest.raises(ParameterError, match="`c` does not go with npf"):
        as_crater_layer({"npf": "moon", "c": 1.0, "age_gyr": 1.0, "d_min_m": 1e3,
                         "d_max_m": 2e3})
    with pytest.raises(ParameterError, match="`colour` is not a crater layer key"):
        as_crater_layer({"colour": "red"})
    with pytest.raises(ParameterError, match="`d_max_m` is missing"):
        as_crater_layer({"npf": "moon", "age_gyr": 1.0, "d_min_m": 1e3})
    with pytest.raises(ParameterError, match="`age_gyr` must be in"):
        ModelAgeLayer("moon", 5.0, 1e3, 2e3)
    with pytest.raises(TypeError):
        as_crater_layer(3)
    with pytest.raises(ValueError, match="missing d_min_m"):
        parse_layer_spec("npf=moon,age_gyr=1")


# --------------------------------------------------------------------------- catalogs
def _craterstats_area(text: str) -> float:
    """craterstats 3.2.1 Cratercount.ReadSCCfile: ``re.findall('\\s*[\\d\\.]*', ...)[0]``."""
    value = re.search(r"^Total_area\s*=\s*(.*)$", text, re.M).group(1)
    return float(re.findall(r"\s*[\d\.]*", value)[0])


@pytest.mark.parametrize("area_m2", [2.5e3, 3.8e13, 1.0e9])
def test_scc_roundtrip(tmp_path, area_m2):
    cat = population(ModelAgeLayer("moon", 1.0, 1000.0, 20000.0), area_m2=5e11, rng=1)
    path = craters.write_scc(cat, tmp_path / "a.scc", area_m2=area_m2, body_radius_m=1737400.0)
    text = path.read_text()
    assert "e+" not in text and "e-" not in text          # plain decimals only
    assert _craterstats_area(text) * 1e6 == pytest.approx(area_m2, rel=1e-12)
    back = craters.read_scc(path)
    assert back["area_m2"] == pytest.approx(area_m2, rel=1e-12)
    assert back["axes_m"] == (1737400.0,) * 3
    np.testing.assert_allclose(back["diameter_m"], cat["diameter_m"], rtol=1e-15)
    np.testing.assert_allclose(back["lat_deg"], cat["lat_deg"])
    lon = np.where(cat["lon_deg"] > 180, cat["lon_deg"] - 360, cat["lon_deg"])
    np.testing.assert_allclose(back["lon_deg"], lon, atol=1e-12)
    assert (back["fraction"] == 1).all()


def test_read_scc_unreadable_area(tmp_path):
    """A Total_area that is not a number is a ValueError naming the file (was an
    AttributeError from a failed regular-expression match; found by mypy)."""
    path = tmp_path / "bad.scc"
    path.write_text("Total_area = unknown <km^2>\ncrater = {diam, fraction, lon, lat\n}\n")
    with pytest.raises(ValueError, match="Total_area must start with a number; got 'unknown"):
        craters.read_scc(path)


def test_scc_planar_and_real_sample(tmp_path):
    cat = population(CraterLayer(1e-3, -2.0, 10.0, 100.0), x_range_m=(0, 1e3),
                     y_range_m=(0, 1e3), rng=1)
    back = craters.read_scc(craters.write_scc(cat, tmp_path / "p.scc", area_m2=1e6))
    assert back["lon_deg"] is None and back["axes_m"] is None
    np.testing.assert_allclose(back["diameter_m"], cat["diameter_m"])
    real = craters.read_scc(SAMPLE_SCC)
    assert len(real["diameter_m"]) == 419 and real["area_m2"] == pytest.approx(6.46427730794e6)
    assert real["fraction"].min() < 1 and real["lat_deg"] is not None
    with pytest.raises(ValueError, match="not a spatial crater count"):
        craters.read_scc(tmp_path.joinpath("x.scc").write_text("a = 1\n") and tmp_path / "x.scc")


def test_robbins_columns(tmp_path):
    cat = population(ModelAgeLayer("moon", 3.8, 1000.0, 20000.0), area_m2=2e10, rng=2)
    path = craters.write_catalog(cat, tmp_path / "r.csv", columns="robbins")
    head = path.read_text().splitlines()[0].split(",")
    assert head[:4] == ["CRATER_ID", "LAT_CIRC_IMG", "LON_CIRC_IMG", "DIAM_CIRC_IMG"]
    assert "age_gyr" in head and "diameter_m" not in head
    row = path.read_text().splitlines()[1].split(",")
    assert row[0] == "CF-0000000" and float(row[3]) == pytest.approx(cat["diameter_m"][0] / 1e3)
    back = craters.read_catalog(path)
    np.testing.assert_allclose(back["diameter_m"], cat["diameter_m"], rtol=1e-14)
    np.testing.assert_allclose(back["lat_deg"], cat["lat_deg"])
    np.testing.assert_allclose(back["lon_deg"], np.mod(cat["lon_deg"], 360.0))
    assert np.array_equal(back["age_gyr"], cat["age_gyr"])
    planar = population(CraterLayer(1e-3, -2.0, 10.0, 100.0), x_range_m=(0, 1e3),
                        y_range_m=(0, 1e3), rng=1)
    with pytest.raises(ParameterError, match="`columns` robbins needs a catalog on a body"):
        craters.write_catalog(planar, tmp_path / "p.csv", columns="robbins")
