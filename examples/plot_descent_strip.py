"""A descent over Eros: camera frames with their depth and crater-label ground truth.

The ``eros`` preset (the NEAR shape model, craters near saturation above 0.2 km, boulders)
seen by a 20 deg camera (512 x 512) descending straight towards a point of the surface:
five frames from 9 km to 1.2 km range, 25 deg off the local vertical, the sun 12 deg above
the local horizon. Each frame is rendered with cast shadows under the Hapke model of an
S-type asteroid (Eros itself: Li et al. 2004), exposed with one fixed exposure for the
whole descent (16-bit), with its ground truth: depth (camera z, metres) and the crater-id
label image (pixel -> catalog row of the crater whose rim contains the surface point),
with the projected rim ellipses of the visible craters drawn over the labels. Boulders
are outlined in white.

Writes ``descent_strip.png``. Environment: ``CRATERFORM_EXAMPLE_OUT`` (default ``out``)
and ``CRATERFORM_EXAMPLE_SMALL=1`` (a coarse body, 3 frames of 128 x 128).
"""

import os
import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.colors import ListedColormap  # noqa: E402
from matplotlib.patches import Ellipse  # noqa: E402

from latlong import Scene, build  # noqa: E402
from latlong.sensors import (  # noqa: E402
    HAPKE_PRESETS,
    Camera,
    Sensor,
    Sun,
    expose,
    render,
    rim_curves,
    rim_ellipses,
    scene_geometry,
    scene_mesh,
)
from latlong.sensors.poses import approach, surface_point  # noqa: E402

small = os.environ.get("CRATERFORM_EXAMPLE_SMALL") == "1"
out = Path(os.environ.get("CRATERFORM_EXAMPLE_OUT", "out"))
out.mkdir(parents=True, exist_ok=True)
t0 = time.perf_counter()

# the body: Eros at magnitude 700 (the preset's: ~16 m between vertices)
body = build(Scene.from_settings({"preset": "eros", "magnitude": 60 if small else 700,
                                  "seed": 4}))
geo = scene_geometry(body)
mesh = scene_mesh(geo)  # the BVH, built once for every frame
rims = rim_curves(geo.craters, geo)  # rim crests fitted to the stamped surface
print(f"body: M = {body.magnitude}, {len(mesh.faces):,} triangles, {len(body.craters)} "
      f"craters, {len(body.boulders)} boulders ({time.perf_counter() - t0:.1f} s)")

# the descent: towards a point of the surface, the sun low in the east of the target
target = surface_point(mesh, -30.0, 90.0)
near = np.linalg.norm(mesh.vertices - target, axis=1) < 1500.0
up = mesh.vertex_normals[near].mean(axis=0)  # the mean local surface normal
up /= np.linalg.norm(up)
east = np.cross([0.0, 0.0, 1.0], up)
east /= np.linalg.norm(east)
north = np.cross(up, east)
sun_elevation_deg = 12.0
el = np.radians(sun_elevation_deg)
sun = Sun(np.cos(el) * (0.8 * east + 0.6 * north) + np.sin(el) * up)
n_frames = 3 if small else 5
poses = approach(target, n_frames=n_frames, start_range_m=30000.0, end_range_m=4000.0,
                 path_angle_deg=25.0, path_azimuth_deg=200.0, duration_s=240.0)
size = 128 if small else 512
camera = Camera.from_fov(20.0, size, size)
model = HAPKE_PRESETS["s-type"]
frames = [render(mesh, camera, poses[k], sun, reflectance=model, ground_truth=geo, seed=k)
          for k in range(n_frames)]
t_render = time.perf_counter()

# one exposure for the descent: the brightest 0.1 % of lit pixels at 90 % of full scale
lit = np.concatenate([f.reflectance[f.reflectance > 0] for f in frames])
sensor = Sensor(exposure_s=0.01, flux_e_per_s=0.9 * 40000.0 / (0.01 * np.percentile(lit, 99.9)),
                bits=16, photon_noise=True, read_noise_e=20.0)
