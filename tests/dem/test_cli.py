"""The dem command line, through the real entry point (python -m dem)."""

from __future__ import annotations

import json
import subprocess
from pathlib import Path

import numpy as np
import pytest
import rasterio
import rasterio.transform
from affine import Affine

import dem

MOON_WKT = ('GEOGCS["Moon 2015",DATUM["Moon_2015",SPHEROID["Moon",1737400,0]],'
            'PRIMEM["Reference_Meridian",0],UNIT["degree",0.0174532925199433]]')


def assert_one_line_error(proc, *needles):
    assert proc.returncode == 2, proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1, proc.stderr
    assert lines[0].startswith("error:") and "Traceback" not in proc.stderr
    for needle in needles:
        assert needle in lines[0], lines[0]


class InProcess:
    """``dem.cli.main`` in this process (quick) with the entry point's exit code and output."""

    def __init__(self, capsys):
        self.capsys = capsys

    def __call__(self, *argv):
        from dem.cli import main

        try:
            code = main(list(argv[1:]))
        except SystemExit as exc:  # argparse errors
            code = exc.code
        out, err = self.capsys.readouterr()
        return subprocess.CompletedProcess(argv, code, out, err)


@pytest.fixture
def lola_tif(tmp_path, lola_crop):
    """The LOLA crop as a 257 x 257 geographic GeoTIFF without craterform tags."""
    path = tmp_path / "in.tif"
    with rasterio.open(path, "w", driver="GTiff", width=257, height=257, count=1,
                       dtype="float32", crs=MOON_WKT, transform=lola_crop.transform) as ds:
        ds.write(lola_crop.heights.astype(np.float32), 1)
    return path


MOON = ["--body-radius-m", "1737400"]


def write_ellipsoid(path):
    """A geographic GeoTIFF on an ellipsoid (Mars's axes): no one radius, so the body
    radius must be given (a sphere's CRS, as the Moon's, gives it itself)."""
    with rasterio.open(path, "w", driver="GTiff", width=9, height=9, count=1,
                       dtype="float32", crs="+proj=longlat +a=3396190 +b=3376200 +no_defs",
                       transform=Affine(0.25, 0, 148.0, 0, -0.25, 32.0)) as ds:
        ds.write(np.zeros((9, 9), np.float32), 1)
    return path


def test_expand_acceptance_257(run_cli, capsys, tmp_path, lola_tif):
    out = tmp_path / "out.tif"
    proc = run_cli("dem", "expand", str(lola_tif), "-o", str(out), "--levels", "1",
                   "--seed", "7", *MOON)
    assert proc.returncode == 0, proc.stderr
    assert "wrote" in proc.stdout
    with rasterio.open(lola_tif) as a, rasterio.open(out) as b:
        zin, zout = a.read(1), b.read(1)
        assert zout.shape == (513, 513) and np.array_equal(zout[::2, ::2], zin)
        assert b.crs == a.crs
        rows, cols = np.mgrid[0:257, 0:257]
        x0, y0 = rasterio.transform.xy(a.transform, rows.ravel(), cols.ravel())
        x1, y1 = rasterio.transform.xy(b.transform, 2 * rows.ravel(), 2 * cols.ravel())
        assert np.abs(np.subtract(x0, x1)).max() < 1e-9
        assert np.abs(np.subtract(y0, y1)).max() < 1e-9
        tags = b.tags()
        assert tags["CRATERFORM_GENERATOR"] == "craterform dem.expand"
        assert tags["CRATERFORM_SEED"] == "7"
        assert "fractal_dimension" in tags["CRATERFORM_PARAMETERS"]
    # the same DEM expanded as 4 tiles (sharing their edge pixels) gives the same pixels
    mosaic = np.full((513, 513), np.nan, np.float32)
    fd = str(dem.read(out).history[-1]["parameters"]["fractal_dimension"])
    for r0 in (0, 128):
        for c0 in (0, 128):
            tile = tmp_path / f"t{r0}_{c0}.tif"
            proc = InProcess(capsys)("dem", "expand", str(lola_tif), "-o", str(tile),
                                     "--seed", "7", "--region", f"{r0},{c0},129", "-q", *MOON)
            assert proc.returncode == 0, proc.stderr
            with rasterio.open(tile) as t:
                mosaic[2 * r0:2 * r0 + 257, 2 * c0:2 * c0 + 257] = t.read(1)
                assert t.transform == b.transform @ Affine.translation(2 * c0, 2 * r0)
            assert dem.read(tile).history[-1]["parameters"]["fractal_dimension"] == float(fd)
    assert np.array_equal(mosaic, zout)


