"""``latlong lidar``: a LIDAR run over a body or any mesh (LAS 1.4 + range images +
``lidar.json``; :mod:`latlong.sensors.lidar_files`)."""

from __future__ import annotations

import argparse

import numpy as np

from craters._shared.cli import CliError, parse_seed
from latlong.sensors.engine import RayMesh
from latlong.sensors.lidar import LIDAR_PATTERNS, LidarSettings
from latlong.sensors.lidar_files import check_output_folder, lidar_run
from latlong.sensors.poses import Poses, read_poses, rotation_matrix
from latlong.sensors.scene_geometry import scene_geometry

__all__ = ["FLAGS", "add_lidar_parser"]

#: Library parameter -> flag, for messages about a setting.
FLAGS = {"pattern": "--pattern", "beams": "--beams", "fov_deg": "--fov-deg",
         "divergence_mrad": "--divergence-mrad", "rays_per_beam": "--rays-per-beam",
         "range_noise_m": "--range-noise-m", "max_range_m": "--max-range-m",
         "return_separation_m": "--return-separation-m", "pulse_rate_hz": "--pulse-rate-hz",
         "quaternion_wxyz": "--quaternion", "position_m": "--position-m", "model": "MODEL",
         "units": "--units"}


def _floats(n: int, what: str):
    def parse(text):
        try:
            vals = tuple(float(p) for p in str(text).split(","))
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected {what}; got {text!r}") from None
        if len(vals) != n or not all(np.isfinite(vals)):
            raise argparse.ArgumentTypeError(f"expected {n} finite numbers {what}; got "
                                             f"{text!r}")
        return vals
    return parse


def _beams(text):
    parts = str(text).lower().split("x")
    try:
        w, h = (int(p) for p in parts)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected WxH beam counts (e.g. 128x96); got "
                                         f"{text!r}") from None
    return w, h


def _inside(mesh: RayMesh, position) -> bool:
    """Inside a closed mesh: the six axis rays all hit a triangle from behind."""
    d = np.vstack([np.eye(3), -np.eye(3)])
    hits = mesh.intersect(np.broadcast_to(position, d.shape), d)
    if (hits.face < 0).any():
        return False
    return bool((np.einsum("ij,ij->i", mesh.face_normals[hits.face], d) > 0).all())


def cmd_lidar(args) -> int:
    if args.poses is not None and (args.position_m is not None or args.quaternion is not None):
        raise CliError("give either --poses or --position-m with --quaternion, not both")
    if args.poses is None and (args.position_m is None or args.quaternion is None):
        raise CliError("give --position-m and --quaternion (or --poses FILE.csv)")
    settings = LidarSettings(
        pattern=args.pattern, beams=args.beams, fov_deg=args.fov_deg,
        divergence_mrad=args.divergence_mrad, rays_per_beam=args.rays_per_beam,
        range_noise_m=args.range_noise_m, max_range_m=args.max_range_m,
        multiple_returns=args.multiple_returns, return_separation_m=args.return_separation_m,
        pulse_rate_hz=args.pulse_rate_hz)
    if args.poses is not None:
        try:
            poses = read_poses(args.poses)
        except ValueError as exc:
            raise CliError(f"--poses: {exc}") from None
    else:
        rotation_matrix(args.quaternion)  # a unit quaternion, else an error on --quaternion
        poses = Poses.one(args.position_m, args.quaternion, args.time_s)
    check_output_folder(args.output, force=args.force)
    geo = scene_geometry(args.model, units=args.units, craters=args.catalog)
    mesh = RayMesh(geo.vertices, geo.faces)
    for k in range(len(poses)):
        if _inside(mesh, poses.position_m[k]):
            where = "--position-m" if args.poses is None else f"--poses row {k + 1}"
            raise CliError(f"{where}: the sensor at {poses.position_m[k].tolist()} m is inside "
                           "the model")
    seed = args.seed if args.seed is not None else int(np.random.default_rng().integers(2**63))
    man = lidar_run(geo, settings, poses, args.output, rng=seed, force=args.force,
                    progress=not args.quiet, mesh=mesh, model_name=str(args.model))
    if not args.quiet:
        n = sum(f["n_returns"] for f in man["frames"])
        print(f"wrote {args.output}: {len(man['frames'])} frames, {n} returns (seed {seed})")
    return 0


def add_lidar_parser(sub) -> None:
    """Register ``latlong lidar``."""
    p = sub.add_parser("lidar", help="simulate a LIDAR (flash or scanning) over a body or "
                       "mesh: LAS 1.4 point clouds, range images and lidar.json")
    p.add_argument("model", help="a body .npz or a mesh file (PLY, OBJ, STL, VTP, VTK, GLB)")
    p.add_argument("-o", "--output", required=True,
                   help="output folder (created; required)")
    p.add_argument("--position-m", type=_floats(3, "X,Y,Z"),
                   help="sensor position X,Y,Z in the body frame, metres (default: none; "
                   "or --poses)")
    p.add_argument("--quaternion", type=_floats(4, "W,X,Y,Z"),
                   help="sensor-to-body rotation W,X,Y,Z, a unit quaternion; sensor frame "
                   "x right, y down, z forward (default: none; or --poses)")
    p.add_argument("--time-s", type=float, default=0.0,
                   help="frame time of a single pose, seconds (default: 0)")
    p.add_argument("--poses", help="trajectory CSV with the header time_s,x_m,y_m,z_m,qw,qx,"
                   "qy,qz (default: none)")
    p.add_argument("--pattern", choices=LIDAR_PATTERNS, default="flash",
                   help="flash (a grid of beams at once), scan (the grid as a raster, one "
                   "beam after the other) or rosette (default: flash)")
    p.add_argument("--beams", type=_beams, default=(128, 128),
                   help="beams WxH: the range image size (default: 128x128)")
    p.add_argument("--fov-deg", type=float, default=20.0,
                   help="field of view across the W beams (rosette: its diameter), degrees "
                   "(default: 20)")
    p.add_argument("--divergence-mrad", type=float, default=0.0,
                   help="full beam divergence at 1/e^2, milliradians (default: 0)")
    p.add_argument("--rays-per-beam", type=int, default=1,
                   help="sub-rays averaged over each footprint (default: 1)")
    p.add_argument("--range-noise-m", type=float, default=0.0,
                   help="range noise standard deviation, metres (default: 0)")
    p.add_argument("--max-range-m", type=float, default=10_000.0,
                   help="longest range that returns, metres (default: 10000)")
    p.add_argument("--multiple-returns", action="store_true",
                   help="report distinct surfaces in a footprint as separate returns "
                   "(default: off)")
    p.add_argument("--return-separation-m", type=float, default=1.0,
                   help="range gap between two returns of one beam, metres (default: 1)")
    p.add_argument("--pulse-rate-hz", type=float, default=100_000.0,
                   help="beams per second of scan and rosette (default: 100000)")
    p.add_argument("--seed", type=parse_seed,
                   help="range-noise seed (default: a fresh one, recorded in lidar.json)")
    p.add_argument("--units", choices=("m", "km"), default="m",
                   help="units of a mesh file (default: m)")
    p.add_argument("--catalog", help="crater catalog CSV that labels the returns (default: "
                   "the body's own)")
    p.add_argument("--force", action="store_true",
                   help="write into an existing, non-empty folder (default: off)")
    p.add_argument("-q", "--quiet", action="store_true",
                   help="no progress bars or messages (default: off)")
    p.set_defaults(func=cmd_lidar)
