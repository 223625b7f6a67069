"""``dem descent``: camera frames of a vertical descent over a DEM site (or an enhanced
layer stack, the finest layer holding each point), the DEM as the
base and craters (and rocks) made on demand for each frame at its own ground pixel
(:func:`dem.ondemand.dem_descent`); the files of ``latlong descent``."""

from __future__ import annotations

from craters.cli.kit import CliError
from craters.cli.options import Values
from latlong.cli.descent import (
    DESCENT,
    LIDAR,
    camera_options,
    check_descent_folder,
    write_descent_run,
)

from .options import READ, RUN, dem_command
from .tile import LAYERS, SITE, read_site, scene_of

HELP = {
    "descent": "camera frames of a descent over a DEM site, craters and rocks made on demand for "
               "each frame",
}

__all__ = ["register"]

OPTIONS = {"input": SITE, **READ, **LAYERS, **DESCENT, **LIDAR, **RUN}


def _descent(v: Values) -> int:
    if v["stop_m"] > v["start_m"]:
        raise CliError(f"--stop-m ({v['stop_m']:g}) must be at most --start-m ({v['start_m']:g})")
    out = check_descent_folder(v)  # before the terrain's kernels (numba) load
    from latlong.ondemand.descent import descent_altitudes

    from ..ondemand import dem_descent

    dem = read_site(v)
    scene = scene_of(dem, v)
    alts = descent_altitudes(v["start_m"], v["stop_m"], v["frames"])
    camera = camera_options(v)
    frames = dem_descent(dem, scene, v["lat_deg"], v["lon_deg"], alts, **camera)
    return write_descent_run(frames, out, v, seed=scene.seed, lidar=camera["lidar"])


def register(sub) -> None:
    """Register ``dem descent``."""
    dem_command(sub, "descent", _descent, OPTIONS,
                HELP["descent"])