@pytest.mark.parametrize("command,extra", [("expand", ["--levels", "2"]), ("fill", [])])
def test_same_seed_same_bytes_any_thread_count(run_cli, capsys, tmp_path, lola_crop, command,
                                               extra):
    z = lola_crop.heights.copy()
    z[100:130, 40:90] = np.nan
    src = tmp_path / "src.tif"
    dem.write(lola_crop.replace(heights=z) if command == "fill" else lola_crop, src)
    files = {}
    for threads in ("1", "2"):
        out = tmp_path / f"{command}_{threads}.tif"
        proc = run_cli("dem", command, str(src), "-o", str(out), "--seed", "5", "-q", *extra,
                       env={"NUMBA_NUM_THREADS": threads})
        assert proc.returncode == 0 and proc.stdout == "", proc.stderr
        files[threads] = out.read_bytes()
    assert files["1"] == files["2"]
    other = tmp_path / "other.tif"
    assert InProcess(capsys)("dem", command, str(src), "-o", str(other), "--seed", "6", "-q",
                             *extra).returncode == 0
    assert other.read_bytes() != files["2"]


def test_fill(run_cli, tmp_path, tiny_geotiff):
    out = tmp_path / "filled.tif"
    proc = run_cli("dem", "fill", str(tiny_geotiff), "-o", str(out), "--seed", "1",
                   "--roughness", "0.01")
    assert proc.returncode == 0, proc.stderr
    a, b = dem.read(tiny_geotiff), dem.read(out)
    assert np.isfinite(b.heights).all() and b.crs == a.crs and b.transform == a.transform
    known = a.known
    assert np.array_equal(b.heights[known], a.heights[known])
    assert b.history[-1]["parameters"]["roughness"] == 0.01


def test_info(run_cli, capsys, lola_tif, tiny_geotiff):
    proc = run_cli("dem", "info", str(lola_tif), *MOON)
    assert proc.returncode == 0, proc.stderr
    out = proc.stdout
    for needle in ("257 x 257 pixels", "Moon 2015", "7580.8", "0.25, 0, 148, 0, -0.25, 32",
                   "unknown    0.000 %", "height_m   min -6059.5",
                   "fractal_d  2.5975 (locally normalised variogram, lags 2-8 px)",
                   "spectral_d 2.5249 (power-spectrum slope, wavelengths 4-16 px)",
                   "resolves   craters from 30323.3 m (4 px)", "craters    147 found of 4-64 px"):
        assert needle in out, out
    proc = InProcess(capsys)("dem", "info", str(tiny_geotiff))
    assert "EPSG:32633" in proc.stdout and "(1 pixels)" in proc.stdout


def write_no_crs(path):
    with rasterio.open(path, "w", driver="GTiff", width=9, height=9, count=1, dtype="float32",
                       transform=Affine(2, 0, 0, 0, -2, 18)) as ds:
        ds.write(np.random.default_rng(0).random((9, 9), dtype=np.float32), 1)


# the acceptance cases run through the real entry point, the others in-process (quicker)
ENTRY_POINT = {"nocrs", "geographic", "allnan", "outside", "not-raster", "no-command"}


