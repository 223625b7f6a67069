"""``latlong lidar``: a LIDAR run over a body or any mesh (LAS 1.4 + range images +
``lidar.json``; :func:`latlong.sensors.lidar_run`). The options (one table,
:func:`lidar_options`: the settings of :class:`~latlong.sensors.LidarSettings`, the
model, pose and run options) and the steps (:func:`run_lidar`) are shared with
``dem lidar``, which sees a DEM or a layer stack."""

from __future__ import annotations

import numpy as np

from craters.cli.kit import parse_seed
from craters.cli.options import Setting, Values, declared_keys
from latlong.sensors import LidarSettings

from .sensor_options import (
    RUN,
    load_model,
    model_options,
    model_scene,
    output_folder,
    pose_options,
    poses_of,
    refuse_inside,
    sensor_command,
    wxh,
)

HELP = {
    "lidar": "simulate a LIDAR (flash or scanning) over a body or mesh: LAS 1.4 point clouds, "
             "range images and lidar.json",
}

__all__ = ["GROUPS", "lidar_options", "register", "run_lidar"]

#: The sections of the LIDAR's options.
GROUPS = {"pose": "pose (body frame; sensor-to-body rotation, OpenCV camera frame)"}


def lidar_options(model_help: str, *, units: bool = True, vertical=None) -> dict[str, Setting]:
    """The options of a LIDAR command (``latlong lidar``, ``dem lidar``)."""
    return {
        **model_options("returns", model_help, units=units),
        **pose_options("sensor", vertical=vertical),
        **declared_keys(LidarSettings, beams={"parse": wxh("beam counts", "128x96", 4096)}),
        "seed": Setting(help="range-noise seed", kind=int, parse=parse_seed,
                        default_text="a fresh one, recorded in lidar.json"),
        **RUN,
    }


def run_lidar(v: Values, load) -> int:
    """The LIDAR command over the surface ``load(v)`` reads from MODEL."""
    from latlong.sensors import lidar_run

    settings = LidarSettings(**{k: v[k] for k in declared_keys(LidarSettings)})
    output_folder(v)
    poses = poses_of(v)
    geometry, mesh = model_scene(v, load)
    poses = poses if poses is not None else poses_of(v, mesh)
    refuse_inside(mesh, poses, v, "sensor")
    seed = v.seed if v.seed is not None else int(np.random.default_rng().integers(2**63))
    man = lidar_run(geometry, settings, poses, v.output, rng=seed, force=v.force,
                    progress=not v.quiet, mesh=mesh, model_name=str(v.model))
    if not v.quiet:
        n = sum(f["n_returns"] for f in man["frames"])
        print(f"wrote {v.output}: {len(man['frames'])} frames, {n} returns (seed {seed})")
    return 0


def register(sub) -> None:
    """Register ``latlong lidar``."""
    sensor_command(sub, "lidar", HELP["lidar"],
                   lidar_options("a body .npz or a mesh file (PLY, OBJ, STL, VTP, VTK, GLB)"),
                   run_lidar, load_model, GROUPS)
