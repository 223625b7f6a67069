"""A LIDAR sweep over a Bennu-like asteroid, shown as a point cloud.

A scanning LIDAR 600 m above the surface of the ``bennu`` preset (the radar shape model
with craters and boulders) slews across it: one raster frame per pose, 0.5 mrad beams of
4 sub-rays, 2 cm range noise, multiple returns. The run is written as the ``latlong
lidar`` command writes it (LAS 1.4 per frame, range images, ``lidar.json``), read back
with laspy and drawn: the merged point cloud in perspective (pyvista, off-screen,
eye-dome lighting) coloured by local height, one frame's range image and its intensity
image.

Writes ``lidar_sweep.png`` and the run folder ``lidar_sweep/``. Environment:
``CRATERFORM_EXAMPLE_OUT`` (default ``out``) and ``CRATERFORM_EXAMPLE_SMALL=1``.
"""

import json
import os
import shutil
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import laspy  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pyvista as pv  # noqa: E402

from latlong import Scene, build  # noqa: E402
from latlong.sensors.camera import Pose  # noqa: E402
from latlong.sensors.lidar import LidarSettings  # noqa: E402
from latlong.sensors.lidar_files import lidar_run  # noqa: E402
from latlong.sensors.poses import Poses  # noqa: E402
from latlong.sensors.scene_geometry import scene_geometry  # noqa: E402

small = os.environ.get("CRATERFORM_EXAMPLE_SMALL") == "1"
out = Path(os.environ.get("CRATERFORM_EXAMPLE_OUT", "out"))
out.mkdir(parents=True, exist_ok=True)

# the body: Bennu's radar shape, craters and boulders (magnitude 250: ~2.4 m spacing)
body = build(Scene.from_settings({"preset": "bennu", "magnitude": 40 if small else 250,
                                  "seed": 1}))
geo = scene_geometry(body)
print(f"body: M = {body.magnitude}, {len(body.craters)} craters, {len(body.boulders)} "
      "boulders")

# the sweep: 860 m from the centre, the boresight slewing across 16 deg of longitude
n_frames = 3 if small else 8
lon = np.radians(np.linspace(-8.0, 8.0, n_frames))
lat = np.radians(10.0)
dist = 860.0
pos = dist * np.stack([np.cos(lat) * np.cos(lon), np.cos(lat) * np.sin(lon),
                       np.full(n_frames, np.sin(lat))], 1)
target = 240.0 * np.stack([np.cos(lat) * np.cos(lon), np.cos(lat) * np.sin(lon),
                           np.full(n_frames, np.sin(lat))], 1)
quats = np.array([Pose.look_at(p, t).quaternion_wxyz for p, t in zip(pos, target, strict=True)])
poses = Poses(np.arange(n_frames) * 2.0, pos, quats)
settings = LidarSettings(pattern="scan", beams=(48, 36) if small else (160, 120),
                         fov_deg=8.0, divergence_mrad=0.5, rays_per_beam=4,
                         range_noise_m=0.02, multiple_returns=True,
                         return_separation_m=0.5)
run = out / "lidar_sweep"
shutil.rmtree(run, ignore_errors=True)
manifest = lidar_run(geo, settings, poses, run, rng=7)

# read the run back as a user would: lidar.json, then the LAS files
man = json.loads((run / "lidar.json").read_text())
clouds = [laspy.read(run / f["files"]["points"]) for f in man["frames"]]
xyz = np.concatenate([np.stack([c.x, c.y, c.z], 1) for c in clouds])
rock = np.concatenate([np.asarray(c.boulder_id) >= 0 for c in clouds])
crater = np.concatenate([np.asarray(c.crater_id) >= 0 for c in clouds])
second = np.concatenate([np.asarray(c.return_number) > 1 for c in clouds])
height = np.linalg.norm(xyz, axis=1) - body.radius_m
print(f"{len(xyz)} returns in {len(clouds)} frames: {int(rock.sum())} on boulders, "
      f"{int(crater.sum())} in craters, {int(second.sum())} second or later returns")

# the picture: the merged cloud in perspective (eye-dome lighting: the relief of the
# points alone), coloured by height above a quadratic fit of the strip (the body's
# curvature and slope removed), plus one frame's range and intensity images
centre = xyz.mean(axis=0)
up = centre / np.linalg.norm(centre)
east = np.cross([0.0, 0.0, 1.0], up)
east /= np.linalg.norm(east)
north = np.cross(up, east)
loc = xyz - centre
x, y, z = loc @ east, loc @ north, loc @ up
fit = np.stack([np.ones_like(x), x, y, x * x, x * y, y * y], 1)
local = z - fit @ np.linalg.lstsq(fit, z, rcond=None)[0]
cloud = pv.PolyData(xyz)
cloud["local height, m"] = local
pl = pv.Plotter(off_screen=True, window_size=(1300, 900))
pl.add_mesh(cloud, scalars="local height, m", cmap="cividis", point_size=2.5,
            clim=np.percentile(local, [1.0, 99.5]),
            scalar_bar_args={"color": "black", "position_x": 0.3, "position_y": 0.06,
                             "width": 0.4, "title_font_size": 22, "label_font_size": 18})
pl.enable_eye_dome_lighting()
span = float(np.ptp(x))
pl.camera_position = [tuple(centre + span * (1.0 * up - 0.75 * north + 0.1 * east)),
                      tuple(centre), tuple(up)]
pl.set_background("white")
picture = pl.screenshot(return_img=True)
pl.close()
fig = plt.figure(figsize=(17, 8.5))
ax = fig.add_axes([0.0, 0.02, 0.62, 0.9])
ax.imshow(picture)
ax.set_axis_off()
ax.set_title(f"LIDAR sweep over a Bennu-like body: {len(clouds)} raster frames, "
             f"{len(xyz):,} returns (LAS 1.4),\n{int(rock.sum()):,} on boulders; the gaps "
             "behind boulders are LIDAR shadows")
mid = man["frames"][len(clouds) // 2]
rng_img = np.load(run / mid["files"]["range"])
ax2 = fig.add_axes([0.64, 0.53, 0.33, 0.40])
im = ax2.imshow(rng_img, cmap="magma")
ax2.set_title(f"range image of frame {len(clouds) // 2} (first returns), m")
fig.colorbar(im, ax=ax2, fraction=0.04)
las = clouds[len(clouds) // 2]
w, h = settings.beams
inten = np.full(w * h, np.nan)
first = np.asarray(las.return_number) == 1
beam_of = np.flatnonzero(np.isfinite(rng_img.reshape(-1)))
inten[beam_of] = np.asarray(las.intensity)[first]
ax3 = fig.add_axes([0.64, 0.06, 0.33, 0.40])
im3 = ax3.imshow(inten.reshape(h, w), cmap="gray")
ax3.set_title("its intensity (range-normalised energy, 16-bit)")
fig.colorbar(im3, ax=ax3, fraction=0.04)
for a in (ax2, ax3):
    a.set_xticks([])
    a.set_yticks([])
fig.savefig(out / "lidar_sweep.png", dpi=110 if not small else 60)
plt.close(fig)
print(f"wrote {out / 'lidar_sweep.png'} and {run}/ ({len(manifest['frames'])} frames)")
