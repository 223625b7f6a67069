"""Terrain on demand over a DEM (dem.ondemand): the DEM as the base, windows of it."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import dem
from dem.ondemand import DemBase, dem_tile
from latlong import Scene
from latlong.ondemand import units_of

LOLA = Path(__file__).resolve().parents[1] / "data" / "ldem4_crop.lbl"


@pytest.fixture(scope="module")
def lola():
    return dem.read(LOLA)


@pytest.fixture(scope="module")
def scene(lola):
    return Scene.from_settings({"base": "sphere", "radius_m": lola.body_radius_m, "body": "moon",
                                "seed": 3, "on_demand": True,
                                "craters": ["c=0.05,k=-2,d_min_m=500,d_max_m=20000"]})


def test_the_base_is_the_dem_at_its_pixel_centres(lola):
    base = DemBase(lola, seed=1)
    t = lola.transform
    rows, cols = np.array([3, 100, 250]), np.array([7, 128, 200])
    lon = t.c + (cols + 0.5) * t.a
    lat = t.f + (rows + 0.5) * t.e
    r = base.radius(units_of(lat, lon))
    assert np.allclose(r - lola.body_radius_m, lola.heights[rows, cols], rtol=0, atol=1e-6)
    # halfway between two pixel centres along a row: Catmull-Rom's (-1, 9, 9, -1) / 16
    r = base.radius(units_of([lat[1]], [lon[1] + 0.5 * t.a]))
    h = lola.heights[100, 127:131]
    want = (-h[0] + 9.0 * h[1] + 9.0 * h[2] - h[3]) / 16.0
    assert r[0] - lola.body_radius_m == pytest.approx(want, abs=1e-6)
    with pytest.raises(ValueError, match="outside"):
        base.radius(units_of([80.0], [180.0]))


def test_dem_windows_agree_where_they_overlap(lola, scene):
    # two windows with the same pixels: one inside the other, the same values there
    big = dem_tile(lola, scene, 5.0, 180.0, size_m=64000.0, pixel_m=1000.0)
    small = dem_tile(lola, scene, 5.0, 180.0, size_m=16000.0, pixel_m=1000.0)
    assert np.array_equal(big.heights_m[24:40, 24:40], small.heights_m)
    assert big.n_craters > 0
    relief = np.ptp(big.heights_m)
    assert 100.0 < relief < 20000.0


def test_a_descent_over_the_dem(lola, scene):
    from dem.ondemand import dem_descent

    frames = list(dem_descent(lola, scene, 5.0, 180.0, [50000.0, 5000.0], width_px=32))
    assert [f.terrain for f in frames] == ["window", "window"]
    assert frames[1].ground_pixel_m == pytest.approx(0.1 * frames[0].ground_pixel_m)
    for f in frames:
        lit = f.frame.reflectance > 0
        assert lit.mean() > 0.5  # the ground fills the picture
    with pytest.raises(ValueError, match="altitudes_m"):
        list(dem_descent(lola, scene, 5.0, 180.0, [3e6], width_px=32))


def test_dem_descent_writes_the_frames_strip_and_manifest(tmp_path):
    import json

    from dem.cli import main

    out = tmp_path / "d"
    code = main(["descent", str(LOLA), "--lat-deg", "10", "--lon-deg", "180", "--start-m",
                 "20000", "--stop-m", "2", "--frames", "3", "--size-px", "32", "--craters",
                 "c=0.08,k=-2,d_min_m=0.1,d_max_m=20000", "--boulders",
                 "c=7e-4,k=-2.11,d_min_m=0.05,d_max_m=5", "--seed", "1", "-q", "-o", str(out),
                 "--lidar", "--lidar-beams", "8x8", "--lidar-max-range-m", "30000"])
    assert code == 0
    meta = json.loads((out / "frames.json").read_text())
    assert [round(f["altitude_m"]) for f in meta["frames"]] == [20000, 200, 2]
    assert all(f["craters"] > 0 for f in meta["frames"])
    assert (out / "strip.png").is_file() and (out / "picture_0002.png").is_file()
    # the LIDAR: every beam returns, its settings and seed in the manifest
    assert meta["lidar"]["beams"] == [8, 8] and meta["lidar_seed"] == 0
    assert all(f["lidar_returns"] == 64 for f in meta["frames"])
    assert (out / "lidar_0002.las").is_file() and (out / "lidar_range_0002.npy").is_file()
    import laspy

    crs = laspy.read(out / "lidar_0002.las").header.parse_crs()  # body-fixed Cartesian
    assert crs is not None and crs.is_geocentric
    # a LIDAR wider than the frames' terrain: one line naming the flag, nothing written
    assert main(["descent", str(LOLA), "--lat-deg", "10", "--lon-deg", "180", "--frames", "1",
                 "--craters", "c=0.08,k=-2,d_min_m=10,d_max_m=100", "--lidar",
                 "--lidar-fov-deg", "60", "-o", str(tmp_path / "w")]) == 2
    assert not (tmp_path / "w").exists()
    # no layer: refused in one line, nothing written
    assert main(["descent", str(LOLA), "--lat-deg", "10", "--lon-deg", "180", "-o",
                 str(tmp_path / "e")]) == 2
    assert not (tmp_path / "e").exists()


@pytest.fixture(scope="module")
def stack(lola):
    return dem.enhance({"layers": 3, "size": 65, "target": [180.0, 0.0], "seed": 4,
                        "craters": []}, dem=lola)


def test_a_stack_base_is_its_finest_layer_inside_and_blends_without_a_seam(stack, scene):
    from dem.ondemand import EDGE_PX, StackBase

    base = StackBase(stack, seed=1)
    fine, coarse = (DemBase(d, seed=1) for d in (stack.layers[-1], stack.layers[-2]))
    t = stack.layers[-1].transform
    ny, nx = stack.layers[-1].shape
    # inside the blend band's inner edge: the finest layer; far outside: the coarser one
    inner = units_of([t.f + (ny / 2) * t.e], [t.c + (nx / 2) * t.a])
    assert base.radius(inner)[0] == fine.radius(inner)[0]
    outer = units_of([t.f + (ny / 2) * t.e], [t.c - 3.0 * t.a])
    assert base.radius(outer)[0] == coarse.radius(outer)[0]
    # across the finest layer's west edge: steps between neighbours of a few cm at most
    # (the layers' relief there spans metres), no jump where the layer starts
    lon = t.c + np.linspace(-4.0, EDGE_PX + 4.0, 600) * t.a
    r = base.radius(units_of(np.full(600, t.f + (ny / 2) * t.e), lon))
    assert np.abs(np.diff(r)).max() < 0.05 * np.ptp(r)
    # a window over the stack
    made = dem_tile(stack, scene, 0.0, 180.0, size_m=20000.0, pixel_m=200.0)
    assert np.isfinite(made.heights_m).all() and made.n_craters > 0


def test_dem_tile_reads_a_stack_manifest(stack, tmp_path):
    from dem.cli import main

    stack.write(tmp_path / "st")
    out = tmp_path / "t.tif"
    assert main(["tile", str(tmp_path / "st" / "manifest.json"), "--lat-deg", "0",
                 "--lon-deg", "180", "--size-m", "4000", "--pixel-m", "40", "--craters",
                 "c=0.08,k=-2,d_min_m=100,d_max_m=1000", "--seed", "1", "-q", "-o",
                 str(out)]) == 0
    assert out.is_file()
    assert main(["tile", str(tmp_path / "nothing.json"), "--lat-deg", "0", "--lon-deg", "180",
                 "--size-m", "4000", "--pixel-m", "40", "--craters",
                 "c=0.08,k=-2,d_min_m=100,d_max_m=1000", "-o", str(tmp_path / "u.tif")]) == 2
