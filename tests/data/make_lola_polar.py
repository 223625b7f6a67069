"""Make ``ldem4_spole.img`` + ``ldem4_spole.lbl``: LOLA LDEM_4 resampled onto a 64 x 64
south polar stereographic grid, labelled as LOLA labels its polar products.

Run once from the repository root with ``../shared`` beside it:
``python tests/data/make_lola_polar.py``. The grid: a sphere of 1737.4 km, polar
stereographic centred on the south pole (true scale at the pole), 15 km pixels,
LINE/SAMPLE_PROJECTION_OFFSET = 31.5 (the pole at the image centre, a pixel corner),
960 x 960 km: latitude -90 to about -74.3 along the edges' midlines, -67.9 at the
corners. Each pixel centre's height is LDEM_4's, interpolated bilinearly in latitude
and longitude (the centres of LDEM_4's pixels at (90 - (row + 0.5) / 4, (col + 0.5) / 4)
degrees), stored as LOLA stores it: int16 DN, metres = DN x 0.5 (rounded), above a
1737.4 km reference sphere (the label's OFFSET). The projection formulas here are the
textbook spherical ones, independent of GDAL: the tests read the product through GDAL
and check it against them.
"""

from pathlib import Path

import numpy as np
from scipy.ndimage import map_coordinates

SRC = Path(__file__).resolve().parents[3] / "shared" / "data" / "dems" / "lola_ldem4"
OUT = Path(__file__).resolve().parent
N = 64  # lines = samples
SCALE_M = 15000.0  # metres per pixel
RADIUS_M = 1737400.0
OFFSET_PX = (N - 1) / 2  # LINE_ and SAMPLE_PROJECTION_OFFSET: the pole at the centre

LABEL = """PDS_VERSION_ID            = "PDS3"

/* LOLA LDEM_4 (LRO LOLA GDR, V3.0) resampled (bilinear) onto a {N} x {N} south */
/* polar stereographic grid by craterform's tests/data/make_lola_polar.py.     */

DATA_SET_ID               = "LRO-L-LOLA-4-GDR-V1.0"
PRODUCT_ID                = "LDEM_4_SPOLE"
SOURCE_PRODUCT_ID         = "LDEM_4"
INSTRUMENT_HOST_NAME      = "LUNAR RECONNAISSANCE ORBITER"
INSTRUMENT_NAME           = "LUNAR ORBITER LASER ALTIMETER"
TARGET_NAME               = MOON
DESCRIPTION               = "LDEM_4 heights on a polar stereographic grid of the
   south pole at {scale_km:g} km/pix, heights relative to a radius of 1737.4 km."

OBJECT                    = UNCOMPRESSED_FILE
FILE_NAME                 = "LDEM4_SPOLE.IMG"
RECORD_TYPE               = FIXED_LENGTH
FILE_RECORDS              = {N}
RECORD_BYTES              = {record}
^IMAGE                    = "LDEM4_SPOLE.IMG"

  OBJECT                  = IMAGE
    NAME                  = HEIGHT
    LINES                 = {N}
    LINE_SAMPLES          = {N}
    MAXIMUM               = {maximum}
    MINIMUM               = {minimum}
    SAMPLE_TYPE           = LSB_INTEGER
    SAMPLE_BITS           = 16
    UNIT                  = METER
    SCALING_FACTOR        = 0.5
    OFFSET                = 1737400.

/* HEIGHT = (DN * SCALING_FACTOR); PLANETARY_RADIUS = HEIGHT + OFFSET, where     */
/* OFFSET is the radius of a reference sphere (as in LOLA's polar products).    */

  END_OBJECT              = IMAGE
END_OBJECT                = UNCOMPRESSED_FILE
OBJECT                    = IMAGE_MAP_PROJECTION
 MAP_PROJECTION_TYPE          = "POLAR STEREOGRAPHIC"
 A_AXIS_RADIUS                = 1737.4 <KM>
 B_AXIS_RADIUS                = 1737.4 <KM>
 C_AXIS_RADIUS                = 1737.4 <KM>
 FIRST_STANDARD_PARALLEL      = 'N/A'
 SECOND_STANDARD_PARALLEL     = 'N/A'
 POSITIVE_LONGITUDE_DIRECTION = "EAST"
 CENTER_LATITUDE              = -90. <DEG>
 CENTER_LONGITUDE             = 0. <DEG>
 REFERENCE_LATITUDE           = 'N/A'
 REFERENCE_LONGITUDE          = 'N/A'
 LINE_FIRST_PIXEL             = 1
 LINE_LAST_PIXEL              = {N}
 SAMPLE_FIRST_PIXEL           = 1
 SAMPLE_LAST_PIXEL            = {N}
 MAP_PROJECTION_ROTATION      = 0.0
 MAP_SCALE                    = {scale_m:g} <METERS/PIXEL>
 MAXIMUM_LATITUDE             = {north:.4f} <DEG>
 MINIMUM_LATITUDE             = -90. <DEG>
 WESTERNMOST_LONGITUDE        = -180. <DEG>
 EASTERNMOST_LONGITUDE        = 180. <DEG>
 LINE_PROJECTION_OFFSET       = {offset:g} <PIXEL>
 SAMPLE_PROJECTION_OFFSET     = {offset:g} <PIXEL>
 COORDINATE_SYSTEM_TYPE       = "BODY-FIXED ROTATING"
 COORDINATE_SYSTEM_NAME       = "MEAN EARTH/POLAR AXIS OF DE421"
END_OBJECT                    = IMAGE_MAP_PROJECTION

END
"""


