"""Clear messages and honest outputs (issue 19 items 7 and 8): library errors reaching a
command line name the flag, never the Python argument; a missing input file is a
``FileNotFoundError`` in Python; a Moon GeoTIFF carries its own sphere radius; no Python
warning reaches a user's terminal; plots with many layers keep their colours apart and
say each layer's pixel size; boulder CSVs are boulder catalogs.

Command lines run in-process through each CLI's ``main`` (as tests/test_bad_inputs.py);
a subprocess only where what Python itself prints on stderr (warnings) is the point.
"""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

DATA = Path(__file__).parent / "data"
LDEM = str(DATA / "ldem4_crop.lbl")
ITOKAWA = str(DATA / "itokawa_8.obj")
OUT = ["-q", "-o", "out.npz"]


def snapshot(folder: Path) -> dict:
    """Every file's bytes (a folder: None), to see that nothing was written or changed."""
    return {p.name: p.is_file() and p.read_bytes() for p in folder.iterdir()}


def main_of(command: str):
    """The ``main`` of the ``latlong``, ``dem`` or ``craters`` command line."""
    import importlib

    return importlib.import_module(f"{command}.cli").main


def tiny_tif(tmp: Path) -> None:
    import dem

    dem.write(dem.Dem(np.arange(9.0).reshape(3, 3), pixel_size_m=1.0), tmp / "tiny.tif")


def nothing(tmp: Path) -> None:
    pass


# (id, setup, command, argv, texts the one error line must hold)
CASES = [
    ("fbm-amplitude-too-rough", nothing, "latlong",
     ["build", "--magnitude", "8", "--seed", "1", "--amplitude-m", "1e30", *OUT],
     ["--amplitude-m is too large for --radius-m = 50 m", "radius <= 0"]),
    ("faults-too-rough", nothing, "latlong",
     ["build", "--magnitude", "8", "--seed", "1", "--base", "faulting", "--max-fault-2-m",
      "3", *OUT], ["--max-fault-1-m and --max-fault-2-m are too large for --radius-m"]),
    ("shape-detail-too-rough", nothing, "latlong",
     ["build", "--magnitude", "8", "--seed", "1", "--base", f"shape:{ITOKAWA}",
      "--shape-units", "km", "--shape-crossings", "outermost", "--amplitude-m", "1e30", *OUT],
     ["--amplitude-m is too large for the shape model"]),
    ("fbm-frequency-1e30", nothing, "latlong",
     ["build", "--magnitude", "8", "--seed", "1", "--frequency", "1e30", *OUT],
     ["--frequency", "--lacunarity ** (--octaves - 1)", "2**31"]),
    ("fbm-persistence-1e30", nothing, "latlong",
     ["build", "--magnitude", "8", "--seed", "1", "--persistence", "1e30", *OUT],
     ["--persistence ** (--octaves - 1)", "1e38"]),
    ("implicit-npz-crossings", nothing, "latlong",
     ["build", "--backend", "implicit", "--shape", ITOKAWA, "--shape-units", "km",
      "--polygons", "5000", "--packing-voxels", "24", "--seed", "1", *OUT],
     ["--shape-crossings must be outermost or innermost for a .npz output", "not star-shaped",
      "or write only meshes"]),
    ("pixel-size-with-crs", nothing, "dem", ["info", LDEM, "--pixel-size-m", "3"],
     ["--pixel-size-m is only for DEMs without a CRS", "ldem4_crop.lbl"]),
    ("pixel-size-negative", nothing, "dem", ["info", LDEM, "--pixel-size-m", "-1"],
     ["--pixel-size-m must be finite and > 0"]),
    ("body-radius-negative", nothing, "dem", ["info", LDEM, "--body-radius-m", "-1"],
     ["--body-radius-m must be in [0.001, 1e+09]"]),
    ("band-beyond-the-file", nothing, "dem", ["info", LDEM, "--band", "3"],
     ["--band must be in [1, 1]", "ldem4_crop.lbl"]),
    ("stack-size", nothing, "dem", ["enhance", LDEM, "--size", "3", "-q", "-o", "site"],
     ["--size must be 2^n + 1 pixels"]),
    ("expand-region", nothing, "dem",
     ["expand", LDEM, "--region", "0,0,20", "--seed", "1", "-q", "-o", "x.tif"],
     ["--region is 20 x 20 pixels", "2^n + 1"]),
    ("spectrum-tiny-dem", tiny_tif, "dem", ["spectrum", "tiny.tif"],
     ["tiny", "at least 8 x 8 pixels"]),
]


