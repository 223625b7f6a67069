"""Crater populations: counts, exponents, positions, ages; catalogs to CSV and back."""

from __future__ import annotations

import json

import numpy as np
import pytest
from scipy import stats

import craters
from craters import CraterLayer, population, power_law_population

KS_P_MIN = 0.01


@pytest.fixture(scope="module")
def big_population():
    return power_law_population(radius=2000.0, c=0.5, k=-2.0, d_min=5.0, d_max=800.0, rng=42)


def test_count_exponent_positions_ages(big_population):
    cat = big_population
    mean = 4 * np.pi * 2000.0**2 * 0.5 * (5.0**-2 - 800.0**-2)
    assert abs(len(cat) - mean) <= 4 * np.sqrt(mean)
    k = craters.fit_power_law_exponent(cat["diameter_m"], 5.0, 800.0)
    assert abs(k - (-2.0)) <= 0.05 * 2.0
    assert stats.kstest(np.sin(np.radians(cat["lat_deg"])), "uniform", args=(-1, 2)).pvalue \
        > KS_P_MIN
    assert stats.kstest(cat["lon_deg"], "uniform", args=(0, 360)).pvalue > KS_P_MIN
    assert (np.diff(cat["age_gyr"]) <= 0).all()  # oldest first
    assert cat["diameter_m"].min() >= 5.0 and cat["diameter_m"].max() <= 800.0


def test_same_seed_same_catalog():
    a = power_law_population(radius=300.0, c=0.5, k=-2.0, d_min=2.0, d_max=50.0, rng=7)
    b = power_law_population(radius=300.0, c=0.5, k=-2.0, d_min=2.0, d_max=50.0, rng=7)
    c = power_law_population(radius=300.0, c=0.5, k=-2.0, d_min=2.0, d_max=50.0, rng=8)
    assert a.tobytes() == b.tobytes() and a.tobytes() != c.tobytes()
    assert np.isnan(a["degradation"]).all()  # from the age, by diffusion when stamped


@pytest.mark.parametrize("B", [2.0, 3.0, 4.0])
def test_inversion_sampling_ks(B):
    d = craters.sample_power_law_diameters(20000, 10.0, 100.0, B, rng=int(B))
    lo, hi = 10.0**-B, 100.0**-B

    def cdf(x):  # Li 2022 eq. 20, normalised
        return (lo - np.asarray(x) ** -B) / (lo - hi)

    assert stats.kstest(d, cdf).pvalue > KS_P_MIN


def test_piecewise_layers_and_rectangles():
    layers = [CraterLayer(0.01, -1.8, 5.0, 20.0, 0.0, 1.0),
              CraterLayer(0.05, -2.5, 20.0, 100.0, 2.0, 3.0, degradation=0.4, kind="old")]
    cat = population(layers, x_range_m=(0.0, 2000.0), y_range_m=(-500.0, 500.0), rng=1)
    assert set(np.unique(cat["layer"])) == {0, 1}
    old = cat[cat["layer"] == 1]
    assert (old["kind"] == "old").all() and (old["degradation"] == 0.4).all()
    assert (old["age_gyr"] >= 2.0).all()
    assert cat["x_m"].min() >= 0 and cat["y_m"].max() <= 500.0
    # ages from the older layer come first
    assert (cat["layer"][: len(old)] == 1).all()
    young = cat[cat["layer"] == 0]
    assert np.isnan(young["degradation"]).all()  # from the age when stamped


@pytest.mark.parametrize("kw,match", [
    ({"c": 0.0}, "`c`"), ({"c": -1.0}, "`c`"), ({"k": 0.0}, "`k`"), ({"k": 1.5}, "`k`"),
    ({"d_min": 50.0, "d_max": 10.0}, "d_min"), ({"d_min": -1.0}, "d_min"),
    ({"d_max": np.nan}, "d_max"), ({"radius": -5.0}, "radius_m"),
])
def test_bad_population_input(kw, match):
    args = {"radius": 100.0, "c": 0.5, "k": -2.0, "d_min": 2.0, "d_max": 20.0} | kw
    with pytest.raises(ValueError, match=match):
        power_law_population(**args)


def test_area_and_radius_conflict():
    with pytest.raises(ValueError, match="exactly one"):
        power_law_population(radius=10.0, area=100.0, c=0.5, k=-2.0, d_min=1.0, d_max=2.0)
    with pytest.raises(ValueError, match="x_range_m"):
        power_law_population(radius=10.0, x_range=(0, 1), y_range=(0, 1), c=0.5, k=-2.0,
                             d_min=1.0, d_max=2.0)
    with pytest.raises(ValueError, match="limit"):
        power_law_population(radius=1e6, c=1.0, k=-2.0, d_min=0.01, d_max=2.0)


