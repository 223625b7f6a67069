"""Tiny SPICE kernels written by the tests (no downloads): a leapseconds kernel, the
Moon's IAU rotation and the Earth's radii, a spacecraft clock and frame, an SPK of the
spacecraft, the sun and the Earth (type 8, relative to the Moon) and a CK of the camera
(type 3), plus a meta-kernel."""

from __future__ import annotations

from pathlib import Path

import numpy as np

SC = -9999
CAM_ID = -9999000
CAM_FRAME = "SC_CAM"

# leap seconds: the entries since 2012 are enough for times after 2017 (the values are
# NAIF's naif0012.tls; a test kernel need not carry the whole table)
LSK = r"""KPL/LSK
\begindata
DELTET/DELTA_T_A = 32.184
DELTET/K = 1.657D-3
DELTET/EB = 1.671D-2
DELTET/M = ( 6.239996D0 1.99096871D-7 )
DELTET/DELTA_AT = ( 35, @2012-JUL-1
                    36, @2015-JUL-1
                    37, @2017-JAN-1 )
\begintext
"""

# the Moon's IAU rotation (pole and prime meridian polynomials, no nutation terms)
PCK = r"""KPL/PCK
\begindata
BODY301_POLE_RA = ( 269.9949 0.0031 0. )
BODY301_POLE_DEC = ( 66.5392 0.0130 0. )
BODY301_PM = ( 38.3213 13.17635815 -1.4D-12 )
BODY301_RADII = ( 1737.4 1737.4 1737.4 )
BODY399_RADII = ( 6378.1366 6378.1366 6356.7519 )
\begintext
"""

SCLK = r"""KPL/SCLK
\begindata
SCLK_KERNEL_ID = ( @2000-01-01/00:00 )
SCLK_DATA_TYPE_9999 = ( 1 )
SCLK01_TIME_SYSTEM_9999 = ( 1 )
SCLK01_N_FIELDS_9999 = ( 2 )
SCLK01_MODULI_9999 = ( 4294967296 65536 )
SCLK01_OFFSETS_9999 = ( 0 0 )
SCLK01_OUTPUT_DELIM_9999 = ( 1 )
SCLK_PARTITION_START_9999 = ( 0.0 )
SCLK_PARTITION_END_9999 = ( 2.81474976710655D14 )
SCLK01_COEFFICIENTS_9999 = ( 0.0 0.0 1.0 )
\begintext
"""

FK = r"""KPL/FK
\begindata
FRAME_SC_CAM = -9999000
FRAME_-9999000_NAME = 'SC_CAM'
FRAME_-9999000_CLASS = 3
FRAME_-9999000_CLASS_ID = -9999000
FRAME_-9999000_CENTER = -9999
CK_-9999000_SCLK = -9999
CK_-9999000_SPK = -9999
NAIF_BODY_NAME += ( 'TESTCRAFT' )
NAIF_BODY_CODE += ( -9999 )
\begintext
"""

# two instruments: the camera with focal length and pixel pitch (100 px), and a second
# whose focal length comes from its field of view (a 10 x 7.5 degree half-angle box) and
# whose boresight is off the image's centre (CCD_CENTER)
IK = r"""KPL/IK
\begindata
INS-9999000_PIXEL_SAMPLES = ( 64 )
INS-9999000_PIXEL_LINES = ( 48 )
INS-9999000_FOCAL_LENGTH = ( 50.0 )
INS-9999000_PIXEL_PITCH = ( 0.5 )
INS-9999001_PIXEL_SAMPLES = ( 80 )
INS-9999001_PIXEL_LINES = ( 60 )
INS-9999001_CCD_CENTER = ( 41.25 29.5 )
INS-9999001_FOV_SHAPE = 'RECTANGLE'
INS-9999001_FOV_FRAME = 'SC_CAM'
INS-9999001_BORESIGHT = ( 0.0 0.0 1.0 )
INS-9999001_FOV_CLASS_SPEC = 'ANGLES'
INS-9999001_FOV_REF_VECTOR = ( 1.0 0.0 0.0 )
INS-9999001_FOV_REF_ANGLE = ( 10.0 )
INS-9999001_FOV_CROSS_ANGLE = ( 7.5 )
INS-9999001_FOV_ANGLE_UNITS = 'DEGREES'
NAIF_BODY_NAME += ( 'TESTCAM' 'TESTCAM_WIDE' )
NAIF_BODY_CODE += ( -9999000 -9999001 )
\begintext
"""

