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
    want = craters.radial_profile(data[:, 0], 1000.0, craters.degradation_from_age(1000.0, 3.0))
    assert np.allclose(data[:, 2], want)
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


@pytest.mark.parametrize("args,needles", [
    (["profile", "--diameter-m", "-5", "--csv", "x.csv"], ["--diameter-m", "> 0"]),
    (["profile", "--diameter-m", "nan", "--csv", "x.csv"], ["--diameter-m", "finite"]),
    (["profile", "--diameter-m", "10", "--degradation", "1.5", "--csv", "x.csv"],
     ["--degradation"]),
    (["profile", "--diameter-m", "10"], ["nothing to write"]),
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
])
def test_bad_input(run_cli, tmp_path, args, needles):
    proc = run_cli("craters", *args, cwd=tmp_path)
    one_line_error(proc, *needles)
    assert list(tmp_path.iterdir()) == []