def test_catalog_csv_roundtrip(tmp_path, big_population):
    cat = big_population[:500]
    path = tmp_path / "cat.csv"
    craters.write_catalog(cat, path)
    first = path.read_text().splitlines()[0]
    assert first.startswith("# craterform crater catalog") and "metres" in first
    back = craters.read_catalog(path)
    assert back.dtype == cat.dtype
    for name in cat.dtype.names:
        floats = cat[name].dtype.kind == "f"
        assert np.array_equal(back[name], cat[name], equal_nan=floats), name  # lossless


def test_geojson_is_rfc_7946(tmp_path):
    cat = craters.make_catalog(x_m=[1.0, 2.0], y_m=[3.0, 4.0], diameter_m=[5.0, 6.0])
    p = craters.write_geojson(cat, tmp_path / "c.geojson",
                              lonlat=lambda x, y: (x * 100.0 - 10.0, y - 10.0), body="Moon",
                              crs="IAU_2015:30100", prj='GEOGCS["Moon"]')
    doc = json.loads(p.read_text())
    # longitudes wrapped to [-180, 180): 190 -> -170; no `crs` member (RFC 7946 4.)
    assert [f["geometry"]["coordinates"] for f in doc["features"]] == [[90.0, -7.0],
                                                                      [-170.0, -6.0]]
    assert "crs" not in doc and doc["craterform"]["crs"] == "IAU_2015:30100"
    assert doc["craterform"]["body"] == "Moon"
    assert doc["features"][0]["properties"]["diameter_m"] == 5.0
    assert (tmp_path / "c.prj").read_text() == 'GEOGCS["Moon"]'
    # a catalog on a body brings its own positions; a planar one needs lonlat
    body = craters.make_catalog(lat_deg=[10.0], lon_deg=[359.5], diameter_m=[5.0])
    doc = json.loads(craters.write_geojson(body, tmp_path / "b.geojson").read_text())
    assert doc["features"][0]["geometry"]["coordinates"] == [-0.5, 10.0]
    assert "craterform" not in doc and not (tmp_path / "b.prj").exists()
    with pytest.raises(ValueError, match="lonlat"):
        craters.write_geojson(cat, tmp_path / "x.geojson")


def test_add_columns_is_append_fields_column_by_column(rng):
    from numpy.lib import recfunctions

    from craters.catalog import add_columns

    n = 500
    cat = craters.make_catalog(lat_deg=rng.uniform(-90, 90, n), lon_deg=rng.uniform(0, 9, n),
                               diameter_m=rng.uniform(1, 9, n), layer=np.arange(n))
    cols = (rng.integers(0, 2**63, n).astype(np.uint64), rng.normal(size=n),
            np.full(n, "transitional"), np.arange(n, dtype=np.int32))
    names = ("id", "depth_m", "morphology", "count")
    for base, args in ((cat, (names, cols)), (cat, ("id", cols[0])),
                       (cat[:0], ("id", cols[0][:0]))):
        want = recfunctions.append_fields(base, *args, usemask=False)
        got = add_columns(base, *args)
        assert got.dtype == want.dtype and got.tobytes() == want.tobytes()
    with pytest.raises(ValueError, match="length 500"):
        add_columns(cat, ("a", "b"), (cols[1], cols[1][:3]))
    with pytest.raises(TypeError, match="structured"):
        add_columns(np.zeros(3), "a", np.zeros(3))


def test_catalog_validation(tmp_path):
    with pytest.raises(ValueError, match="x_m, y_m or lat_deg"):
        craters.make_catalog(diameter_m=[1.0])
    with pytest.raises(ValueError, match="diameter_m"):
        craters.make_catalog(x_m=[0.0], y_m=[0.0], diameter_m=[-1.0])
    with pytest.raises(ValueError, match="lat_deg"):
        craters.make_catalog(lat_deg=[95.0], lon_deg=[0.0], diameter_m=[1.0])
    with pytest.raises(ValueError, match="length"):
        craters.make_catalog(x_m=[0.0, 1.0], y_m=[0.0], diameter_m=[1.0, 2.0])
    with pytest.raises(FileNotFoundError, match="does not exist"):
        craters.read_catalog(tmp_path / "none.csv")
    bad = tmp_path / "bad.csv"
    bad.write_text("x_m,y_m,diameter_m\n1,2,abc\n")
    with pytest.raises(ValueError, match="diameter_m"):
        craters.read_catalog(bad)
