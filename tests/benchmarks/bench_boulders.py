"""Benchmark: generate and place boulders on an M = 500 body (plain script).

Acceptance of the boulder issue: 10 000 boulders generated and placed on an M = 500 body
in at most 30 s, with the catalog's size-frequency exponent within 5 % of the requested
one. Also reports, in the same process:

* the mesh-surface ray query (``LatLongGrid.surface_radii``) against VTK's OBB-tree
  ray casting on the same body mesh (the reference a renderer-side tool would use),
* placement with the 64 lowest vertices as candidates against testing every vertex of
  the finest level (same answer, checked).

Usage: ``python tests/benchmarks/bench_boulders.py [--magnitude 500] [--boulders 10000]``.
"""

from __future__ import annotations

import argparse
import json
import time

import numpy as np

import craters
import craters.boulders.placement as bmod
from latlong import BoulderLayer, Scene, boulder_population, build, place_boulders
from latlong.surface import band_areas


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--magnitude", type=int, default=500)
    parser.add_argument("--boulders", type=int, default=10_000)
    parser.add_argument("--k", type=float, default=-3.0)
    args = parser.parse_args()
    body = build(Scene.from_settings({"preset": "fig5a", "magnitude": args.magnitude,
                                      "radius_m": 1000.0, "seed": 1,
                                      "craters": ["c=0.05,k=-2,d_min_m=10,d_max_m=200"]}))
    area = float(band_areas(body).sum())
    d_min, d_max = 1.0, 30.0
    c = args.boulders / (area * (d_min**args.k - d_max**args.k))
    layer = BoulderLayer(c=c, k=args.k, d_min_m=d_min, d_max_m=d_max, near=0.3)
    # warm the numba kernels on a handful
    place_boulders(body, boulder_population(body, layer.__class__(
        c=c * 1e-3, k=args.k, d_min_m=d_min, d_max_m=d_max), rng=0)[:5])

    t0 = time.perf_counter()
    found = boulder_population(body, layer, rng=1)
    t_pop = time.perf_counter() - t0
    t0 = time.perf_counter()
    placed = place_boulders(body, found)
    t_place = time.perf_counter() - t0
    k_fit = craters.fit_power_law_exponent(placed["diameter_m"], d_min, d_max)
    err = np.abs(placed["bottom_depth_m"] - placed["burial_m"]) / placed["diameter_m"]
    print(f"M={body.magnitude}: {len(placed):,} boulders; population {t_pop:.2f} s, "
          f"placement {t_place:.2f} s, total {t_pop + t_place:.2f} s (limit 30 s)")
    print(f"size-frequency exponent fitted {k_fit:.3f} vs requested {args.k} "
          f"({abs(k_fit / args.k - 1) * 100:.2f} %); burial error max {err.max():.2e} of "
          f"the size; floating boulders {(placed['bottom_depth_m'] <= 0).sum()}")

    # reference 1: every vertex as a candidate
    saved = bmod._CANDIDATES
    bmod._CANDIDATES = 10**9
    try:
        t0 = time.perf_counter()
        full = place_boulders(body, found)
        t_full = time.perf_counter() - t0
    finally:
        bmod._CANDIDATES = saved
    same = np.abs(full["bottom_depth_m"] - placed["bottom_depth_m"]) / placed["diameter_m"]
    centre_diff = max(np.abs(full[f"centre_{a}_m"] - placed[f"centre_{a}_m"]).max()
                      for a in "xyz")
    print(f"placement testing all vertices: {t_full:.2f} s ({t_full / t_place:.1f}x the "
          f"64-candidate placement); centres differ by at most {centre_diff:.2e} m, "
          f"depths by {same.max():.2e} of the size")

    # reference 2: VTK OBB-tree ray casting against the same triangles
    import vtk

    rng = np.random.default_rng(2)
    n_rays = 10_000
    colat = np.arccos(rng.uniform(-1, 1, n_rays))
    lon = rng.uniform(0, 2 * np.pi, n_rays)
    t0 = time.perf_counter()
    ours = body.grid.surface_radii(body.radii_m, colat, lon)
    t_ours = time.perf_counter() - t0
    t0 = time.perf_counter()
    mesh = body.to_pyvista()
    tree = vtk.vtkOBBTree()
    tree.SetDataSet(mesh)
    tree.BuildLocator()
    t_tree = time.perf_counter() - t0
    u = np.stack([np.sin(colat) * np.cos(lon), np.sin(colat) * np.sin(lon), np.cos(colat)], 1)
    far = 4.0 * body.radii_m.max() * np.asarray(body.stretch).max()
    pts = vtk.vtkPoints()
    n_vtk = 2_000  # VTK answers one ray per Python call: a subset
    ref = np.empty(n_vtk)
    t0 = time.perf_counter()
    for i in range(n_vtk):
        tree.IntersectWithLine((0.0, 0.0, 0.0), tuple(far * u[i]), pts, None)
        ref[i] = np.linalg.norm(pts.GetPoint(pts.GetNumberOfPoints() - 1))
    t_vtk = time.perf_counter() - t0
    per_ours, per_vtk = t_ours / n_rays, t_vtk / n_vtk
    print(f"surface ray queries: surface_radii {per_ours * 1e6:.2f} us/ray ({n_rays:,} rays), "
          f"VTK OBB tree {per_vtk * 1e6:.0f} us/ray ({n_vtk:,} rays) + {t_tree:.1f} s to "
          f"build ({per_vtk / per_ours:.0f}x without the build); largest difference "
          f"{np.abs(ours[:n_vtk] - ref).max():.2e} m")
    print(json.dumps({"n": int(len(placed)), "population_s": round(t_pop, 3),
                      "placement_s": round(t_place, 3), "k_fit": round(float(k_fit), 4),
                      "all_vertices_s": round(t_full, 3),
                      "ray_us_ours": round(per_ours * 1e6, 3),
                      "ray_us_vtk": round(per_vtk * 1e6, 1)}))


if __name__ == "__main__":
    main()
