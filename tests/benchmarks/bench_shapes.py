"""Benchmark: importing a real shape model onto the lat/long grid (plain script).

Itokawa q = 32 (12 288 facets): the full import at M = 1000 (butterfly subdivision,
6 M rays), and the ray caster against two references measured in the same run: the
numba brute force (every ray against every facet) and VTK's OBB tree called ray by ray.
Usage: ``python tests/benchmarks/bench_shapes.py [--quick]``.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from latlong import LatLongGrid
from latlong.shapes import ShapeModel, cast_radii, from_shape_model, read_shape_model

DATA = Path(__file__).parents[1] / "data"


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--quick", action="store_true")
    args = parser.parse_args()
    model = read_shape_model(DATA / "itokawa_32.obj", units="km")
    from_shape_model(model, 8, crossings="outermost")  # compile
    m = 300 if args.quick else 1000
    t0 = time.perf_counter()
    body = from_shape_model(model, m, crossings="outermost")
    t = time.perf_counter() - t0
    print(f"import Itokawa q=32 at M={m} ({body.n_vertices:,} rays, butterfly x2 = "
          f"{len(model.faces) * 16:,} facets): {t:.2f} s")
    moved = ShapeModel(model.vertices - model.volume_centroid, model.faces)
    g = LatLongGrid(100)
    cast_radii(moved, LatLongGrid(4), brute_force=True)
    t0 = time.perf_counter()
    fast = cast_radii(moved, g)
    t_fast = time.perf_counter() - t0
    t0 = time.perf_counter()
    slow = cast_radii(moved, g, brute_force=True)
    t_slow = time.perf_counter() - t0
    same = all(np.array_equal(a, b) for a, b in zip(fast, slow, strict=True))
    print(f"M=100 ({g.n_vertices:,} rays, {len(model.faces):,} facets): ring-gather caster "
          f"{t_fast:.3f} s, numba brute force {t_slow:.2f} s (x{t_slow / t_fast:.0f}); "
          f"identical results: {same}")
    import vtk

    mesh = moved.to_pyvista()
    tree = vtk.vtkOBBTree()
    tree.SetDataSet(mesh)
    tree.BuildLocator()
    u = g.unit_vectors()[:: max(1, g.n_vertices // 5000)]
    pts = vtk.vtkPoints()
    far = 10 * float(np.abs(moved.vertices).max())
    t0 = time.perf_counter()
    for d in u:
        tree.IntersectWithLine((0.0, 0.0, 0.0), tuple(d * far), pts, None)
    t_vtk = time.perf_counter() - t0
    rate_vtk = len(u) / t_vtk
    rate_fast = g.n_vertices / t_fast
    print(f"VTK OBB tree, one Python call per ray: {rate_vtk:,.0f} rays/s vs ring-gather "
          f"caster {rate_fast:,.0f} rays/s (x{rate_fast / rate_vtk:.0f})")


if __name__ == "__main__":
    main()
