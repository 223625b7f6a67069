"""Benchmark: stamping 50 000 craters on a magnitude-1000 body (plain script).

R = 10 km body (6 M vertices), N_cum ~ D^-2 between 20 m and 2 km, roughness on, each
crater diffused for its age on a small body of that size (craters.small_body).
``--moon``: issue 20's other benchmark, M = 330 (653 k vertices), the Moon (R = 1737.4
km, flat sphere), 2000 craters of 25-250 km.
Reports, in one run: craters/s and vertex-updates/s of ``stamp_craters`` on one thread
(the serial kernel) and on all threads (parallel waves, same bytes: checked), best of
``--repeat``, and their ratio; the share of time per stage (population, profile tables,
gather + local coordinates, local grid + plane fit, crater evaluation + write-back) and
craters/s of a naive stamp that scans every vertex per crater.
Usage: ``python tests/benchmarks/bench_body_craters.py [--quick | --moon] [--repeat R]``
(quick: M = 300, R = 3 km, D 20-600 m).
"""

from __future__ import annotations

import argparse
import time

import numba
import numpy as np

import craters
from latlong import Body, LatLongGrid
from latlong._crater_kernels import _stamp_body_kernel
from latlong.cratering import stamp_craters


def run_kernel(body, cat, prof, rng, **switches):
    """Call the kernel directly (same arguments as stamp_craters) with benchmark switches;
    ``prof`` = :func:`craters.stamping_profiles` of ``cat``."""
    unit = body.grid.unit_vectors() if switches.get("naive") else np.empty((0, 3))
    n = len(cat)
    rim = craters.rim_perturbations(n, 0.02, rng=rng)
    seeds = rng.integers(0, 2**63, size=n, dtype=np.uint64)
    radii = np.array(body.radii_m)
    outs = [np.zeros(n), np.zeros(n), np.zeros((n, 3)), np.zeros(n), np.zeros(n), np.zeros(n),
            np.zeros(n, dtype=np.bool_)]
    g = body.grid
    t0 = time.perf_counter()
    _stamp_body_kernel(g.magnitude, g.ring_offsets(), unit, radii,
                       np.asarray(body.stretch), cat["lat_deg"].copy(), cat["lon_deg"].copy(),
                       cat["diameter_m"].copy(), prof.tables[:n], prof.depth_m[:n],
                       prof.warps(1.0)[:n].copy(), rim, seeds,
                       3.0, True, 20.0, 45.0, np.array([0.03, 0.06, 0.05]), 2.0**-0.8, *outs,
                       np.empty((0, 3)), **switches)
    return time.perf_counter() - t0


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--moon", action="store_true")
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    m, radius, n_target, d_min, d_max = (
        (300, 3000.0, 5000, 20.0, 600.0) if args.quick
        else (330, 1_737_400.0, 2000, 25_000.0, 250_000.0) if args.moon
        else (1000, 10_000.0, 50_000, 20.0, 2000.0))
    grid = LatLongGrid(m)
    t0 = time.perf_counter()
    grid.unit_vectors()
    body = Body.sphere(grid, radius)
    t_setup = time.perf_counter() - t0
    area = 4 * np.pi * radius**2
    c = n_target / (area * (d_min**-2 - d_max**-2))
    t0 = time.perf_counter()
    cat = craters.power_law_population(radius=radius, c=c, k=-2.0, d_min=d_min, d_max=d_max,
                                       rng=1)
    t_pop = time.perf_counter() - t0
    target = "moon" if args.moon else craters.small_body(radius)
    threads = numba.get_num_threads()
    runs = {}
    for nt in (1, threads):
        numba.set_num_threads(nt)
        stamp_craters(body, cat[:50], rng=2, target=target)  # compile this path
        times = []
        for _ in range(args.repeat):
            t0 = time.perf_counter()
            out = stamp_craters(body, cat, rng=2, target=target)
            times.append(time.perf_counter() - t0)
        runs[nt] = (min(times), out)
    numba.set_num_threads(threads)
    updates = runs[1][1].craters["n_vertices"].sum()
    same = np.array_equal(runs[1][1].radii_m, runs[threads][1].radii_m)
    print(f"M={m} ({grid.n_vertices:,} vertices), R={radius:g} m, {len(cat)} craters "
          f"(D {d_min:g}-{d_max:g} m, N_cum ~ D^-2), roughness on; {updates:.3g} vertex "
          f"updates; best of {args.repeat}:")
    for nt, (t, _) in runs.items():
        print(f"  {nt} thread(s): {t:.2f} s = {len(cat) / t:.0f} craters/s, "
              f"{updates / t / 1e6:.2f} M vertex-updates/s ({updates / t / nt / 1e6:.2f} M "
              "per core)")
    print(f"  {threads} threads / 1 thread: x{runs[1][0] / runs[threads][0]:.2f}; radii "
          f"{'identical' if same else 'DIFFERENT'}")
    rng = np.random.default_rng(3)
    small = Body.sphere(LatLongGrid(8), radius)
    t0 = time.perf_counter()
    prof = craters.stamping_profiles(cat, target)
    t_prof = time.perf_counter() - t0
    for sw in ({"stop_after": 1}, {"stop_after": 2}, {}, {"naive": True}):
        run_kernel(small, cat[:2], prof, rng, **sw)  # compile each variant
    t1 = run_kernel(body, cat, prof, rng, stop_after=1)
    t2 = run_kernel(body, cat, prof, rng, stop_after=2)
    t3 = run_kernel(body, cat, prof, rng)
    total = t_pop + t_prof + t3
    print(f"(grid unit vectors, once per body: {t_setup:.2f} s) share of the cratering time: "
          f"population {t_pop / total:.1%}, profile tables (morphology + diffusion) "
          f"{t_prof / total:.1%}, gather + local coordinates {t1 / total:.1%}, "
          f"local grid + plane fit {(t2 - t1) / total:.1%}, "
          f"evaluate + write back {(t3 - t2) / total:.1%}")
    sub = cat[:: max(1, len(cat) // 200)]
    sprof = craters.stamping_profiles(sub, target)
    t_fast = run_kernel(body, sub, sprof, rng)
    t_naive = run_kernel(body, sub, sprof, rng, naive=True)
    print(f"naive stamp scanning every vertex, same {len(sub)} craters: "
          f"{len(sub) / t_naive:.0f} craters/s vs ring gather {len(sub) / t_fast:.0f} "
          f"craters/s (x{t_naive / t_fast:.0f})")


if __name__ == "__main__":
    main()
