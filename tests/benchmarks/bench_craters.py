"""Benchmark: stamping a crater catalog into a large grid (plain script).

10 000 craters with N_cum ~ D^-2 between 8 and 200 m on a 4097 x 4097 grid of 1 m
pixels, roughness on. Reports, for one numba thread (the serial kernel) and for all of
them (parallel waves), the best of ``--repeat`` runs as craters/s and pixel-updates/s
(pixels within the ejecta edge, 3 R of round rims, of the craters stamped, clipped
to the grid), their ratio and whether the heights are the same bytes (sha256); and, as a
reference in the same run, a plain-numpy stamp of the same craters over their bounding
boxes (profile + plane, no roughness; each profile an exact diffusion solve) on a
subset. Usage: ``python tests/benchmarks/bench_craters.py [--quick] [--repeat N]``
(``NUMBA_NUM_THREADS`` sets "all").
"""

from __future__ import annotations

import argparse
import hashlib
import os
import time

import numba
import numpy as np

import craters


def numpy_reference(h, pixel, cat):
    """Per-crater numpy stamp (plane fit by lstsq, profile, no rim offsets/roughness)."""
    h = h.copy()
    ny, nx = h.shape
    for row in craters.sort_oldest_first(cat):
        cx, cy, d = row["x_m"] / pixel, row["y_m"] / pixel, row["diameter_m"]
        reach = 1.5 * d / pixel + 1
        i0, i1 = max(0, int(cy - reach)), min(ny, int(cy + reach) + 2)
        j0, j1 = max(0, int(cx - reach)), min(nx, int(cx + reach) + 2)
        yy, xx = np.mgrid[i0:i1, j0:j1]
        dx, dy = (xx - cx) * pixel, (yy - cy) * pixel
        r = np.hypot(dx, dy)
        x = r / (d / 2)
        box = h[i0:i1, j0:j1]
        inside = x <= 1
        if inside.sum() >= 3:
            a = np.stack([np.ones(inside.sum()), dx[inside], dy[inside]], 1)
            p = np.linalg.lstsq(a, box[inside], rcond=None)[0]
        else:
            p = np.array([box.mean(), 0.0, 0.0])
        deg = None if np.isnan(row["degradation"]) else row["degradation"]
        prof = craters.radial_profile(x, d, age_gyr=None if deg is not None else row["age_gyr"],
                                      degradation=deg)
        plane = p[0] + p[1] * dx + p[2] * dy
        out = np.where(inside, plane + prof, box + prof)
        h[i0:i1, j0:j1] = np.where(x < 3, out, box)
    return h


def pixel_updates(shape, pixel, stamped, ejecta_edge=craters.DEFAULT_EJECTA_EDGE):
    """Pixels within ``ejecta_edge`` radii (round rims) of the stamped craters, clipped."""
    ny, nx = shape
    total = 0
    for row in stamped:
        cx, cy = row["x_m"] / pixel, row["y_m"] / pixel
        reach = ejecta_edge * 0.5 * row["diameter_m"] / pixel
        i = np.arange(max(0, int(np.ceil(cy - reach))), min(ny - 1, int(np.floor(cy + reach))) + 1)
        j = np.arange(max(0, int(np.ceil(cx - reach))), min(nx - 1, int(np.floor(cx + reach))) + 1)
        total += int(((i[:, None] - cy) ** 2 + (j[None, :] - cx) ** 2 < reach**2).sum())
    return total


def timed_stamp(h0, cat, threads, repeat):
    """Best wall time (s) of ``repeat`` stamps on ``threads`` numba threads, the heights'
    sha256 and the stamped catalog."""
    numba.set_num_threads(threads)
    best = np.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        h, stamped = craters.stamp_many(h0, 1.0, cat, rng=2, return_catalog=True)
        best = min(best, time.perf_counter() - t0)
    return best, hashlib.sha256(h.tobytes()).hexdigest(), stamped


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--repeat", type=int, default=3, help="runs per thread count (best)")
    args = parser.parse_args()
    n_px = 1025 if args.quick else 4097
    side = float(n_px - 1)
    area = side * side
    # choose c so that about 10 000 craters fall in [8, 200] m
    target = 2500 if args.quick else 10_000
    c = target / (area * (8.0**-2 - 200.0**-2))
    cat = craters.power_law_population(c=c, k=-2.0, d_min=8.0, d_max=200.0,
                                       x_range=(0, side), y_range=(0, side), rng=1)
    h0 = np.zeros((n_px, n_px))
    n_all = numba.config.NUMBA_NUM_THREADS
    for threads in sorted({1, n_all}):  # compile the serial and the wave kernels
        numba.set_num_threads(threads)
        craters.stamp_many(h0[:256, :256], 1.0, cat[cat["diameter_m"] < 20][:200], rng=0)
    label = f"{len(cat)} craters (D 8-200 m, N_cum ~ D^-2) on {n_px}^2 at 1 m, roughness on"
    print(f"stamp_many: {label}; best of {args.repeat}, {os.cpu_count()} cores")
    runs = {}
    for threads in sorted({1, n_all}):
        t, digest, stamped = timed_stamp(h0, cat, threads, args.repeat)
        px = pixel_updates(h0.shape, 1.0, stamped)
        runs[threads] = (t, digest)
        print(f"  {threads} thread{'s' if threads > 1 else ''}: {t:.2f} s = {len(cat) / t:.0f} "
              f"craters/s, {px / t / 1e6:.2f} M pixel-updates/s ({px / 1e6:.1f} M pixels)")
    t1, d1 = runs[1]
    tn, dn = runs[n_all]
    print(f"  {n_all} threads / 1: x{t1 / tn:.2f}; heights identical (sha256): {d1 == dn} "
          f"({d1[:16]})")
    sub = cat[:: max(1, len(cat) // 500)]
    t0 = time.perf_counter()
    numpy_reference(h0, 1.0, sub)
    t_ref = time.perf_counter() - t0
    t0 = time.perf_counter()
    craters.stamp_many(h0, 1.0, sub, roughness=False, rng=2)
    t_fast = time.perf_counter() - t0
    print(f"same {len(sub)}-crater subset, no roughness: numba ({n_all} threads) {t_fast:.3f} s, "
          f"plain numpy "
          f"{t_ref:.3f} s (x{t_ref / t_fast:.1f})")


if __name__ == "__main__":
    main()