@pytest.mark.parametrize("case,args,needles", [
    ("nocrs", ["expand", "{nocrs}", "-o", "{out}"], ["no CRS", "--pixel-size-m"]),
    ("nocrs-info", ["info", "{nocrs}"], ["no CRS", "--pixel-size-m"]),
    ("geographic", ["expand", "{ellipsoid}", "-o", "{out}"],
     ["geographic CRS", "--body-radius-m"]),
    ("allnan", ["fill", "{nan}", "-o", "{out}", "--pixel-size-m", "1"], ["NoData/NaN"]),
    ("outside", ["expand", "{geo}", "-o", "{out}", "--region", "200,200,129", *MOON],
     ["not inside the DEM"]),
    ("outside-bounds", ["expand", "{geo}", "-o", "{out}", "--region", "0,0,1,1", *MOON],
     ["not inside the DEM"]),
    ("not-raster", ["expand", "{text}", "-o", "{out}"], ["not a raster file"]),
    ("missing", ["info", "{missing}"], ["does not exist"]),
    ("size", ["expand", "{geo}", "-o", "{out}", "--region", "0,0,100", *MOON], ["2^n + 1"]),
    ("levels", ["expand", "{geo}", "-o", "{out}", "--levels", "0", *MOON], ["--levels"]),
    ("levels-syntax", ["expand", "{geo}", "-o", "{out}", "--levels", "two"], ["--levels"]),
    ("fd", ["expand", "{geo}", "-o", "{out}", "--fractal-dimension", "3.5", *MOON],
     ["--fractal-dimension", "[2, 3]"]),
    ("fd-nan", ["expand", "{geo}", "-o", "{out}", "--fractal-dimension", "nan"],
     ["--fractal-dimension", "finite"]),
    ("roughness", ["fill", "{geo}", "-o", "{out}", "--roughness", "-1", *MOON], ["--roughness"]),
    ("gap-craters", ["fill", "{geo}", "-o", "{out}", "--craters", "c=1,k=2,d_min_m=1,d_max_m=5",
                     *MOON], ["--craters", "k"]),
    ("region-syntax", ["expand", "{geo}", "-o", "{out}", "--region", "1,2"], ["--region"]),
    ("seed", ["fill", "{geo}", "-o", "{out}", "--seed", "-4"], ["--seed"]),
    ("radius", ["fill", "{geo}", "-o", "{out}", "--body-radius-m", "0"], ["--body-radius-m"]),
    ("band", ["fill", "{geo}", "-o", "{out}", "--band", "2", *MOON], ["band", "[1, 1]"]),
    ("suffix", ["fill", "{geo}", "-o", "{png}", *MOON], ["unknown format"]),
    ("no-output", ["fill", "{geo}", *MOON], ["-o/--output"]),
    ("no-input", ["fill", "-o", "{out}"], ["needs an input"]),
    ("in-is-out", ["fill", "{geo}", "-o", "{geo}", "--force", *MOON], ["is the input"]),
    ("unknown-flag", ["fill", "{geo}", "--frobnicate"], ["unrecognized"]),
    ("no-command", [], ["required"]),
])
def test_bad_input_one_line_exit_2_nothing_written(run_cli, capsys, tmp_path, lola_tif, case,
                                                   args, needles):
    write_no_crs(tmp_path / "nocrs.tif")
    dem.write(dem.Dem(np.full((5, 5), np.nan), pixel_size_m=1.0), tmp_path / "nan.tif")
    (tmp_path / "notes.txt").write_text("not a raster\n")
    write_ellipsoid(tmp_path / "ellipsoid.tif")
    names = {"nocrs": tmp_path / "nocrs.tif", "geo": lola_tif, "nan": tmp_path / "nan.tif",
             "ellipsoid": tmp_path / "ellipsoid.tif",
             "text": tmp_path / "notes.txt", "missing": tmp_path / "none.tif",
             "out": tmp_path / "out.tif", "png": tmp_path / "out.png"}
    before = sorted(p.name for p in tmp_path.iterdir())
    runner = run_cli if case in ENTRY_POINT else InProcess(capsys)
    proc = runner("dem", *[a.format(**names) for a in args])
    assert_one_line_error(proc, *needles)
    assert sorted(p.name for p in tmp_path.iterdir()) == before


def test_existing_output_needs_force(run_cli, capsys, tmp_path, tiny_geotiff):
    out = tmp_path / "x.tif"
    out.write_bytes(b"keep me")
    proc = InProcess(capsys)("dem", "fill", str(tiny_geotiff), "-o", str(out))
    assert_one_line_error(proc, "exists", "--force")
    assert out.read_bytes() == b"keep me"
    proc = run_cli("dem", "fill", str(tiny_geotiff), "-o", str(out), "--force", "-q")
    assert proc.returncode == 0 and proc.stdout == ""
    assert dem.read(out).shape == (33, 33)


