"""``latlong lidar``: a LIDAR run over a body or any mesh (LAS 1.4 + range images +
``lidar.json``; :func:`latlong.sensors.lidar_run`). The options and the steps are shared
with ``dem lidar`` (:func:`add_lidar_options`, :func:`run_lidar`), which sees a DEM or a
layer stack."""

from __future__ import annotations

import numpy as np

from craters.cli.kit import parse_seed

from .sensor_options import (
    MODEL_FLAGS,
    add_model_options,
    add_pose_options,
    add_run_options,
    add_sensor_command,
    flagged,
    load_model,
    model_scene,
    output_folder,
    poses_from_args,
    refuse_inside,
    wxh,
)

__all__ = ["FLAGS", "add_lidar_options", "add_lidar_parser", "run_lidar"]

#: Library parameter -> flag, for messages about a setting.
FLAGS = {"pattern": "--pattern", "beams": "--beams", "fov_deg": "--fov-deg",
         "divergence_mrad": "--divergence-mrad", "rays_per_beam": "--rays-per-beam",
         "range_noise_m": "--range-noise-m", "max_range_m": "--max-range-m",
         "return_separation_m": "--return-separation-m", "pulse_rate_hz": "--pulse-rate-hz",
         "quaternion_wxyz": "--quaternion", "position_m": "--position-m", **MODEL_FLAGS}


def run_lidar(args, load) -> int:
    """The LIDAR command over the surface ``load(args)`` reads from MODEL."""
    from latlong.sensors import LidarSettings, lidar_run

    with flagged(FLAGS):
        settings = LidarSettings(
            pattern=args.pattern, beams=args.beams, fov_deg=args.fov_deg,
            divergence_mrad=args.divergence_mrad, rays_per_beam=args.rays_per_beam,
            range_noise_m=args.range_noise_m, max_range_m=args.max_range_m,
            multiple_returns=args.multiple_returns,
            return_separation_m=args.return_separation_m, pulse_rate_hz=args.pulse_rate_hz)
        output_folder(args)
        poses = poses_from_args(args)
        geometry, mesh = model_scene(args, load)
        poses = poses if poses is not None else poses_from_args(args, mesh)
        refuse_inside(mesh, poses, args, "sensor")
        seed = args.seed if args.seed is not None \
            else int(np.random.default_rng().integers(2**63))
        man = lidar_run(geometry, settings, poses, args.output, rng=seed, force=args.force,
                        progress=not args.quiet, mesh=mesh, model_name=str(args.model))
    if not args.quiet:
        n = sum(f["n_returns"] for f in man["frames"])
        print(f"wrote {args.output}: {len(man['frames'])} frames, {n} returns (seed {seed})")
    return 0


def add_lidar_options(p, *, model_help: str, units: bool = True, vertical=None) -> None:
    """The options of a LIDAR command (``latlong lidar``, ``dem lidar``)."""
    from latlong.sensors import LIDAR_PATTERNS

    add_model_options(p, "returns", model_help, units=units)
    add_pose_options(p, "sensor", vertical=vertical)
    p.add_argument("--pattern", choices=LIDAR_PATTERNS, default="flash",
                   help="flash (a grid of beams at once), scan (the grid as a raster, one "
                   "beam after the other) or rosette (default: flash)")
    p.add_argument("--beams", type=wxh("beam counts", "128x96", 4096), default=(128, 128),
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
    add_run_options(p)


def add_lidar_parser(sub) -> None:
    """Register ``latlong lidar``."""
    add_sensor_command(sub, "lidar", "simulate a LIDAR (flash or scanning) over a body or "
                       "mesh: LAS 1.4 point clouds, range images and lidar.json",
                       add_lidar_options, run_lidar, load_model,
                       model_help="a body .npz or a mesh file (PLY, OBJ, STL, VTP, VTK, GLB)")
