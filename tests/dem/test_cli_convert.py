"""``dem convert``: any DEM ``dem.read`` reads (PDS3, GeoTIFF) -> a cloud-optimised GeoTIFF."""

from __future__ import annotations

import os
import shutil
import subprocess

import numpy as np
import pytest

import dem

DATA = os.path.join(os.path.dirname(__file__), "..", "data")


def convert(capsys, *argv):
    """``dem convert ...`` in this process: the exit code and output as the entry point's."""
    from dem.cli import main

    try:
        code = main(["convert", *map(str, argv)])
    except SystemExit as exc:  # argparse errors
        code = exc.code
    out, err = capsys.readouterr()
    return subprocess.CompletedProcess(argv, code, out, err)


@pytest.fixture
def pds(tmp_path):
    """The LOLA LDEM_4 crop (PDS3 .lbl + .img) copied into ``tmp_path``."""
    for name in ("ldem4_crop.lbl", "ldem4_crop.img"):
        shutil.copy(os.path.join(DATA, name), tmp_path / name)
    return tmp_path / "ldem4_crop.lbl"


def test_pds_to_geotiff_keeps_heights_georeferencing_and_body(capsys, tmp_path, pds):
    out = tmp_path / "moon.tif"
    proc = convert(capsys, pds, "-o", out)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.splitlines()[-1] == f"wrote {out}" and proc.stderr == ""
    src, got = dem.read(pds), dem.read(out)
    assert got.shape == src.shape == (257, 257)
    np.testing.assert_array_equal(got.heights, src.heights.astype(np.float32))
    assert got.transform == src.transform
    assert got.body_radius_m == src.body_radius_m == 1737400.0
    assert got.pixel_size_m == pytest.approx(src.pixel_size_m)


def test_geotiff_with_nodata_and_quiet(capsys, tmp_path, tiny_geotiff):
    out = tmp_path / "x.tif"
    proc = convert(capsys, tiny_geotiff, "-o", out, "-q")
    assert proc.returncode == 0 and proc.stdout == "" and proc.stderr == ""
    got, src = dem.read(out), dem.read(tiny_geotiff)
    assert np.isnan(got.heights[3, 4]) and np.isnan(src.heights[3, 4])
    np.testing.assert_array_equal(got.heights, src.heights)
    assert got.crs == src.crs and got.transform == src.transform
    assert sorted(p.name for p in tmp_path.iterdir()) == ["tiny.tif", "x.tif"]


def test_same_input_same_bytes(capsys, tmp_path, pds):
    for name in ("a.tif", "b.tif"):
        assert convert(capsys, pds, "-o", tmp_path / name, "-q").returncode == 0
    assert (tmp_path / "a.tif").read_bytes() == (tmp_path / "b.tif").read_bytes()


@pytest.mark.parametrize(("case", "args", "needles"), [
    ("in-is-out", ["{tif}", "-o", "{tif}", "--force"], ["is the input"]),
    ("in-is-out-link", ["{tif}", "-o", "{link}", "--force"], ["is the input"]),
    ("in-is-out-dots", ["{tif}", "-o", "{dots}", "--force"], ["is the input"]),
    ("exists", ["{pds}", "-o", "{tif}"], ["exists", "--force"]),
    ("missing", ["{none}", "-o", "{out}"], ["does not exist"]),
    ("suffix", ["{pds}", "-o", "{png}"], ["unknown format", ".tif"]),
    ("no-output", ["{pds}"], ["-o/--output"]),
    ("band", ["{pds}", "-o", "{out}", "--band", "2"], ["band", "[1, 1]"]),
    ("band-syntax", ["{pds}", "-o", "{out}", "--band", "two"], ["--band"]),
    ("not-a-raster", ["{text}", "-o", "{out}"], ["notes.txt"]),
])
def test_bad_input_one_line_exit_2_nothing_written(capsys, tmp_path, pds, case, args, needles):
    tif = tmp_path / "in.tif"
    dem.write(dem.read(pds), tif)
    (tmp_path / "link.tif").symlink_to(tif)
    (tmp_path / "sub").mkdir()
    (tmp_path / "notes.txt").write_text("not a raster\n")
    names = {"pds": pds, "tif": tif, "link": tmp_path / "link.tif",
             "dots": tmp_path / "sub" / ".." / "in.tif", "none": tmp_path / "none.lbl",
             "out": tmp_path / "out.tif", "png": tmp_path / "out.png",
             "text": tmp_path / "notes.txt"}
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir() if p.is_file()}
    proc = convert(capsys, *[a.format(**names) for a in args])
    assert proc.returncode == 2, proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error:"), proc.stderr
    for needle in needles:
        assert needle in lines[0], lines[0]
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir() if p.is_file()} == before


def test_every_option_has_a_config_key_and_shows_its_default():
    from dem.cli import build_parser

    sub = build_parser()._subparsers._group_actions[0].choices["convert"]
    actions = [a for a in sub._actions if a.dest != "help"]
    options = sub.get_default("func").options  # the table of the flags and config keys
    assert {a.dest for a in actions} - {"config"} == set(options)
    for action in actions:
        assert "(default: " in action.help, action.dest


def test_config_file(capsys, tmp_path, pds):
    cfg = tmp_path / "c.toml"
    out = tmp_path / "c.tif"
    cfg.write_text(f'input = "{pds}"\noutput = "{out}"\nquiet = true\n')
    proc = convert(capsys, "--config", cfg)
    assert proc.returncode == 0 and proc.stdout == "", proc.stderr
    assert dem.read(out).shape == (257, 257)


if __name__ == "__main__":
    pytest.main([__file__, "-q"])
