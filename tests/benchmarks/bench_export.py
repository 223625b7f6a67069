"""Benchmark: build a very large body and export it as patched glTF (plain script).

Default: M = 4096 (100.7 M vertices), radius 1 km, Perlin fBm (fig5a) with craters
N_cum = 0.05 D^-2 between 2 and 100 m, exported with K = 64 and levels of detail 0..2.
Reports the time of each stage, strips/s and MB/s written. Run it under
``/usr/bin/time -v`` for the peak memory. Usage:
``python tests/benchmarks/bench_export.py [--magnitude M] [--patch-k K] [--lod L] [--out DIR]``.
"""

from __future__ import annotations

import argparse
import json
import tempfile
import time
from pathlib import Path

from latlong import Scene, build
from latlong.gltf import export_glb


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--magnitude", type=int, default=4096)
    parser.add_argument("--patch-k", type=int, default=64)
    parser.add_argument("--lod", type=int, default=2)
    parser.add_argument("--out", default=None, help="folder for the .glb (default: temp)")
    args = parser.parse_args()
    folder = Path(args.out or tempfile.mkdtemp(prefix="craterform-bench-"))
    folder.mkdir(parents=True, exist_ok=True)
    glb = folder / f"body_M{args.magnitude}.glb"
    scene = Scene.from_settings({"preset": "fig5a", "magnitude": args.magnitude,
                                 "radius_m": 1000.0, "seed": 1,
                                 "craters": ["c=0.05,k=-2,d_min_m=2,d_max_m=100"]})
    t0 = time.perf_counter()
    body = build(scene)
    t_build = time.perf_counter() - t0
    print(f"build M={body.magnitude} ({body.n_vertices:,} vertices, {len(body.craters):,} "
          f"craters): {t_build:.1f} s")
    t0 = time.perf_counter()
    man = export_glb(body, glb, patch_k=args.patch_k, lod=args.lod)
    t_export = time.perf_counter() - t0
    files = [glb] + [glb.with_name(b) for b in man["buffers"] if b != glb.name]
    size = sum(f.stat().st_size for f in files)
    n_strips = sum(sum(p["bands"][1] - p["bands"][0] for p in lv["patches"])
                   for lv in man["levels"])
    n_patches = sum(len(lv["patches"]) for lv in man["levels"])
    n_tri = sum(lv["n_triangles"] for lv in man["levels"])
    print(f"export K={args.patch_k}, LOD 0..{args.lod}: {t_export:.1f} s, {n_patches:,} "
          f"patches, {n_strips:,} strips ({n_strips / t_export:,.0f} strips/s), "
          f"{n_tri:,} triangles, {size / 2**20:,.0f} MiB ({size / 2**20 / t_export:.0f} MiB/s)")
    print(json.dumps({"build_s": round(t_build, 1), "export_s": round(t_export, 1),
                      "bytes": size, "files": [f.name for f in files],
                      "patches": n_patches}))
    for f in files + [glb.with_suffix(".json")]:
        f.unlink()


if __name__ == "__main__":
    main()
