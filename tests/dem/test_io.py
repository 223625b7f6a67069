"""GeoTIFF and PDS3 reading and writing."""

from __future__ import annotations

import hashlib
import logging
import os
from pathlib import Path

import numpy as np
import pytest
import rasterio
from affine import Affine
from rasterio.windows import Window

import dem
from dem import Dem
from dem._pds import Quantity, find_object, parse_label

DATA = os.path.join(os.path.dirname(__file__), "..", "data")
MOON_WKT = ('GEOGCS["Moon 2015",DATUM["Moon_2015",SPHEROID["Moon",1737400,0]],'
            'PRIMEM["Reference_Meridian",0],UNIT["degree",0.0174532925199433]]')


# --------------------------------------------------------------------------- GeoTIFF
def test_read_geotiff_nodata_crs_transform(tiny_geotiff):
    d = dem.read(tiny_geotiff)
    assert d.shape == (33, 33) and d.crs.to_epsg() == 32633
    assert d.transform == Affine(10.0, 0, 500000.0, 0, -10.0, 4000000.0)
    assert d.pixel_size_m == (10.0, 10.0)
    assert np.isnan(d.heights[3, 4]) and d.nan_fraction == pytest.approx(1 / 33**2)
    assert d.heights[2, 5] == 2 + 10


@pytest.mark.parametrize("shape", [(33, 40), (300, 257), (600, 530)])
def test_write_round_trip_as_cloud_optimised_geotiff(tmp_path, shape):
    from rio_cogeo.cogeo import cog_validate

    rng = np.random.default_rng(1)
    z = rng.normal(0, 100, shape).astype(np.float32).astype(np.float64)
    z[5, 7] = np.nan
    t = Affine(2.5, 0, -1000.0, 0, -2.5, 3000.0)
    d = Dem(z, t, "EPSG:32633", tags={"SOURCE": "test"})
    out = dem.write(d, tmp_path / "r.tif")
    with rasterio.open(out) as ds:
        prof = ds.profile
        assert prof["dtype"] == "float32" and np.isnan(prof["nodata"])
        assert prof["compress"] == "deflate" and prof["tiled"]
        assert (prof["blockxsize"], prof["blockysize"]) == (256, 256)
        assert ds.tags()["SOURCE"] == "test" and ds.units == ("metre",)
        assert ds.descriptions == ("height",)
        assert (len(ds.overviews(1)) > 0) == (max(shape) > 256)
    if shape == (600, 530):  # the first overview: averages of the known pixels
        with rasterio.open(out, overview_level=0) as ov:
            coarse = ov.read(1)
        want = np.nanmean(z.reshape(300, 2, 265, 2), axis=(1, 3))
        np.testing.assert_allclose(coarse, want, rtol=1e-5, atol=1e-3)
    valid, errors, warnings = cog_validate(out, strict=True)
    assert valid and not errors and not warnings
    back = dem.read(out)
    assert np.array_equal(back.heights, z, equal_nan=True)
    assert back.transform == t and back.crs == d.crs
    assert sorted(p.name for p in tmp_path.iterdir()) == ["r.tif"]  # no temporary left


def test_write_is_deterministic_and_atomic(tmp_path, lola_crop):
    a = dem.write(lola_crop, tmp_path / "a.tif")
    b = dem.write(lola_crop, tmp_path / "b.tif")
    assert hashlib.sha256(a.read_bytes()).digest() == hashlib.sha256(b.read_bytes()).digest()
    (tmp_path / "c.tif").write_bytes(b"old")
    with pytest.raises(ValueError, match="GeoTIFF"):
        dem.write(lola_crop, tmp_path / "c.png")
    with pytest.raises(TypeError, match="Dem"):
        dem.write(np.zeros((3, 3)), tmp_path / "c.tif")
    assert (tmp_path / "c.tif").read_bytes() == b"old"


def write_foreign_geographic(path, z):
    """A geographic (Moon) GeoTIFF written by rasterio directly, without craterform tags."""
    with rasterio.open(path, "w", driver="GTiff", width=z.shape[1], height=z.shape[0],
                       count=1, dtype="float32", crs=MOON_WKT,
                       transform=Affine(0.25, 0, 148.0, 0, -0.25, 32.0)) as ds:
        ds.write(z.astype(np.float32), 1)
    return path


