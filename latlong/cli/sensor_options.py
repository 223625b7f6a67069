"""Options shared by the sensor commands (``latlong camera``, ``latlong lidar``): number
lists, sizes, the pose / trajectory options and the output folder."""

from __future__ import annotations

import argparse
import re
from pathlib import Path

import numpy as np

from craters._shared import ParameterError, ParameterTypeError, check_outside_folder
from craters.cli.kit import CliError

__all__ = ["POSE_FLAGS", "add_pose_options", "allow_negative_lists", "numbers",
           "output_folder", "poses_from_args", "refuse_inside", "wxh"]

_NUM = r"[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?"
#: "--position-m -3000,0,0": a comma list of numbers that starts with "-" is a value.
_NUMBER_LIST = re.compile(rf"^-(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?(,{_NUM})*$")
#: Library parameter -> flag of the pose options.
POSE_FLAGS = {"quaternion_wxyz": "--quaternion", "position_m": "--position-m",
              "n_frames": "--frames", "start_range_m": "--range-m",
              "end_range_m": "--range-m", "path_angle_deg": "--path-angle-deg",
              "path_azimuth_deg": "--path-azimuth-deg", "duration_s": "--duration-s",
              "vertical": "--vertical", "lat_deg": "--target-lat-lon",
              "lon_deg": "--target-lat-lon", "target_m": "--target-m", "time_s": "--time-s"}


def allow_negative_lists(parser: argparse.ArgumentParser) -> None:
    """Let ``parser`` take ``-3000,0,0`` as a value, not as an option."""
    parser._negative_number_matcher = _NUMBER_LIST


def numbers(n: int, what: str):
    """An argparse type: ``n`` finite comma-separated numbers (``what`` names them)."""
    def parse(text):
        try:
            vals = [float(p) for p in str(text).split(",")]
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected {what}; got {text!r}") from None
        if len(vals) != n or not np.isfinite(vals).all():
            raise argparse.ArgumentTypeError(f"expected {what} ({n} finite numbers); "
                                             f"got {text!r}")
        return vals
    return parse


def wxh(what: str, example: str, hi: int = 16384):
    """An argparse type: ``WxH`` with both in [1, hi]."""
    def parse(text):
        parts = str(text).lower().split("x")
        try:
            w, h = (int(p) for p in parts)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected WxH {what}, e.g. {example}; got "
                                             f"{text!r}") from None
        if not (1 <= w <= hi and 1 <= h <= hi):
            raise argparse.ArgumentTypeError(f"width and height must be in [1, {hi}]; got "
                                             f"{text!r}")
        return w, h
    return parse


def add_pose_options(group, sensor: str) -> None:
    """The pose options: one pose, a trajectory file, or a generated approach."""
    group.add_argument("--position-m", type=numbers(3, "X,Y,Z"),
                       help=f"{sensor} position X,Y,Z in metres (default: none; or --poses "
                       "or --target-*)")
    group.add_argument("--quaternion", type=numbers(4, "W,X,Y,Z"),
                       help=f"{sensor}-to-body unit quaternion W,X,Y,Z; {sensor} frame x "
                       "right, y down, z forward (default: none)")
    group.add_argument("--time-s", type=float, default=0.0,
                       help="time of a single pose, seconds (default: 0)")
    group.add_argument("--poses", help="trajectory: CSV with the header time_s,x_m,y_m,z_m,"
                       "qw,qx,qy,qz, or TOML [[frame]] tables (default: none)")
    group.add_argument("--target-lat-lon", type=numbers(2, "LAT,LON in degrees"),
                       help="generate an approach towards the surface point in this "
                       "direction from the origin, degrees (default: none)")
    group.add_argument("--target-m", type=numbers(3, "X,Y,Z"),
                       help="generate an approach towards this body-frame point, metres "
                       "(default: none)")
    group.add_argument("--frames", type=int, default=10,
                       help="frames of a generated approach (default: 10)")
    group.add_argument("--range-m", type=numbers(2, "START,END in metres"),
                       help="first and last range to the target of a generated approach, "
                       "spaced geometrically (required with --target-*)")
    group.add_argument("--path-angle-deg", type=float, default=0.0,
                       help="approach line from the target's local vertical, degrees "
                       "(default: 0 = straight down)")
    group.add_argument("--path-azimuth-deg", type=float, default=0.0,
                       help="direction of that tilt from local north towards east, degrees "
                       "(default: 0)")
    group.add_argument("--vertical", type=numbers(3, "X,Y,Z"),
                       help="local vertical at the target of a generated approach, body "
                       "frame; 0,0,1 for a dem mesh (default: the target's radial direction)")
    group.add_argument("--duration-s", type=float,
                       help="time from the first to the last generated frame, seconds "
                       "(default: one second per frame)")