@pytest.mark.parametrize("setup,command,argv,texts", [c[1:] for c in CASES],
                         ids=[c[0] for c in CASES])
def test_errors_name_the_flag_not_the_python_argument(tmp_path, monkeypatch, capsys, setup,
                                                      command, argv, texts):
    setup(tmp_path)
    monkeypatch.chdir(tmp_path)
    monkeypatch.delenv("CRATERFORM_DEBUG", raising=False)
    before = snapshot(tmp_path)
    rc = main_of(command)(list(argv))
    err = capsys.readouterr().err
    lines = err.strip().splitlines()
    assert rc == 2 and len(lines) == 1 and lines[0].startswith("error: "), err
    for text in texts:
        assert text in lines[0], lines[0]
    assert "`" not in lines[0], lines[0]  # a Python name such as `radii_m` or `crossings`
    assert snapshot(tmp_path) == before  # nothing written, inputs unchanged


# --------------------------------------------------------------------------- body .npz
def mesh_ply(tmp: Path) -> None:
    from latlong import Body, LatLongGrid

    Body.sphere(LatLongGrid(4), 10.0).export(tmp / "body.ply")


@pytest.mark.parametrize("argv", [["info", "body.ply"],
                                  ["render", "body.ply", "-o", "x.png"],
                                  ["export", "body.ply", "-o", "x.glb"]],
                         ids=["info", "render", "export"])
def test_latlong_body_commands_say_a_body_npz_is_needed(tmp_path, monkeypatch, capsys, argv):
    mesh_ply(tmp_path)
    monkeypatch.chdir(tmp_path)
    before = snapshot(tmp_path)
    from latlong.cli import main

    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "is not a body .npz" in err and "mesh" in err, err
    assert "pickle" not in err
    assert snapshot(tmp_path) == before


# --------------------------------------------------------------------------- Moon GeoTIFF
@pytest.mark.parametrize("crs", ["IAU_2015:30100", "+proj=longlat +R=1737400 +no_defs"],
                         ids=["iau-code", "proj-sphere"])
def test_dem_info_reads_a_moon_geotiff_and_prints_its_sphere_radius(tmp_path, capsys, crs):
    """A Moon GeoTIFF without craterform tags (another tool's): its CRS is a sphere, whose
    radius converts degrees to metres (issue 19 item 7: refused before)."""
    import rasterio
    from affine import Affine

    from dem.cli import main

    path = tmp_path / "moon.tif"
    try:
        with rasterio.open(path, "w", driver="GTiff", width=9, height=9, count=1,
                           dtype="float32", crs=crs,
                           transform=Affine(0.01, 0, 10, 0, -0.01, 5)) as ds:
            ds.write(np.arange(81, dtype="float32").reshape(9, 9), 1)
    except rasterio.errors.CRSError:  # pragma: no cover - a PROJ without the IAU codes
        pytest.skip(f"this PROJ does not know {crs}")
    assert main(["info", str(path)]) == 0
    out = capsys.readouterr().out
    assert re.search(r"^body_m +1737400$", out, re.MULTILINE), out
    assert re.search(r"^pixel_m +302\.1 x 303\.2", out, re.MULTILINE), out  # 0.01 deg


# --------------------------------------------------------------------------- missing files
def _read_stack(p):
    import dem

    return dem.read_stack(p)


def _scene(p):
    from latlong import Scene

    return Scene.from_toml(p)


def _scene_shape(p):
    from latlong import Scene

    return Scene.from_settings({"base": f"shape:{p}", "shape_units": "km"})