def test_geographic_radius_from_the_file_its_sphere_or_the_caller(tmp_path, lola_crop):
    foreign = write_foreign_geographic(tmp_path / "f.tif", lola_crop.heights)
    # the CRS is a sphere (the Moon's): its radius, as `dem info` prints (issue 19 item 7)
    assert dem.read(foreign).body_radius_m == 1737400.0
    assert dem.read(foreign).pixel_size_m == pytest.approx(lola_crop.pixel_size_m)
    assert dem.read(foreign, body_radius_m=1737400.0).pixel_size_m == pytest.approx(
        lola_crop.pixel_size_m)
    p = dem.write(lola_crop, tmp_path / "g.tif")  # records the radius it knows
    back = dem.read(p)
    assert back.body_radius_m == 1737400.0
    assert back.pixel_size_m == pytest.approx(lola_crop.pixel_size_m)
    assert np.array_equal(back.heights, lola_crop.heights)
    assert back.tags["PDS_PRODUCT_ID"] == "LDEM_4_CROP"
    assert dem.read(p, body_radius_m=1.0).body_radius_m == 1.0  # explicit value wins
    # a body name gives its mean radius where the file gives none, never over the file's
    assert dem.read(foreign, body="mars").body_radius_m == 3_389_500.0
    assert dem.read(p, body="mars").body_radius_m == 1737400.0
    with pytest.raises(ValueError, match="body"):
        dem.read(foreign, body="titan")


def test_read_errors(tmp_path, tiny_geotiff):
    with pytest.raises(FileNotFoundError, match="does not exist"):
        dem.read(tmp_path / "none.tif")
    text = tmp_path / "notes.tif"
    text.write_text("hello, not a raster\n")
    with pytest.raises(ValueError, match="not a raster file"):
        dem.read(text)
    with pytest.raises(ValueError, match=r"`band` must be in \[1, 1\]"):
        dem.read(tiny_geotiff, band=2)
    with pytest.raises(ValueError, match="band"):
        dem.read(tiny_geotiff, band=0)
    nocrs = tmp_path / "nocrs.tif"
    with rasterio.open(nocrs, "w", driver="GTiff", width=4, height=4, count=1,
                       dtype="float32", transform=Affine(2, 0, 0, 0, -2, 8)) as ds:
        ds.write(np.zeros((4, 4), np.float32), 1)
    with pytest.raises(ValueError, match="`pixel_size_m` is needed: the DEM has no CRS"):
        dem.read(nocrs)
    assert dem.read(nocrs, pixel_size_m=3.0).pixel_size_m == (3.0, 3.0)
    allnan = tmp_path / "nan.tif"
    dem.write(Dem(np.full((4, 4), np.nan), pixel_size_m=1.0), allnan)
    with pytest.raises(ValueError, match="every pixel is NoData"):
        dem.read(allnan)


def test_scale_offset_applied(tmp_path):
    p = tmp_path / "so.tif"
    with rasterio.open(p, "w", driver="GTiff", width=3, height=3, count=1, dtype="int16",
                       crs="EPSG:32633", transform=Affine(1, 0, 5, 0, -1, 9)) as ds:
        ds.write(np.full((3, 3), 10, np.int16), 1)
        ds.scales = (0.5,)
        ds.offsets = (100.0,)
    assert dem.read(p).heights[0, 0] == 105.0


# --------------------------------------------------------------------------- PDS3
def test_lola_crop_label_and_values(lola_crop):
    raw = np.fromfile(os.path.join(DATA, "ldem4_crop.img"), dtype="<i2").reshape(257, 257)
    assert np.array_equal(lola_crop.heights, raw * 0.5)  # HEIGHT = DN x 0.5, OFFSET not added
    assert lola_crop.body_radius_m == 1737400.0 and lola_crop.crs.is_geographic
    assert lola_crop.transform == Affine(0.25, 0, 148.0, 0, -0.25, 32.0)
    assert lola_crop.tags["PDS_REFERENCE_RADIUS_M"] == "1737400.0"
    assert lola_crop.pixel_size_m[1] == pytest.approx(1737400 * np.pi / 720)
    via_img = dem.read(os.path.join(DATA, "ldem4_crop.img"))  # finds the .lbl beside it
    assert np.array_equal(via_img.heights, lola_crop.heights)


LDEM4 = Path(__file__).resolve().parents[3] / "shared/data/dems/lola_ldem4/LDEM_4.LBL"