def _shown(exc, flags: dict) -> CliError:
    if isinstance(exc, ParameterError | ParameterTypeError) and exc.name in flags:
        return CliError(exc.shown_as(flags[exc.name]))
    return CliError(str(exc))


def poses_from_args(args, mesh=None):
    """The :class:`~latlong.sensors.poses.Poses` the options ask for (``mesh``: the
    model's :class:`~latlong.sensors.engine.RayMesh`, needed by ``--target-lat-lon``
    only: without it that case gives None, so that the other pose errors come before the
    model is read)."""
    from latlong.sensors.poses import Poses, approach, read_poses, surface_point

    single = args.position_m is not None or args.quaternion is not None
    generated = args.target_lat_lon is not None or args.target_m is not None
    if sum((single, args.poses is not None, generated)) != 1 or (
            args.target_lat_lon is not None and args.target_m is not None):
        raise CliError("give one of: --position-m with --quaternion, --poses FILE, or "
                       "--target-lat-lon / --target-m (with --range-m)")
    try:
        if args.poses is not None:
            try:
                return read_poses(args.poses)
            except ValueError as exc:
                raise CliError(f"--poses: {exc}") from None
        if single:
            if args.position_m is None or args.quaternion is None:
                raise CliError("--position-m and --quaternion go together")
            return Poses.one(args.position_m, args.quaternion, args.time_s)
        if args.range_m is None:
            raise CliError("--range-m START,END is required with --target-lat-lon / "
                           "--target-m")
        if args.target_m is None and mesh is None:
            return None
        target = surface_point(mesh, *args.target_lat_lon) if args.target_m is None \
            else args.target_m
        return approach(target, n_frames=args.frames, start_range_m=args.range_m[0],
                        end_range_m=args.range_m[1], path_angle_deg=args.path_angle_deg,
                        path_azimuth_deg=args.path_azimuth_deg, duration_s=args.duration_s,
                        vertical=args.vertical)
    except (ParameterError, ParameterTypeError) as exc:
        raise _shown(exc, POSE_FLAGS) from None


def refuse_inside(mesh, poses, args, sensor: str) -> None:
    """A one-line error if a pose puts the sensor inside the model."""
    from latlong.sensors import camera_inside

    for k in range(len(poses)):
        if camera_inside(mesh, poses.position_m[k]):
            where = "--position-m" if args.position_m is not None else \
                "--poses" if args.poses is not None else "--range-m"
            raise CliError(f"{where}: the {sensor} of frame {k} at "
                           f"{poses.position_m[k].tolist()} m is inside the model "
                           f"{str(args.model)!r}")


def output_folder(args) -> Path:
    """``-o/--output`` checked: a real folder, its parent writable, empty unless
    ``--force``, holding no input (MODEL, --poses, --catalog)."""
    from latlong.sensors.lidar_files import check_output_folder

    try:
        check_outside_folder(args.output, [
            ("model", args.model), ("poses", getattr(args, "poses", None)),
            ("catalog", getattr(args, "catalog", None))], flag="")
        return check_output_folder(args.output, force=args.force)
    except ValueError as exc:
        raise CliError(f"-o/--output: {exc}") from None
