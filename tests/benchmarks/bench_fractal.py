"""The two fractal-dimension estimators side by side (plain script, not a test).

``dem.fractal_fit`` (locally normalised variogram, lags 2-8 px) and ``dem.spectral_fit``
(power-spectrum slope, F = (8 - beta) / 2) over its default band (4 px to a quarter of
the longest wavelength) and over the band that matches the variogram's lags (4-16 px),
on the same DEMs: fBm surfaces of known F made by spectral synthesis here (amplitude
f^(-beta/2), random phases; independent of the project's RMD code), the LOLA crop in
tests/data, and RMD output (``dem.expand`` of a white-noise seed at a given F, and of the
LOLA crop with its defaults). The column ``v1-4`` is the first estimator (normaliser
m(p) itself, lags 1-4) for the record. Usage:
``python tests/benchmarks/bench_fractal.py [--quick]``.
"""

from __future__ import annotations

import argparse
import math
import os
import platform
import sys
from pathlib import Path

import numpy as np

import dem
from dem.fractal import local_msd

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "tests"))
from conftest import spectral_fbm  # noqa: E402  (the tests' spectral synthesis)

CROP = ROOT / "tests" / "data" / "ldem4_crop.lbl"


def fbm_surface(n, fractal_dimension, rng):
    """Spectral synthesis of beta = 8 - 2F (tests/conftest.py's, independent of RMD)."""
    return spectral_fbm(n, 8.0 - 2.0 * fractal_dimension, rng)


def first_estimator(d):
    """The estimator before issue 21: normaliser m(p) itself, lags 1-4."""
    z = d.heights
    m = local_msd(z)
    lags, g = [], []
    for k in range(1, 5):
        for a, b, ma, mb in ((z[:, k:], z[:, :-k], m[:, k:], m[:, :-k]),
                             (z[k:], z[:-k], m[k:], m[:-k])):
            n = 0.5 * (ma + mb)
            ok = np.isfinite(a - b) & (n > 0)
            lags.append(k)
            g.append(np.mean((a - b)[ok] ** 2 / n[ok]))
    return 3.0 - np.polyfit(np.log(lags), np.log(g), 1)[0] / 2.0


def row(label, d, truth=None):
    v = dem.fractal_fit(d)
    s = dem.spectral_fit(d)
    m = dem.spectral_fit(d, 4.0, 16.0)
    vals = [first_estimator(d), v.fractal_dimension, s.fractal_dimension, m.fractal_dimension]
    return label, truth, vals, [v.warning, s.warning, m.warning]


def fmt(label, truth, vals, warn, spread=None):
    t = f"{truth:5.2f}" if truth is not None else "    -"
    cells = []
    for k, v in enumerate(vals):
        c = f"{v:5.3f}"
        if spread is not None:
            c += f"±{spread[k]:.3f}"
        cells.append(f"{c:>12}")
    diff = abs(vals[1] - vals[3])
    flags = " ".join("!" if w else "." for w in warn)
    return (f"{label:<34} {t} " + " ".join(cells) + f" {abs(vals[1] - vals[2]):8.3f}"
            f" {diff:8.3f}  {flags}")


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--quick", action="store_true", help="fewer and smaller surfaces")
    args = parser.parse_args()
    n, reps = (257, 2) if args.quick else (513, 6)
    print(f"machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cores")
    print(f"{'DEM':<34} {'F':>5} {'v1-4 (old)':>12} {'variogram':>12} {'spec dflt':>12} "
          f"{'spec 4-16':>12} {'|v-sd|':>8} {'|v-s16|':>8}  out-of-[2,3] v/sd/s16")
    rng = np.random.default_rng(2021)
    for f in (2.1, 2.2, 2.3, 2.4, 2.5, 2.6, 2.7, 2.8):
        runs = [row("", dem.Dem(fbm_surface(n, f, rng) * 100.0, pixel_size_m=10.0), f)
                for _ in range(reps)]
        vals = np.array([r[2] for r in runs])
        warn = [any(r[3][k] for r in runs) for k in range(3)]
        print(fmt(f"fBm {n}^2 spectral synthesis x{reps}", f, list(vals.mean(0)), warn,
                  list(vals.std(0))))
    lola = dem.read(CROP)
    print(fmt(*row("LOLA LDEM_4 crop 257^2 (7.6 km/px)", lola)))
    s = dem.spectral_fit(lola, 16.0, 64.0)
    print(f"{'  LOLA spectrum 16-64 px only':<34}     -       F = {s.fractal_dimension:.3f}: "
          f"{s.warning or 'a surface dimension'}")
    levels = 4 if args.quick else 5
    for f in (2.2, 2.5, 2.8):
        seed = dem.Dem(np.random.default_rng(3).normal(0, 100, (17, 17)), pixel_size_m=128.0)
        e = dem.expand(seed, levels, fractal_dimension=f, roughness=1.0, rng=5)
        print(fmt(*row(f"RMD 17^2 seed x{2**levels} ({e.shape[0]}^2)", e, f)))
    e = dem.expand(lola, 1 if args.quick else 2, rng=4)
    print(fmt(*row(f"RMD LOLA crop x{2 ** (1 if args.quick else 2)} (defaults)", e,
                   e.history[-1]["parameters"]["fractal_dimension"])))
    print("F = the synthesis' (fBm) or the expansion's F; v1-4 the old estimator; "
          "! = some estimate outside [2, 3]")
    assert math.isfinite(s.fractal_dimension)


if __name__ == "__main__":
    main()
