"""Benchmark: the camera against Mitsuba 3 and the LIDAR against raw embreex, in one run
on one mesh (issue 32's speed item: camera >= 2x Mitsuba 3 ``scalar_rgb`` with direct
light and shadows; LIDAR >= 0.8 of embreex's rays per second).

Mesh: a body of magnitude M (default 1000: 6 M vertices, 12 M triangles), radius 1 km,
Perlin fBm relief (+-30 m), as ``bench_sensors_camera.py``. Camera: 1024 x 1024, 30 deg,
the whole body in view, the sun 20 deg above the terminator's plane; craterform's
``render`` (Lommel-Seeliger, cast shadows, smooth normals, the sensor) against Mitsuba's
``direct`` integrator (1 sample a pixel: one emitter sample, no BSDF sample, a diffuse
BSDF), both after a warm-up, best of ``--repeat``; the BVH/scene builds are timed apart.
LIDAR: a 512 x 512 flash from the same pose; ``lidar_frame`` (first returns, ranges,
labels, no noise) against embreex's ``EmbreeScene.run(origins, directions, output=1)``
on the same beams (float32 rays, first hits), best of ``--repeat``.

Usage: ``python tests/benchmarks/bench_sensors_peers.py [--magnitude 1000] [--repeat 3]``
(needs ``pip install mitsuba``).
"""

from __future__ import annotations

import argparse
import math
import tempfile
import time
from pathlib import Path

import numpy as np


def best(fn, repeat: int) -> tuple[float, object]:
    out, times = fn(), []
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return min(times), out


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--magnitude", type=int, default=1000)
    ap.add_argument("--size", type=int, default=1024)
    ap.add_argument("--beams", type=int, default=512)
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()

    import mitsuba as mi
    from embreex import rtcore_scene
    from embreex.mesh_construction import TriangleMesh

    from latlong import Body, LatLongGrid, perlin_fbm
    from latlong.meshio.writers import array_source, write_mesh
    from latlong.sensors import Camera, LidarSettings, Pose, RayMesh, Sun, lidar_frame, render

    grid = LatLongGrid(args.magnitude)
    body = Body.from_heights(grid, 1000.0, perlin_fbm(grid, 2.0, 8, 0.5, 2.0, 30.0, rng=1))
    verts, faces = body.vertices(), grid.triangles()
    print(f"mesh M={args.magnitude}: {len(verts):,} vertices, {len(faces):,} triangles")
    t0 = time.perf_counter()
    mesh = RayMesh(verts, faces)
    t_bvh = time.perf_counter() - t0

    distance = 1060.0 / math.tan(math.radians(15.0)) + 1060.0
    pose = Pose.look_at([distance, 0.0, 0.0], [0.0, 0.0, 0.0], up=(0.0, 0.0, 1.0))
    el = math.radians(20.0)
    sun = Sun([math.sin(el), math.cos(el), 0.0])
    camera = Camera.from_fov(30.0, args.size, args.size)
    t_ours, frame = best(lambda: render(mesh, camera, pose, sun), args.repeat)
    seen = float((frame.face >= 0).mean())
    shadow = float(((frame.face >= 0) & (frame.sunlit == 0)).mean())

    mi.set_variant("scalar_rgb")
    with tempfile.TemporaryDirectory() as tmp:
        ply = Path(tmp) / "body.ply"
        write_mesh(array_source(verts, faces, "bench"), ply)
        t0 = time.perf_counter()
        scene = mi.load_dict({
            "type": "scene",
            "integrator": {"type": "direct", "emitter_samples": 1, "bsdf_samples": 0},
            "sensor": {"type": "perspective", "fov": 30.0, "fov_axis": "x",
                       "to_world": mi.ScalarTransform4f().look_at(
                           origin=[distance, 0.0, 0.0], target=[0.0, 0.0, 0.0],
                           up=[0.0, 0.0, 1.0]),
                       "film": {"type": "hdrfilm", "width": args.size, "height": args.size,
                                "rfilter": {"type": "box"}, "pixel_format": "luminance"},
                       "sampler": {"type": "independent", "sample_count": 1}},
            "sun": {"type": "directional", "direction": (-sun.direction).tolist(),
                    "irradiance": {"type": "rgb", "value": [math.pi] * 3}},
            "body": {"type": "ply", "filename": str(ply),
                     "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb",
                                                                 "value": [0.12] * 3}}}})
        t_mi_scene = time.perf_counter() - t0
        t_mi, img = best(lambda: mi.render(scene, spp=1), args.repeat)
    mi_seen = float((np.asarray(img)[:, :, 0] > 0).mean())  # lit pixels: 0 in shadow

    settings = LidarSettings(beams=(args.beams, args.beams), fov_deg=30.0, pattern="flash",
                             max_range_m=1e5)
    t_lidar, lf = best(lambda: lidar_frame(mesh, settings, pose.position_m,
                                           pose.quaternion_wxyz), args.repeat)
    n_rays = args.beams * args.beams
    beam_dirs = Camera.from_fov(30.0, args.beams, args.beams).rays(pose)[1]
    dirs = np.ascontiguousarray(beam_dirs.reshape(-1, 3), dtype=np.float32)
    origins = np.ascontiguousarray(np.broadcast_to(pose.position_m, dirs.shape),
                                   dtype=np.float32)
    t0 = time.perf_counter()
    escene = rtcore_scene.EmbreeScene()
    TriangleMesh(escene, verts.astype(np.float32), faces.astype(np.int32))
    t_embree_build = time.perf_counter() - t0
    t_embree, hits = best(lambda: escene.run(origins, dirs, output=1), args.repeat)
    e_hit = float((np.asarray(hits["primID"]) >= 0).mean())

    print(f"BVH: craterform {t_bvh:.2f} s, Mitsuba scene load {t_mi_scene:.2f} s, "
          f"embreex scene {t_embree_build:.2f} s")
    print(f"camera {args.size}^2, direct light + shadows: craterform {t_ours:.3f} s "
          f"(surface in {seen:.0%} of pixels, {shadow:.0%} in cast or attached shadow), "
          f"Mitsuba 3 scalar_rgb direct 1 spp {t_mi:.3f} s (lit in {mi_seen:.0%}): "
          f"ratio {t_mi / t_ours:.2f}x (>1: craterform faster)")
    print(f"LIDAR {args.beams}^2 beams: lidar_frame {t_lidar:.3f} s "
          f"({n_rays / t_lidar / 1e6:.2f} M rays/s, {len(lf.range_m) / n_rays:.0%}"
          f" returns), embreex run {t_embree:.3f} s ({n_rays / t_embree / 1e6:.2f} M rays/s, "
          f"{e_hit:.0%} hits): ratio {t_embree / t_lidar:.2f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
