"""``latlong descent``: camera frames of a vertical descent from orbit to touchdown over
terrain made on demand for each frame (:mod:`latlong.ondemand.descent`), with the
scene options of ``latlong build``: per frame the camera's files (image, depth, range,
normals) and an 8-bit picture for people (exposed on its own lit pixels), and
``frames.json``; ``strip.png`` puts the pictures side by side. ``--lidar`` also fires a
LIDAR (the ``--lidar-*`` options: :class:`~latlong.sensors.LidarSettings`' settings) from
the camera's pose in every frame.
"""

from __future__ import annotations

import dataclasses
import sys

from craters._shared import ParameterError
from craters.cli.kit import CliError, parse_seed
from craters.cli.options import Setting, Values, command, declared_keys

from ..scene import SETTINGS, Scene
from .build import GROUPS
from .tile import on_demand_options

HELP = {
    "descent": "camera frames of a descent from orbit to touchdown over terrain made on demand "
               "for each frame",
}

__all__ = ["DESCENT", "LIDAR", "OPTIONS", "camera_options", "check_descent_folder",
           "lidar_settings", "register", "write_descent_run"]

def _camera_setting(key: str) -> Setting:
    """A setting of :class:`~latlong.sensors.CameraSettings` (declared there once)."""
    from latlong.sensors import CameraSettings

    return declared_keys(CameraSettings)[key]


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
    # the camera's setting, off by default: ~2.5 s more a 1024^2 frame
    "bounces": dataclasses.replace(_camera_setting("bounces"), default=0, run=True),
    "output": Setting(help="output folder", flag="-o/--output", required=True, run=True),
}


def _lidar_table() -> dict[str, Setting]:
    from latlong.sensors import LidarSettings

    from .sensor_options import wxh

    out = {"lidar": Setting(False, "also fire a LIDAR from the camera's pose in every frame "
                            "(lidar_NNNN.las, lidar_range_NNNN.npy; the --lidar-* options)",
                            run=True, group="lidar")}
    for k, s in declared_keys(LidarSettings, beams={
            "parse": wxh("beam counts", "128x96", 4096)}).items():
        out[f"lidar_{k}"] = dataclasses.replace(s, key=f"lidar_{k}", run=True, group="lidar")
    out["lidar_seed"] = Setting(0, "the LIDAR's range-noise seed", kind=int, parse=parse_seed,
                                range=(0, 2**63 - 1), run=True, group="lidar")
    return out


#: The LIDAR options of the descent commands (``--lidar`` and ``--lidar-*``).
LIDAR = _lidar_table()
#: Every option of ``latlong descent``: the scene's settings, the descent, the outputs.
OPTIONS = on_demand_options("descent", {**DESCENT, **LIDAR})
_GROUPS = {"descent": "descent and outputs", "lidar": "LIDAR (with --lidar)", **GROUPS}


def _descent(v: Values) -> int:
    if v["stop_m"] > v["start_m"]:
        raise CliError(f"--stop-m ({v['stop_m']:g}) must be at most --start-m ({v['start_m']:g})")
    out = check_descent_folder(v)  # before the terrain's kernels (numba) load
    from ..ondemand.descent import descent, descent_altitudes

    scene = Scene.from_settings({**{k: v[k] for k in SETTINGS if k in v.given},
                                 "on_demand": True})
    alts = descent_altitudes(v["start_m"], v["stop_m"], v["frames"])
    camera = camera_options(v)
    frames = descent(scene, v["lat_deg"], v["lon_deg"], alts, **camera)
    return write_descent_run(frames, out, v, seed=scene.seed, lidar=camera["lidar"])


def lidar_settings(v: Values):
    """The :class:`~latlong.sensors.LidarSettings` of ``--lidar-*`` (None without
    ``--lidar``); an error names the flag."""
    from latlong.sensors import LidarSettings

    if not v["lidar"]:
        return None
    names = [f.name for f in dataclasses.fields(LidarSettings)]
    try:
        return LidarSettings(**{k: v[f"lidar_{k}"] for k in names})
    except ParameterError as exc:
        raise CliError(exc.shown_as(_lidar_flag(exc.name), name_of=_lidar_flag)) from None


def _lidar_flag(name: str) -> str:
    return f"--lidar-{name.replace('_', '-')}"


def check_descent_folder(v: Values):
    """The checked output folder of a descent command (``-o``, ``--force``), once the
    frames' memory and files are known to fit."""
    from latlong.ondemand.window import check_descent_memory
    from latlong.sensors.camera_files import check_frames_disk
    from latlong.sensors.runs import check_output_folder

    try:
        check_descent_memory(v["size_px"])
    except ParameterError as exc:
        raise exc.renamed("size_px") from None
    try:
        out = check_output_folder(v["output"], force=v["force"])
        check_frames_disk(out, v["size_px"], v["size_px"], v["frames"])
        return out
    except ValueError as exc:
        raise CliError(f"-o/--output: {exc}") from None


def camera_options(v: Values) -> dict:
    """The camera keywords of :func:`latlong.ondemand.descent.descent` from the options."""
    return {"fov_deg": v["fov_deg"], "width_px": v["size_px"],
            "sun_azimuth_deg": v["sun_azimuth_deg"], "sun_elevation_deg": v["sun_elevation_deg"],
            "lidar": lidar_settings(v), "lidar_seed": v["lidar_seed"], "bounces": v["bounces"]}


def write_descent_run(frames, out, v: Values, *, seed, lidar=None) -> int:
    """Write a descent's frames (:func:`latlong.ondemand.descent.write_descent`; ``lidar``:
    the LidarSettings they were flown with, :func:`camera_options`) with the command's
    progress lines; exit status 0."""
    from ..ondemand.descent import write_descent

    def report(i, f):
        if not v["quiet"]:
            lidar = "" if f.lidar is None else f", {len(f.lidar)} LIDAR returns"
            print(f"frame {i}: altitude {f.altitude_m:.4g} m, ground pixel "
                  f"{f.ground_pixel_m:.3g} m, {f.n_craters} craters, {f.n_rocks} rocks "
                  f"({f.terrain}){lidar}", file=sys.stderr)

    try:
        n = write_descent(frames, out, seed=seed, site_lat_lon_deg=(v["lat_deg"], v["lon_deg"]),
                          report=report, lidar=lidar, lidar_seed=v["lidar_seed"],
                          bounces=v["bounces"])
    except ParameterError as exc:
        if exc.name != "lidar":  # the LIDAR's reach beyond the terrain window
            raise
        raise CliError(exc.shown_as("--lidar-fov-deg", name_of=lambda n: "--fov-deg")) \
            from None
    if not v["quiet"]:
        print(f"wrote {n} frames, {out / 'strip.png'}, {out / 'frames.json'}")
    return 0


def register(sub) -> None:
    """Register ``latlong descent``."""
    command(sub, "descent", _descent, OPTIONS, groups=_GROUPS, config=True, prog="latlong",
            help=HELP["descent"])
