"""Measure: crater-id labels against the projected rim ellipses on crater-saturated frames.

Issue 17's acceptance: for the visible craters of a frame, the pixels labelled with a
crater's id all lie within its projected rim ellipse and cover >= 95 % of it. Frames: a
512 x 512 flash LIDAR (one beam per pixel, its pinhole intrinsics) over a 1 km body
(M = 400, ~4 m spacing) with ~1500 craters of 30-300 m (N_cum ~ D^-2, overlapping),
seen at nadir and 35 degrees off nadir, with the rim ellipses of the catalog rule and
fitted to the surface (:func:`latlong.sensors.labels.rim_curves`). Per crater whose
ellipse has a semi-minor axis of >= 8 px and lies in the frame: the share of its
labelled pixels within the ellipse grown by 1.5 px, and the share of the ellipse's
pixels labelled with its id - raw, and with the pixels of younger craters (which win
where they overlap, by the label rule) set aside. Writes ``sensors_lidar_labels.png`` (range image,
label image with the ellipses) to the folder given (default: the current one).
Usage: ``python tests/benchmarks/measure_label_coverage.py [OUT_FOLDER]``.
"""

from __future__ import annotations

import itertools
import sys
from pathlib import Path

import numpy as np

import craters
from latlong import Body, LatLongGrid, stamp_craters
from latlong.sensors.camera import Camera, Pose
from latlong.sensors.engine import RayMesh
from latlong.sensors.labels import rim_curves, rim_ellipses
from latlong.sensors.lidar import LidarSettings, lidar_frame
from latlong.sensors.render import Sun, render
from latlong.sensors.scene_geometry import scene_geometry


def _look_at(position_m, target_m):
    return Pose.look_at(position_m, target_m).quaternion_wxyz


def ellipse_radius(e, i, j):
    ca, sa = np.cos(np.radians(e["angle_deg"])), np.sin(np.radians(e["angle_deg"]))
    x, y = i - e["centre_x_px"], j - e["centre_y_px"]
    return np.hypot((x * ca + y * sa) / e["semi_major_px"],
                    (-x * sa + y * ca) / e["semi_minor_px"])


def measure(body, geo, mesh, pos, target, rims=None, size=512, sensor="lidar"):
    q = _look_at(pos, target)
    s = LidarSettings(beams=(size, size), fov_deg=30.0)
    k = s.intrinsics()
    if sensor == "camera":  # the camera's crater-id image, same intrinsics and pose
        cam = Camera(k["fx"], k["fy"], k["cx"], k["cy"], size, size)
        fr = render(mesh, cam, Pose(pos, q), Sun(pos / np.linalg.norm(pos)), ground_truth=geo)
        lab = fr.crater_id.astype(np.int64)
    else:
        fr = lidar_frame(mesh, s, pos, q, ground_truth=geo)
        lab = np.full(size * size, -1)
        lab[fr.beam] = fr.crater_id
        lab = lab.reshape(size, size)
    ell = rim_ellipses(body.craters, (k["fx"], k["fy"], k["cx"], k["cy"]), pos, q,
                       ids=np.unique(lab[lab >= 0]), width=size, height=size, rims=rims)
    i, j = np.meshgrid(np.arange(size) + 0.5, np.arange(size) + 0.5)
    rows = []
    for e in ell:
        if e["semi_minor_px"] < 8:
            continue
        r = ellipse_radius(e, i, j)
        inside = r <= 1.0
        if not inside.sum() or (np.abs(e["centre_x_px"] - size / 2) + e["semi_major_px"]
                                > size / 2) or (np.abs(e["centre_y_px"] - size / 2)
                                                + e["semi_major_px"] > size / 2):
            continue  # partly outside the frame
        mine = lab == e["crater_id"]
        within = (r[mine] <= 1.0 + 1.5 / e["semi_minor_px"]).mean()
        cover = (mine & inside).sum() / inside.sum()
        younger = inside & (lab > e["crater_id"])
        cover_free = (mine & inside).sum() / max((inside & ~younger).sum(), 1)
        rows.append((int(e["crater_id"]), e["semi_minor_px"], within, cover, cover_free))
    return fr, lab, ell, np.array(rows)


