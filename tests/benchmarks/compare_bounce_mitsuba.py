"""Compare: light bounced between surfaces (``render(..., bounces=1 or 2)``) against
Mitsuba 3's path tracer on the same mesh, BRDF, camera and sun (issue 32's acceptance:
"median relative difference <= 5 % over shadowed crater floors", Lambert, >= 256 spp).

Scene: a fresh 100 m crater (craters.radial_profile, 241 x 241 vertices over 3.2
radii) on flat ground, Lambert albedo 0.3, the sun 15 degrees above the horizon, a
camera 300 m above looking straight down (25 degree field of view), facet normals in
both renderers. Mitsuba: ``scalar_rgb``, the ``path`` integrator with ``max_depth`` 2
(direct light: checks that the two set-ups agree) and 2 + ``--bounces``, a directional
emitter of irradiance pi (so a Lambert surface's radiance is I/F), a box pixel filter
and ``--spp`` independent samples a pixel; craterform with ``--spp`` bounce rays a
pixel. Shadowed floor pixels: inside 0.8 radii with no direct light in either renderer.

Usage: ``python tests/benchmarks/compare_bounce_mitsuba.py [--size 96] [--spp 4096]
[--bounces 1] [--our-spp N] [--filter-px R]`` (``--our-spp 16 --filter-px 4``: the
camera's defaults against Mitsuba's ``--spp``)
(needs ``pip install mitsuba``).
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

import numpy as np

import craters
from latlong.sensors import Camera, Lambert, Pose, RayMesh
from latlong.sensors.render import render

DIAMETER_M = 100.0
ALBEDO = 0.3
ELEVATION_DEG = 15.0
FOV_DEG = 25.0
HEIGHT_M = 300.0


def crater_mesh(n: int = 241) -> tuple[np.ndarray, np.ndarray]:
    rad = DIAMETER_M / 2
    xs = np.linspace(-1.6 * rad, 1.6 * rad, n)
    x, y = np.meshgrid(xs, xs)
    r = np.hypot(x, y) / rad
    z = np.asarray(craters.radial_profile(r, DIAMETER_M))
    v = np.column_stack([x.ravel(), y.ravel(), z.ravel()])
    idx = np.arange(n * n).reshape(n, n)
    a, b, c, d = idx[:-1, :-1].ravel(), idx[:-1, 1:].ravel(), idx[1:, :-1].ravel(), \
        idx[1:, 1:].ravel()
    f = np.concatenate([np.column_stack([a, b, d]), np.column_stack([a, d, c])])
    return v, f


def write_ply(path: Path, v: np.ndarray, f: np.ndarray) -> None:
    with open(path, "w") as fh:
        fh.write(f"ply\nformat ascii 1.0\nelement vertex {len(v)}\nproperty float x\n"
                 f"property float y\nproperty float z\nelement face {len(f)}\n"
                 "property list uchar int vertex_indices\nend_header\n")
        np.savetxt(fh, v, fmt="%.9g")
        np.savetxt(fh, np.column_stack([np.full(len(f), 3), f]), fmt="%d")


def mitsuba_image(ply: Path, sun: np.ndarray, size: int, spp: int, depth: int) -> np.ndarray:
    import mitsuba as mi

    mi.set_variant("scalar_rgb")
    scene = mi.load_dict({
        "type": "scene",
        "integrator": {"type": "path", "max_depth": depth},
        "sensor": {"type": "perspective", "fov": FOV_DEG, "fov_axis": "x",
                   "to_world": mi.ScalarTransform4f().look_at(
                       origin=[0.0, 0.0, HEIGHT_M], target=[0.0, 0.0, 0.0],
                       up=[0.0, 1.0, 0.0]),
                   "film": {"type": "hdrfilm", "width": size, "height": size,
                            "rfilter": {"type": "box"}, "pixel_format": "luminance"},
                   "sampler": {"type": "independent", "sample_count": spp}},
        "sun": {"type": "directional", "direction": (-sun).tolist(),
                "irradiance": {"type": "rgb", "value": [np.pi] * 3}},
        "crater": {"type": "ply", "filename": str(ply), "face_normals": True,
                   "bsdf": {"type": "diffuse",
                            "reflectance": {"type": "rgb", "value": [ALBEDO] * 3}}},
    })
    return np.asarray(mi.render(scene, spp=spp), dtype=np.float64)[:, :, 0]


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", type=int, default=96)
    ap.add_argument("--spp", type=int, default=4096)
    ap.add_argument("--bounces", type=int, choices=(1, 2), default=1)
    ap.add_argument("--our-spp", type=int, default=None,
                    help="craterform's bounce rays a pixel (default: --spp)")
    ap.add_argument("--filter-px", type=int, default=0,
                    help="craterform's bounce_filter_px (the camera's default: 4)")
    args = ap.parse_args()
    our_spp = args.spp if args.our_spp is None else args.our_spp
    v, f = crater_mesh()
    mesh = RayMesh(v, f)
    el = np.radians(ELEVATION_DEG)
    sun = np.array([np.cos(el), 0.0, np.sin(el)])
    cam = Camera.from_fov(FOV_DEG, args.size, args.size)
    # OpenCV frame: y down in the image = -y of the ground, as Mitsuba's "up" = +y
    pose = Pose.look_at([0.0, 0.0, HEIGHT_M], [0.0, 0.0, 0.0], up=(0.0, 1.0, 0.0))
    kw = {"reflectance": Lambert(ALBEDO), "normals": "face"}
    t0 = time.perf_counter()
    direct = render(mesh, cam, pose, sun, **kw).reflectance
    t1 = time.perf_counter()
    # more than render's 4096 rays a pixel: the mean of renders with other seeds
    runs = [render(mesh, cam, pose, sun, bounces=args.bounces, bounce_samples=min(our_spp, 4096),
                   bounce_filter_px=args.filter_px, seed=s, **kw)
            for s in range(max(1, our_spp // 4096))]
    ours = runs[0]
    bounced = np.mean([fr.reflectance for fr in runs], axis=0)
    t2 = time.perf_counter()
    with tempfile.TemporaryDirectory() as tmp:
        ply = Path(tmp) / "crater.ply"
        write_ply(ply, v, f)
        t3 = time.perf_counter()
        mi_direct = mitsuba_image(ply, sun, args.size, 64, 2)
        t4 = time.perf_counter()
        mi_bounce = mitsuba_image(ply, sun, args.size, args.spp, 2 + args.bounces)
        t5 = time.perf_counter()
    pts = ours.position_m
    r = np.hypot(pts[:, :, 0], pts[:, :, 1]) / (DIAMETER_M / 2)
    lit_both = (direct > 0) & (mi_direct > 0.02 * ALBEDO)
    agree = np.median(np.abs(direct[lit_both] - mi_direct[lit_both]) / mi_direct[lit_both])
    print(f"direct light, lit pixels ({lit_both.sum()}): median relative difference "
          f"{agree:.4f} (Mitsuba 64 spp over each pixel's area, craterform at its centre)")
    floor = (r < 0.8) & (direct == 0.0) & (mi_direct == 0.0)
    rel = (bounced[floor] - mi_bounce[floor]) / mi_bounce[floor]
    print(f"shadowed floor pixels: {floor.sum()}; bounced I/F median "
          f"{np.median(bounced[floor]):.5f} (craterform) vs {np.median(mi_bounce[floor]):.5f}"
          " (Mitsuba)")
    print(f"median relative difference {np.median(np.abs(rel)):.4f}, median signed "
          f"{np.median(rel):+.4f}, 90th percentile {np.percentile(np.abs(rel), 90):.4f}")
    print(f"times: craterform direct {t1 - t0:.2f} s, bounce ({our_spp} rays a pixel, "
          f"filter {args.filter_px} px) "
          f"{t2 - t1:.2f} s; Mitsuba direct {t4 - t3:.2f} s, path depth {2 + args.bounces} "
          f"({args.spp} spp) "
          f"{t5 - t4:.2f} s")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
