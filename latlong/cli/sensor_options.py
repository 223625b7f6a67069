"""Options shared by the sensor commands (``latlong camera``, ``latlong lidar`` and their
``dem`` twins ``dem camera``, ``dem lidar``), as tables of declared settings
(:mod:`craters.cli.options`): the model and output options (:func:`model_options`), the
pose / trajectory options (:func:`pose_options`), and the steps every sensor command
takes (the output folder checked, the model read and its BVH built, poses inside the
model refused). Library errors are shown under the flags by the kit: a setting's key, or
a library parameter in its ``also``.
"""

from __future__ import annotations

import argparse
import re
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

from craters._shared import check_outside_folder
from craters.cli.kit import CliError
from craters.cli.options import QUIET, Setting, Values, command, default_of, shown_value

__all__ = ["RUN", "allow_negative_lists", "load_model", "model_options", "model_scene",
           "numbers", "output_folder", "pose_options", "poses_of", "refuse_inside",
           "sensor_command", "wxh"]

_NUM = r"[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?"
#: "--position-m -3000,0,0": a comma list of numbers that starts with "-" is a value.
_NUMBER_LIST = re.compile(rf"^-(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?(,{_NUM})*$")


def numbers(n: int, what: str) -> Callable[[str], list[float]]:
    """A parser of ``n`` finite comma-separated numbers (``what`` names them)."""
    def parse(text):
        try:
            vals = [float(p) for p in str(text).split(",")]
        except ValueError:
            raise ValueError(f"expected {what}; got {text!r}") from None
        if len(vals) != n or not np.isfinite(vals).all():
            raise ValueError(f"expected {what} ({n} finite numbers); got {text!r}")
        return vals
    return parse


def wxh(what: str, example: str, hi: int = 16384) -> Callable[[str], tuple[int, int]]:
    """A parser of ``WxH`` with both in [1, hi]."""
    def parse(text):
        parts = str(text).lower().split("x")
        try:
            w, h = (int(p) for p in parts)
        except ValueError:
            raise ValueError(f"expected WxH {what}, e.g. {example}; got {text!r}") from None
        if not (1 <= w <= hi and 1 <= h <= hi):
            raise ValueError(f"width and height must be in [1, {hi}]; got {text!r}")
        return w, h
    return parse


def model_options(what: str, model_help: str, *, units: bool = True) -> dict[str, Setting]:
    """MODEL, ``-o/--output``, (``--units`` for mesh files) and ``--catalog``; ``what``
    the sensor's outputs (e.g. "frames")."""
    from latlong import load_surface
    from latlong.meshio.readers import UNITS

    return {
        "model": Setting(help=model_help, flag="MODEL", required=True, run=True),
        "output": Setting(help="output folder (created)", flag="-o/--output", required=True,
                          metavar="FOLDER", run=True),
        **({"units": Setting(default_of(load_surface, "units"), "units of a mesh file's "
                             "coordinates", choices=tuple(sorted(UNITS, key=lambda u: UNITS[u])),
                             run=True)} if units else {}),
        "catalog": Setting(help=f"crater catalog CSV that labels the {what}", run=True,
                           default_text="the model's own, if it has one", also=("craters",)),
    }


#: ``--force`` and ``-q/--quiet``.
RUN = {"force": Setting(False, "write into an existing, non-empty folder", run=True),
       "quiet": QUIET}


