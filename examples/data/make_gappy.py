"""Make ``ldem4_gappy.tif``: the LOLA LDEM_4 crop of ``tests/data`` with NoData holes
where the truth is known, the input of the README's ``dem fill`` and of the gap-filling
Python in ``dem``'s docstring.

Three holes, like those of real DEMs: the floor of the crater Daedalus (93 km, 5.9 S
179.4 E; a disc of 0.35 of its diameter, as a shadowed floor would be), a missing
ground track (a band 5 pixels wide, rows 20-119), and an irregular blob (union of
discs). The known pixels are the crop's heights unchanged (metres, float32).

Run from the repository root: ``python examples/data/make_gappy.py``.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

import dem

ROOT = Path(__file__).resolve().parents[2]
SOURCE = ROOT / "tests" / "data" / "ldem4_crop.lbl"
OUT = Path(__file__).resolve().parent / "ldem4_gappy.tif"

#: Daedalus crater (IAU Gazetteer of Planetary Nomenclature): centre and diameter
DAEDALUS_LON_DEG, DAEDALUS_LAT_DEG, DAEDALUS_D_M = 179.4, -5.9, 93_000.0


def main() -> None:
    d = dem.read(SOURCE)
    frame = dem.local_frame(d)
    rows, cols = np.indices(d.shape)
    xs, ys = d.xy(rows, cols)
    x_m, y_m = frame.to_local(xs, ys)
    cx, cy = frame.to_local(DAEDALUS_LON_DEG, DAEDALUS_LAT_DEG)
    hole = np.hypot(x_m - cx, y_m - cy) < 0.35 * DAEDALUS_D_M          # the crater floor
    hole |= (cols >= 200) & (cols < 205) & (rows >= 20) & (rows < 120)  # a missing track
    for r, c, radius_px in ((60, 60, 6), (66, 68, 5), (58, 70, 4)):     # an irregular blob
        hole |= np.hypot(rows - r, cols - c) < radius_px
    heights = d.heights.copy()
    heights[hole] = np.nan
    dem.write(d.replace(heights=heights), OUT)
    print(f"wrote {OUT.name}: {int(hole.sum())} unknown pixels of {hole.size}")


if __name__ == "__main__":
    main()
