"""The craters command line through its entry point."""

from __future__ import annotations

import numpy as np
import pytest

import craters


def one_line_error(proc, *needles):
    assert proc.returncode == 2, proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error:") and "Traceback" not in proc.stderr
    for n in needles:
        assert n in lines[0], lines[0]


def test_profile_csv_and_plot(run_cli, tmp_path):
    csv, png = tmp_path / "p.csv", tmp_path / "p.png"
    proc = run_cli("craters", "profile", "--diameter-m", "1000", "--age-gyr", "3",
                   "--csv", str(csv), "--plot", str(png))
    assert proc.returncode == 0, proc.stderr
    data = np.loadtxt(csv, delimiter=",", skiprows=2)
    want = craters.radial_profile(data[:, 0], 1000.0, age_gyr=3.0)
    assert np.allclose(data[:, 2], want)
    header = csv.read_text().splitlines()[0]
    assert "depth_m=" in header and "rim_height_m=" in header and "body=moon" in header
    assert png.stat().st_size > 20_000
    assert "depth" in proc.stdout


def test_population_csv_and_plot(run_cli, tmp_path):
    out, png = tmp_path / "c.csv", tmp_path / "sfd.png"
    proc = run_cli("craters", "population", "--craters", "c=0.5,k=-2,d_min_m=5,d_max_m=100",
                   "--radius-m", "200", "--seed", "3", "-o", str(out), "--plot", str(png))
    assert proc.returncode == 0, proc.stderr
    cat = craters.read_catalog(out)
    want = craters.power_law_population(radius=200.0, c=0.5, k=-2.0, d_min=5.0, d_max=100.0,
                                        rng=3)
    assert np.array_equal(cat["diameter_m"], want["diameter_m"])
    assert png.stat().st_size > 20_000


def test_population_model_age_scc_and_robbins(run_cli, tmp_path):
    scc, csv = tmp_path / "m.scc", tmp_path / "m.csv"
    spec = "npf=moon,age_gyr=3.8,d_min_m=100,d_max_m=20000,equilibrium=trask"
    proc = run_cli("craters", "population", "--craters", spec, "--area-m2", "1e9", "--seed",
                   "2", "-o", str(scc))
    assert proc.returncode == 0, proc.stderr
    assert "saturated below D = 4" in proc.stdout
    got = craters.read_scc(scc)
    want = craters.population(craters.parse_layer_spec(spec), area_m2=1e9, rng=2)
    np.testing.assert_allclose(got["diameter_m"], want["diameter_m"], rtol=1e-15)
    assert got["area_m2"] == pytest.approx(1e9) and got["axes_m"] == (1737400.0,) * 3
    proc = run_cli("craters", "population", "--craters", spec, "--area-m2", "1e9", "--seed",
                   "2", "-o", str(csv), "--columns", "robbins", "-q")
    assert proc.returncode == 0 and proc.stdout == "", proc.stderr
    assert csv.read_text().startswith("CRATER_ID,LAT_CIRC_IMG,LON_CIRC_IMG,DIAM_CIRC_IMG,")
    assert np.allclose(craters.read_catalog(csv)["diameter_m"], want["diameter_m"])


def test_population_on_a_body_lists_morphology(run_cli, tmp_path):
    """--body alone: the body's whole surface, and each crater's fresh shape class there
    (the Moon's simple/complex transition is near 15-20 km, Mars' near 7 km)."""
    spec = "npf=moon,age_gyr=3.8,d_min_m=3000,d_max_m=100000"
    classes = {}
    for body in ("moon", "mars"):
        out = tmp_path / f"{body}.csv"
        proc = run_cli("craters", "population", "--body", body, "--craters", spec, "--seed",
                       "1", "-o", str(out))
        assert proc.returncode == 0, proc.stderr
        cat = craters.read_catalog(out)
        area = 4 * np.pi * craters.get_target(body).radius_m ** 2
        assert f"on {area:.6g} m^2" in proc.stdout
        assert (cat["morphology"] == craters.morphology_class(cat["diameter_m"], body)).all()
        classes[body] = cat["morphology"][(cat["diameter_m"] > 9e3) & (cat["diameter_m"] < 11e3)]
    assert set(classes["moon"]) == {"simple"} and "simple" not in set(classes["mars"])
    # gravity moves the transition (1/g): a low-gravity Moon makes 10 km craters simple
    out = tmp_path / "g.csv"
    proc = run_cli("craters", "population", "--body", "mars", "--gravity-m-s2", "0.5",
                   "--craters", spec, "--seed", "1", "-o", str(out))
    cat = craters.read_catalog(out)
    assert set(cat["morphology"][cat["diameter_m"] < 11e3]) == {"simple"}