def pose_options(sensor: str, *, vertical=None) -> dict[str, Setting]:
    """The pose options (group ``pose``): one pose, a trajectory file, or a generated
    approach (:func:`~latlong.sensors.poses.approach`, whose defaults they take);
    ``vertical`` the default local vertical of an approach (None: radial)."""
    from latlong.sensors.poses import Poses, approach

    def pose(default=None, help=None, **kw):
        return Setting(default, help, group="pose", **kw)

    def of_approach(key, help, **kw):
        return pose(default_of(approach, key), help, **kw)

    xyz = numbers(3, "X,Y,Z")
    return {
        "position_m": pose(help=f"{sensor} position X,Y,Z", unit="m", parse=xyz,
                           metavar="X,Y,Z", default_text="none; or --poses or --target-*"),
        "quaternion": pose(help=f"{sensor}-to-body unit quaternion W,X,Y,Z; {sensor} frame x "
                           "right, y down, z forward", parse=numbers(4, "W,X,Y,Z"),
                           metavar="W,X,Y,Z", also=("quaternion_wxyz",)),
        "time_s": pose(default_of(Poses.one, "time_s"), "time of a single pose", unit="s"),
        "poses": pose(help="trajectory: CSV with the header time_s,x_m,y_m,z_m,qw,qx,qy,qz, "
                      "or TOML [[frame]] tables", metavar="FILE", run=True),
        "target_lat_lon": pose(help="generate an approach towards the surface point in this "
                               "direction from the origin", unit="deg",
                               parse=numbers(2, "LAT,LON in degrees"), metavar="LAT,LON",
                               also=("lat_deg", "lon_deg")),
        "target_m": pose(help="generate an approach towards this body-frame point X,Y,Z",
                         unit="m", parse=xyz, metavar="X,Y,Z"),
        "frames": of_approach("n_frames", "frames of a generated approach",
                              also=("n_frames",)),
        "range_m": pose(help="first and last range to the target of a generated approach "
                        "(spaced geometrically; needed with --target-*)", unit="m",
                        parse=numbers(2, "START,END in metres"), metavar="START,END",
                        also=("start_range_m", "end_range_m")),
        "path_angle_deg": of_approach("path_angle_deg", "approach line from the target's "
                                      "local vertical (0 = straight down)", unit="deg"),
        "path_azimuth_deg": of_approach("path_azimuth_deg", "direction of that tilt from "
                                        "local north towards east", unit="deg"),
        "vertical": pose(vertical, "local vertical at the target of a generated approach, "
                         "body frame; 0,0,1 for a dem mesh", parse=xyz, metavar="X,Y,Z",
                         default_text="the target's radial direction" if vertical is None
                         else f"{shown_value(vertical)}, the site's up"),
        "duration_s": of_approach("duration_s", "time from the first to the last generated "
                                  "frame", unit="s", kind=float,
                                  default_text="one second per frame"),
        "spice": pose(help="SPICE kernels for the poses (and the camera's sun): a "
                      "meta-kernel .tm or kernel files, comma-separated; with --utc, "
                      "--target, --observer, --frame, --instrument-frame", metavar="FILES",
                      run=True),
        "utc": pose(help="SPICE times START,STOP,STEP_S (UTC, UTC, seconds)",
                    metavar="START,STOP,STEP_S"),
        "target": pose(help="SPICE name or id of the body the model is", metavar="BODY"),
        "observer": pose(help="SPICE name or id of the spacecraft", metavar="SC"),
        "frame": pose(help="SPICE body-fixed frame of the model (e.g. IAU_MOON)",
                      metavar="FRAME"),
        "instrument_frame": pose(help=f"SPICE frame of the {sensor} (+Z boresight, +X right, "
                                 "+Y down)", metavar="FRAME"),
        "abcorr": pose("NONE", "SPICE aberration correction",
                       choices=("NONE", "LT", "LT+S", "CN", "CN+S")),
    }


_SPICE_KEYS = ("utc", "target", "observer", "frame", "instrument_frame")


def spice_of(v: Values):
    """The :class:`~latlong.sensors.spice.SpiceSequence` that ``--spice`` asks for, or
    None without it."""
    if v.spice is None:
        if any(v[k] is not None for k in _SPICE_KEYS):
            raise CliError("--utc, --target, --observer, --frame and --instrument-frame go "
                           "with --spice")
        return None
    missing = [k for k in _SPICE_KEYS if v[k] is None]
    if missing:
        raise CliError(f"--spice needs {', '.join('--' + k.replace('_', '-') for k in missing)}")
    from latlong.sensors.spice import spice_sequence

    try:
        return spice_sequence(v.spice, utc=v.utc, target=v.target, observer=v.observer,
                              frame=v.frame, camera_frame=v.instrument_frame,
                              abcorr=v.abcorr, planet=v.get("planet"))
    except (ValueError, FileNotFoundError) as exc:
        raise CliError(str(exc)) from None


def sensor_command(sub, name: str, help: str, options: dict[str, Setting], run: Callable,
                   load: Callable, groups: dict[str, str]) -> None:
    """Register the sensor command ``name`` (:func:`craters.cli.options.command`):
    ``run(values, load)``, ``load(values)`` the surface of MODEL."""
    parser = command(sub, name, lambda v: run(v, load), options, help=help, groups=groups)
    allow_negative_lists(parser)


def allow_negative_lists(parser: argparse.ArgumentParser) -> None:
    """Let ``parser`` take ``-3000,0,0`` as a value, not as an option."""
    parser._negative_number_matcher = _NUMBER_LIST