def main():
    out = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(".")
    radius = 1000.0
    body = Body.sphere(LatLongGrid(400), radius)
    area = 4 * np.pi * radius**2
    cat = craters.power_law_population(radius=radius, c=1500 / (area * (30.0**-2 - 300.0**-2)),
                                       k=-2.0, d_min=30.0, d_max=300.0, rng=4)
    body = stamp_craters(body, cat, rng=4)
    geo = scene_geometry(body)
    mesh = RayMesh(geo.vertices, geo.faces)
    print(f"body: R = 1 km, M = 400, {len(body.craters)} craters of 30-300 m")
    views = {"nadir": ([radius + 900.0, 0.0, 0.0], [0.0, 0.0, 0.0]),
             "35 deg off nadir": ([radius + 700.0, -500.0, 0.0], [radius, 0.0, 0.0])}
    fitted = rim_curves(body.craters, geo)
    shown = []
    for (name, (pos, target)), (rule, rims), sensor in itertools.product(
            views.items(), (("catalog rims", None), ("rims fitted to the surface", fitted)),
            ("lidar", "camera")):
        fr, lab, ell, rows = measure(body, geo, mesh, np.array(pos), np.array(target), rims,
                                     sensor=sensor)
        if sensor == "camera":
            print(f"{name}, {rule}, camera frame (latlong.render crater_id):")
            print(f"  labelled pixels within their ellipse (+1.5 px): min "
                  f"{rows[:, 2].min():.4f}; ellipse covered, younger craters set aside: min "
                  f"{rows[:, 4].min():.3f} median {np.median(rows[:, 4]):.3f}, >= 0.95 for "
                  f"{np.mean(rows[:, 4] >= 0.95):.0%}")
            continue
        print(f"{name}, {rule}: {len(rows)} craters fully in the frame with semi-minor "
              ">= 8 px")
        print(f"  labelled pixels within their ellipse (+1.5 px): min {rows[:, 2].min():.4f}, "
              f"mean {rows[:, 2].mean():.4f}")
        print(f"  ellipse covered by its id: raw min {rows[:, 3].min():.3f} median "
              f"{np.median(rows[:, 3]):.3f}, >= 0.95 for {np.mean(rows[:, 3] >= 0.95):.0%}; "
              f"younger craters set aside: min {rows[:, 4].min():.3f} median "
              f"{np.median(rows[:, 4]):.3f}, >= 0.95 for {np.mean(rows[:, 4] >= 0.95):.0%}")
        worst = rows[np.argmin(rows[:, 4])]
        print(f"  worst (younger set aside): crater {int(worst[0])}, semi-minor "
              f"{worst[1]:.1f} px, cover {worst[4]:.3f}")
        if rims is not None:
            shown.append((name, fr, lab, ell))
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.patches import Ellipse

    fig, axes = plt.subplots(2, 2, figsize=(13, 13))
    cmap = plt.get_cmap("tab20")
    for row, (name, fr, lab, ell) in enumerate(shown):
        axes[row, 0].imshow(fr.range_image, cmap="magma")
        axes[row, 0].set_title(f"{name}: LIDAR range image, 512 x 512 flash")
        shade = np.where(lab >= 0, lab % 20, np.nan)
        axes[row, 1].imshow(np.isfinite(fr.range_image), cmap="gray", vmin=0, vmax=3)
        axes[row, 1].imshow(shade, cmap=cmap, vmin=0, vmax=19, interpolation="nearest")
        for e in ell:  # imshow puts pixel (0, 0)'s centre at 0: pixel coords - 0.5
            axes[row, 1].add_patch(Ellipse((e["centre_x_px"] - 0.5, e["centre_y_px"] - 0.5),
                                           2 * e["semi_major_px"], 2 * e["semi_minor_px"],
                                           angle=e["angle_deg"], fill=False, color="k",
                                           lw=0.8))
        axes[row, 1].set_title("crater_id per beam (colour), fitted rim ellipses")
        for a in axes[row]:
            a.set_xticks([])
            a.set_yticks([])
    fig.tight_layout()
    fig.savefig(out / "sensors_lidar_labels.png", dpi=80)
    print(f"wrote {out / 'sensors_lidar_labels.png'}")


if __name__ == "__main__":
    main()