@pytest.mark.skipif(not LDEM4.is_file(), reason="needs ../shared/data beside the project")
def test_full_ldem4_matches_gdal_georeferencing():
    d = dem.read(LDEM4)
    assert d.shape == (720, 1440) and d.transform == Affine(0.25, 0, 0.0, 0, -0.25, 90.0)
    assert d.pixel_size_m[0] == pytest.approx(7580.84, abs=0.01)
    with rasterio.open(LDEM4) as ds:  # GDAL's PDS driver
        assert np.array_equal(ds.read(1) * 0.5, d.heights)


def write_pds(tmp_path, data, *, sample_type, bits, extra="", image_extra="", prefix=0,
              attached=False, pointer=None, projection=True):
    """A small PDS3 product (detached or attached label) around ``data``."""
    lines, samples = data.shape
    nbytes = bits // 8
    record = prefix + samples * nbytes
    proj = """OBJECT = IMAGE_MAP_PROJECTION
  MAP_PROJECTION_TYPE = "SIMPLE CYLINDRICAL"
  A_AXIS_RADIUS = 3396.19 <KM>
  MAP_RESOLUTION = 2 <PIX/DEG>
  CENTER_LATITUDE = 0.0 <DEG>
  CENTER_LONGITUDE = 0.0 <DEG>
  LINE_PROJECTION_OFFSET = -20.5 <PIXEL>
  SAMPLE_PROJECTION_OFFSET = -40.5 <PIXEL>
  MAXIMUM_LATITUDE = -10.0 <DEG>
  WESTERNMOST_LONGITUDE = 20.0 <DEG>
END_OBJECT = IMAGE_MAP_PROJECTION""" if projection else ""
    body = b"".join(b"\0" * prefix + row.tobytes() for row in data)

    def label(ptr):
        return f"""PDS_VERSION_ID = PDS3
RECORD_TYPE = FIXED_LENGTH
RECORD_BYTES = {record}
{ptr}
TARGET_NAME = MARS
{extra}
OBJECT = IMAGE
  LINES = {lines}
  LINE_SAMPLES = {samples}
  SAMPLE_TYPE = {sample_type}
  SAMPLE_BITS = {bits}
  LINE_PREFIX_BYTES = {prefix}
  {image_extra}
END_OBJECT = IMAGE
{proj}
END
"""
    if attached:
        n_label = -(-1200 // record)  # records reserved for the label
        text = label(f"^IMAGE = {n_label + 1}").encode()
        assert len(text) <= n_label * record
        path = tmp_path / "att.img"
        path.write_bytes(text.ljust(n_label * record, b" ") + body)
        return path
    (tmp_path / "X.IMG").write_bytes(body)
    path = tmp_path / "x.lbl"
    path.write_text(label(pointer or '^IMAGE = "X.IMG"'))
    return path


@pytest.mark.parametrize("sample_type,bits,dtype", [
    ("MSB_INTEGER", 16, ">i2"), ("LSB_INTEGER", 32, "<i4"), ("PC_REAL", 32, "<f4"),
    ("IEEE_REAL", 32, ">f4"), ("LSB_UNSIGNED_INTEGER", 16, "<u2"),
    ("MSB_UNSIGNED_INTEGER", 8, "u1"), ("PC_REAL", 64, "<f8"),
])
@pytest.mark.parametrize("attached", [False, True])
def test_pds_sample_types(tmp_path, sample_type, bits, dtype, attached):
    data = (np.arange(6 * 8).reshape(6, 8) % 200).astype(dtype)
    path = write_pds(tmp_path, data, sample_type=sample_type, bits=bits, attached=attached,
                     prefix=4, image_extra="SCALING_FACTOR = 2.0\n  OFFSET = 10.0")
    d = dem.read(path)
    # OFFSET 10 m is not a reference radius (the body is 3396 km): it is added
    assert np.array_equal(d.heights, data.astype(np.float64) * 2.0 + 10.0)
    assert d.transform == Affine(0.5, 0, 20.0, 0, -0.5, -10.0)
    assert d.body_radius_m == 3396190.0


def test_pds_missing_constant_and_record_pointer(tmp_path):
    data = np.array([[1, -32768, 3], [4, 5, -32768]], dtype="<i2")
    path = write_pds(tmp_path, data, sample_type="LSB_INTEGER", bits=16,
                     image_extra="MISSING_CONSTANT = -32768", pointer='^IMAGE = ("X.IMG", 1)')
    d = dem.read(path)
    assert np.isnan(d.heights[0, 1]) and np.isnan(d.heights[1, 2]) and d.heights[1, 0] == 4
    hexdata = np.array([[1.5, -3.4028226550889045e38]], dtype=">f4")
    path = write_pds(tmp_path, hexdata, sample_type="IEEE_REAL", bits=32,
                     image_extra="MISSING_CONSTANT = 16#FF7FFFFB#")
    d = dem.read(path)
    assert d.heights[0, 0] == 1.5 and np.isnan(d.heights[0, 1])


def test_pds_without_projection_needs_pixel_size(tmp_path):
    data = np.ones((3, 3), dtype="<i2")
    path = write_pds(tmp_path, data, sample_type="LSB_INTEGER", bits=16, projection=False)
    with pytest.raises(ValueError, match="no CRS"):
        dem.read(path)
    assert dem.read(path, pixel_size_m=5.0).pixel_size_m == (5.0, 5.0)


@pytest.mark.parametrize("image_extra,pointer,match", [
    ("", '^IMAGE = "MISSING.IMG"', "is missing"),
    ("BANDS = 2", None, "truncated"),
    ("", '^IMAGE = ("X.IMG", 3)', "truncated"),
])
def test_pds_errors(tmp_path, image_extra, pointer, match):
    data = np.ones((3, 3), dtype="<i2")
    path = write_pds(tmp_path, data, sample_type="LSB_INTEGER", bits=16,
                     image_extra=image_extra, pointer=pointer)
    missing = match == "is missing"  # the image file: FileNotFoundError, as any input
    with pytest.raises(FileNotFoundError if missing else ValueError, match=match):
        dem.read(path, band=2 if "BANDS" in image_extra else 1)


def test_pds_bad_labels(tmp_path):
    data = np.ones((3, 3), dtype="<i2")
    path = write_pds(tmp_path, data, sample_type="VAX_REAL", bits=32)
    with pytest.raises(ValueError, match="unsupported SAMPLE_TYPE"):
        dem.read(path)
    lone = tmp_path / "lone.img"
    lone.write_bytes(b"\0" * 64)
    with pytest.raises(ValueError, match="no PDS label"):
        dem.read(lone)
    broken = tmp_path / "broken.lbl"
    broken.write_text("PDS_VERSION_ID = PDS3\nOBJECT = IMAGE\n  LINES = 3\n")
    with pytest.raises(ValueError, match="cannot parse the PDS label"):
        dem.read(broken)
    noimage = tmp_path / "noimage.lbl"
    noimage.write_text("PDS_VERSION_ID = PDS3\nEND\n")
    with pytest.raises(ValueError, match="no IMAGE object"):
        dem.read(noimage)
    with pytest.raises(ValueError, match="band"):
        dem.read(os.path.join(DATA, "ldem4_crop.lbl"), band=2)


def test_parse_label_values():
    lab = parse_label("""PDS_VERSION_ID = PDS3
    /* comment = ignored */
    NAMES = {"A B",
             'C'}
    PAIR = (1, 2.5 <KM>)
    DATE = 2017-09-15
    HEX = 16#FF7FFFFB#
    OBJECT = OUTER
      GROUP = INNER
        X = -3
      END_GROUP = INNER
    END_OBJECT = OUTER
    END""")
    assert lab["NAMES"] == ["A B", "C"] and lab["DATE"] == "2017-09-15"
    assert lab["PAIR"][0] == 1 and isinstance(lab["PAIR"][1], Quantity)
    assert lab["PAIR"][1].unit == "KM" and lab["HEX"] == "16#FF7FFFFB#"
    inner, parent = find_object(lab, "INNER")
    assert inner == {"X": -3} and parent is lab["OUTER"]
    assert find_object(lab, "NOPE") == (None, None)


@pytest.mark.parametrize("source", ["geotiff", "pds", "nocrs"])
def test_windowed_read_is_the_crop(tmp_path, lola_crop, source):
    if source == "pds":
        path, kw = os.path.join(DATA, "ldem4_crop.lbl"), {}
        whole = lola_crop
    elif source == "geotiff":
        whole = dem.expand(lola_crop, 1, rng=1)  # level 1, origin (0, 0): tags travel
        path, kw = dem.write(whole, tmp_path / "g.tif"), {}
        whole = dem.read(path)
    else:
        whole = Dem(np.arange(35.0).reshape(5, 7), pixel_size_m=3.0)
        path, kw = dem.write(whole, tmp_path / "n.tif"), {}
        whole = dem.read(path)
    for win in ((0, 0, 1, 1), (2, 3, 2, 4), Window(1, 2, 3, 3), (0, 0, *whole.shape)):
        got = dem.read(path, window=win, **kw)
        want = whole.crop(win if isinstance(win, Window) else Window(win[1], win[0], win[3],
                                                                       win[2]))
        assert np.array_equal(got.heights, want.heights, equal_nan=True)
        assert got.transform == want.transform and got.crs == want.crs
        assert (got.level, got.origin) == (want.level, want.origin)
        assert got.pixel_size_m == want.pixel_size_m and dict(got.tags) == dict(want.tags)


def test_windowed_read_errors(tmp_path):
    d = Dem(np.arange(35.0).reshape(5, 7), pixel_size_m=3.0)
    z = d.heights.copy()
    z[:2, :2] = np.nan
    path = dem.write(d.replace(heights=z), tmp_path / "n.tif")
    for win, match in (((0, 0, 6, 1), "not inside"), ((-1, 0, 1, 1), "offsets >= 0"),
                       ((0, 0, 0, 1), "sizes >= 1"), ((0.5, 0, 1, 1), "integer"),
                       ((1, 2, 3), "rasterio Window"), ((0, 0, 2, 2), "every pixel of")):
        with pytest.raises((ValueError, TypeError), match=match) as info:
            dem.read(path, window=win)
        assert "window" in str(info.value)


def test_window_writer_leaves_nothing_on_error(tmp_path):
    out = tmp_path / "w.tif"
    out.write_bytes(b"old")
    with pytest.raises(ValueError, match="not inside"):
        with dem.WindowWriter(out, (4, 4), pixel_size_m=1.0) as w:
            w.write(np.zeros((2, 2)), 0, 0)
            w.write(np.zeros((2, 2)), 3, 3)
    assert out.read_bytes() == b"old" and [p.name for p in tmp_path.iterdir()] == ["w.tif"]
    with pytest.raises(ValueError, match="pixel_size_m"):
        dem.WindowWriter(tmp_path / "x.tif", (4, 4))
    assert [p.name for p in tmp_path.iterdir()] == ["w.tif"]


def test_read_lattice_tags(tiny_geotiff, caplog):
    """The expansion level and lattice origin come from the tags; an origin that is not a
    (row, col) pair is ignored with a warning, as a malformed level is (it was passed on
    as a 3-tuple and refused by Dem; found by mypy)."""
    with rasterio.open(tiny_geotiff, "r+") as ds:
        ds.update_tags(CRATERFORM_LEVEL="1", CRATERFORM_ORIGIN="4,5")
    d = dem.read(tiny_geotiff)
    assert (d.level, d.origin) == (1, (4, 5))
    with rasterio.open(tiny_geotiff, "r+") as ds:
        ds.update_tags(CRATERFORM_ORIGIN="4,5,6")
    with caplog.at_level(logging.WARNING, logger="dem.io"):
        d = dem.read(tiny_geotiff)
    assert (d.level, d.origin) == (0, (0, 0))
    assert "ignoring malformed CRATERFORM_LEVEL/CRATERFORM_ORIGIN tags" in caplog.text


def test_a_crs_given_replaces_the_files(tmp_path, run_cli):
    """``crs`` / ``--crs``: the CRS of a file without one (or with a wrong one), checked
    before anything is read."""
    path = tmp_path / "nocrs.tif"
    with rasterio.open(path, "w", driver="GTiff", width=8, height=8, count=1,
                       dtype="float32", transform=Affine(0.25, 0, 148, 0, -0.25, 32)) as ds:
        ds.write(np.ones((8, 8), "float32"), 1)
    d = dem.read(path, crs="IAU_2015:30100")
    assert d.crs.to_authority() == ("IAU_2015", "30100") and d.body_radius_m == 1737400.0
    assert d.pixel_size_m[1] == pytest.approx(0.25 * np.pi / 180 * 1737400.0)
    with pytest.raises(ValueError, match="`crs` must be a CRS PROJ knows"):
        dem.read(path, crs="IAU_2015:1")
    proc = run_cli("dem", "info", str(path), "--crs", "IAU_2015:30100")
    assert proc.returncode == 0 and "IAU_2015:30100" in proc.stdout, proc.stderr
    proc = run_cli("dem", "info", str(path), "--crs", "nowhere")
    assert proc.returncode == 2 and proc.stderr.startswith("error: --crs must be")
    assert proc.stderr.count("\n") == 1