def test_config_file(run_cli, capsys, tmp_path, tiny_geotiff):
    cfg = tmp_path / "x.toml"
    out = tmp_path / "e.tif"
    cfg.write_text(f'input = "{tiny_geotiff}"\noutput = "{out}"\nlevels = 2\nseed = 3\n'
                   f'fractal_dimension = 2.3\nroughness = 0.02\nregion = "0,0,17"\n'
                   f'quiet = true\n')
    # the tiny GeoTIFF has a NoData pixel at (3, 4): fill first, then expand
    filled = tmp_path / "f.tif"
    assert InProcess(capsys)("dem", "fill", str(tiny_geotiff), "-o", str(filled),
                             "-q").returncode == 0
    proc = run_cli("dem", "expand", "--config", str(cfg), str(filled))
    assert proc.returncode == 0, proc.stderr
    e = dem.read(out)
    params = e.history[-1]["parameters"]
    assert e.shape == (65, 65) and params["roughness"] == 0.02 and params["levels"] == 2
    assert proc.stdout == ""  # quiet from the file
    run = InProcess(capsys)
    cfg.write_text('levels = 2\ncolour = "red"\n')
    assert_one_line_error(run("dem", "expand", "--config", str(cfg), str(filled)),
                          "colour", "allowed")
    cfg.write_text("levels = 'two'\n")  # the library checks it, the file's key is named
    assert_one_line_error(run("dem", "expand", "--config", str(cfg), str(filled), "-o",
                              str(tmp_path / "x.tif")), "config", "key 'levels'", "integer")
    cfg.write_text("levels = \n")
    assert_one_line_error(run("dem", "expand", "--config", str(cfg), str(filled)), "TOML")


COMMANDS = ("info", "fill", "expand", "enhance", "mesh", "slopes", "spectrum")


def options_for(command: str) -> dict:
    """The options of ``dem COMMAND`` by key: the table that makes its flags, help texts
    and config keys (:func:`craters.cli.options.command`)."""
    from dem.cli import build_parser

    return build_parser()._subparsers._group_actions[0].choices[command].get_default(
        "func").options


@pytest.mark.parametrize("command", COMMANDS)
def test_every_option_has_a_config_key_and_shows_its_default(command):
    from dem.cli import build_parser

    sub = build_parser()._subparsers._group_actions[0].choices[command]
    actions = [a for a in sub._actions if a.dest != "help"]
    assert {a.dest for a in actions} - {"config"} == set(options_for(command))
    assert "input" in options_for(command)  # the input is positional everywhere
    for action in actions:
        assert "(default: " in action.help, (command, action.dest)


def test_quiet_means_the_same_everywhere():
    quiet = {options_for(c)["quiet"] for c in COMMANDS if "quiet" in options_for(c)}
    assert len(quiet) == 1 and next(iter(quiet)).flag == "-q/--quiet"
    assert {c for c in COMMANDS if "quiet" not in options_for(c)} == {"info"}


# --------------------------------------------------------------------------- enhance, mesh
def write_scene(path, **keys):
    """A TOML scene (strings, numbers, lists of those)."""
    def fmt(v):
        if isinstance(v, bool):
            return "true" if v else "false"
        if isinstance(v, list | tuple):
            return "[" + ", ".join(fmt(x) for x in v) + "]"
        return f'"{v}"' if isinstance(v, str) else repr(v)

    path.write_text("".join(f"{k} = {fmt(v)}\n" for k, v in keys.items()))
    return path


def scene_keys(tmp_path, lola_tif, **extra):
    keys = dict(input=str(lola_tif), output=str(tmp_path / "stack"), layers=4, size=65,
                target=[180.0, -0.5], body_radius_m=1737400.0,
                craters=["c=0.05,k=-2,d_min_m=200,d_max_m=100000",
                         "c=0.005,k=-1.8,d_min_m=20000,d_max_m=200000,age_min_gyr=3,age_max_gyr=3.8,kind=old"])
    keys.update(extra)
    return keys