def _toml(p):
    from craters._shared import load_toml

    return load_toml(p)


def _catalog(p):
    import craters

    return craters.read_catalog(p)


def _scc(p):
    import craters

    return craters.read_scc(p)


def _dem(p):
    import dem

    return dem.read(p)


def _body(p):
    import latlong

    return latlong.load(p)


def _camera_catalog(p):
    from latlong.sensors.scene_geometry import craters_catalog

    return craters_catalog(p)


def _gabor_example(p):
    from latlong.implicit import read_example

    return read_example(p)


def _shape(p):
    from latlong.shapes import read_shape_model

    return read_shape_model(p, units="m")


@pytest.mark.parametrize("read,name", [
    (_dem, "none.tif"), (_dem, "none.lbl"), (_read_stack, "manifest.json"), (_body, "b.npz"),
    (_shape, "m.obj"), (_scene, "scene.toml"), (_scene_shape, "m.obj"), (_toml, "x.toml"),
    (_catalog, "c.csv"), (_scc, "c.scc"), (_camera_catalog, "c.csv"), (_gabor_example, "g.npy"),
], ids=["dem.read", "dem.read-pds", "dem.read_stack", "latlong.load", "read_shape_model",
        "Scene.from_toml", "Scene-shape-base", "load_toml", "read_catalog", "read_scc",
        "camera-catalog", "gabor-example"])
def test_a_missing_file_is_file_not_found(tmp_path, read, name):
    with pytest.raises(FileNotFoundError, match="does not exist") as info:
        read(tmp_path / name)
    assert not isinstance(info.value, ValueError)


@pytest.mark.parametrize("argv,texts", [
    (["build", "--base", "shape:missing.obj", "--shape-units", "km", *OUT],
     ["--base: shape model 'missing.obj' does not exist"]),
    (["build", "--backend", "implicit", "--shape", "missing.obj", "--shape-units", "km", *OUT],
     ["--shape: shape model 'missing.obj' does not exist"]),
    (["info", "missing.npz"], ["model file 'missing.npz' does not exist"]),
], ids=["base-shape", "implicit-shape", "info"])
def test_a_missing_file_is_one_line_naming_the_flag(tmp_path, monkeypatch, capsys, argv,
                                                    texts):
    from latlong.cli import main

    monkeypatch.chdir(tmp_path)
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("error: ") and "Traceback" not in err
    for text in texts:
        assert text in err, err
    assert list(tmp_path.iterdir()) == []


# --------------------------------------------------------------------------- warnings
WARNING = re.compile(r"\b\w*Warning\b")  # RuntimeWarning, ComplexWarning, UserWarning ...


@pytest.mark.parametrize("argv", [
    ["latlong", "build", "--magnitude", "8", "--seed", "1", "--amplitude-m", "1e30", *OUT],
    ["latlong", "build", "--magnitude", "8", "--seed", "1", "--frequency", "1e30", *OUT],
    ["latlong", "build", "--magnitude", "8", "--seed", "1", "--persistence", "1e30", *OUT],
    ["latlong", "build", "--magnitude", "8", "--seed", "1", "--base", "faulting",
     "--max-fault-1-m", "1e30", *OUT],
    ["dem", "info", LDEM, "--body-radius-m", "1e-300"],
    ["dem", "info", "cplx.tif"],
    ["dem", "spectrum", "flat.tif"],
    ["dem", "slopes", "flat.tif"],
    ["dem", "fill", "flat.tif", "--seed", "1", "-q", "-o", "f.tif"],
], ids=["amplitude", "frequency", "persistence", "faults", "radius", "complex-tif",
        "flat-spectrum", "flat-slopes", "flat-fill"])
