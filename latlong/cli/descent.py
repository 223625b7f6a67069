"""``latlong descent``: camera frames of a vertical descent from orbit to touchdown over
terrain made on demand for each frame (:mod:`latlong.ondemand.descent`), with the
scene options of ``latlong build``: per frame the camera's files (image, depth, range,
normals) and an 8-bit picture for people (exposed on its own lit pixels), and
``frames.json``; ``strip.png`` puts the pictures side by side.
"""

from __future__ import annotations

import sys

import numpy as np

from craters.cli.kit import CliError
from craters.cli.options import FORCE, QUIET, Setting, Values, command, declared_keys

from ..scene import SETTING_PARTS, SETTINGS, Scene
from .build import GROUPS

__all__ = ["OPTIONS", "register"]

DESCENT = {
    "lat_deg": Setting(help="latitude of the landing site", unit="deg", range=(-90.0, 90.0),
                       kind=float, required=True, run=True),
    "lon_deg": Setting(help="longitude of the landing site", unit="deg", range="finite",
                       kind=float, required=True, run=True),
    "start_m": Setting(100000.0, "first altitude above the site", unit="m", range=(0.01, 1e9),
                       run=True),
    "stop_m": Setting(1.0, "last altitude above the site", unit="m", range=(0.001, 1e9),
                      run=True),
    "frames": Setting(6, "frames, altitudes evenly spaced in log", range=(1, 100000), run=True),
    "fov_deg": Setting(30.0, "horizontal field of view", unit="deg", range=(1.0, 120.0),
                       run=True),
    "size_px": Setting(512, "picture width and height", range=(16, 8192), run=True),
    "sun_azimuth_deg": Setting(90.0, "sun azimuth at the site, clockwise from north",
                               unit="deg", range="finite", run=True),
    "sun_elevation_deg": Setting(25.0, "sun elevation above the site's horizon", unit="deg",
                                 range=(0.5, 90.0), run=True),
    "output": Setting(help="output folder", flag="-o/--output", required=True, run=True),
}
#: Every option of ``latlong descent``: the scene's settings, the descent, the outputs.
OPTIONS = {k: s for k, s in declared_keys(
    *(part for part in SETTING_PARTS if part[0] not in ("implicit", "render")),
    ("descent", DESCENT), ("output", {"quiet": QUIET, "force": FORCE})).items()
    if k not in ("on_demand", "max_memory_gb", "radii_on_disk", "surface", "spacing_m")}
_GROUPS = {"descent": "descent and outputs", **GROUPS}


def display(reflectance: np.ndarray, scale: float) -> np.ndarray:
    """An 8-bit picture of an I/F image: ``scale`` to white, gamma 1/2.2."""
    return (255.0 * np.clip(reflectance / scale, 0.0, 1.0) ** (1.0 / 2.2) + 0.5).astype(np.uint8)


def _descent(v: Values) -> int:
    from craters._shared import atomic_path
    from latlong.sensors.camera_files import write_frame, write_manifest
    from latlong.sensors.runs import check_output_folder, run_folder

    from ..ondemand.descent import descent, descent_altitudes

    if v["stop_m"] > v["start_m"]:
        raise CliError(f"--stop-m ({v['stop_m']:g}) must be at most --start-m ({v['start_m']:g})")
    try:
        out = check_output_folder(v["output"], force=v["force"])
    except ValueError as exc:
        raise CliError(f"-o/--output: {exc}") from None
    scene = Scene.from_settings({**{k: v[k] for k in SETTINGS if k in v.given},
                                 "on_demand": True})
    alts = descent_altitudes(v["start_m"], v["stop_m"], v["frames"])
    from PIL import Image

    entries, pictures = [], []
    with run_folder(out, "frames.json") as tmp:
        for i, f in enumerate(descent(scene, v["lat_deg"], v["lon_deg"], alts,
                                      fov_deg=v["fov_deg"], width_px=v["size_px"],
                                      sun_azimuth_deg=v["sun_azimuth_deg"],
                                      sun_elevation_deg=v["sun_elevation_deg"])):
            files = write_frame(tmp, i, f.frame)
            r = f.frame.reflectance
            # each picture exposed on its own lit pixels (the 99.5th percentile to white),
            # as a descent camera's auto-exposure would
            lit = r[r > 0]
            scale = float(np.percentile(lit, 99.5)) if len(lit) else 1.0
            pic = display(r, scale)
            files["picture"] = f"picture_{i:04d}.png"
            with atomic_path(tmp / files["picture"]) as p:
                Image.fromarray(pic).save(p, format="PNG")
            pictures.append(pic)
            entries.append({"altitude_m": f.altitude_m, "ground_pixel_m": f.ground_pixel_m,
                            "picture_white_if": scale,
                            "terrain": f.terrain, "craters": f.n_craters, "rocks": f.n_rocks,
                            "position_m": [float(x) for x in f.frame.pose.position_m],
                            "quaternion_wxyz": [float(x) for x in
                                                f.frame.pose.quaternion_wxyz],
                            "sun_direction": [float(x) for x in f.frame.sun.direction],
                            "files": files})
            if not v["quiet"]:
                print(f"frame {i}: altitude {f.altitude_m:.4g} m, ground pixel "
                      f"{f.ground_pixel_m:.3g} m, {f.n_craters} craters, {f.n_rocks} rocks "
                      f"({f.terrain})",
                      file=sys.stderr)
        gap = np.zeros((pictures[0].shape[0], 4), np.uint8)
        strip = np.concatenate([x for p in pictures for x in (p, gap)][:-1], axis=1)
        with atomic_path(tmp / "strip.png") as p:
            Image.fromarray(strip).save(p, format="PNG")
        cam = f.frame.camera
        write_manifest(tmp, {"intrinsics": cam.intrinsics(), "seed": scene.seed,
                             "site_lat_lon_deg": [v["lat_deg"], v["lon_deg"]],
                             "frames": entries})
    if not v["quiet"]:
        print(f"wrote {len(entries)} frames, {out / 'strip.png'}, {out / 'frames.json'}")
    return 0


def register(sub) -> None:
    """Register ``latlong descent``."""
    command(sub, "descent", _descent, OPTIONS, groups=_GROUPS, config=True, prog="latlong",
            help="camera frames of a descent from orbit to touchdown over terrain made on "
            "demand for each frame")