images = [expose(f.reflectance, sensor, seed=k) for k, f in enumerate(frames)]
shadow = np.mean([np.mean((f.sunlit == 0) & (f.face >= 0)) for f in frames])
print(f"{n_frames} frames of {size} x {size}; {100 * shadow:.0f} % of the ground in shadow")

# the picture: images, depth, crater labels with the projected rim ellipses
rng = np.random.default_rng(0)
colours = ListedColormap(np.concatenate([[[0.0, 0.0, 0.0]],
                                         0.2 + 0.8 * rng.random((len(geo.craters), 3))]))
fig, axes = plt.subplots(3, n_frames, figsize=(3.4 * n_frames, 11.2), squeeze=False)
fx, fy, cx, cy = camera.fx, camera.fy, camera.cx, camera.cy
for k, f in enumerate(frames):
    pose = poses[k]
    rng_c = float(np.linalg.norm(pose.position_m - target))
    height = float((pose.position_m - target) @ up)
    a0, a1, a2 = axes[0, k], axes[1, k], axes[2, k]
    a0.imshow(images[k], cmap="gray", vmin=0, vmax=65535, interpolation="nearest")
    a0.set_title(f"t = {pose.time_s:.0f} s: range {rng_c / 1e3:.2f} km\n"
                 f"height {height / 1e3:.2f} km, {rng_c / fx:.2f} m/px", fontsize=10)
    im = a1.imshow(f.depth_m / 1e3, cmap="viridis", interpolation="nearest")
    cb = fig.colorbar(im, ax=a1, orientation="horizontal", fraction=0.05, pad=0.03)
    cb.set_label("depth (camera z), km", fontsize=9)
    cb.ax.tick_params(labelsize=8)
    ids = f.crater_id  # the labels over the image: each crater its own colour
    grey = np.repeat(images[k][..., None] / 65535.0, 3, axis=2)
    over = np.where((ids >= 0)[..., None], 0.45 * grey + 0.55 * colours(ids + 1)[..., :3],
                    0.8 * grey)
    a2.imshow(over, interpolation="nearest")
    if f.boulder_id is not None and (f.boulder_id >= 0).any():
        a2.contour(f.boulder_id >= 0, levels=[0.5], colors="white", linewidths=0.8)
    seen, counts = np.unique(ids[ids >= 0], return_counts=True)
    big = seen[counts >= 150]  # rims drawn for the craters of 150 pixels or more
    ell = rim_ellipses(geo.craters, (fx, fy, cx, cy), pose.position_m, pose.quaternion_wxyz,
                       ids=big, width=camera.width, height=camera.height, rims=rims)
    for e in ell:
        a2.add_patch(Ellipse((e["centre_x_px"] - 0.5, e["centre_y_px"] - 0.5),
                             2 * e["semi_major_px"], 2 * e["semi_minor_px"],
                             angle=e["angle_deg"], fill=False, ec="yellow", lw=0.8))
    a2.set_xlim(-0.5, camera.width - 0.5)
    a2.set_ylim(camera.height - 0.5, -0.5)
    a2.set_title(f"{len(seen)} craters labelled, {len(ell)} rims (>= 150 px)", fontsize=10)
    for a in (a0, a1, a2):
        a.set_xticks([])
        a.set_yticks([])
axes[0, 0].set_ylabel("image (Hapke S-type, 16-bit)", fontsize=10)
axes[1, 0].set_ylabel("depth ground truth", fontsize=10)
axes[2, 0].set_ylabel("crater ids over the image,\nprojected rims (yellow), boulders (white)",
                     fontsize=10)
fig.suptitle(f"Descent over 433 Eros (preset 'eros', M = {body.magnitude}): {camera.width} x "
             f"{camera.height} px, 20 deg field of view, sun {sun_elevation_deg:.0f} deg above "
             "the local horizon, cast shadows", fontsize=12)
fig.tight_layout(rect=(0, 0, 1, 0.97))
fig.savefig(out / "descent_strip.png", dpi=60 if small else 100)
plt.close(fig)
print(f"rendered in {t_render - t0:.1f} s (with the body); wrote {out / 'descent_strip.png'}")
