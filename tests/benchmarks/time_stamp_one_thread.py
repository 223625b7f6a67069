"""One-thread wall time of ``latlong.stamp_craters`` on issue 20's benchmarks (plain
script), for before/after comparisons across checkouts: run it with ``PYTHONPATH`` set to
an older checkout and without, interleaved. Prints the best and median of ``REPS`` runs
and the radii's sha256 prefix. Usage: ``python tests/benchmarks/time_stamp_one_thread.py
M R N DMIN DMAX REPS`` (M = 1000: ``1000 10000 50000 20 2000 7``; the Moon:
``330 1737400 2000 25000 250000 15``)."""

import hashlib
import sys
import time

import numba
import numpy as np

import craters
from latlong import Body, LatLongGrid, stamp_craters


def main() -> None:
    m, radius, n = int(sys.argv[1]), float(sys.argv[2]), int(sys.argv[3])
    d_min, d_max, reps = float(sys.argv[4]), float(sys.argv[5]), int(sys.argv[6])
    body = Body.sphere(LatLongGrid(m), radius)
    c = n / (4 * np.pi * radius**2 * (d_min**-2 - d_max**-2))
    cat = craters.sort_oldest_first(craters.power_law_population(
        radius=radius, c=c, k=-2.0, d_min=d_min, d_max=d_max, rng=1))
    numba.set_num_threads(1)
    target = "moon" if radius > 1e6 else craters.small_body(radius)
    stamp_craters(body, cat[:50], rng=2, target=target)  # compile
    times = []
    for _ in range(reps):
        t0 = time.perf_counter()
        out = stamp_craters(body, cat, rng=2, target=target)
        times.append(time.perf_counter() - t0)
    print(f"M={m} n={len(cat)} one thread: best {min(times):.3f} s, median "
          f"{np.median(times):.3f} s; radii sha256 "
          f"{hashlib.sha256(out.radii_m.tobytes()).hexdigest()[:8]}")


if __name__ == "__main__":
    main()
