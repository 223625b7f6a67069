"""Options shared by the sensor commands (``latlong camera``, ``latlong lidar`` and their
``dem`` twins ``dem camera``, ``dem lidar``): number lists, sizes, the model and output
options, the pose / trajectory options, and the steps every sensor command takes (the
output folder checked, the model read and its BVH built, poses inside the model refused,
library errors shown under the flags)."""

from __future__ import annotations

import argparse
import contextlib
import re
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

from craters._shared import ParameterError, ParameterTypeError, check_outside_folder
from craters.cli.kit import CliError

__all__ = ["MODEL_FLAGS", "POSE_FLAGS", "add_model_options", "add_pose_options",
           "add_run_options", "add_sensor_command", "allow_negative_lists", "flagged",
           "load_model", "model_scene", "numbers", "output_folder", "poses_from_args",
           "refuse_inside", "wxh"]

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
#: Library parameter -> flag of the model and output options.
MODEL_FLAGS = {"model": "MODEL", "units": "--units", "craters": "--catalog"}


@contextlib.contextmanager
def flagged(flags: dict):
    """Library parameter errors shown under the command's ``flags`` (one line)."""
    try:
        yield
    except (ParameterError, ParameterTypeError) as exc:
        if exc.name not in flags:
            raise
        raise CliError(exc.shown_as(flags[exc.name], lambda k: flags.get(k, f"`{k}`"))) \
            from None


def add_model_options(parser, what: str, model_help: str, *, units: bool = True) -> None:
    """MODEL, ``-o/--output``, ``--catalog`` (and ``--units`` for mesh files); ``what``
    the sensor's outputs (e.g. "frames")."""
    # "--position-m -3000,0,0": a comma list of numbers starting with "-" is a value
    allow_negative_lists(parser)
    parser.add_argument("model", help=model_help)
    parser.add_argument("-o", "--output", required=True,
                        help="output folder (created; required)")
    if units:
        parser.add_argument("--units", choices=("m", "km"), default="m",
                            help="units of a mesh file's coordinates (default: m)")
    parser.add_argument("--catalog", help=f"crater catalog CSV that labels the {what} "
                        "(default: the model's own, if it has one)")


def add_sensor_command(sub, name: str, help: str, add_options: Callable, run: Callable,
                       load: Callable, **options) -> None:
    """Register the sensor command ``name``: its options (``add_options(parser,
    **options)``) and ``run(args, load)``, ``load(args)`` the surface of MODEL."""
    parser = sub.add_parser(name, help=help)
    add_options(parser, **options)
    parser.set_defaults(func=lambda args: run(args, load))


def add_run_options(group) -> None:
    """``--force`` and ``-q/--quiet``."""
    group.add_argument("--force", action="store_true",
                       help="write into an existing, non-empty folder (default: off)")
    group.add_argument("-q", "--quiet", action="store_true",
                       help="no progress bars or messages (default: off)")


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


def add_pose_options(group, sensor: str, *, vertical=None) -> None:
    """The pose options: one pose, a trajectory file, or a generated approach;
    ``vertical`` the default local vertical of an approach (None: radial)."""
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
    group.add_argument("--vertical", type=numbers(3, "X,Y,Z"), default=vertical,
                       help="local vertical at the target of a generated approach, body "
                       "frame; 0,0,1 for a dem mesh (default: " + (
                           "the target's radial direction" if vertical is None else
                           ",".join(f"{v:g}" for v in vertical) + ", the site's up") + ")")
    group.add_argument("--duration-s", type=float,
                       help="time from the first to the last generated frame, seconds "
                       "(default: one second per frame)")


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
    with flagged(POSE_FLAGS):
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


def load_model(args):
    """The surface of MODEL for ``latlong camera`` and ``latlong lidar``: a body ``.npz``
    or a mesh file in ``--units`` (:func:`latlong.load_surface`)."""
    from latlong import load_surface

    return load_surface(args.model, units=args.units)


def model_scene(args, load: Callable) -> tuple:
    """``(geometry, mesh)`` of MODEL: the surface ``load(args)`` reads, labelled by
    ``--catalog`` or its own catalog, and its BVH (built once, for every frame); unless
    ``--quiet``, a line with its size and the time taken."""
    from latlong.sensors import ray_scene

    t0 = time.perf_counter()
    with flagged(MODEL_FLAGS):
        geometry, mesh = ray_scene(load(args), craters=args.catalog)
    if not args.quiet:
        print(f"model {args.model}: {len(mesh.faces)} triangles, read and BVH built in "
              f"{time.perf_counter() - t0:.1f} s")
    return geometry, mesh


def output_folder(args) -> Path:
    """``-o/--output`` checked: a real folder, its parent writable, empty unless
    ``--force``, holding no input (MODEL, --poses, --catalog)."""
    from latlong.sensors.runs import check_output_folder

    try:
        check_outside_folder(args.output, [
            ("model", args.model), ("poses", getattr(args, "poses", None)),
            ("catalog", getattr(args, "catalog", None))], flag="")
        return check_output_folder(args.output, force=args.force)
    except ValueError as exc:
        raise CliError(f"-o/--output: {exc}") from None
