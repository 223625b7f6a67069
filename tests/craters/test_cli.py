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
])
def test_bad_input(run_cli, tmp_path, args, needles):
    proc = run_cli("craters", *args, cwd=tmp_path)
    one_line_error(proc, *needles)
    assert list(tmp_path.iterdir()) == []