@pytest.mark.parametrize("args,needles", [
    (["profile", "--diameter-m", "-5", "--csv", "x.csv"], ["--diameter-m", "> 0"]),
    (["profile", "--diameter-m", "nan", "--csv", "x.csv"], ["--diameter-m", "finite"]),
    (["profile", "--diameter-m", "10", "--degradation", "1.5", "--csv", "x.csv"],
     ["--degradation"]),
    (["profile", "--diameter-m", "10", "-q"], ["nothing to do"]),
    (["profile", "--diameter-m", "10", "--age-gyr", "-1"], ["--age-gyr"]),
    (["profile", "--diameter-m", "10", "--age-gyr", "1", "--degradation", "0.5"],
     ["--age-gyr", "--degradation"]),
    (["profile", "--diameter-m", "10", "--body", "small-body"], ["--body-radius-m"]),
    (["population", "--craters", "c=0,k=-2,d_min_m=5,d_max_m=10", "--radius-m", "9", "-o", "x.csv"],
     ["`c`"]),
    (["population", "--craters", "c=1,k=1,d_min_m=5,d_max_m=10", "--radius-m", "9", "-o", "x.csv"],
     ["`k`"]),
    (["population", "--craters", "c=1,k=-2,d_min_m=50,d_max_m=10", "--radius-m", "9", "-o",
      "x.csv"],
     ["d_min_m"]),
    (["population", "--craters", "c=1,k=-2,d_min_m=5,d_max_m=10", "-o", "x.csv"], ["exactly one"]),
    (["population", "--craters", "c=1,k=-2,d_min_m=5,d_max_m=10", "--radius-m", "9", "-o", "x.txt"],
     ["unknown format"]),
    (["population", "--craters", "c=1,k=-2", "--radius-m", "9", "-o", "x.csv"], ["missing"]),
    (["population", "--radius-m", "9", "-o", "x.csv", "--seed", "x"], ["--seed"]),
    (["population", "--craters", "npf=moon,k=-2,age_gyr=3,d_min_m=1000,d_max_m=9000",
      "--area-m2", "1e9", "-o", "x.scc"], ["`k` does not go with npf"]),
    (["population", "--craters", "npf=moon,age_gyr=0,d_min_m=1000,d_max_m=9000",
      "--area-m2", "1e9", "-o", "x.scc"], ["`age_gyr`", "(0, 4.5]"]),
    (["population", "--craters", "npf=moon,age_gyr=5,d_min_m=1000,d_max_m=9000",
      "--area-m2", "1e9", "-o", "x.scc"], ["`age_gyr`", "(0, 4.5]"]),
    (["population", "--craters", "npf=titan,age_gyr=1,d_min_m=1000,d_max_m=9000",
      "--area-m2", "1e9", "-o", "x.scc"], ["`npf` must be one of moon"]),
    (["population", "--craters", "npf=moon,age_gyr=1,d_min_m=1,d_max_m=9000",
      "--area-m2", "1e9", "-o", "x.scc"], ["`d_min_m`", "[10, 300000] m"]),
    (["population", "--craters", "npf=moon,age_gyr=1,d_min_m=1000,d_max_m=9000",
      "--area-m2", "1e9", "-o", "x.scc", "--columns", "robbins"], ["--columns"]),
    (["population", "--craters", "npf=moon,age_gyr=1,d_min_m=1000,d_max_m=9000",
      "--area-m2", "1e9", "-o", "x.csv", "--body", "titan"], ["--body", "moon"]),
    (["population", "--craters", "npf=moon,age_gyr=1,d_min_m=1000,d_max_m=9000",
      "--area-m2", "1e9", "-o", "x.csv", "--gravity-m-s2", "2"], ["--gravity-m-s2", "--body"]),
    (["population", "--craters", "npf=moon,age_gyr=1,d_min_m=1000,d_max_m=9000",
      "--body", "moon", "--gravity-m-s2", "0", "-o", "x.csv"], ["--gravity-m-s2", "> 0"]),
    (["population", "--craters", "npf=moon,age_gyr=1,d_min_m=1000,d_max_m=9000",
      "--body", "small-body", "-o", "x.csv"], ["--radius-m"]),
])
def test_bad_input(run_cli, tmp_path, args, needles):
    proc = run_cli("craters", *args, cwd=tmp_path)
    one_line_error(proc, *needles)
    assert list(tmp_path.iterdir()) == []
