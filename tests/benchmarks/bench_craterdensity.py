"""The crater detector, crater densities and craters in filled gaps (plain script).

1. Recall of ``dem.detect_craters`` by diameter on craters stamped by
   ``craters.stamp_many`` into fBm scenes (tests/dem/test_craterdensity.py's), for two
   ranges of degradation, and its false craters on the fBm alone.
2. The LOLA crop: craters found, their density (``dem.crater_density``) and the
   diameter below which it resolves no craters (``dem.resolved_diameter_m``).
3. ``dem.fill_gaps`` of a 160-px disc cut from the LOLA crop: craters stamped in it and
   the density the detector then finds inside against around (``out/bench_gap_craters.png``).

Usage: ``python tests/benchmarks/bench_craterdensity.py [--quick]``.
"""

from __future__ import annotations

import argparse
import os
import platform
import sys
import time
from pathlib import Path

import numpy as np

import dem

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "tests"))
sys.path.insert(0, str(ROOT / "tests" / "dem"))
from conftest import spectral_fbm  # noqa: E402
from test_craterdensity import cratered_scene, disc, matches  # noqa: E402

CROP = ROOT / "tests" / "data" / "ldem4_crop.lbl"


def fbm(n, f, rng):
    return spectral_fbm(n, 8.0 - 2.0 * f, rng)


def recall(scenes: int) -> None:
    bins = (3, 4, 5, 6, 8, 12, 24, 61)
    for degradation in ((0.0, 0.6), (0.6, 0.9)):
        rows, false, alone = [], 0, []
        for seed in range(scenes):
            d, truth, terrain = cratered_scene(seed, fbm, degradation=degradation)
            found = dem.detect_craters(d, min_diameter_px=3.0)
            hit = matches(found, truth, 100.0)
            rows += list(zip(truth["diameter_m"] / 100.0, hit, strict=True))
            false += len(found) - sum(matches(truth, found[i:i + 1], 100.0)[0]
                                      for i in range(len(found)))
            alone.append(len(dem.detect_craters(terrain)))
        rows = np.array(rows)
        parts = []
        for lo, hi in zip(bins[:-1], bins[1:], strict=True):
            sel = (rows[:, 0] >= lo) & (rows[:, 0] < hi)
            parts.append(f"{lo}-{hi} px {rows[sel, 1].mean():.2f} ({sel.sum()})")
        print(f"detector recall, degradation {degradation[0]}-{degradation[1]}: "
              + ", ".join(parts))
        print(f"  detections matching no stamped crater: {false / scenes:.1f} per 384^2 "
              f"scene; on the fBm alone (4 px and up): {alone}")


def lola() -> None:
    crop = dem.read(CROP)
    t = time.perf_counter()
    found = dem.detect_craters(crop)
    elapsed = time.perf_counter() - t
    dens = dem.crater_density(crop)
    fitted = dem.crater_density(crop, exponent=None)
    print(f"LOLA crop: {len(found)} craters of 4-64 px ({elapsed:.2f} s); density from "
          f"{dens.d_lo_m / 1e3:.0f} km: N(>D) = {dens.c:.3g} D^{dens.k:g} (D in m, per m^2; "
          f"{dens.count} craters, N(>{dens.d_lo_m / 1e3:.0f} km) = "
          f"{dens.count / dens.area_m2 * 1e6:.3g} per km^2); fitted exponent {fitted.k:.2f}; "
          f"resolves craters from {dem.resolved_diameter_m(crop) / 1e3:.1f} km (4 px)")


def gap(quick: bool) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.colors import LightSource

    crop = dem.read(CROP)
    hole = disc(crop.shape, 80)
    gappy = crop.replace(heights=np.where(hole, np.nan, crop.heights))
    inner, ring = disc(crop.shape, 72), disc(crop.shape, 128) & ~disc(crop.shape, 88)
    ratios = []
    for seed in (1,) if quick else (1, 2, 3, 4):
        t = time.perf_counter()
        filled, cat = dem.fill_gaps(gappy, rng=seed, return_catalog=True)
        elapsed = time.perf_counter() - t
        note = filled.history[-1]["parameters"]["crater_density"][0]
        found = dem.detect_craters(filled)
        big = found["diameter_m"] >= 6 * crop.resolution_m
        r, c = found["row"].astype(int), found["col"].astype(int)
        d_in = (inner[r, c] & big).sum() / inner.sum()
        d_out = (ring[r, c] & big).sum() / ring.sum()
        ratios.append(d_in / d_out)
        print(f"fill of a 160-px disc in the LOLA crop, seed {seed}: {len(cat)} craters "
              f"stamped ({elapsed:.2f} s), density used c = {note['c']:.3g}, k = {note['k']} "
              f"from {note['craters_found']} craters around; detected 6 px and up inside "
              f"{1e4 * d_in:.2f} / around {1e4 * d_out:.2f} per 10^4 px (ratio "
              f"{d_in / d_out:.2f})")
        if seed == 1:
            light = LightSource(azdeg=315, altdeg=40)
            fig, axes = plt.subplots(1, 2, figsize=(12, 6))
            ex = 3.0 / np.std(np.diff(crop.heights, axis=1))
            for ax, (title, z) in zip(axes, (("LOLA crop", crop.heights),
                                             ("160-px disc filled, craters stamped",
                                              filled.heights)), strict=True):
                ax.imshow(light.hillshade(z, vert_exag=ex), cmap="gray")
                ax.set_title(title)
            for row in found:
                axes[1].add_patch(plt.Circle((row["col"], row["row"]),
                                             row["diameter_m"] / 2 / crop.resolution_m,
                                             fill=False, color="red", lw=0.6))
            axes[1].contour(hole, levels=[0.5], colors="yellow", linewidths=0.8)
            fig.tight_layout()
            path = ROOT / "out" / "bench_gap_craters.png"
            path.parent.mkdir(exist_ok=True)
            fig.savefig(path, dpi=80)
            print(f"wrote {path}")
    print(f"inside/around density ratio: {np.round(ratios, 2).tolist()}")


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--quick", action="store_true", help="fewer scenes")
    args = parser.parse_args()
    print(f"machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cores")
    recall(2 if args.quick else 5)
    lola()
    gap(args.quick)


if __name__ == "__main__":
    main()
