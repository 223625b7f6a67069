"""Issue 19 item 9: formats users expect. Every GeoTIFF ``dem`` writes is a valid
cloud-optimised GeoTIFF; PDS3 products are read through GDAL's PDS driver (polar
stereographic and any projection it knows) behind craterform's label checks, with the
LOLA offset rule; IAU CRS codes are kept through read and write."""

from __future__ import annotations

import logging
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import rasterio
from affine import Affine
from rasterio.crs import CRS

import dem
from dem.crscode import CRS_TAG, restore_crs

DATA = Path(__file__).resolve().parents[1] / "data"
LDEM4 = Path(__file__).resolve().parents[3] / "shared/data/dems/lola_ldem4/LDEM_4.LBL"
MOON_R = 1737400.0


def run(capsys, *argv):
    """``dem ...`` in this process: exit code, stdout, stderr."""
    from dem.cli import main

    try:
        code = main([str(a) for a in argv])
    except SystemExit as exc:  # argparse errors
        code = exc.code
    out, err = capsys.readouterr()
    return subprocess.CompletedProcess(argv, code, out, err)


def copy_product(folder: Path, stem: str) -> Path:
    """A shipped PDS3 product (.lbl + .img) copied into ``folder``; the label's path."""
    for suffix in (".lbl", ".img"):
        shutil.copy(DATA / f"{stem}{suffix}", folder / f"{stem}{suffix}")
    return folder / f"{stem}.lbl"


def write_scene(path: Path, **keys) -> Path:
    def fmt(v):
        if isinstance(v, list | tuple):
            return "[" + ", ".join(fmt(x) for x in v) + "]"
        return f'"{v}"' if isinstance(v, str) else repr(v)

    path.write_text("".join(f"{k} = {fmt(v)}\n" for k, v in keys.items()))
    return path