def test_enhance_and_mesh_through_the_entry_point(run_cli, tmp_path, lola_tif):
    scene = write_scene(tmp_path / "scene.toml", **scene_keys(tmp_path, lola_tif))
    proc = run_cli("dem", "enhance", "--config", str(scene), "--seed", "9")
    assert proc.returncode == 0, proc.stderr
    assert "wrote" in proc.stdout and "seed 9" in proc.stdout
    stack = dem.read_stack(tmp_path / "stack" / "manifest.json")
    assert len(stack) == 4 and stack.is_consistent()
    for k in range(1, 4):  # every pair, from the files
        r0, c0, w = stack.windows[k - 1]
        with rasterio.open(tmp_path / "stack" / f"layer_{k:02d}.tif") as fine, \
                rasterio.open(tmp_path / "stack" / f"layer_{k - 1:02d}.tif") as coarse:
            assert np.array_equal(fine.read(1)[::2, ::2],
                                  coarse.read(1)[r0:r0 + w, c0:c0 + w])
            assert fine.crs == coarse.crs
            assert fine.transform.a == pytest.approx(coarse.transform.a / 2, rel=1e-12)
    info = stack.info
    c = info["craters"]
    assert info["seed"] == 9 and sum(c["stamped"]) > 20
    assert c["drawn"] == (sum(c["stamped"]) + sum(c["erased_on_steep_ground"])
                          + sum(c["erased_by_younger_crater"]) + c["rejected"])
    ids = np.concatenate([cat["index"] for cat in stack.catalogs])
    assert len(ids) == len(set(ids.tolist()))
    # the target pixel is the centre of every layer
    for d in stack.layers:
        x, y = d.xy(32, 32)
        assert abs(x - 180.0) < 0.25 and abs(y + 0.5) < 0.25
    for suffix in (".ply", ".vtp"):
        out = tmp_path / f"mesh{suffix}"
        proc = run_cli("dem", "mesh", str(tmp_path / "stack" / "manifest.json"), "-o", str(out))
        assert proc.returncode == 0 and "wrote" in proc.stdout, proc.stderr
        m = __import__("pyvista").read(out)
        assert m.n_points == 3 * (65**2 - 33**2) + 65**2
    proc = run_cli("dem", "mesh", str(lola_tif), "-o", str(tmp_path / "one.ply"), "-q", *MOON)
    assert proc.returncode == 0 and proc.stdout == ""


def check_geojson_files(folder: Path) -> None:
    """Every GeoJSON of a stack over the LOLA crop (longitudes 166-194 east) is RFC 7946:
    no `crs` member (geojson-validator), longitudes in [-180, 180), the body's IAU code
    in the foreign member and in the sidecar .prj."""
    import geojson_validator
    from rasterio.crs import CRS

    files = sorted(folder.glob("*.geojson"))
    assert files
    lons = []
    for path in files:
        doc = json.loads(path.read_text())
        assert geojson_validator.validate_structure(doc, check_crs=True) == {}
        assert doc["craterform"]["crs"] == "IAU_2015:30100"
        assert doc["craterform"]["body"] == "Moon"
        prj = CRS.from_wkt(path.with_suffix(".prj").read_text())
        assert prj.to_authority(confidence_threshold=50) == ("IAU_2015", "30100")
        lons += [f["geometry"]["coordinates"][0] for f in doc["features"]]
    lons = np.array(lons)
    assert len(lons) > 10 and (lons >= -180).all() and (lons < 180).all()
    assert (lons < -170).any() and (lons > 170).any()  # both sides of the antimeridian


