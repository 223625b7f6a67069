"""Zarr DEMs (:mod:`dem.zarrio`): every writer of one DEM takes a ``.zarr`` output, the
same heights, CRS, transform and tags as its GeoTIFF; the same DEM gives the same files
byte for byte whether written whole, window by window in any order, tile by tile or with
the tiles as dask tasks; an independent reader (zarr-python) reads it; outputs are
replaced only when they are Zarr DEMs, and nothing is left behind on errors."""

from __future__ import annotations

import hashlib
import os
import subprocess
from pathlib import Path

import numpy as np
import pytest

import dem
from dem import Dem
from dem.expandfile import expand_to_file
from dem.expansion import expand
from dem.io import WindowWriter
from dem.tiledfill import fill_to_file

DATA = Path(__file__).resolve().parents[1] / "data"
LOLA = DATA / "ldem4_crop.lbl"


def files_of(store: Path) -> dict[str, str]:
    """Relative path -> sha256 of every file of a store."""
    out = {}
    for root, _, names in os.walk(store):
        for name in names:
            p = Path(root) / name
            out[str(p.relative_to(store))] = hashlib.sha256(p.read_bytes()).hexdigest()
    return out


def run(capsys, *argv):
    from dem.cli import main

    try:
        code = main([str(a) for a in argv])
    except SystemExit as exc:
        code = exc.code
    out, err = capsys.readouterr()
    return subprocess.CompletedProcess(argv, code, out, err)


@pytest.fixture(scope="module")
def lola():
    return dem.read(LOLA)


def test_round_trip_keeps_heights_crs_transform_and_tags(lola, tmp_path):
    dem.write(lola, tmp_path / "m.zarr")
    dem.write(lola, tmp_path / "m.tif")
    z, t = dem.read(tmp_path / "m.zarr"), dem.read(tmp_path / "m.tif")
    assert sorted(os.listdir(tmp_path / "m.zarr")) == [".zgroup", ".zmetadata", "X", "Y",
                                                        "height"]
    np.testing.assert_array_equal(z.heights, t.heights)
    # the same CRS (GDAL's Zarr driver gives a geographic CRS longitude first, its GeoTIFF
    # driver latitude first; the transform says where pixels are either way)
    assert z.crs.to_dict() == t.crs.to_dict() and z.transform == t.transform
    assert z.body_radius_m == t.body_radius_m == 1737400.0
    assert z.pixel_size_m == t.pixel_size_m
    assert {k: v for k, v in t.tags.items() if k != "AREA_OR_POINT"} == z.tags


def test_without_crs_and_with_unknown_pixels(tmp_path):
    h = np.arange(35.0).reshape(5, 7)
    h[1:3, 2:4] = np.nan
    d = Dem(h, pixel_size_m=(2.0, 3.0))
    back = dem.read(dem.write(d, tmp_path / "p.zarr"))
    np.testing.assert_array_equal(back.heights, h)
    assert back.crs is None and back.pixel_size_m == (2.0, 3.0)


def test_same_dem_same_files_whole_or_windows_in_any_order(lola, tmp_path):
    whole = files_of(dem.write(lola, tmp_path / "a.zarr"))
    assert files_of(dem.write(lola, tmp_path / "b.zarr")) == whole
    rows, cols = lola.shape
    windows = [(r, c, min(100, rows - r), min(70, cols - c))
               for r in range(0, rows, 100) for c in range(0, cols, 70)]
    with WindowWriter(tmp_path / "w.zarr", lola.shape, transform=lola.transform,
                      crs=lola.crs, tags=lola.tags, body_radius_m=lola.body_radius_m) as out:
        for r, c, h, w in reversed(windows):  # bottom right first, unaligned to chunks
            out.write(lola.heights[r:r + h, c:c + w], r, c)
    assert files_of(tmp_path / "w.zarr") == whole
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.zarr", "b.zarr", "w.zarr"]


def test_tiled_expand_into_zarr_is_the_whole_expand(lola, tmp_path):
    made = expand_to_file(lola, tmp_path / "t.zarr", 2, rng=3, tile_px=129)
    assert made.tiles == 64  # tiles of 33 x 33 input pixels
    whole = dem.write(expand(lola, 2, rng=3), tmp_path / "w.zarr")
    assert files_of(made.path) == files_of(whole)
    tif = expand_to_file(lola, tmp_path / "t.tif", 2, rng=3, tile_px=129)
    np.testing.assert_array_equal(dem.read(made.path).heights, dem.read(tif.path).heights)


def test_tiled_fill_into_zarr(tmp_path):
    z = np.random.default_rng(2).standard_normal((90, 80)).cumsum(0).cumsum(1)
    z[20:50, 10:40] = np.nan
    src = dem.write(Dem(z, pixel_size_m=10.0), tmp_path / "in.tif")
    made = fill_to_file(src, tmp_path / "f.zarr", rng=4, tile_px=32)
    ref = fill_to_file(src, tmp_path / "f.tif", rng=4, tile_px=32)
    np.testing.assert_array_equal(dem.read(made.path).heights, dem.read(ref.path).heights)
    assert np.isfinite(dem.read(made.path).heights).all()


