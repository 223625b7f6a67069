"""The latlong command line, through the real entry point."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from latlong import load

SMALL = ["--magnitude", "12"]


def assert_one_line_error(proc, *needles):
    assert proc.returncode == 2, proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1, proc.stderr
    assert lines[0].startswith("error:")
    assert "Traceback" not in proc.stderr
    for needle in needles:
        assert needle in lines[0], lines[0]


def test_build_faulting_outputs(run_cli, tmp_path):
    out = [tmp_path / n for n in ("a.npz", "a.ply", "a.obj")]
    proc = run_cli("latlong", "build", *SMALL, "--base", "faulting", "--seed", "3",
                   "--faults-2", "100", *sum((["-o", str(p)] for p in out), []),
                   "--preview", str(tmp_path / "a.png"))
    assert proc.returncode == 0, proc.stderr
    assert all(p.stat().st_size > 0 for p in out)
    body = load(out[0])
    assert body.magnitude == 12
    meta = body.metadata
    assert meta["seed"] == 3 and meta["base"] == "faulting" and meta["preset"] == "paper"
    assert meta["parameters"]["n_faults_2"] == 100
    assert np.array_equal(body.stretch, [2.0, 1.0, 1.0])  # the paper preset
    assert "wrote" in proc.stdout


def test_preview_is_not_blank(run_cli, tmp_path):
    png = tmp_path / "p.png"
    proc = run_cli("latlong", "build", "--magnitude", "40", "--seed", "1", "--preview", str(png))
    assert proc.returncode == 0, proc.stderr
    import matplotlib.image as mpimg

    img = mpimg.imread(png)[..., :3]
    lit = img.max(axis=2) > 0.1
    assert 0.05 < lit.mean() < 0.9  # the body fills part of the frame
    assert img[lit].std() > 0.02  # shaded, not a flat silhouette


def test_same_seed_same_bytes_any_thread_count(run_cli, tmp_path):
    files = {}
    for tag, threads in (("one", "1"), ("two", "2")):
        d = tmp_path / tag
        d.mkdir()
        proc = run_cli("latlong", "build", "--magnitude", "30", "--base", "faulting",
                       "--seed", "5", "--faults-1", "300", "--faults-2", "500",
                       "-o", str(d / "b.npz"), "-o", str(d / "b.ply"), "-q",
                       env={"NUMBA_NUM_THREADS": threads})
        assert proc.returncode == 0, proc.stderr
        files[tag] = [(d / n).read_bytes() for n in ("b.npz", "b.ply")]
    assert files["one"] == files["two"]
    d = tmp_path / "other"
    d.mkdir()
    proc = run_cli("latlong", "build", "--magnitude", "30", "--base", "faulting", "--seed", "6",
                   "--faults-1", "300", "--faults-2", "500", "-o", str(d / "b.npz"), "-q")
    assert proc.returncode == 0
    assert (d / "b.npz").read_bytes() != files["one"][0]


@pytest.mark.parametrize("args,needles", [
    (["--magnitude", "0"], ["--magnitude", "[1,"]),
    (["--magnitude", "-3"], ["--magnitude"]),
    (["--magnitude", "100000000"], ["--magnitude 100000000", "memory", "GB", "--max-memory-gb"]),
    (["--magnitude", "abc"], ["--magnitude"]),
    (["--base", "cube"], ["--base", "sphere, faulting, fbm"]),
    (["--seed", "1.5"], ["--seed"]),
    (["--seed", "-1"], ["--seed"]),
    (["--radius-m", "nan"], ["--radius-m", "finite"]),
    (["--radius-m", "-5"], ["--radius-m", "[0.001, 1e+09]"]),
    (["--base", "fbm", "--octaves", "0"], ["--octaves"]),
    (["--base", "fbm", "--frequency", "inf"], ["--frequency"]),
    (["--base", "fbm", "--faults-1", "10"], ["--faults-1", "faulting"]),
    (["--base", "faulting", "--max-fault-1-m", "nan"], ["--max-fault-1-m"]),
    (["--base", "faulting", "--preset", "fig5a"], ["--preset fig5a", "faulting"]),
    (["--stretch", "1,2"], ["--stretch"]),
    (["--sun-elevation-deg", "95"], ["--sun-elevation-deg"]),
    (["--frobnicate"], ["unrecognized"]),
])
def test_bad_input_one_line_exit_2(run_cli, tmp_path, args, needles):
    out = tmp_path / "x.npz"
    proc = run_cli("latlong", "build", *SMALL, *args, "-o", str(out))
    assert_one_line_error(proc, *needles)
    assert list(tmp_path.iterdir()) == []


def test_bad_outputs(run_cli, tmp_path):
    proc = run_cli("latlong", "build", *SMALL, "-o", str(tmp_path / "nodir" / "x.npz"))
    assert_one_line_error(proc, "does not exist")
    proc = run_cli("latlong", "build", *SMALL, "-o", str(tmp_path / "x.xyz"))
    assert_one_line_error(proc, "unknown format")
    proc = run_cli("latlong", "build", *SMALL)
    assert_one_line_error(proc, "nothing to write")
    ro = tmp_path / "ro"
    ro.mkdir()
    ro.chmod(0o500)
    try:
        proc = run_cli("latlong", "build", *SMALL, "-o", str(ro / "x.npz"))
        import os

        if os.access(ro, os.W_OK):  # running as root: permissions do not bind
            assert proc.returncode == 0
        else:
            assert_one_line_error(proc, "not writable")
    finally:
        ro.chmod(0o700)
    # an unwritable target that binds even for root
    proc = run_cli("latlong", "build", *SMALL, "-o", "/proc/craterform.npz")
    assert_one_line_error(proc, "/proc")


def test_existing_output_needs_force(run_cli, tmp_path):
    out = tmp_path / "x.npz"
    out.write_bytes(b"keep me")
    proc = run_cli("latlong", "build", *SMALL, "-o", str(out))
    assert_one_line_error(proc, "exists", "--force")
    assert out.read_bytes() == b"keep me"
    proc = run_cli("latlong", "build", *SMALL, "-o", str(out), "--force", "-q")
    assert proc.returncode == 0 and proc.stdout == ""
    assert load(out).magnitude == 12


def test_config_file(run_cli, tmp_path):
    cfg = tmp_path / "scene.toml"
    out = tmp_path / "s.npz"
    cfg.write_text(f'magnitude = 10\nbase = "fbm"\npreset = "fig5c"\nseed = 9\n'
                   f'radius_m = 500\nstretch = [1, 1, 1.5]\noutput = ["{out}"]\nquiet = true\n')
    proc = run_cli("latlong", "build", "--config", str(cfg))
    assert proc.returncode == 0, proc.stderr
    body = load(out)
    assert body.magnitude == 10 and body.radius_m == 500
    assert body.metadata["parameters"]["lacunarity"] == 2.5
    assert np.array_equal(body.stretch, [1, 1, 1.5])
    # the command line overrides the file
    proc = run_cli("latlong", "build", "--config", str(cfg), "--magnitude", "6", "--force")
    assert proc.returncode == 0, proc.stderr
    assert load(out).magnitude == 6
    bad = tmp_path / "bad.toml"
    bad.write_text("magnitude = 10\ncolour = 'red'\n")
    assert_one_line_error(run_cli("latlong", "build", "--config", str(bad)), "colour")
    bad.write_text("magnitude = 'ten'\n")
    assert_one_line_error(run_cli("latlong", "build", "--config", str(bad)), "magnitude")
    bad.write_text("magnitude = \n")
    assert_one_line_error(run_cli("latlong", "build", "--config", str(bad)), "TOML")


def test_every_option_has_a_config_key():
    from latlong.cli import build_parser
    from latlong.cli.build import OPTIONS

    parser = build_parser()
    build = parser._subparsers._group_actions[0].choices["build"]
    dests = {a.dest for a in build._actions} - {"help", "config"}
    assert dests == {*OPTIONS, "wait"}  # --wait: every command that has --force


def test_info(run_cli, tmp_path):
    out = tmp_path / "i.npz"
    assert run_cli("latlong", "build", *SMALL, "--seed", "4", "-o", str(out), "-q").returncode == 0
    proc = run_cli("latlong", "info", str(out))
    assert proc.returncode == 0, proc.stderr
    assert "magnitude  12" in proc.stdout and "seed       4" in proc.stdout
    assert_one_line_error(run_cli("latlong", "info", str(tmp_path / "none.npz")), "does not exist")


def test_other_entry_points(run_cli):
    for pkg in ("craters", "dem", "latlong"):
        proc = run_cli(pkg, "--version")
        assert proc.returncode == 0 and "craterform" in proc.stdout


def test_cratered_preset_outputs_and_determinism(run_cli, tmp_path):
    digests = {}
    for tag, env in (("a", {}), ("b", {}), ("t1", {"NUMBA_NUM_THREADS": "1"})):
        d = tmp_path / tag
        d.mkdir()
        # craters from 3 m (~7 000): the preset's 1 m makes ~62 000, mostly below this mesh
        proc = run_cli("latlong", "build", "--preset", "fbm-cratered", "--magnitude", "60",
                       "--craters", "c=0.5,k=-2,d_min_m=3,d_max_m=15",
                       "--seed", "1", "-o", str(d / "a.npz"), "--catalog", str(d / "a.csv"),
                       "--preview", str(d / "a.png"), "-q", env=env)
        assert proc.returncode == 0, proc.stderr
        digests[tag] = [(d / n).read_bytes() for n in ("a.npz", "a.csv", "a.png")]
    assert digests["a"] == digests["b"] == digests["t1"]
    import craters

    body = load(tmp_path / "a" / "a.npz")
    cat = craters.read_catalog(tmp_path / "a" / "a.csv")
    assert len(cat) == len(body.craters) > 100
    for name in ("lat_deg", "lon_deg", "diameter_m", "depth_m", "rim_radius_m", "age_gyr"):
        assert np.array_equal(cat[name], body.craters[name])
    assert body.metadata["preset"] == "fbm-cratered"


def test_crater_layers_from_options_and_config(run_cli, tmp_path):
    out = tmp_path / "c.npz"
    proc = run_cli("latlong", "build", "--magnitude", "40", "--base", "sphere", "--radius-m",
                   "100", "--craters", "c=0.2,k=-2,d_min_m=3,d_max_m=20", "--craters",
                   "c=0.01,k=-3,d_min_m=20,d_max_m=30,degradation=0.5", "--seed", "2", "-o",
                   str(out), "-q")
    assert proc.returncode == 0, proc.stderr
    cat = load(out).craters
    assert set(np.unique(cat["layer"])) <= {0, 1} and len(cat) > 10
    cfg = tmp_path / "scene.toml"
    out2 = tmp_path / "d.npz"
    cfg.write_text(f'magnitude = 40\nbase = "sphere"\nradius_m = 100\nseed = 2\n'
                   f'output = ["{out2}"]\nquiet = true\ncrater_roughness = false\n'
                   '[[craters]]\nc = 0.2\nk = -2.0\nd_min_m = 3\nd_max_m = 20\n'
                   'age_max_gyr = 1.0\nkind = "young"\n')
    proc = run_cli("latlong", "build", "--config", str(cfg))
    assert proc.returncode == 0, proc.stderr
    cat2 = load(out2).craters
    assert (cat2["kind"] == "young").all() and (cat2["age_gyr"] <= 1.0).all()
    cfg.write_text('magnitude = 40\n[[craters]]\nc = 0.2\nk = -2.0\nd_min_m = 3\n'
                   'd_max_m = 20\nshape = "round"\n')
    assert_one_line_error(run_cli("latlong", "build", "--config", str(cfg), "-o",
                                  str(tmp_path / "x.npz")), "shape")


def test_model_age_craters_scc_and_robbins(run_cli, tmp_path):
    """npf layers from an option and a [[craters]] table; the catalog as .scc (the body's
    area, its axes) and with Robbins column names."""
    import craters

    scc, csv, out = tmp_path / "c.scc", tmp_path / "c.csv", tmp_path / "c.npz"
    base = ["--magnitude", "40", "--base", "sphere", "--radius-m", "20000", "--seed", "4",
            "--stretch", "1.2,1,1"]
    spec = "npf=moon,age_gyr=3.8,d_min_m=300,d_max_m=3000,equilibrium=hartmann"
    proc = run_cli("latlong", "build", *base, "--craters", spec, "--catalog", str(scc),
                   "-o", str(out), "-q")
    assert proc.returncode == 0, proc.stderr
    body = load(out)
    got = craters.read_scc(scc)
    assert len(got["diameter_m"]) == len(body.craters) > 50
    np.testing.assert_allclose(got["diameter_m"], body.craters["diameter_m"])
    assert got["axes_m"] == pytest.approx((24000.0, 20000.0, 20000.0))
    from latlong.surface import band_areas
    assert got["area_m2"] == pytest.approx(float(band_areas(body).sum()), rel=1e-12)
    cfg = tmp_path / "scene.toml"
    cfg.write_text('magnitude = 40\nbase = "sphere"\nradius_m = 20000\nseed = 4\n'
                   'stretch = [1.2, 1, 1]\ncatalog_columns = "robbins"\n'
                   f'catalog = "{csv}"\nquiet = true\n'
                   '[[craters]]\nnpf = "moon"\nage_gyr = 3.8\nd_min_m = 300\n'
                   'd_max_m = 3000\nequilibrium = "hartmann"\n')
    proc = run_cli("latlong", "build", "--config", str(cfg))
    assert proc.returncode == 0, proc.stderr
    assert csv.read_text().startswith("CRATER_ID,LAT_CIRC_IMG,LON_CIRC_IMG,DIAM_CIRC_IMG,")
    np.testing.assert_allclose(craters.read_catalog(csv)["diameter_m"],
                               body.craters["diameter_m"])


@pytest.mark.parametrize("args,needles", [
    (["--craters", "npf=moon,c=1,age_gyr=3,d_min_m=10,d_max_m=20"],
     ["--craters", "`c` does not go with npf"]),
    (["--craters", "npf=moon,age_gyr=9,d_min_m=10,d_max_m=20"], ["--craters", "(0, 4.5]"]),
    (["--craters", "c=1,k=-2,d_min_m=1,d_max_m=5", "--catalog", "c.scc",
      "--catalog-columns", "robbins"], ["--catalog-columns", "CSV"]),
    (["--craters", "c=1,k=-2,d_min_m=1,d_max_m=5", "--catalog", "c.csv",
      "--catalog-columns", "nasa"], ["--catalog-columns", "craterform, robbins"]),
    (["--radius-m", "100", "--craters", "c=0.1,k=-2,d_min_m=5,d_max_m=150"],
     ["--craters", "larger than the body"]),
    (["--craters", "c=0,k=-2,d_min_m=1,d_max_m=5"], ["--craters", "`c`"]),
    (["--craters", "c=-1,k=-2,d_min_m=1,d_max_m=5"], ["--craters", "`c`"]),
    (["--craters", "c=0.1,k=-2,d_min_m=-1,d_max_m=5"], ["--craters", "d_min_m"]),
    (["--craters", "c=0.1,k=-2,d_min_m=1,d_max_m=-5"], ["--craters", "d_max_m"]),
    (["--preset", "vesta-like"], ["--preset", "fbm-cratered"]),
    (["--catalog", "x.csv"], ["--catalog", "crater layers"]),
    (["--views", "4", "--preview", "p.png"], ["--views"]),
])
def test_bad_crater_input(run_cli, tmp_path, args, needles):
    proc = run_cli("latlong", "build", "--magnitude", "20", *args, "-o", "out.npz",
                   cwd=tmp_path)
    assert_one_line_error(proc, *needles)
    assert list(tmp_path.iterdir()) == []


def test_presets_command(run_cli):
    proc = run_cli("latlong", "presets")
    assert proc.returncode == 0
    for name in ("fbm-cratered", "faulted-cratered", "eros", "itokawa", "bennu", "paper",
                 "fig5c"):
        assert f"\n{name}\n" in "\n" + proc.stdout
    assert "craters = ['c=0.5,k=-2,d_min_m=1,d_max_m=15']" in proc.stdout


def test_render_command(run_cli, tmp_path):
    model = tmp_path / "m.npz"
    assert run_cli("latlong", "build", "--magnitude", "30", "--seed", "1", "-o", str(model),
                   "-q").returncode == 0
    one, six = tmp_path / "one.png", tmp_path / "six.png"
    proc = run_cli("latlong", "render", str(model), "-o", str(one), "--width-px", "320",
                   "--height-px", "240", "--view-lat-deg", "30", "--view-lon-deg", "45",
                   "--camera-distance-m", "400", "-q")
    assert proc.returncode == 0, proc.stderr
    proc = run_cli("latlong", "render", str(model), "-o", str(six), "--views", "6",
                   "--width-px", "200", "--height-px", "150", "-q")
    assert proc.returncode == 0, proc.stderr
    import matplotlib.image as mpimg

    img1, img6 = mpimg.imread(one), mpimg.imread(six)
    assert img1.shape[:2] == (240, 320) and img6.shape[:2] == (300, 600)
    for tile in (img6[:150, :200], img6[150:, 400:]):
        assert (tile[..., :3].max(axis=2) > 0.1).mean() > 0.05  # each view shows the body
    assert_one_line_error(run_cli("latlong", "render", str(model), "-o", str(one)), "exists")
    assert_one_line_error(run_cli("latlong", "render", str(model), "-o", str(tmp_path / "x.png"),
                                  "--sun-elevation-deg", "100"), "--sun-elevation-deg")


def test_shape_model_base(run_cli, tmp_path):
    data = Path(__file__).parents[1] / "data"
    out, png = tmp_path / "b.npz", tmp_path / "b.png"
    proc = run_cli("latlong", "build", "--base", f"shape:{data / 'bennu_radar_sbgat.obj'}",
                   "--shape-units", "km", "--magnitude", "60", "--craters",
                   "c=0.9,k=-3,d_min_m=10,d_max_m=40", "--amplitude-m", "0.5", "--seed", "2",
                   "-o", str(out), "--preview", str(png), "-q")
    assert proc.returncode == 0, proc.stderr
    body = load(out)
    assert body.metadata["base"] == "shape" and len(body.craters) > 0
    assert 200 < body.radius_m < 290  # Bennu's volume-equivalent radius is ~246 m
    itokawa = data / "itokawa_32.obj"
    for args, needles in (
            ([f"shape:{itokawa}"], ["--shape-units"]),
            ([f"shape:{itokawa}", "--shape-units", "km"],
             ["--shape-crossings", "not star-shaped", "%", "--surface mesh"]),
            ([f"shape:{itokawa}", "--shape-units", "km", "--shape-crossings", "outermost",
              "--craters", "c=0.1,k=-2,d_min_m=5,d_max_m=40"], ["--craters", "resolution"]),
            ([f"shape:{itokawa}", "--shape-units", "km", "--radius-m", "5"],
             ["--radius-m", "shape"]),
            ([f"shape:{tmp_path / 'none.obj'}", "--shape-units", "km"], ["does not exist"]),
            (["shape:"], ["needs a path"])):
        proc = run_cli("latlong", "build", "--magnitude", "20", "--base", *args, "-o",
                       str(tmp_path / "x.npz"))
        assert_one_line_error(proc, *needles)
    assert not (tmp_path / "x.npz").exists()


def test_slopes_and_spectrum_commands(run_cli, tmp_path):
    data = Path(__file__).parents[1] / "data"
    model = tmp_path / "m.npz"
    assert run_cli("latlong", "build", "--preset", "eros", "--magnitude", "40",
                   "--seed", "3", "-o", str(model), "-q").returncode == 0
    csv, png = tmp_path / "s.csv", tmp_path / "s.png"
    proc = run_cli("latlong", "slopes", str(model), "--compare", str(data / "eros001708.tab"),
                   "--shape-units", "km", "--label", "synthetic", "Eros", "--csv", str(csv),
                   "--plot", str(png))
    assert proc.returncode == 0, proc.stderr
    lines = proc.stdout.splitlines()
    assert lines[0].split()[:2] == ["input", "median_deg"]
    assert lines[1].startswith("synthetic") and lines[2].startswith("Eros")
    text = csv.read_text().splitlines()
    assert text[0].startswith("# latlong slopes") and "deg" in text[1]
    table = np.loadtxt(csv, delimiter=",", skiprows=2)
    assert table[:, 2].sum() == pytest.approx(1.0) and table[:, 4].sum() == pytest.approx(1.0)
    assert png.stat().st_size > 20_000
    csv2, png2 = tmp_path / "p.csv", tmp_path / "p.png"
    proc = run_cli("latlong", "spectrum", str(model), "--compare",
                   str(data / "eros001708.tab"), "--shape-units", "km", "--magnitude", "40",
                   "--csv", str(csv2), "--plot", str(png2), "-q")
    assert proc.returncode == 0, proc.stderr
    assert "power_m2" in csv2.read_text().splitlines()[1]
    assert_one_line_error(run_cli("latlong", "slopes", str(data / "eros001708.tab"),
                                  "--csv", str(tmp_path / "x.csv")), "--shape-units")
    assert_one_line_error(run_cli("latlong", "slopes", str(model), "--radius-deg", "-1",
                                  "--csv", str(tmp_path / "x.csv")), "--radius-deg")
    assert_one_line_error(run_cli("latlong", "slopes", str(model), "--compare", str(model),
                                  "--label", "one", "--csv", str(tmp_path / "x.csv")),
                          "--label")
    assert not (tmp_path / "x.csv").exists()


def test_gravitational_slopes_command(run_cli, tmp_path):
    data = Path(__file__).parents[1] / "data"
    eros = str(data / "eros001708.tab")
    csv = tmp_path / "g.csv"
    proc = run_cli("latlong", "slopes", eros, "--shape-units", "km", "--density-kg-m3",
                   "2670", "--period-h", "5.27", "--spin-axis", "0,0,1", "--csv", str(csv))
    assert proc.returncode == 0, proc.stderr
    median = float(proc.stdout.splitlines()[1].split()[1])
    assert 4 < median < 15  # gravitational, not the ~40 deg geometric median
    head = csv.read_text().splitlines()[0]
    assert "effective gravity" in head and "2670 kg/m^3" in head and " m at the mean" in head
    for args, flag in ((("--period-h", "5"), "--period-h"),
                       (("--spin-axis", "0,0,1"), "--spin-axis"),
                       (("--density-kg-m3", "-3"), "--density-kg-m3"),
                       (("--density-kg-m3", "2670", "--period-h", "0"), "--period-h"),
                       (("--density-kg-m3", "2670", "--spin-axis", "0,0"), "--spin-axis")):
        assert_one_line_error(run_cli("latlong", "slopes", eros, "--shape-units", "km",
                                      *args, "--csv", str(tmp_path / "x.csv")), flag)
    assert not (tmp_path / "x.csv").exists()


def test_build_summary_gives_a_stretched_body_its_true_size():
    """Issue 19 item 8: a stretched body's summary gives its distances from the centre,
    not its radii (which printed 127 m for a body reaching 239 m)."""
    from latlong import Body, LatLongGrid
    from latlong.cli.build import _distance_range

    body = Body.sphere(LatLongGrid(12), 100.0).replace(stretch=(2.0, 1.0, 0.5))
    lo, hi = _distance_range(body)
    assert abs(hi - 200.0) < 1e-9 and abs(lo - 50.0) < 1e-9
    assert _distance_range(Body.sphere(LatLongGrid(4), 7.0)) == (7.0, 7.0)