def test_enhance_same_seed_same_bytes_any_thread_count(run_cli, capsys, tmp_path, lola_tif):
    scene = write_scene(tmp_path / "scene.toml",
                        **scene_keys(tmp_path, lola_tif, layers=3, output="unused"))
    trees = {}
    for threads in ("1", "2"):
        out = tmp_path / f"stack{threads}"
        proc = run_cli("dem", "enhance", "--config", str(scene), "-o", str(out), "--seed", "4",
                       "-q", env={"NUMBA_NUM_THREADS": threads})
        assert proc.returncode == 0 and proc.stdout == "", proc.stderr
        trees[threads] = {p.name: p.read_bytes() for p in sorted(out.iterdir())}
    # per layer: tif, csv, geojson + its prj, scc; and the manifest
    assert len(trees["1"]) == 3 + 3 * 4 + 1 and trees["1"] == trees["2"]
    check_geojson_files(tmp_path / "stack1")
    other = tmp_path / "other"
    assert InProcess(capsys)("dem", "enhance", "--config", str(scene), "-o", str(other),
                             "--seed", "5", "-q").returncode == 0
    assert (other / "layer_02.tif").read_bytes() != trees["2"]["layer_02.tif"]


@pytest.mark.parametrize("case,extra,argv,needles", [
    ("unknown-key", {"colour": "red"}, [], ["unknown key", "colour", "allowed"]),
    ("target-outside", {"target": [10.0, 10.0]}, [], ["outside the base DEM"]),
    ("target-flag-outside", {}, ["--target", "100,80"], ["outside the base DEM"]),
    ("size-zero", {"size": 0}, [], ["size", "2^n + 1"]),
    ("size-negative", {}, ["--size", "-65"], ["size", "2^n + 1"]),
    ("size-not-2n1", {"size": 64}, [], ["size", "2^n + 1"]),
    ("size-too-big", {"size": 513}, [], ["at least 513 x 513"]),
    ("layers-zero", {"layers": 0}, [], ["layers"]),
    ("layers-text", {"layers": "many"}, [], ["layers"]),
    ("crater-spec", {"craters": ["c=0.5,k=2,d_min_m=1,d_max_m=5"]}, [], ["k", "< 0"]),
    ("crater-spec-key", {"craters": ["c=0.5,k=-2,d_min_m=1,d_max_m=5,colour=1"]}, [],
     ["unknown item"]),
    ("crater-flag", {}, ["--craters", "c=0.5,k=-2,d_min_m=9,d_max_m=5"], ["--craters", "d_min_m"]),
    ("craters-not-list", {"craters": "c=0.5,k=-2,d_min_m=1,d_max_m=5"}, [], ["list"]),
    ("too-many-craters", {"craters": ["c=1e6,k=-3,d_min_m=0.001,d_max_m=5"]}, [],
     ["craters", "d_min_m"]),
    ("no-output", {"output": None}, [], ["-o/--output"]),
    ("no-input", {"input": None}, [], ["needs an input"]),
    ("no-radius", {"body_radius_m": None, "input": "ellipsoid.tif"}, [],
     ["geographic CRS", "--body-radius-m"]),
    ("bad-toml", None, [], ["TOML"]),
    ("missing-scene", "missing", [], ["does not exist"]),
])
def test_enhance_bad_input_one_line_exit_2_nothing_written(run_cli, capsys, tmp_path, lola_tif,
                                                          case, extra, argv, needles):
    scene = tmp_path / "scene.toml"
    if extra is None:
        scene.write_text("layers = \n")
    elif extra != "missing":
        keys = {k: v for k, v in {**scene_keys(tmp_path, lola_tif), **extra}.items()
                if v is not None}
        if keys.get("input") == "ellipsoid.tif":
            keys["input"] = str(write_ellipsoid(tmp_path / "ellipsoid.tif"))
        write_scene(scene, **keys)
    before = sorted(p.name for p in tmp_path.iterdir())
    runner = run_cli if case in ("unknown-key", "target-outside", "size-zero") else \
        InProcess(capsys)
    proc = runner("dem", "enhance", "--config", str(scene), *argv)
    assert_one_line_error(proc, *needles)
    assert sorted(p.name for p in tmp_path.iterdir()) == before


def test_enhance_existing_output(run_cli, capsys, tmp_path, lola_tif):
    scene = write_scene(tmp_path / "scene.toml", **scene_keys(tmp_path, lola_tif, layers=2))
    run = InProcess(capsys)
    assert run("dem", "enhance", "--config", str(scene), "-q", "--seed", "1").returncode == 0
    first = (tmp_path / "stack" / "layer_01.tif").read_bytes()
    assert_one_line_error(run("dem", "enhance", "--config", str(scene), "--seed", "2"), "exists",
                          "--force")
    assert (tmp_path / "stack" / "layer_01.tif").read_bytes() == first
    assert run("dem", "enhance", "--config", str(scene), "-q", "--seed", "2",
               "--force").returncode == 0
    assert (tmp_path / "stack" / "layer_01.tif").read_bytes() != first
    assert sorted(p.name for p in tmp_path.iterdir()) == ["in.tif", "scene.toml", "stack"]


