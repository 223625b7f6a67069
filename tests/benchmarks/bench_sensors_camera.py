"""Benchmark: the camera (latlong.render) against the pyvista preview (plain script).

A body of magnitude M (default 1000: 6 M vertices, 12 M triangles), radius 1 km, Perlin
fBm relief (+-30 m); one view at 1024 x 1024 with the sun 20 degrees above the local
horizon of the view's centre (long cast shadows). Measures, in the same run:

* the BVH build (``scene_mesh``: Embree, 12 M triangles) and its memory (peak RSS
  before and after, ``resource``),
* ``latlong.render`` of the frame with cast shadows, after the BVH (best of ``--repeat``;
  the first call also computes the vertex normals and is reported separately),
* the pyvista preview of the same view (``pyvista_preview`` below: the preview as it
  was up to commit 2bb7aa7, VTK off-screen, Lambert, no shadows, same size; previews now
  go through the engine) and today's ``latlong.render_preview`` (BVH build included),
  and prints the ratios. Usage:
``python tests/benchmarks/bench_sensors_camera.py [--magnitude M] [--size N] [--repeat R]``.
"""

from __future__ import annotations

import argparse
import math
import resource
import tempfile
import time
from pathlib import Path

import numpy as np


def pyvista_preview(body, png, view, size):
    """The preview's pyvista/VTK renderer as it was up to 2bb7aa7 (the reference)."""
    import pyvista as pv
    from PIL import Image

    mesh = body.to_pyvista().compute_normals(cell_normals=False, point_normals=True,
                                             split_vertices=False, consistent_normals=False,
                                             auto_orient_normals=False)
    lo, hi = mesh.points.min(axis=0), mesh.points.max(axis=0)
    centre, extent = 0.5 * (lo + hi), 0.5 * float(np.linalg.norm(hi - lo))
    v, right, up = view
    plotter = pv.Plotter(off_screen=True, window_size=(size, size), lighting="none")
    try:
        plotter.set_background("black")
        plotter.add_mesh(mesh, color=(0.78, 0.76, 0.72), smooth_shading=True, ambient=0.03,
                         diffuse=1.0, specular=0.0, show_scalar_bar=False)
        light = pv.Light(position=tuple(centre + right * 10 * extent),
                         focal_point=tuple(centre), light_type="scene light", intensity=1.0)
        light.positional = False
        plotter.add_light(light)
        rel = np.asarray(mesh.points) - centre
        tan_v = math.tan(math.radians(15.0))
        fit = float((rel @ v).max()) + 1.08 * max(float(np.abs(rel @ right).max()),
                                                  float(np.abs(rel @ up).max())) / tan_v
        plotter.camera_position = [tuple(centre + v * fit), tuple(centre), tuple(up)]
        plotter.camera.view_angle = 30.0
        plotter.camera.clipping_range = (max(fit - 2 * extent, 1e-3 * fit), fit + 2 * extent)
        Image.fromarray(plotter.screenshot(return_img=True)).save(png)
    finally:
        plotter.close()


def peak_rss_gb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1e6


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--magnitude", type=int, default=1000)
    parser.add_argument("--size", type=int, default=1024)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--quality", default="medium", help="Embree build quality")
    args = parser.parse_args()

    import latlong
    from latlong import Body, LatLongGrid, perlin_fbm
    from latlong.preview import camera_frame
    from latlong.sensors import Camera, Pose, RayMesh, Sun

    t0 = time.perf_counter()
    grid = LatLongGrid(args.magnitude)
    heights = perlin_fbm(grid, 2.0, 8, 0.5, 2.0, 30.0, rng=1)
    body = Body.from_heights(grid, 1000.0, heights)
    verts, faces = body.vertices(), grid.triangles()
    print(f"body M={args.magnitude}: {len(verts):,} vertices, {len(faces):,} triangles "
          f"({time.perf_counter() - t0:.1f} s to make); peak RSS {peak_rss_gb():.2f} GB")

    rss0 = peak_rss_gb()
    t0 = time.perf_counter()
    mesh = RayMesh(verts, faces, build_quality=args.quality)
    t_bvh = time.perf_counter() - t0
    print(f"BVH build ({args.quality}): {t_bvh:.2f} s; peak RSS {rss0:.2f} -> "
          f"{peak_rss_gb():.2f} GB")

    # the preview's default view: from (lat 0, lon -90), framed as the preview frames it
    view_lat, view_lon = 0.0, -90.0
    toward, right, up = camera_frame(view_lat, view_lon)
    fov_v = 30.0  # the preview's vertical field of view
    centre = 0.5 * (verts.min(0) + verts.max(0))
    rel = verts - centre
    half = max(float(np.abs(rel @ right).max()), float(np.abs(rel @ up).max()))
    distance = float((rel @ toward).max()) + 1.08 * half / math.tan(math.radians(fov_v / 2))
    size = args.size
    camera = Camera.from_fov(fov_v, size, size)  # square: horizontal = vertical
    pose = Pose.look_at(centre + toward * distance, centre, up)
    sun_dir = math.cos(math.radians(20)) * right + math.sin(math.radians(20)) * toward
    sun = Sun(sun_dir)

    t0 = time.perf_counter()
    frame = latlong.render(mesh, camera, pose, sun)
    t_first = time.perf_counter() - t0
    times = []
    for _ in range(args.repeat):
        t0 = time.perf_counter()
        frame = latlong.render(mesh, camera, pose, sun)
        times.append(time.perf_counter() - t0)
    t_render = min(times)
    hit = frame.face >= 0
    shadow = hit & (frame.sunlit == 0)
    print(f"latlong.render {size}x{size} with shadows: {t_render:.3f} s best of "
          f"{args.repeat} ({', '.join(f'{t:.3f}' for t in times)}); first call "
          f"{t_first:.2f} s (vertex normals); {hit.mean():.0%} of pixels on the body, "
          f"{shadow.sum() / max(hit.sum(), 1):.0%} of those in shadow")

    with tempfile.TemporaryDirectory() as tmp:
        png = Path(tmp) / "preview.png"
        times_p, times_n = [], []
        for _ in range(max(1, min(args.repeat, 2))):
            t0 = time.perf_counter()
            pyvista_preview(body, png, (toward, right, up), size)
            times_p.append(time.perf_counter() - t0)
            t0 = time.perf_counter()
            latlong.render_preview(body, png, view_lat_deg=view_lat, view_lon_deg=view_lon,
                                   width_px=size, height_px=size)
            times_n.append(time.perf_counter() - t0)
    t_prev = min(times_p)
    print(f"pyvista preview (up to 2bb7aa7) same view: {t_prev:.2f} s best of {len(times_p)}; "
          f"latlong.render_preview now (engine, BVH build included): {min(times_n):.2f} s")
    print(f"ratio pyvista preview / render: {t_prev / t_render:.1f}x (target >= 5); render "
          f"{t_render:.3f} s (target <= 1 s); BVH {t_bvh:.1f} s (target <= 10 s); peak RSS "
          f"{peak_rss_gb():.2f} GB")


if __name__ == "__main__":
    main()