START_UTC = "2025-03-01T12:00:00"


def nadir_c_matrix(p: np.ndarray) -> np.ndarray:
    """The C-matrix (J2000 -> camera) of a camera at ``p`` (km from the Moon, J2000)
    looking at the Moon's centre: rows are the camera's x, y, z axes in J2000."""
    z = -p / np.linalg.norm(p)
    x = np.cross([0.0, 0.0, 1.0], z)
    x /= np.linalg.norm(x)
    return np.array([x, np.cross(z, x), z])


def write_kernels(folder: Path, *, duration_s: float = 600.0) -> Path:
    """Write the kernels into ``folder``; the meta-kernel's path."""
    import spiceypy as sp

    folder.mkdir(parents=True, exist_ok=True)
    texts = {"test.tls": LSK, "moon.tpc": PCK, "craft.tsc": SCLK, "craft.tf": FK,
             "craft.ti": IK}
    for name, text in texts.items():
        (folder / name).write_text(text)
    sp.kclear()
    try:
        for name in texts:
            sp.furnsh(str(folder / name))
        t0 = sp.str2et(START_UTC) - 60.0
        n, step = int(duration_s / 10.0) + 20, 10.0
        t = t0 + step * np.arange(n)
        # a circular-ish orbit 100 km above the Moon, and the sun far along +x
        w = 1.6 / 1837.4  # rad/s
        p = 1837.4 * np.column_stack([np.cos(w * (t - t0)), np.sin(w * (t - t0)),
                                      0.1 * np.ones(n)])
        v = np.gradient(p, step, axis=0)
        sun = np.column_stack([1.47e8 - 30.0 * (t - t0), 2.0e7 + 0.5 * (t - t0),
                               8.0e6 * np.ones(n)])
        spk = folder / "craft.bsp"
        handle = sp.spkopn(str(spk), "test", 0)
        sp.spkw08(handle, SC, 301, "J2000", t[0], t[-1], "craft", 3, n,
                  np.hstack([p, v]), t[0], step)
        sp.spkw08(handle, 10, 301, "J2000", t[0], t[-1], "sun", 3, n,
                  np.hstack([sun, np.gradient(sun, step, axis=0)]), t[0], step)
        # the Earth 384 400 km away, moving slowly
        earth = np.column_stack([-3.0e5 + 1.0 * (t - t0), 2.4e5 * np.ones(n),
                                 1.0e4 * np.ones(n)])
        sp.spkw08(handle, 399, 301, "J2000", t[0], t[-1], "earth", 3, n,
                  np.hstack([earth, np.gradient(earth, step, axis=0)]), t[0], step)
        sp.spkcls(handle)
        ticks = np.array([sp.sce2c(SC, float(x)) for x in t])
        quats = np.array([sp.m2q(nadir_c_matrix(x)) for x in p])
        ck = folder / "craft.bc"
        handle = sp.ckopn(str(ck), "test", 0)
        sp.ckw03(handle, ticks[0], ticks[-1], CAM_ID, "J2000", False, "cam", n, ticks,
                 quats, np.zeros((n, 3)), 1, ticks[:1])
        sp.ckcls(handle)
    finally:
        sp.kclear()
    tm = folder / "test.tm"
    names = list(texts) + ["craft.bsp", "craft.bc"]
    tm.write_text("KPL/MK\n\\begindata\nKERNELS_TO_LOAD = (\n"
                  + "\n".join(f"  '{folder / n}'" for n in names) + " )\n\\begintext\n")
    return tm
