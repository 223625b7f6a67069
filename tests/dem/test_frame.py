"""Local metric frames: world <-> metres, pixel affines, the square-pixel rule."""

from __future__ import annotations

import math

import numpy as np
import pytest
from affine import Affine

import dem
from dem.frame import LocalFrame, grid_affine, grid_pixel_size, local_frame, pixel_affine

MOON_WKT = ('GEOGCS["Moon 2015",DATUM["Moon_2015",SPHEROID["Moon",1737400,0]],'
            'PRIMEM["Reference_Meridian",0],UNIT["degree",0.0174532925199433]]')


def test_projected_frame_is_a_translation_in_metres():
    d = dem.Dem(np.zeros((5, 7)), Affine(2.0, 0, 1000.0, 0, -2.0, 5000.0), "EPSG:2056")
    f = local_frame(d)
    assert f.kind == "projected" and f.scale_x == f.scale_y == 1.0
    x0, y0 = d.xy(2, 3)
    assert [float(v) for v in f.to_local(x0 + 4.0, y0 - 6.0)] == [4.0, -6.0]
    # feet: the unit converts
    feet = dem.Dem(np.zeros((5, 5)), Affine(10.0, 0, 0, 0, -10.0, 0), "EPSG:2229")
    assert local_frame(feet).scale_x == pytest.approx(0.3048006, rel=1e-6)


def test_geographic_frame_is_equirectangular_at_the_origin():
    lat0 = 30.0
    d = dem.Dem(np.zeros((9, 9)), Affine(0.01, 0, 10.0, 0, -0.01, lat0 + 0.045), MOON_WKT,
                body_radius_m=1737400.0)
    f = local_frame(d)
    assert f.kind == "equirectangular"
    x0, y0 = (float(v) for v in d.xy(4, 4))
    assert y0 == pytest.approx(lat0)
    x, y = f.to_local(x0 + 1.0, y0 + 1.0)
    deg = math.pi / 180.0 * 1737400.0
    assert float(x) == pytest.approx(deg * math.cos(math.radians(lat0)), rel=1e-12)
    assert float(y) == pytest.approx(deg, rel=1e-12)
    back = f.to_world(x, y)
    assert float(back[0]) == pytest.approx(x0 + 1.0) and float(back[1]) == pytest.approx(y0 + 1)
    # 30 degrees north, square degrees are not square metres: stamping refuses
    with pytest.raises(ValueError, match="square pixels"):
        grid_pixel_size(pixel_affine(d, f))


def test_pixel_affine_grid_affine_roundtrip_with_rotation():
    t = Affine.translation(100.0, 200.0) @ Affine.rotation(30.0) @ Affine.scale(5.0, -5.0)
    d = dem.Dem(np.zeros((11, 11)), t, "EPSG:32633")
    f = local_frame(d)
    a = pixel_affine(d, f)
    assert a @ (5, 5) == pytest.approx((0.0, 0.0), abs=1e-9)  # origin at the centre pixel
    p = grid_pixel_size(a)
    assert p == pytest.approx(5.0)
    g = grid_affine(a, p)
    # grid frame: pixel (row i, col j) at (j p, i p)
    for col, row in ((0, 0), (3, 7), (10, 2)):
        assert g @ (a @ (col, row)) == pytest.approx((col * p, row * p), abs=1e-9)


def test_no_crs_frame_uses_the_pixel_size():
    d = dem.Dem(np.zeros((4, 4)), pixel_size_m=(3.0, 3.0))
    f = local_frame(d, origin=(0, 0))
    assert f.kind == "pixel"
    assert pixel_affine(d, f) @ (1, 1) == pytest.approx((3.0, 3.0))
    # the identity transform has rows going down: y = +row, so the grid frame flips y
    assert pixel_affine(d, f).determinant > 0


def test_frame_dict_roundtrip_and_validation():
    f = LocalFrame(1.5, -2.0, 3.0, 4.0, "equirectangular")
    assert LocalFrame.from_dict(f.to_dict()) == f
    with pytest.raises(ValueError, match="scale_x"):
        LocalFrame(0.0, 0.0, 0.0, 1.0)
    with pytest.raises(ValueError, match="kind"):
        LocalFrame(0.0, 0.0, 1.0, 1.0, "polar")
    with pytest.raises(ValueError, match="bad local frame"):
        LocalFrame.from_dict({"origin_world": [0, 0]})


def test_world_to_lonlat_and_body_axes():
    """Positions on the body for .scc catalogs: geographic CRSs directly, projected ones
    inverted on their own sphere or ellipsoid; axes from the CRS's SPHEROID."""
    from rasterio.crs import CRS

    from dem.frame import body_axes_m, world_to_lonlat

    polar = CRS.from_proj4("+proj=stere +lat_0=-90 +lon_0=0 +k=1 +x_0=0 +y_0=0 +R=1737400 "
                           "+units=m +no_defs")
    lon, lat = world_to_lonlat(polar, [0.0, 0.0], [0.0, 10000.0])
    assert lat[0] == pytest.approx(-90.0)
    # polar stereographic: a point 10 km from the pole lies 2 R atan(r / 2R) of arc away
    arc = 2 * 1737400.0 * np.arctan(10000.0 / (2 * 1737400.0))
    assert lat[1] == pytest.approx(-90.0 + np.degrees(arc / 1737400.0), abs=1e-9)
    assert body_axes_m(polar) == pytest.approx((1737400.0,) * 3)
    utm = CRS.from_epsg(32633)
    lon, lat = world_to_lonlat(utm, [500000.0], [0.0])
    assert lon[0] == pytest.approx(15.0) and lat[0] == pytest.approx(0.0, abs=1e-9)
    assert body_axes_m(utm) == pytest.approx((6378137.0, 6378137.0, 6356752.314245), rel=1e-12)
    geo = CRS.from_wkt('GEOGCS["Moon",DATUM["D_Moon",SPHEROID["Moon",1737400,0]],'
                       'PRIMEM["Reference_Meridian",0],UNIT["degree",0.0174532925199433]]')
    assert world_to_lonlat(geo, [181.0], [2.0]) == ([181.0], [2.0])
    assert world_to_lonlat(None, [1.0], [2.0]) is None and body_axes_m(None) is None
    assert body_axes_m(utm, 1000.0) == (1000.0,) * 3