@pytest.mark.parametrize("case,args,needles", [
    ("suffix", ["{manifest}", "-o", "{tmp}/m.xyz"], ["unknown format", ".ply"]),
    ("no-output", ["{manifest}"], ["-o/--output"]),
    ("not-a-manifest", ["{json}", "-o", "{tmp}/m.ply"], ["not a craterform stack manifest"]),
    ("nan-dem", ["{nan}", "-o", "{tmp}/m.ply"], ["NaN"]),
    ("exists", ["{manifest}", "-o", "{tmp}/keep.ply"], ["exists", "--force"]),
])
def test_mesh_bad_input_one_line_exit_2_nothing_written(capsys, tmp_path, lola_crop, case,
                                                        args, needles):
    layer = lola_crop.crop(rasterio.windows.Window(0, 0, 9, 9))
    dem.Stack([layer], [], dem.local_frame(layer)).write(tmp_path / "st")
    (tmp_path / "other.json").write_text('{"format": "something else"}')
    (tmp_path / "keep.ply").write_text("keep me")
    z = np.array(layer.heights)
    z[3, 3] = np.nan
    dem.write(layer.replace(heights=z), tmp_path / "nan.tif")
    names = {"manifest": tmp_path / "st" / "manifest.json", "json": tmp_path / "other.json",
             "nan": tmp_path / "nan.tif", "tmp": tmp_path}
    before = sorted(p.name for p in tmp_path.iterdir())
    proc = InProcess(capsys)("dem", "mesh", *[a.format(**names) for a in args])
    assert_one_line_error(proc, *needles)
    assert sorted(p.name for p in tmp_path.iterdir()) == before
    assert (tmp_path / "keep.ply").read_text() == "keep me"


def test_enhance_options_are_the_config_plus_the_run_options():
    assert set(options_for("enhance")) == {*dem.EnhanceConfig.keys(), "output", "force",
                                           "quiet", "wait"}


def test_enhance_parses_each_spec_and_checks_seed_and_folder_once(capsys, tmp_path, lola_tif,
                                                                 monkeypatch):
    import collections

    import craters._shared.settings
    import dem.cli.enhance
    import dem.config

    calls = collections.Counter()

    def counted(module, name, only=None):
        real = getattr(module, name)

        def call(*args, **kwargs):
            if only is None or only(*args):
                calls[name] += 1
            return real(*args, **kwargs)

        monkeypatch.setattr(module, name, call)

    counted(dem.config, "parse_layer_spec")
    counted(dem.config, "parse_boulder_specs")
    counted(craters._shared.settings, "check_int", only=lambda name, *_: name == "seed")
    counted(dem.cli.enhance, "check_stack_folder")
    scene = write_scene(tmp_path / "scene.toml", **scene_keys(tmp_path, lola_tif, layers=2))
    proc = InProcess(capsys)("dem", "enhance", "--config", str(scene), "--seed", "3", "-q",
                             "--boulders", "c=0.00001,k=-3,d_min_m=300,d_max_m=2000")
    assert proc.returncode == 0, proc.stderr
    assert calls == {"parse_layer_spec": 2, "parse_boulder_specs": 1, "check_int": 1,
                     "check_stack_folder": 1}
    # the input as the argument overrides the file's, the other options come from the file
    copy = tmp_path / "copy.tif"
    copy.write_bytes(lola_tif.read_bytes())
    proc = InProcess(capsys)("dem", "enhance", str(copy), "--config", str(scene), "-o",
                             str(tmp_path / "other"), "--seed", "3", "-q")
    assert proc.returncode == 0, proc.stderr
    info = dem.read_stack(tmp_path / "other").info
    assert info["parameters"]["input"] == str(copy) and info["parameters"]["layers"] == 2
