"""The Dem object: pixel sizes from the CRS, immutability, windows, crops, history."""

from __future__ import annotations

import math

import numpy as np
import pytest
from affine import Affine
from rasterio.coords import BoundingBox
from rasterio.crs import CRS
from rasterio.windows import Window

from dem import Dem

MOON_WKT = ('GEOGCS["Moon",DATUM["D_Moon",SPHEROID["Moon",1737400,0]],'
            'PRIMEM["Reference_Meridian",0],UNIT["degree",0.0174532925199433]]')


def test_pixel_size_without_crs():
    d = Dem(np.zeros((3, 4)), pixel_size_m=(2.0, 3.0))
    assert d.pixel_size_m == (2.0, 3.0) and d.resolution_m == pytest.approx(math.sqrt(6))
    with pytest.raises(ValueError, match="pixel_size_m.*no CRS"):
        Dem(np.zeros((3, 4)))
    with pytest.raises(ValueError, match="pixel_size_m"):
        Dem(np.zeros((3, 4)), pixel_size_m=-1.0)
    with pytest.raises(TypeError, match="pixel_size_m"):
        Dem(np.zeros((3, 4)), pixel_size_m="big")


@pytest.mark.parametrize("epsg,factor", [(32633, 1.0), (2227, 0.3048006096012192)])
def test_pixel_size_projected(epsg, factor):
    d = Dem(np.zeros((5, 5)), Affine(10.0, 0, 0, 0, -20.0, 0), CRS.from_epsg(epsg))
    assert d.pixel_size_m == pytest.approx((10 * factor, 20 * factor))
    with pytest.raises(ValueError, match="only for DEMs without a CRS"):
        Dem(np.zeros((5, 5)), Affine(10.0, 0, 0, 0, -20.0, 0), CRS.from_epsg(epsg),
            pixel_size_m=1.0)


@pytest.mark.parametrize("lat0", [0.0, 60.0, -45.0])
def test_pixel_size_geographic(lat0):
    # 11 rows of 0.5 degrees centred on lat0
    t = Affine(0.25, 0, 10.0, 0, -0.5, lat0 + 2.75)
    d = Dem(np.zeros((11, 8)), t, MOON_WKT, body_radius_m=1737400.0)
    ground = 1737400.0 * math.radians(1)
    assert d.pixel_size_m == pytest.approx((0.25 * ground * math.cos(math.radians(lat0)),
                                            0.5 * ground))
    # a sphere's CRS gives the radius itself (issue 19 item 7); an ellipsoid's does not
    assert Dem(np.zeros((11, 8)), t, MOON_WKT).pixel_size_m == d.pixel_size_m
    with pytest.raises(ValueError, match=r"body_radius_m.*geographic CRS.*radius 3396190 m"):
        Dem(np.zeros((11, 8)), t, "+proj=longlat +a=3396190 +b=3376200 +no_defs")


def test_validation():
    with pytest.raises(ValueError, match="2-D"):
        Dem(np.zeros(5), pixel_size_m=1.0)
    with pytest.raises(ValueError, match="infinite"):
        Dem(np.array([[1.0, np.inf]]), pixel_size_m=1.0)
    with pytest.raises(TypeError, match="transform"):
        Dem(np.zeros((2, 2)), (1, 0, 0, 0, -1, 0), pixel_size_m=1.0)
    with pytest.raises(ValueError, match="invertible"):
        Dem(np.zeros((2, 2)), Affine(0, 0, 0, 0, 0, 0), pixel_size_m=1.0)
    with pytest.raises(ValueError, match="crs"):
        Dem(np.zeros((2, 2)), crs="not a crs")
    with pytest.raises(TypeError, match="tags"):
        Dem(np.zeros((2, 2)), pixel_size_m=1.0, tags={"a": 1})


def test_immutable_and_inputs_untouched():
    z = np.arange(12.0).reshape(3, 4)
    d = Dem(z, pixel_size_m=1.0)
    z[0, 0] = 99.0
    assert d.heights[0, 0] == 0.0
    with pytest.raises(ValueError):
        d.heights[0, 0] = 5.0
    with pytest.raises(TypeError):
        d.tags["x"] = "y"
    e = d.replace(heights=d.heights + 1)
    assert e.heights[0, 0] == 1.0 and d.heights[0, 0] == 0.0 and e.transform == d.transform
    with pytest.raises(ValueError, match="shape"):
        d.replace(heights=np.zeros((2, 2)))


def test_nan_fraction_and_bounds():
    z = np.zeros((4, 5))
    z[0, :2] = np.nan
    d = Dem(z, Affine(2.0, 0, 100.0, 0, -2.0, 50.0), "EPSG:32633")
    assert d.nan_fraction == pytest.approx(0.1)
    assert d.bounds == BoundingBox(100.0, 42.0, 110.0, 50.0)
    x, y = d.xy([0, 3], [0, 4])
    assert x.tolist() == [101.0, 109.0] and y.tolist() == [49.0, 43.0]


def test_window_crop_and_origin():
    t = Affine(2.0, 0, 100.0, 0, -2.0, 50.0)
    d = Dem(np.arange(30.0).reshape(5, 6), t, "EPSG:32633", origin=(10, 20), level=1)
    c = d.crop(Window(2, 1, 3, 2))
    assert c.heights.tolist() == [[8.0, 9.0, 10.0], [14.0, 15.0, 16.0]]
    assert c.origin == (11, 22) and c.level == 1
    assert c.xy(0, 0) == d.xy(1, 2)
    # bounds select the pixels whose centres lie inside (edges included)
    x0, y0 = d.xy(1, 2)
    x1, y1 = d.xy(3, 4)
    assert d.window(BoundingBox(x0, y1, x1, y0)) == Window(2, 1, 3, 3)
    with pytest.raises(ValueError, match="not inside the DEM"):
        d.window(Window(4, 0, 3, 3))
    with pytest.raises(ValueError, match="no pixels"):
        d.window(BoundingBox(100.2, 49.2, 100.8, 49.8))  # between pixel centres
    with pytest.raises(ValueError, match="not inside the DEM"):
        d.window(BoundingBox(0, 0, 1, 1))
    with pytest.raises(TypeError, match="Window"):
        d.window(5)
    # the same regions as tuples or text (what `dem expand --region` takes)
    assert d.window((1, 2, 3)) == d.window("1,2,3") == Window(2, 1, 3, 3)
    assert d.window((x0, y1, x1, y0)) == d.window(f"{x0},{y1},{x1},{y0}") == Window(2, 1, 3, 3)
    with pytest.raises(ValueError, match="ROW,COL,SIZE"):
        d.window("1,2")
    with pytest.raises(ValueError, match="ROW,COL,SIZE"):
        d.window((1.5, 2, 3))


def test_history_tags():
    d = Dem(np.zeros((3, 3)), pixel_size_m=1.0, tags={"keep": "me"})
    e = d.with_step(np.ones((3, 3)), "dem.test", 5, {"a": 1})
    f = e.with_step(np.ones((3, 3)), "dem.other", None, {"b": 2})
    assert [s["op"] for s in f.history] == ["dem.test", "dem.other"]
    assert f.tags["keep"] == "me" and f.tags["CRATERFORM_GENERATOR"] == "craterform dem.other"
    assert f.tags["CRATERFORM_SEED"] == "null" and e.tags["CRATERFORM_SEED"] == "5"
    assert d.history == [] and "CRATERFORM_HISTORY" not in d.tags