def make_outputs(capsys, tmp: Path, command: str, source: Path, target) -> list[Path]:
    """Run ``dem COMMAND`` on ``source`` (a GeoTIFF or PDS3 label); the GeoTIFFs it wrote."""
    moon = ["--body-radius-m", repr(MOON_R)]
    if command == "convert":
        args, made = [source, "-o", tmp / "convert.tif"], [tmp / "convert.tif"]
    elif command == "fill":
        d = dem.read(source, body_radius_m=MOON_R)
        z = d.heights.copy()
        z[d.shape[0] // 3:d.shape[0] // 2, 10:40] = np.nan
        gappy = dem.write(d.replace(heights=z), tmp / "gappy.tif")
        args = [gappy, "-o", tmp / "fill.tif", "--seed", "3", *moon]
        made = [gappy, tmp / "fill.tif"]
    elif command == "expand":
        args = [source, "-o", tmp / "expand.tif", "--levels", "1", "--seed", "3", *moon]
        made = [tmp / "expand.tif"]
    else:
        scene = write_scene(tmp / "scene.toml", input=str(source), output=str(tmp / "stack"),
                            layers=3, size=65 if command == "enhance" else 257,
                            target=list(target), body_radius_m=MOON_R,
                            craters=["c=0.05,k=-2,d_min_m=200,d_max_m=100000"])
        args, made = ["--config", scene, "--seed", "3"], None
        command = "enhance"
    proc = run(capsys, command, *args, "-q")
    assert proc.returncode == 0, proc.stderr
    if made is None:
        made = sorted((tmp / "stack").glob("*.tif"))
        assert len(made) == 3
    return made


# --------------------------------------------------------------------------- COG
@pytest.mark.parametrize("case", ["convert-pds", "convert-polar-pds", "convert-tiny",
                                  "convert-geotiff", "fill", "expand", "enhance-257"])
def test_every_geotiff_dem_writes_is_a_valid_cog(capsys, tmp_path, case, tiny_geotiff):
    from rio_cogeo.cogeo import cog_validate

    lola = copy_product(tmp_path, "ldem4_crop")
    if case == "convert-polar-pds":
        made = make_outputs(capsys, tmp_path, "convert", copy_product(tmp_path, "ldem4_spole"),
                            None)
    elif case == "convert-tiny":  # 3 x 4 pixels, no CRS: one partial tile, no overview
        tiny = dem.write(dem.Dem(np.arange(12.0).reshape(3, 4), pixel_size_m=5.0),
                         tmp_path / "tiny.tif")
        made = make_outputs(capsys, tmp_path, "convert", tiny, None)
    elif case == "convert-geotiff":
        made = make_outputs(capsys, tmp_path, "convert", tiny_geotiff, None)
    elif case == "convert-pds":
        made = make_outputs(capsys, tmp_path, "convert", lola, None)
    else:
        made = make_outputs(capsys, tmp_path, case, lola, (180.0, -0.5))
    for path in made:
        valid, errors, warnings = cog_validate(path, strict=True)
        assert valid and not errors and not warnings, (path.name, errors, warnings)
        with rasterio.open(path) as ds:
            assert ds.block_shapes == [(256, 256)] or max(ds.shape) < 256
            assert bool(ds.overviews(1)) == (max(ds.shape) > 256), (path.name, ds.shape)


@pytest.mark.parametrize("shape", [(1, 1), (257, 3), (3, 1000), (1025, 2), (256, 256)])
def test_odd_shapes_are_valid_cogs(tmp_path, shape):
    from rio_cogeo.cogeo import cog_validate

    z = np.random.default_rng(0).normal(size=shape)
    path = dem.write(dem.Dem(z, pixel_size_m=1.0), tmp_path / "odd.tif")
    valid, errors, warnings = cog_validate(path, strict=True)
    assert valid and not errors and not warnings, (errors, warnings)
    assert np.array_equal(dem.read(path).heights, z.astype(np.float32))


# --------------------------------------------------------------------------- IAU codes
def iau_input(tmp: Path, code: str, lola) -> tuple[Path, tuple[float, float]]:
    """The LOLA crop's heights as a GeoTIFF in the IAU CRS ``code`` (written by dem)."""
    crs = CRS.from_user_input(code)
    if crs.is_geographic:
        transform, target = lola.transform, (180.0, -0.5)
    else:  # a south polar stereographic map, 1 km pixels around the pole
        transform, target = Affine(1000.0, 0, -128500.0, 0, -1000.0, 128500.0), (0.0, 0.0)
    d = dem.Dem(lola.heights, transform, crs, body_radius_m=MOON_R)
    return dem.write(d, tmp / "in.tif"), target


@pytest.mark.parametrize("command", ["convert", "fill", "expand", "enhance"])
@pytest.mark.parametrize("code", ["IAU_2015:30100", "IAU_2015:30135"])
def test_iau_crs_code_kept_through_every_command(capsys, tmp_path, lola_crop, code, command):
    source, target = iau_input(tmp_path, code, lola_crop)
    assert dem.read(source).crs.to_authority() == tuple(code.split(":"))
    for path in make_outputs(capsys, tmp_path, command, source, target):
        got = dem.read(path).crs
        assert got.to_authority() == tuple(code.split(":")), path.name
        assert got == CRS.from_user_input(code)


def test_iau_crs_of_a_foreign_geotiff_and_the_tag(tmp_path, lola_crop, caplog):
    # a GeoTIFF another program wrote with the Moon's IAU CRS: read and written, kept
    foreign = tmp_path / "foreign.tif"
    with rasterio.open(foreign, "w", driver="GTiff", width=257, height=257, count=1,
                       dtype="float32", crs="IAU_2015:30100",
                       transform=lola_crop.transform) as ds:
        ds.write(lola_crop.heights.astype(np.float32), 1)
    back = dem.read(dem.write(dem.read(foreign, body="moon"), tmp_path / "out.tif"))
    assert back.crs.to_authority() == ("IAU_2015", "30100")
    assert CRS_TAG not in back.tags  # the GeoTIFF keys keep this one: no tag, same bytes
    # a code the keys lose is in the tag, which is dropped from the Dem's tags
    polar = dem.Dem(lola_crop.heights, Affine(1000.0, 0, 0, 0, -1000.0, 0), "IAU_2015:30135")
    path = dem.write(polar, tmp_path / "polar.tif")
    with rasterio.open(path) as ds:
        assert ds.tags()[CRS_TAG] == "IAU_2015:30135" and ds.crs.to_authority() is None
        file_crs = ds.crs
    assert CRS_TAG not in dem.read(path).tags
    # a stale tag (the file's CRS is another) or a malformed one is ignored, with a word
    tags = {CRS_TAG: "IAU_2015:30135"}
    with caplog.at_level(logging.WARNING, logger="dem.crscode"):
        assert restore_crs(CRS.from_epsg(32633), tags, "x.tif") == CRS.from_epsg(32633)
        assert restore_crs(file_crs, {CRS_TAG: "NOPE:1"}, "x.tif") == file_crs
    assert tags == {} and caplog.text.count("ignoring the tag") == 2


# --------------------------------------------------------------------------- PDS3
def centres(t: Affine, rows, cols):
    """Map coordinates of pixel centres (a north-up transform)."""
    return t.c + t.a * (np.asarray(cols) + 0.5), t.f + t.e * (np.asarray(rows) + 0.5)


def test_polar_stereographic_lola_product(tmp_path):
    sys.path.insert(0, str(DATA))
    try:
        from make_lola_polar import OFFSET_PX, SCALE_M, pixel_lat_lon
    finally:
        sys.path.remove(str(DATA))
    d = dem.read(DATA / "ldem4_spole.lbl")
    raw = np.fromfile(DATA / "ldem4_spole.img", dtype="<i2").reshape(64, 64)
    assert np.array_equal(d.heights, raw * 0.5)  # DN x 0.5; OFFSET = 1737.4 km not added
    assert d.tags["PDS_REFERENCE_RADIUS_M"] == "1737400.0" and d.body_radius_m == MOON_R
    edge = (OFFSET_PX + 0.5) * SCALE_M
    assert d.transform == Affine(SCALE_M, 0, -edge, 0, -SCALE_M, edge)
    assert d.pixel_size_m == (SCALE_M, SCALE_M)
    params = d.crs.to_dict()
    assert params["proj"] == "stere" and params["lat_0"] == -90 and params["R"] == MOON_R
    assert d.crs.linear_units == "metre"
    # pixel centres through the CRS GDAL read = the textbook spherical formulas
    from pyproj import CRS as ProjCRS
    from pyproj import Transformer

    crs = ProjCRS.from_wkt(d.crs.to_wkt())
    to_geo = Transformer.from_crs(crs, crs.geodetic_crs, always_xy=True)
    rows, cols = np.mgrid[0:64, 0:64]
    lon, lat = to_geo.transform(*centres(d.transform, rows, cols))
    want_lat, want_lon = pixel_lat_lon(rows, cols)
    assert np.abs(lat - want_lat).max() < 1e-9
    assert np.abs((lon - want_lon + 180.0) % 360.0 - 180.0).max() < 1e-9
    win = dem.read(DATA / "ldem4_spole.img", window=(5, 7, 20, 11))  # the .img finds its label
    assert np.array_equal(win.heights, d.heights[5:25, 7:18])
    assert win.transform == d.transform @ Affine.translation(7, 5)


@pytest.mark.skipif(not LDEM4.is_file(), reason="needs ../shared/data beside the project")
def test_polar_product_heights_are_ldem4s():
    sys.path.insert(0, str(DATA))
    try:
        from make_lola_polar import ldem4_heights
    finally:
        sys.path.remove(str(DATA))
    d = dem.read(DATA / "ldem4_spole.lbl")
    from pyproj import CRS as ProjCRS
    from pyproj import Transformer

    crs = ProjCRS.from_wkt(d.crs.to_wkt())
    rows, cols = np.mgrid[0:64, 0:64]
    lon, lat = Transformer.from_crs(crs, crs.geodetic_crs, always_xy=True).transform(
        *centres(d.transform, rows, cols))
    ldem4 = dem.read(LDEM4)
    dn = np.rint(ldem4.heights / 0.5).astype(np.int16)
    np.testing.assert_allclose(d.heights, ldem4_heights(dn, lat, lon % 360.0), atol=0.25)


def test_dem_convert_of_the_polar_product(capsys, tmp_path):
    label = copy_product(tmp_path, "ldem4_spole")
    out = tmp_path / "polar.tif"
    proc = run(capsys, "convert", label, "-o", out)
    assert proc.returncode == 0 and proc.stderr == "", proc.stderr
    assert proc.stdout.splitlines()[-1] == f"wrote {out}"
    src, got = dem.read(label), dem.read(out)
    np.testing.assert_array_equal(got.heights, src.heights.astype(np.float32))
    assert got.transform == src.transform and got.crs == src.crs
    assert got.body_radius_m == MOON_R and got.tags["PDS_PRODUCT_ID"] == "LDEM_4_SPOLE"


@pytest.mark.parametrize("label", [DATA / "ldem4_crop.lbl", LDEM4])
def test_gdal_georeference_of_lola_matches_craterforms(label):
    """Simple cylindrical LOLA maps keep craterform's geographic georeference; GDAL's
    own (metres on the label's sphere) agrees with it to 1/1000 of a pixel."""
    if not label.is_file():
        pytest.skip("needs ../shared/data beside the project")
    d = dem.read(label)
    with rasterio.open(label) as ds:  # GDAL alone (a shipped, trusted label)
        t, crs = ds.transform, ds.crs.to_dict()
        assert np.array_equal(ds.read(1) * ds.scales[0], d.heights)
    m_per_deg = crs["R"] if "R" in crs else crs["a"]
    m_per_deg *= np.pi / 180.0
    rows, cols = d.shape
    for c, r in ((0, 0), (cols, 0), (0, rows), (cols, rows)):
        gx, gy = centres(t, r - 0.5, c - 0.5)
        lon, lat = crs["lon_0"] + gx / m_per_deg, gy / m_per_deg
        x, y = centres(d.transform, r - 0.5, c - 0.5)
        assert abs(lon - x) / d.transform.a < 1e-3 and abs(lat - y) / -d.transform.e < 1e-3


def test_gdal_never_sees_a_file_the_label_names_outside_its_folder(tmp_path):
    """GDAL alone follows a COMPRESSED_FILE object to any file; dem.read hands GDAL only
    the checked ^IMAGE file."""
    folder = tmp_path / "pds"
    folder.mkdir()
    lola = dem.read(DATA / "ldem4_crop.lbl")
    dem.write(lola.replace(heights=lola.heights + 1000.0), tmp_path / "secret.tif")
    shutil.copy(DATA / "ldem4_crop.img", folder / "LDEM4_CROP.IMG")
    text = (DATA / "ldem4_crop.lbl").read_text(encoding="latin-1")
    label = folder / "x.lbl"
    label.write_text(text.replace(
        "OBJECT                    = UNCOMPRESSED_FILE",
        'OBJECT = COMPRESSED_FILE\r\n FILE_NAME = "../secret.tif"\r\n ENCODING_TYPE = "ZIP"\r\n'
        "END_OBJECT = COMPRESSED_FILE\r\nOBJECT = UNCOMPRESSED_FILE"), encoding="latin-1")
    with rasterio.open(label) as ds:  # the threat: GDAL alone opens ../secret.tif
        assert str(tmp_path / "secret.tif") in [str(Path(f).resolve()) for f in ds.files]
    got = dem.read(label)
    assert np.array_equal(got.heights, lola.heights) and got.transform == lola.transform


def write_product(folder: Path, data: np.ndarray, sample_type: str, projection: str = "",
                  image_extra: str = "") -> Path:
    (folder / "P.IMG").write_bytes(data.tobytes())
    label = folder / "p.lbl"
    label.write_text(f"""PDS_VERSION_ID = PDS3
RECORD_TYPE = FIXED_LENGTH
RECORD_BYTES = {data.shape[1] * data.itemsize}
^IMAGE = "P.IMG"
TARGET_NAME = MARS
OBJECT = IMAGE
  LINES = {data.shape[0]}
  LINE_SAMPLES = {data.shape[1]}
  SAMPLE_TYPE = {sample_type}
  SAMPLE_BITS = {8 * data.itemsize}
  {image_extra}
END_OBJECT = IMAGE
{projection}
END
""")
    return label


@pytest.mark.parametrize(("sample_type", "dtype", "values"), [
    ("LSB_INTEGER", "<i4", [-2_000_000_000, -1, 0, 2_000_000_000]),
    ("MSB_INTEGER", ">i4", [-2_000_000_000, -7, 3, 2_147_483_647]),
    ("MSB_UNSIGNED_INTEGER", ">u4", [0, 1, 4_000_000_000, 4_294_967_295]),
    ("LSB_INTEGER", "i1", [-128, -1, 0, 127]),
    ("MSB_INTEGER", ">i8", [-(2**40), -1, 0, 2**40]),
    ("PC_REAL", "<f8", [-1e300, -0.5, 0.0, 1e-300]),
])
def test_pds_samples_gdal_names_otherwise_keep_their_values(tmp_path, sample_type, dtype,
                                                             values):
    """GDAL's PDS driver takes 32- and 64-bit integers for floats and signed bytes for
    unsigned: their bits are read back as the label's type."""
    data = np.array([values, values[::-1]], dtype=dtype)
    d = dem.read(write_product(tmp_path, data, sample_type), pixel_size_m=1.0)
    assert np.array_equal(d.heights, data.astype(np.float64))


def test_equirectangular_off_the_equator_is_gdals(tmp_path):
    """An EQUIRECTANGULAR map with a standard parallel (HiRISE-style), refused before,
    is GDAL's projected CRS in metres."""
    proj = """OBJECT = IMAGE_MAP_PROJECTION
  MAP_PROJECTION_TYPE = EQUIRECTANGULAR
  A_AXIS_RADIUS = 3396.19 <KM>
  C_AXIS_RADIUS = 3396.19 <KM>
  CENTER_LATITUDE = 40.0 <DEG>
  CENTER_LONGITUDE = 180.0 <DEG>
  MAP_SCALE = 1.0 <METERS/PIXEL>
  LINE_PROJECTION_OFFSET = 2400000.5 <PIXEL>
  SAMPLE_PROJECTION_OFFSET = -3.5 <PIXEL>
  POSITIVE_LONGITUDE_DIRECTION = EAST
END_OBJECT = IMAGE_MAP_PROJECTION"""
    data = np.arange(12, dtype="<f4").reshape(3, 4)
    d = dem.read(write_product(tmp_path, data, "PC_REAL", proj))
    params = d.crs.to_dict()
    assert params["proj"] == "eqc" and params["lat_ts"] == 40 and params["lon_0"] == 180
    assert d.transform == Affine(1.0, 0, 3.0, 0, -1.0, 2400001.0)
    assert d.pixel_size_m == (1.0, 1.0) and d.body_radius_m == 3396190.0
    assert np.array_equal(d.heights, data)


def test_heights_in_kilometres_and_the_lola_offset(tmp_path):
    """A floating-point product in km with OFFSET = 1737.4 (km, the reference radius), as
    LOLA's polar float products: metres, and the offset recorded, not added."""
    proj = ("OBJECT = IMAGE_MAP_PROJECTION\n  " + "\n  ".join(POLAR)
            + "\nEND_OBJECT = IMAGE_MAP_PROJECTION")
    data = np.array([[-1.25, 0.0], [0.5, 2.0]], dtype="<f4")
    d = dem.read(write_product(tmp_path, data, "PC_REAL", proj,
                               "UNIT = KILOMETER\n  SCALING_FACTOR = 1\n  OFFSET = 1737.4"))
    assert np.array_equal(d.heights, data * 1000.0)
    assert d.tags["PDS_REFERENCE_RADIUS_M"] == "1737400.0"
    other = dem.read(write_product(tmp_path, data, "PC_REAL", proj,
                                   "UNIT = METER\n  SCALING_FACTOR = 2\n  OFFSET = 10"))
    assert np.array_equal(other.heights, data * 2.0 + 10.0)  # an OFFSET of 10 m: added


POLAR = ('MAP_PROJECTION_TYPE = "POLAR STEREOGRAPHIC"', "A_AXIS_RADIUS = 1737.4 <KM>",
         "C_AXIS_RADIUS = 1737.4 <KM>", "CENTER_LATITUDE = -90.0",
         "MAP_SCALE = 5 <METERS/PIXEL>")


@pytest.mark.parametrize(("change", "match"), [
    (("MAP_SCALE = 5 <METERS/PIXEL>", "MAP_SCALE = 0 <METERS/PIXEL>"), "MAP_SCALE must be"),
    (("A_AXIS_RADIUS = 1737.4 <KM>", "A_AXIS_RADIUS = 0 <KM>"), "A_AXIS_RADIUS must be"),
    (("CENTER_LATITUDE = -90.0", "POSITIVE_LONGITUDE_DIRECTION = WEST"),
     "POSITIVE_LONGITUDE_DIRECTION"),
    (('"POLAR STEREOGRAPHIC"', "HAMMER"), "no CRS for MAP_PROJECTION_TYPE 'HAMMER'"),
])
def test_pds_projection_errors(tmp_path, change, match):
    data = np.ones((3, 3), dtype="<i2")
    keys = "\n  ".join(POLAR).replace(*change)
    proj = f"OBJECT = IMAGE_MAP_PROJECTION\n  {keys}\nEND_OBJECT = IMAGE_MAP_PROJECTION"
    with pytest.raises(ValueError, match=match) as info:
        dem.read(write_product(tmp_path, data, "LSB_INTEGER", proj))
    assert "p.lbl" in str(info.value) and "\n" not in str(info.value)


if __name__ == "__main__":
    sys.exit(pytest.main([__file__, "-q"]))
