"""Make ``ldem4_crop.img`` + ``ldem4_crop.lbl``: a 257 x 257 crop of LOLA LDEM_4.

Run once from the repository root with ``../shared`` beside it:
``python tests/data/make_lola_crop.py``. The crop is lines 233..489 and samples
593..849 (1-based) of LDEM_4: latitude 32 N to 32.25 S, longitude 148 to 212.25 E,
centred on the equator and the map's central meridian (180 E). The samples are copied
unchanged (int16 DN, metres = DN x 0.5); the label is LDEM_4's with the sizes and the
map projection adjusted for the crop.
"""

from pathlib import Path

import numpy as np

SRC = Path(__file__).resolve().parents[3] / "shared" / "data" / "dems" / "lola_ldem4"
OUT = Path(__file__).resolve().parent
ROW0, COL0, N = 232, 592, 257  # 0-based first line / sample, size
RES = 4  # pixels per degree

LABEL = """PDS_VERSION_ID            = "PDS3"

/* A {N} x {N} crop of LDEM_4 (LRO LOLA GDR, V3.0) made by craterform's  */
/* tests/data/make_lola_crop.py: lines {first_line}..{last_line},              */
/* samples {first_sample}..{last_sample} of LDEM_4.IMG.                            */

DATA_SET_ID               = "LRO-L-LOLA-4-GDR-V1.0"
PRODUCT_ID                = "LDEM_4_CROP"
SOURCE_PRODUCT_ID         = "LDEM_4"
INSTRUMENT_HOST_NAME      = "LUNAR RECONNAISSANCE ORBITER"
INSTRUMENT_NAME           = "LUNAR ORBITER LASER ALTIMETER"
TARGET_NAME               = MOON
PRODUCER_INSTITUTION_NAME = "GODDARD SPACE FLIGHT CENTER"
DESCRIPTION               = "Crop of the LOLA LDEM_4 shape map (radius) of the
   Moon at 7580.84 m/pix, heights relative to a radius of 1737.4 km,
   pixel registered."

OBJECT                    = UNCOMPRESSED_FILE
FILE_NAME                 = "LDEM4_CROP.IMG"
RECORD_TYPE               = FIXED_LENGTH
FILE_RECORDS              = {N}
RECORD_BYTES              = {record}
^IMAGE                    = "LDEM4_CROP.IMG"

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
/* OFFSET is the radius of a reference sphere (as in LDEM_4.LBL).                */

  END_OBJECT              = IMAGE
END_OBJECT                = UNCOMPRESSED_FILE
OBJECT                    = IMAGE_MAP_PROJECTION
 MAP_PROJECTION_TYPE          = "SIMPLE CYLINDRICAL"
 MAP_RESOLUTION               = {RES} <pix/deg>
 A_AXIS_RADIUS                = 1737.4 <km>
 B_AXIS_RADIUS                = 1737.4 <km>
 C_AXIS_RADIUS                = 1737.4 <km>
 POSITIVE_LONGITUDE_DIRECTION = "EAST"
 CENTER_LATITUDE              = 0 <deg>
 CENTER_LONGITUDE             = 180 <deg>
 LINE_FIRST_PIXEL             = 1
 LINE_LAST_PIXEL              = {N}
 SAMPLE_FIRST_PIXEL           = 1
 SAMPLE_LAST_PIXEL            = {N}
 MAP_PROJECTION_ROTATION      = 0.0
 MAP_SCALE                    = 7580.84 <m/pix>
 MAXIMUM_LATITUDE             = {north:g} <deg>
 MINIMUM_LATITUDE             = {south:g} <deg>
 WESTERNMOST_LONGITUDE        = {west:g} <deg>
 EASTERNMOST_LONGITUDE        = {east:g} <deg>
 LINE_PROJECTION_OFFSET       = {lpo:g} <pix>
 SAMPLE_PROJECTION_OFFSET     = {spo:g} <pix>
 COORDINATE_SYSTEM_TYPE       = "BODY-FIXED ROTATING"
 COORDINATE_SYSTEM_NAME       = "MEAN EARTH/POLAR AXIS OF DE421"
END_OBJECT                    = IMAGE_MAP_PROJECTION

END
"""


def main() -> None:
    src = np.fromfile(SRC / "LDEM_4.IMG", dtype="<i2").reshape(720, 1440)
    crop = np.ascontiguousarray(src[ROW0:ROW0 + N, COL0:COL0 + N])
    (OUT / "ldem4_crop.img").write_bytes(crop.astype("<i2").tobytes())

    north = 90 - ROW0 / RES
    south = 90 - (ROW0 + N) / RES
    west = COL0 / RES
    east = (COL0 + N) / RES
    label = LABEL.format(N=N, RES=RES, first_line=ROW0 + 1, last_line=ROW0 + N,
                         first_sample=COL0 + 1, last_sample=COL0 + N, maximum=int(crop.max()),
                         minimum=int(crop.min()), record=2 * N, lpo=359.5 - ROW0,
                         spo=719.5 - COL0, north=north, south=south, west=west, east=east)
    (OUT / "ldem4_crop.lbl").write_text(label.replace("\n", "\r\n"), encoding="ascii")
    msg = f"wrote {OUT / 'ldem4_crop.img'} and .lbl: {N} x {N}, lat {north:g}..{south:g}, "
    print(msg + f"lon {west:g}..{east:g}")  # noqa: T201


if __name__ == "__main__":
    main()
