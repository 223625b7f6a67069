"""Benchmark: LIDAR returns per second on a cratered magnitude-300 body (plain script).

Body: R = 3 km sphere, M = 300 (540 002 vertices, 1.08 M triangles), ~3000 craters of
20-600 m. The sensor is 1 km above the surface looking straight down; a 1024 x 1024 flash
frame (every beam hits). Reports, after the BVH is built (its build time too):
returns/s of :func:`latlong.sensors.lidar.lidar_frame` with thin beams (the issue's
>= 1 M returns/s), with the crater/boulder labels, with 8 sub-rays per beam, the LAS
write rate, and in the same run the rays/s of trimesh's Embree ray queries
(``trimesh.ray.ray_pyembree``, first hits with locations) and of bare Embree calls, with
the ratios. Usage: ``python tests/benchmarks/bench_lidar.py [--quick]`` (quick: 512 x 512
beams).
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

import numpy as np

import craters
from latlong import Body, LatLongGrid, stamp_craters
from latlong.sensors.camera import Pose, quaternion_to_matrix
from latlong.sensors.engine import RayMesh
from latlong.sensors.lidar import LidarSettings, beam_pattern, lidar_frame
from latlong.sensors.lidar_files import write_las
from latlong.sensors.scene_geometry import scene_geometry


def _look_at(position_m, target_m):
    return Pose.look_at(position_m, target_m).quaternion_wxyz


def best_of(fn, repeats=3):
    times = []
    out = None
    for _ in range(repeats):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return min(times), out


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--quick", action="store_true")
    args = parser.parse_args()
    n_side = 512 if args.quick else 1024
    radius = 3000.0
    t0 = time.perf_counter()
    body = Body.sphere(LatLongGrid(300), radius)
    area = 4 * np.pi * radius**2
    cat = craters.power_law_population(radius=radius, c=3000 / (area * (20.0**-2 - 600.0**-2)),
                                       k=-2.0, d_min=20.0, d_max=600.0, rng=1)
    body = stamp_craters(body, cat, rng=1)
    print(f"body: M = 300, {body.n_vertices} vertices, {len(body.craters)} craters "
          f"({time.perf_counter() - t0:.1f} s to make)")
    geo = scene_geometry(body)
    t_build, mesh = best_of(lambda: RayMesh(geo.vertices, geo.faces), 1)
    print(f"BVH: {len(geo.faces)} triangles built in {t_build:.2f} s")
    pos = np.array([radius + 1000.0, 0.0, 0.0])
    q = _look_at(pos, [0.0, 0.0, 0.0])
    thin = LidarSettings(beams=(n_side, n_side), fov_deg=40.0)
    lidar_frame(mesh, LidarSettings(beams=(8, 8)), pos, q)  # compile / warm up
    t_thin, fr = best_of(lambda: lidar_frame(mesh, thin, pos, q))
    n = len(fr)
    rate = n / t_thin
    print(f"flash {n_side}x{n_side}, thin beams: {n} returns in {t_thin:.3f} s = "
          f"{rate / 1e6:.2f} M returns/s")
    t_lab, fr_lab = best_of(lambda: lidar_frame(mesh, thin, pos, q, ground_truth=geo))
    print(f"  with crater/boulder labels: {len(fr_lab) / t_lab / 1e6:.2f} M returns/s "
          f"({int((fr_lab.crater_id >= 0).sum())} returns in craters)")
    wide = LidarSettings(beams=(n_side // 2, n_side // 2), fov_deg=40.0, divergence_mrad=2.0,
                         rays_per_beam=8, multiple_returns=True)
    t_wide, fr_w = best_of(lambda: lidar_frame(mesh, wide, pos, q))
    print(f"  {n_side // 2}x{n_side // 2} beams x 8 sub-rays, multiple returns: "
          f"{len(fr_w) / t_wide / 1e6:.2f} M returns/s ({8 * wide.n_beams / t_wide / 1e6:.2f} "
          f"M sub-rays/s)")
    with tempfile.TemporaryDirectory() as tmp:
        t_las, _ = best_of(lambda: write_las(fr_lab, Path(tmp) / "f.las"), 1)
    print(f"  LAS 1.4 write: {len(fr_lab) / t_las / 1e6:.2f} M points/s")

    # references, same rays
    d = beam_pattern(thin)[0] @ quaternion_to_matrix(q).T
    o = np.broadcast_to(pos, d.shape)
    import trimesh
    from trimesh.ray.ray_pyembree import RayMeshIntersector

    tm = trimesh.Trimesh(geo.vertices, geo.faces, process=False)
    inter = RayMeshIntersector(tm)
    inter.intersects_first(o[:10], d[:10])  # build its scene
    t_tm, _ = best_of(lambda: inter.intersects_location(o, d, multiple_hits=False), 1)
    t_raw, _ = best_of(lambda: mesh.intersect(o, d))
    print(f"reference: trimesh Embree first hits with locations {len(d) / t_tm / 1e6:.2f} M "
          f"rays/s; RayMesh.intersect alone {len(d) / t_raw / 1e6:.2f} M rays/s")
    print(f"ratios: lidar_frame / trimesh = {rate / (len(d) / t_tm):.2f}; "
          f"lidar_frame / RayMesh.intersect = {rate / (len(d) / t_raw):.2f}")
    print(f"target >= 1 M returns/s: {'met' if rate >= 1e6 else 'NOT met'} "
          f"({rate / 1e6:.2f} M returns/s)")


if __name__ == "__main__":
    main()