def poses_of(v: Values, mesh=None):
    """The :class:`~latlong.sensors.poses.Poses` the options ask for (``mesh``: the
    model's :class:`~latlong.sensors.engine.RayMesh`, needed by ``--target-lat-lon``
    only: without it that case gives None, so that the other pose errors come before the
    model is read)."""
    from latlong.sensors.poses import Poses, approach, read_poses, surface_point

    single = v.position_m is not None or v.quaternion is not None
    generated = v.target_lat_lon is not None or v.target_m is not None
    if sum((single, v.poses is not None, generated, v.spice is not None)) != 1 or (
            v.target_lat_lon is not None and v.target_m is not None):
        raise CliError("give one of: --position-m with --quaternion, --poses FILE, "
                       "--target-lat-lon / --target-m (with --range-m), or --spice")
    if v.spice is not None:
        return spice_of(v).poses
    if v.poses is not None:
        try:
            return read_poses(v.poses)
        except ValueError as exc:
            raise CliError(f"--poses: {exc}") from None
    if single:
        if v.position_m is None or v.quaternion is None:
            raise CliError("--position-m and --quaternion go together")
        return Poses.one(v.position_m, v.quaternion, v.time_s)
    if v.range_m is None:
        raise CliError("--range-m START,END is required with --target-lat-lon / --target-m")
    if v.target_m is None and mesh is None:
        return None
    target = surface_point(mesh, *v.target_lat_lon) if v.target_m is None else v.target_m
    return approach(target, n_frames=v.frames, start_range_m=v.range_m[0],
                    end_range_m=v.range_m[1], path_angle_deg=v.path_angle_deg,
                    path_azimuth_deg=v.path_azimuth_deg, duration_s=v.duration_s,
                    vertical=v.vertical)


#: The farthest a sensor may be from the model, in model radii (the Moon seen from the
#: Earth is 220 radii away; 1e6 radii make a 1 km body 0.2 microradians wide).
MAX_RANGE_RADII = 1e6


def refuse_inside(mesh, poses, v: Values, sensor: str) -> None:
    """A one-line error if a pose puts the sensor inside the model or absurdly far from it."""
    from latlong.sensors import camera_inside

    centre, radius = mesh.bounding_sphere
    radius = max(radius, 1e-3)
    where = v.where("position_m" if v.position_m is not None else
                    "poses" if v.poses is not None else "range_m")
    for k in range(len(poses)):
        far = float(np.linalg.norm(poses.position_m[k] - centre))
        if far > MAX_RANGE_RADII * radius:
            raise CliError(f"{where}: the {sensor} of frame {k} is {far:.3g} m "
                           f"from the model, more than {MAX_RANGE_RADII:g} times its "
                           f"{radius:.3g} m radius (it would be far below a pixel)")
        if camera_inside(mesh, poses.position_m[k]):
            raise CliError(f"{where}: the {sensor} of frame {k} at "
                           f"{poses.position_m[k].tolist()} m is inside the model "
                           f"{str(v.model)!r}")


def load_model(v: Values):
    """The surface of MODEL for ``latlong camera`` and ``latlong lidar``: a body ``.npz``
    or a mesh file in ``--units`` (:func:`latlong.load_surface`)."""
    from latlong import load_surface

    return load_surface(v.model, units=v.units)


def model_scene(v: Values, load: Callable) -> tuple:
    """``(geometry, mesh)`` of MODEL: the surface ``load(v)`` reads, labelled by
    ``--catalog`` or its own catalog, and its BVH (built once, for every frame); unless
    ``--quiet``, a line with its size and the time taken."""
    from latlong.sensors import ray_scene

    t0 = time.perf_counter()
    geometry, mesh = ray_scene(load(v), craters=v.catalog)
    if not v.quiet:
        print(f"model {v.model}: {len(mesh.faces)} triangles, read and BVH built in "
              f"{time.perf_counter() - t0:.1f} s")
    return geometry, mesh


def output_folder(v: Values) -> Path:
    """``-o/--output`` checked: a real folder, its parent writable, empty unless
    ``--force``, holding no input (MODEL, --poses, --catalog)."""
    from latlong.sensors.runs import check_output_folder

    try:
        check_outside_folder(v.output, [
            ("model", v.model), ("poses", v.poses), ("catalog", v.catalog)], flag="")
        return check_output_folder(v.output, force=v.force)
    except ValueError as exc:
        raise CliError(f"{v.where('output')}: {exc}") from None
