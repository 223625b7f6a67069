"""The 0.5 m descent frame against real LROC NAC pictures with their craters marked by hand
(issue 37's look item, issue 36's landing-scale look): how many craters a person would
recognise, and how bright crater interiors are.

Real data (not shipped: GPL-3): the test crops of the CraterDANet crater set (Yang, Xu,
Ma, Xu & Liu, "CraterDANet: a convolutional neural network for small-scale crater
detection via synthetic-to-real domain adaptation", IEEE TGRS; github.com/yizuifangxiuyh/
Lunar_Crater_Detection_Data, ``LRO_DATA/test``): 1000 x 1000 pixel crops of calibrated NAC
frames at 0.5 m a pixel near the Chang'e-4 site (45-46 deg S, Von Karman's mare floor),
each ``NAME.png`` with ``NAME.txt`` listing the craters of 8 pixels and more marked on it
(box x, y, width, height, centre). The sun's elevation of each frame is not in the set.

Measured per picture, on the marked craters of >= 8 pixels (4 m):

* **density**: craters >= 4, 8, 16 m per m^2 over the equilibrium density the benchmark
  scene uses, N_cum = 0.08 D^-2 (``measure_ondemand``'s saturated layers; Gault 1970);
* **contrast**: (95th - 5th percentile) / median of the picture in the crater's box;
* **bright interiors**: the share of craters whose box is on average > 1.1 x the local
  median (61 pixels).

Ours: ``measure_ondemand``'s lunar mare scene, a 1000^2 frame 0.5 m a pixel at (0.01,
0.01) deg (``latlong.ondemand.descent``, its default albedo and relief) at each sun
elevation; the catalogue's craters >= 8 pixels in the frame, their box contrast, and
how many reach the NAC marked craters' pooled 10th-percentile contrast (what a person
recognised there) per m^2 over 0.08 D^-2; bright interiors as above. Usage:

    python tests/benchmarks/measure_nac_craters.py --nac-dir DIR [--sun-elevation-deg 15,20,30]
"""

from __future__ import annotations

import argparse
import re
import sys
from pathlib import Path

import numpy as np
from PIL import Image

sys.path.insert(0, str(Path(__file__).resolve().parent))

PIXEL_M = 0.5
SIZE_PX = 1000
EQ_C = 0.08  # N_cum = EQ_C D^-2 per m^2 (measure_ondemand's saturated layers)
MIN_PX = 8.0
BOUNDS_M = (4, 8, 16)


def box(img: np.ndarray, cx: float, cy: float, d: float) -> np.ndarray | None:
    """The picture inside a crater's D x D box (None where it leaves the picture)."""
    h = max(1, int(round(d / 2)))
    x0, y0 = int(cx) - h, int(cy) - h
    if x0 < 0 or y0 < 0 or x0 + 2 * h + 1 > img.shape[1] or y0 + 2 * h + 1 > img.shape[0]:
        return None
    return img[y0:y0 + 2 * h + 1, x0:x0 + 2 * h + 1]


def crater_stats(img: np.ndarray, cx, cy, d_px) -> tuple[np.ndarray, np.ndarray]:
    """(contrast, interior mean / local median) of each crater (NaN off the picture)."""
    con = np.full(len(cx), np.nan)
    bright = np.full(len(cx), np.nan)
    for i in range(len(cx)):
        p = box(img, cx[i], cy[i], d_px[i])
        if p is None:
            continue
        p5, p50, p95 = np.percentile(p, [5, 50, 95])
        con[i] = (p95 - p5) / max(p50, 1e-12)
        y, x = int(cy[i]), int(cx[i])
        local = np.median(img[max(y - 30, 0):y + 31, max(x - 30, 0):x + 31])
        bright[i] = p.mean() / max(local, 1e-12)
    return con, bright


def density_row(d_m: np.ndarray) -> str:
    area = (SIZE_PX * PIXEL_M) ** 2
    return "  ".join(f">={b} m {np.sum(d_m >= b) / area / (EQ_C * b ** -2.0):.2f}"
                     for b in BOUNDS_M)


def summary(d_m: np.ndarray, con: np.ndarray, bright: np.ndarray) -> str:
    return (f"density/eq {density_row(d_m)}  contrast p10/p50 {np.percentile(con, 10):.2f}/"
            f"{np.median(con):.2f}  bright > 1.1: {np.mean(bright > 1.1):.2f}")


def nac(folder: Path) -> float:
    """Print each NAC picture's figures; returns the marked craters' pooled p10 contrast."""
    pooled = []
    for png in sorted(folder.glob("*.png")):
        txt = png.with_suffix(".txt")
        if not txt.exists():
            continue
        img = np.asarray(Image.open(png).convert("L"), dtype=np.float64)[:SIZE_PX, :SIZE_PX]
        rows = [re.split(r"[,\s]+", line.strip()) for line in txt.read_text().splitlines()[1:]
                if line.strip()]
        a = np.array(rows, dtype=np.float64)
        d_px = 0.5 * (a[:, 3] + a[:, 4])
        keep = d_px >= MIN_PX
        con, bright = crater_stats(img, a[keep, 5], a[keep, 6], d_px[keep])
        ok = np.isfinite(con)
        pooled.append(con[ok])
        print(f"NAC {png.stem[:14]:14s} marked {ok.sum():4d}  "
              f"{summary(d_px[keep][ok] * PIXEL_M, con[ok], bright[ok])}")
    if not pooled:
        raise SystemExit(f"error: --nac-dir {str(folder)!r} holds no NAME.png with NAME.txt")
    return float(np.percentile(np.concatenate(pooled), 10))


def ours(sun_elevation_deg: float, threshold: float) -> None:
    import measure_ondemand as mo

    from latlong.ondemand.descent import descent

    site = (0.01, 0.01)
    alt = 0.5 * SIZE_PX * PIXEL_M / np.tan(np.radians(15.0))  # a 30 deg field of view
    (f,) = list(descent(mo.scene(), *site, [alt], width_px=SIZE_PX, fov_deg=30.0,
                        sun_azimuth_deg=270.0, sun_elevation_deg=sun_elevation_deg))
    cat = f.craters
    centres = np.stack([cat["centre_x_m"], cat["centre_y_m"], cat["centre_z_m"]], 1)
    col, row = f.frame.camera.project(centres, f.frame.pose)[0].T  # pixel coordinates
    px = f.ground_pixel_m
    d_px = cat["diameter_m"] / px
    sel = (d_px >= MIN_PX) & (col >= 0) & (col < SIZE_PX) & (row >= 0) & (row < SIZE_PX)
    con, bright = crater_stats(f.frame.reflectance.astype(np.float64), col[sel], row[sel],
                               d_px[sel])
    ok = np.isfinite(con)
    d_m = cat["diameter_m"][sel][ok]
    print(f"ours sun {sun_elevation_deg:4g} deg: craters {ok.sum():4d}  "
          f"{summary(d_m, con[ok], bright[ok])}\n    recognisable (contrast >= "
          f"{threshold:.2f}): density/eq {density_row(d_m[con[ok] >= threshold])}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--nac-dir", type=Path, required=True,
                    help="folder of CraterDANet test crops: NAME.png beside NAME.txt")
    ap.add_argument("--sun-elevation-deg", default="15,20,30",
                    help="our frame's sun elevations, comma-separated (default 15,20,30)")
    args = ap.parse_args()
    threshold = nac(args.nac_dir)
    print(f"pooled 10th percentile of the marked craters' contrast: {threshold:.3f}")
    for elev in (float(x) for x in args.sun_elevation_deg.split(",")):
        ours(elev, threshold)


if __name__ == "__main__":
    main()
