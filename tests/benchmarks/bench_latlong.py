"""Benchmarks for the latlong foundation (plain script; not part of the test run).

Each speed is reported as a ratio against a reference measured in the same run, plus
the absolute time on this machine. Usage: ``python tests/benchmarks/bench_latlong.py
[--quick]`` (``--quick`` uses smaller sizes).
"""

from __future__ import annotations

import argparse
import os
import platform
import time

import numpy as np


def best_of(fn, repeat=3):
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        result = fn()
        times.append(time.perf_counter() - t0)
    return min(times), result


def chunked_brute_force(u, normals, heights, chunk=64):
    """The fastest plain-numpy brute force: (N x chunk) sign matrix times heights."""
    out = np.zeros(len(u))
    for s in range(0, len(normals), chunk):
        out += (u @ normals[s:s + chunk].T > 0) @ heights[s:s + chunk]
    return out


def bench_faults(quick):
    from latlong import LatLongGrid, apply_faults, random_faults

    m = 100 if quick else 300
    g = LatLongGrid(m)
    u = g.unit_vectors()
    normals, heights = random_faults(3000, 1.0, rng=0)
    apply_faults(LatLongGrid(4), normals[:2], heights[:2])  # compile
    t_fast, fast = best_of(lambda: apply_faults(g, normals, heights))
    t_slow, slow = best_of(lambda: chunked_brute_force(u, normals, heights), repeat=1)
    err = np.abs(fast - slow).max()
    print(f"apply_faults M={m}, 3000 faults: {t_fast:.3f} s; chunked numpy brute force "
          f"{t_slow:.3f} s; speed-up x{t_slow / t_fast:.0f}; max |diff| {err:.2e} m")
    m2 = 300 if quick else 1000
    g2 = LatLongGrid(m2)
    g2.unit_vectors()
    n2, h2 = random_faults(20000, 0.03, rng=1)
    t2, _ = best_of(lambda: apply_faults(g2, n2, h2))
    print(f"apply_faults M={m2} ({g2.n_vertices:,} vertices), 20000 faults: {t2:.3f} s")


def bench_fbm(quick):
    import noise

    from latlong import LatLongGrid, fbm3

    m = 300 if quick else 1000
    u = LatLongGrid(m).unit_vectors() * 1.5
    x, y, z = (np.ascontiguousarray(u[:, i]) for i in range(3))
    fbm3(x[:10], y[:10], z[:10], 10, 0.5, 1.75)  # compile
    t_fast, _ = best_of(lambda: fbm3(x, y, z, 10, 0.5, 1.75))
    k = 200_000
    xs, ys, zs = x[:k].tolist(), y[:k].tolist(), z[:k].tolist()
    pn = noise.pnoise3
    t_ref, _ = best_of(lambda: [pn(a, b, c, octaves=10, persistence=0.5, lacunarity=1.75)
                                for a, b, c in zip(xs, ys, zs, strict=True)], repeat=1)
    rate_ref = k / t_ref
    rate = len(x) / t_fast
    print(f"fbm3 on M={m} ({len(x):,} points, 10 octaves): {t_fast:.3f} s = "
          f"{rate / 1e6:.1f} M points/s; noise.pnoise3 list comprehension "
          f"{rate_ref / 1e6:.2f} M points/s; speed-up x{rate / rate_ref:.1f}")


def bench_smooth(quick):
    from latlong import LatLongGrid, smooth
    from latlong.smoothing import _operator

    m = 200 if quick else 400
    g = LatLongGrid(m)
    f = np.random.default_rng(0).standard_normal(g.n_vertices)
    _operator.cache_clear()
    t0 = time.perf_counter()
    smooth(g, f, 20.0, radius_m=50.0, passes=3)
    cold = time.perf_counter() - t0
    warm, _ = best_of(lambda: smooth(g, f, 20.0, radius_m=50.0, passes=3))
    print(f"smooth M={m} ({g.n_vertices:,} vertices), 20 m filter on a 50 m body, 3 passes: "
          f"{cold:.2f} s first call (builds the Laplacians), {warm:.2f} s after")


def bench_slopes(quick):
    from latlong import Body, LatLongGrid, perlin_fbm, slopes

    m = 300 if quick else 1000
    g = LatLongGrid(m)
    body = Body.from_heights(g, 1000.0, perlin_fbm(g, 1.5, 10, 0.5, 1.75, 300.0, rng=1))
    slopes(Body.sphere(LatLongGrid(8), 1.0))  # compile
    t, _ = best_of(lambda: slopes(body, 3.0), repeat=1)
    print(f"slopes M={m} ({g.n_vertices:,} vertices), 3 deg area-weighted caps: {t:.1f} s")


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--quick", action="store_true")
    args = parser.parse_args()
    import numba

    print(f"machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cores, "
          f"numba threads {numba.get_num_threads()}")
    bench_faults(args.quick)
    bench_fbm(args.quick)
    bench_smooth(args.quick)
    bench_slopes(args.quick)


if __name__ == "__main__":
    main()
