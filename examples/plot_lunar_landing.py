"""A lunar landing over a ``dem enhance`` stack: camera frames, depth and crater labels.

The README's landing-site stack (``examples/site.toml``: the LOLA LDEM_4 crop in
``tests/data`` around 0 N 180 E, 11 layers of 129 x 129 from 7.6 km down to 7.4 m per
pixel, a 3.9 Gyr lunar crater population below what LOLA resolves) is meshed as ``dem
mesh`` meshes it: one open, crack-free multi-resolution surface in the stack's local
frame (x east, y north, z = height above the 1737.4 km sphere, metres; the Moon's
curvature left out). Only the layers from 59 km across down are meshed: the view never
reaches further, and a smaller model keeps the shadow rays' lift (a fraction of the
model's size) to centimetres. A 30 deg camera (512 x 512) descends towards the site
along a line 35 deg off the vertical, from 40 km to 1.2 km range, with the sun 8 deg
above the eastern horizon (a morning landing, as Apollo's at 7-15 deg): Hapke's model
with lunar parameters, cast shadows, one fixed exposure. The crater catalog of the stack
gives every frame's crater-id image; the rims of the labelled craters are projected as
ellipses (rims fitted to the stamped surface). Level of detail: each frame meshes the
layers down to the first finer than 0.7 of its pixel size at the site. The stack adds
smaller craters only in its finer, central layers, so the crater density steps up towards
the site: the denser patch in the middle of the first frames is the stack's structure,
not the Moon's.

Writes ``lunar_landing.png``. Environment: ``CRATERFORM_EXAMPLE_OUT`` (default ``out``)
and ``CRATERFORM_EXAMPLE_SMALL=1`` (5 layers of 65 x 65, 3 frames of 128 x 128).
"""

import os
import time
import tomllib
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.colors import ListedColormap  # noqa: E402
from matplotlib.patches import Ellipse  # noqa: E402

import dem  # noqa: E402
from dem.stack import Stack  # noqa: E402
from latlong.sensors import (  # noqa: E402
    HAPKE_PRESETS,
    Camera,
    SceneGeometry,
    Sensor,
    Sun,
    expose,
    render,
    rim_curves,
    rim_ellipses,
    scene_mesh,
)
from latlong.sensors.poses import approach  # noqa: E402

small = os.environ.get("CRATERFORM_EXAMPLE_SMALL") == "1"
out = Path(os.environ.get("CRATERFORM_EXAMPLE_OUT", "out"))
out.mkdir(parents=True, exist_ok=True)
root = Path(__file__).resolve().parents[1]
t0 = time.perf_counter()

# the stack of examples/site.toml (as `dem enhance --config examples/site.toml` makes it)
with open(root / "examples" / "site.toml", "rb") as f:
    site = tomllib.load(f)
base = dem.read(root / site.pop("input"))
site.pop("output")
scene = {**site, "seed": 2014}
if small:
    scene.update(layers=5, size=65)
stack = dem.enhance(scene, dem=base)
sizes = stack.pixel_sizes_m()
first = 1 if small else 3  # the coarsest layer meshed


def site_model(finest):
    """The mesh of layers first..finest, its crater catalog (as the labels want it) and
    the rims fitted to it."""
    sub = Stack(stack.layers[first:finest + 1], stack.windows[first:finest], stack.frame,
                stack.catalogs[first:finest + 1])
    verts, faces, _ = dem.mesh.mesh_arrays(sub)
    mesh = scene_mesh((verts, faces))
    # centre on the surface (a vertical ray down the mesh), up axis +z, rim radius; rows
    # in stamping order (coarse layers first), craters outside the meshed area dropped
    cat = np.concatenate([c for c in stack.catalogs[:finest + 1] if c is not None and len(c)])
    half = 0.5 * (sub.layers[0].shape[0] - 1) * sizes[first]
    cat = cat[(np.abs(cat["x_m"]) < half) & (np.abs(cat["y_m"]) < half)]
    top = verts[:, 2].max() + 100.0
    hits = mesh.intersect(np.stack([cat["x_m"], cat["y_m"], np.full(len(cat), top)], 1),
                          np.tile([0.0, 0.0, -1.0], (len(cat), 1)))
    labels = np.zeros(len(cat), dtype=[(n, "<f8") for n in (
        "centre_x_m", "centre_y_m", "centre_z_m", "normal_x", "normal_y", "normal_z",
        "rim_radius_m", "rim_height_m", "diameter_m")])
    for name, value in (("centre_x_m", cat["x_m"]), ("centre_y_m", cat["y_m"]),
                        ("centre_z_m", top - hits.t_m), ("normal_z", 1.0),
                        ("rim_radius_m", cat["rim_radius_m"]),
                        ("rim_height_m", cat["rim_height_m"]),
                        ("diameter_m", cat["diameter_m"])):
        labels[name] = value
    geo = SceneGeometry(verts, faces, np.full(len(faces), -1, dtype=np.int32), labels)
    ground = top - mesh.intersect([0.0, 0.0, top], [[0.0, 0.0, -1.0]]).t_m[0]
    return mesh, geo, rim_curves(labels, geo), np.array([0.0, 0.0, ground])