def pixel_lat_lon(rows, cols):
    """Latitude and east longitude (degrees) of pixel centres (0-based line, sample).

    South polar stereographic on a sphere, true scale at the pole: x = (sample -
    SAMPLE_PROJECTION_OFFSET) * scale, y = (LINE_PROJECTION_OFFSET - line) * scale;
    r = 2 R tan((90 + lat) / 2), x = r sin(lon), y = r cos(lon).
    """
    x = (np.asarray(cols, dtype=np.float64) - OFFSET_PX) * SCALE_M
    y = (OFFSET_PX - np.asarray(rows, dtype=np.float64)) * SCALE_M
    lat = np.degrees(2.0 * np.arctan(np.hypot(x, y) / (2.0 * RADIUS_M))) - 90.0
    lon = np.degrees(np.arctan2(x, y)) % 360.0
    return lat, lon


def ldem4_heights(ldem4_dn, lat, lon):
    """LDEM_4 heights (m) at (lat, lon), bilinear between pixel centres."""
    row = (90.0 - lat) * 4.0 - 0.5
    col = lon * 4.0 - 0.5
    dn = map_coordinates(ldem4_dn.astype(np.float64), [row, col], order=1, mode="grid-wrap")
    return dn * 0.5


def main() -> None:
    src = np.fromfile(SRC / "LDEM_4.IMG", dtype="<i2").reshape(720, 1440)
    rows, cols = np.mgrid[0:N, 0:N]
    lat, lon = pixel_lat_lon(rows, cols)
    dn = np.rint(ldem4_heights(src, lat, lon) / 0.5).astype("<i2")
    (OUT / "ldem4_spole.img").write_bytes(dn.tobytes())
    north = float(pixel_lat_lon(-0.5, OFFSET_PX)[0])  # the top edge's midpoint
    label = LABEL.format(N=N, record=2 * N, maximum=int(dn.max()), minimum=int(dn.min()),
                         scale_km=SCALE_M / 1000, scale_m=SCALE_M, north=north,
                         offset=OFFSET_PX)
    (OUT / "ldem4_spole.lbl").write_text(label.replace("\n", "\r\n"), encoding="ascii")
    print(f"wrote {OUT / 'ldem4_spole.img'} and .lbl: {N} x {N}, "  # noqa: T201
          f"{SCALE_M / 1000:g} km pixels, heights {dn.min() * 0.5:g}..{dn.max() * 0.5:g} m")


if __name__ == "__main__":
    main()