def test_zarr_python_reads_the_store(lola, tmp_path):
    zarr = pytest.importorskip("zarr")
    dem.write(lola, tmp_path / "m.zarr")
    group = zarr.open_group(str(tmp_path / "m.zarr"), mode="r")
    a = group["height"]
    assert a.shape == lola.shape and a.dtype == np.float32
    np.testing.assert_array_equal(a[:], lola.heights.astype(np.float32))
    assert list(a.attrs["_ARRAY_DIMENSIONS"]) == ["Y", "X"]  # what xarray reads
    assert a.attrs["CRATERFORM_BODY_RADIUS_M"] == "1737400.0"
    x = group["X"][:]  # pixel-centre coordinates along a row, in CRS units
    np.testing.assert_allclose(x[:2], [lola.transform.c + 0.5 * lola.transform.a,
                                       lola.transform.c + 1.5 * lola.transform.a])


def test_cli_writes_and_reads_zarr(tmp_path, capsys):
    out = tmp_path / "c.zarr"
    assert run(capsys, "convert", LOLA, "-o", out).returncode == 0
    r = run(capsys, "expand", out, "-o", tmp_path / "e.zarr", "--levels", "1", "--seed", "2")
    assert r.returncode == 0, r.stderr
    assert dem.read(tmp_path / "e.zarr").shape == (513, 513)
    r = run(capsys, "info", tmp_path / "e.zarr")
    assert r.returncode == 0 and "513 x 513 pixels" in r.stdout


def test_cli_replaces_only_zarr_dems(tmp_path, capsys):
    out = tmp_path / "c.zarr"
    assert run(capsys, "convert", LOLA, "-o", out).returncode == 0
    before = files_of(out)
    r = run(capsys, "convert", LOLA, "-o", out)
    assert r.returncode == 2
    assert r.stderr == f"error: output '{out}' exists; use --force to overwrite\n"
    assert run(capsys, "convert", LOLA, "-o", out, "--force").returncode == 0
    assert files_of(out) == before
    # a folder that is not a Zarr DEM is never replaced
    foreign = tmp_path / "mine.zarr"
    foreign.mkdir()
    (foreign / "notes.txt").write_text("keep")
    r = run(capsys, "convert", LOLA, "-o", foreign, "--force")
    assert r.returncode == 2 and r.stderr.count("\n") == 1
    assert "holds 'notes.txt', which a Zarr DEM does not; refusing" in r.stderr
    assert (foreign / "notes.txt").read_text() == "keep"
    # a symbolic link is replaced as a link: its target is untouched
    target = tmp_path / "target.zarr"
    assert run(capsys, "convert", LOLA, "-o", target).returncode == 0
    kept = files_of(target)
    link = tmp_path / "link.zarr"
    link.symlink_to(target)
    assert run(capsys, "expand", LOLA, "-o", link, "--force", "--seed", "1").returncode == 0
    assert not link.is_symlink() and dem.read(link).shape == (513, 513)
    assert files_of(target) == kept
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]


def test_a_folder_that_is_not_a_store_is_a_one_line_error(tmp_path, capsys):
    (tmp_path / "empty.zarr").mkdir()
    with pytest.raises(ValueError, match="is a folder but not a Zarr store"):
        dem.read(tmp_path / "empty.zarr")
    r = run(capsys, "info", tmp_path / "empty.zarr")
    assert r.returncode == 2 and r.stderr.count("\n") == 1


def test_a_failed_write_leaves_nothing(lola, tmp_path):
    with pytest.raises(RuntimeError), WindowWriter(tmp_path / "x.zarr", lola.shape,
                                                   transform=lola.transform, crs=lola.crs) as w:
        w.write(lola.heights[:10], 0, 0)
        raise RuntimeError("stop")
    assert list(tmp_path.iterdir()) == []


def test_other_readers_resolve_the_stores_iau_code_and_warp_it_as_the_geotiff(lola, tmp_path):
    # GDAL writes an IAU_2015 CRS into `_CRS` as ID["IAU",30100] (no version), which no PROJ
    # resolves: rasterio and pyproj saw a CRS without a code where the GeoTIFF of the same
    # DEM reads as IAU_2015:30100. Warping (GDAL's transformer, which follows the CRS's
    # axis order) gives the GeoTIFF's pixels: latitude and longitude are not swapped
    import rasterio
    from rasterio.warp import Resampling, reproject

    dem.write(lola, tmp_path / "m.zarr")
    dem.write(lola, tmp_path / "m.tif")
    assert str(dem.read(tmp_path / "m.zarr").crs) == "IAU_2015:30100"
    warped = []
    for name in ("m.zarr", "m.tif"):
        with rasterio.open(tmp_path / name) as src:
            assert src.crs.to_authority() == ("IAU_2015", "30100")
            out = np.full((60, 80), np.nan, np.float32)
            reproject(rasterio.band(src, 1), out, dst_crs=src.crs,
                      dst_transform=rasterio.Affine(0.5, 0.0, 160.0, 0.0, -0.5, 20.0),
                      resampling=Resampling.nearest)
            warped.append(out)
    assert np.isfinite(warped[0]).all() and np.array_equal(warped[0], warped[1])