def test_no_python_warning_reaches_the_terminal(tmp_path, argv):
    """Python's own warning lines (overflow, invalid value, ComplexWarning ...) never
    show: run as a user does, with Python's default warning filters."""
    import rasterio
    from affine import Affine

    import dem

    dem.write(dem.Dem(np.zeros((9, 9)), pixel_size_m=1.0), tmp_path / "flat.tif")
    z = (np.arange(81.0).reshape(9, 9) * (1 + 1j)).astype(np.complex64)
    with rasterio.open(tmp_path / "cplx.tif", "w", driver="GTiff", width=9, height=9,
                       count=1, dtype="complex64", crs="EPSG:32633",
                       transform=Affine(10.0, 0, 5e5, 0, -10.0, 4e6)) as ds:
        ds.write(z, 1)
    proc = subprocess.run([sys.executable, "-W", "default", "-m", *argv], cwd=tmp_path,
                          capture_output=True, text=True, timeout=300)
    assert not WARNING.search(proc.stderr), proc.stderr
    assert "Traceback" not in proc.stderr


# --------------------------------------------------------------------------- plots
def test_many_series_get_distinct_colours():
    from craters.cli.report import series_colors

    for n in (1, 10, 11, 24):
        colours = [tuple(c) for c in series_colors(n)]
        assert len(set(colours)) == n


def test_dem_stack_plots_distinct_colours_and_pixel_sizes(tmp_path, monkeypatch):
    """11 layers: no colour twice (layer 0 and 10 were both blue); each legend entry
    says its layer's pixel size."""
    import matplotlib.pyplot as plt

    import craters.cli.report as report
    from dem.cli import main

    site = tmp_path / "site"
    assert main(["enhance", LDEM, "-o", str(site), "--layers", "11", "--size", "33",
                 "--seed", "1", "-q"]) == 0
    figures = []

    def keep(fig, path):
        figures.append([(line.get_label(), line.get_color()) for ax in fig.axes
                        for line in ax.get_lines()])
        plt.close(fig)

    monkeypatch.setattr(report, "save_figure", keep)
    manifest = str(site / "manifest.json")
    assert main(["slopes", manifest, "--plot", str(tmp_path / "s.png"), "-q"]) == 0
    assert main(["spectrum", manifest, "--plot", str(tmp_path / "p.png"), "-q"]) == 0
    import dem

    pixels = [f"{layer.resolution_m:.3g} m/px" for layer in dem.read_stack(manifest).layers]
    for lines in figures:
        per_panel = lines[:11]  # the first panel (slopes: histogram; spectrum: the only)
        colours = [str(c) for _, c in per_panel]
        assert len(per_panel) == 11 and len(set(colours)) == 11, colours
        for k, (label, _) in enumerate(per_panel):
            assert label.startswith(f"manifest layer {k}, {pixels[k]}"), label
    assert len(figures) == 2


# --------------------------------------------------------------------------- boulder CSV
def test_boulder_csv_is_a_boulder_catalog_and_reads_back(tmp_path, monkeypatch):
    import craters
    import latlong
    from latlong.cli import main

    monkeypatch.chdir(tmp_path)
    assert main(["build", "--magnitude", "16", "--seed", "1", "--radius-m", "500", "--base",
                 "sphere", "--boulders", "c=0.05,k=-3,d_min_m=3,d_max_m=10", "-q", "-o",
                 "b.npz", "--boulder-catalog", "b.csv"]) == 0
    head, columns = Path("b.csv").read_text().splitlines()[:2]
    assert "boulder catalog" in head and "crater catalog" not in head
    names = columns.split(",")
    assert {"lat_deg", "lon_deg", "diameter_m", "height_m", "burial_frac",
            "centre_x_m"} <= set(names)
    assert not {"age_gyr", "degradation"} & set(names)
    placed = latlong.load("b.npz").boulders
    back = craters.read_catalog("b.csv")
    assert len(placed) > 10 and back.dtype == placed.dtype
    for name in placed.dtype.names:
        assert np.array_equal(back[name], placed[name]), name
    crater_csv = craters.write_catalog(craters.make_catalog(
        x_m=[1.0], y_m=[2.0], diameter_m=[3.0]), tmp_path / "c.csv")
    assert "crater catalog" in crater_csv.read_text().splitlines()[0]


if __name__ == "__main__":
    sys.exit(pytest.main([__file__, "-q"]))