models = {}
print(f"stack: {len(stack)} layers, {sizes[0]:.0f} ... {sizes[-1]:.1f} m/px, "
      f"{sum(len(c) for c in stack.catalogs if c is not None)} craters "
      f"({time.perf_counter() - t0:.1f} s)")

# the landing: towards the site (the stack's origin), sun low in the east
target = site_model(first)[3]  # the site: the stack's origin, on the ground
sun_elevation_deg = 8.0
el = np.radians(sun_elevation_deg)
sun = Sun([np.cos(el) * np.cos(np.radians(10.0)), np.cos(el) * np.sin(np.radians(10.0)),
           np.sin(el)])
n_frames = 3 if small else 5
start_m, end_m = (30000.0, 4000.0) if small else (40000.0, 1200.0)
poses = approach(target, n_frames=n_frames, start_range_m=start_m, end_range_m=end_m,
                 path_angle_deg=35.0, path_azimuth_deg=180.0, duration_s=180.0,
                 vertical=(0.0, 0.0, 1.0))
size = 128 if small else 512
camera = Camera.from_fov(30.0, size, size)
model = HAPKE_PRESETS["moon"]
frames, finest = [], []
for k in range(n_frames):  # level of detail: layers down to the frame's pixel size
    gsd = np.linalg.norm(poses.position_m[k] - target) / camera.fx
    j = max(i for i in range(first, len(stack)) if i == first or sizes[i] >= 0.7 * gsd)
    if j not in models:
        models[j] = site_model(j)
    mesh, geo, rims, _ = models[j]
    finest.append(j)
    frames.append(render(mesh, camera, poses[k], sun, reflectance=model, ground_truth=geo,
                         seed=k))
t_render = time.perf_counter()

# one exposure for the landing: the brightest 0.1 % of lit pixels at 90 % of full scale
lit = np.concatenate([f.reflectance[f.reflectance > 0] for f in frames])
sensor = Sensor(exposure_s=0.01, flux_e_per_s=0.9 * 40000.0 / (0.01 * np.percentile(lit, 99.9)),
                bits=16, photon_noise=True, read_noise_e=20.0)
images = [expose(f.reflectance, sensor, seed=k) for k, f in enumerate(frames)]
shadow = [float(np.mean((f.sunlit == 0) & (f.face >= 0))) for f in frames]
print(f"{n_frames} frames of {size} x {size}; ground in shadow: "
      f"{', '.join(f'{100 * s:.0f} %' for s in shadow)}")

# the picture: images, depth, crater labels over the image with the projected rims
rng = np.random.default_rng(0)
colours = ListedColormap(np.concatenate([[[0.0, 0.0, 0.0]], 0.2 + 0.8 * rng.random(
    (sum(len(c) for c in stack.catalogs if c is not None), 3))]))
fig, axes = plt.subplots(3, n_frames, figsize=(3.4 * n_frames, 11.2), squeeze=False)
fx, fy, cx, cy = camera.fx, camera.fy, camera.cx, camera.cy
for k, f in enumerate(frames):
    pose = poses[k]
    rng_c = float(np.linalg.norm(pose.position_m - target))
    height = float(pose.position_m[2] - target[2])
    _, geo, rims, _ = models[finest[k]]
    a0, a1, a2 = axes[0, k], axes[1, k], axes[2, k]
    a0.imshow(images[k], cmap="gray", vmin=0, vmax=65535, interpolation="nearest")
    a0.set_title(f"t = {pose.time_s:.0f} s: range {rng_c / 1e3:.1f} km, height "
                 f"{height / 1e3:.1f} km\n{rng_c / fx:.1f} m/px at the site; mesh down to "
                 f"{sizes[finest[k]]:.3g} m/px", fontsize=10)
    im = a1.imshow(f.depth_m / 1e3, cmap="viridis", interpolation="nearest")
    cb = fig.colorbar(im, ax=a1, orientation="horizontal", fraction=0.05, pad=0.03)
    cb.set_label("depth (camera z), km", fontsize=9)
    cb.ax.tick_params(labelsize=8)
    ids = f.crater_id
    grey = np.repeat(images[k][..., None] / 65535.0, 3, axis=2)
    over = np.where((ids >= 0)[..., None], 0.45 * grey + 0.55 * colours(ids + 1)[..., :3],
                    0.8 * grey)
    a2.imshow(over, interpolation="nearest")
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
axes[0, 0].set_ylabel("image (Hapke, lunar parameters, 16-bit)", fontsize=10)
axes[1, 0].set_ylabel("depth ground truth", fontsize=10)
axes[2, 0].set_ylabel("crater ids over the image,\nprojected rims (yellow)", fontsize=10)
fig.suptitle(f"Lunar landing at 0 N 180 E over the examples/site.toml stack (LOLA LDEM_4 + "
             f"dem enhance, {len(stack)} layers): {camera.width} x {camera.height} px, 30 deg "
             f"field of view, sun {sun_elevation_deg:.0f} deg above the eastern horizon, cast "
             "shadows", fontsize=12)
fig.tight_layout(rect=(0, 0, 1, 0.97))
fig.savefig(out / "lunar_landing.png", dpi=60 if small else 100)
plt.close(fig)
print(f"rendered in {t_render - t0:.1f} s (with the stack); wrote {out / 'lunar_landing.png'}")
