"""Measure locality of terrain on demand (issue 37): for 1000 random vertices of an
Eros-like scene, the radius computed alone, in a batch of 10^6 points and inside the
whole-body build at the same resolution are the same float64 bytes.

Scene: the ``eros`` preset (the NEAR shape model, its crater layers, its 40-100 m
boulders as rocks in the relief) with ``on_demand = true`` at ``--magnitude`` (default the
preset's 700: 2.94 M vertices). The body is built patch by patch
(:func:`latlong.ondemand.patches.build_patches`, ``--patches``, in this process); the
batch is the 1000 vertices among 10^6 - 1000 other random vertices; each "alone" value
is one call with one point. Prints the counts of differing values (0 is the acceptance)
and the times.

Usage: ``python tests/benchmarks/measure_ondemand_locality.py [--magnitude 700]
[--patches 4] [--points 1000] [--batch 1000000]``
"""

from __future__ import annotations

import argparse
import sys
import time

import numpy as np


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--magnitude", type=int, default=700)
    ap.add_argument("--patches", type=int, default=4)
    ap.add_argument("--points", type=int, default=1000)
    ap.add_argument("--batch", type=int, default=1_000_000)
    ap.add_argument("--seed", type=int, default=1)
    args = ap.parse_args()
    from latlong import LatLongGrid, Scene
    from latlong.ondemand.field import crater_field
    from latlong.ondemand.patches import build_patches

    scene = Scene.from_settings({"preset": "eros", "seed": args.seed, "on_demand": True,
                                 "magnitude": args.magnitude})
    grid = LatLongGrid(args.magnitude)
    field = crater_field(scene)
    d_min = 3.0 * grid.spacing(field.base.radius_m)
    t0 = time.perf_counter()
    body = build_patches(scene, patches=args.patches)
    t_build = time.perf_counter() - t0
    print(f"whole body: magnitude {args.magnitude}, {grid.n_vertices} vertices in "
          f"{args.patches} patches, {len(body.craters)} craters >= {d_min:.3g} m, "
          f"{t_build:.1f} s", flush=True)
    rng = np.random.default_rng(args.seed)
    n_batch = min(args.batch, grid.n_vertices)
    batch_idx = rng.choice(grid.n_vertices, n_batch, replace=False)
    pick = batch_idx[:args.points]
    units = grid.unit_vectors_of(batch_idx)
    t0 = time.perf_counter()
    batch = field.radii(units, d_min)
    t_batch = time.perf_counter() - t0
    t0 = time.perf_counter()
    alone = np.array([field.radii(grid.unit_vectors_of(np.array([i])), d_min)[0] for i in pick])
    t_alone = time.perf_counter() - t0
    whole = body.radii_m[pick]
    diff_batch = int((batch[:args.points].view(np.uint64) != whole.view(np.uint64)).sum())
    diff_alone = int((alone.view(np.uint64) != whole.view(np.uint64)).sum())
    print(f"batch of {n_batch} points: {t_batch:.1f} s; {args.points} points alone: "
          f"{t_alone:.1f} s ({1e3 * t_alone / args.points:.1f} ms a point)")
    print(f"differing float64 values: batch vs whole body {diff_batch} of {args.points}, "
          f"alone vs whole body {diff_alone} of {args.points}")
    return 0 if diff_batch == 0 and diff_alone == 0 else 1


if __name__ == "__main__":
    sys.exit(main())
