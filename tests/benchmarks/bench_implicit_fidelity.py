"""How closely the implicit backend's coarse surface follows its constraint (issue 16):
Eros (7790 plates), Itokawa (q=32) and Bennu (radar), no craters, no Gabor noise, about
200 000 triangles, with the constraint's field (weight 1, the default) and the bare
metaballs (weight 0). Prints the mean and 99th-percentile distance (% of the longest
axis) and the KS distance of the slope-against-a-5 %-smoothed-copy distributions
(:func:`latlong.implicit.shape_fidelity`). Acceptance: <= 0.3 %, <= 1 %, <= 0.1.

    python tests/benchmarks/bench_implicit_fidelity.py [--polygons 200000] [--fine 0.01]
"""

import argparse
import time
from pathlib import Path

from latlong.implicit import implicit_surface, shape_fidelity
from latlong.shapes import ShapeModel, read_shape_model

DATA = Path(__file__).parents[1] / "data"
BODIES = ("eros007790.tab", "itokawa_32.obj", "bennu_radar_sbgat.obj")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--polygons", type=int, default=200_000, help="(default: 200000)")
    ap.add_argument("--fine", type=float, default=0.01,
                    help="local normal radius, fraction of the axis (default: 0.01)")
    args = ap.parse_args()
    print(f"{'body':24s} {'weight':>6s} {'build s':>7s} {'mean %':>7s} {'p99 %':>6s} "
          f"{'slope KS':>8s} {'median slope (body / constraint)':>34s}")
    for name in BODIES:
        model = read_shape_model(DATA / name, units="km")
        moved = ShapeModel(model.vertices - model.volume_centroid, model.faces)
        for weight in (1.0, 0.0):
            t = time.perf_counter()
            surf = implicit_surface(model, target_polygons=args.polygons,
                                    constraint_weight=weight, rng=1)
            dt = time.perf_counter() - t
            f = shape_fidelity((surf.base_vertices, surf.base_faces), moved, fine=args.fine)
            ok = f.mean_fraction <= 0.003 and f.p99_fraction <= 0.01 and f.slope_ks <= 0.1
            print(f"{name:24s} {weight:6g} {dt:7.1f} {100 * f.mean_fraction:7.3f} "
                  f"{100 * f.p99_fraction:6.3f} {f.slope_ks:8.3f} "
                  f"{f.slope_median_deg[0]:16.2f} / {f.slope_median_deg[1]:5.2f} deg "
                  f"{'ok' if ok else 'FAILS'}", flush=True)


if __name__ == "__main__":
    main()
