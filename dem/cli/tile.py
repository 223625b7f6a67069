"""``dem tile``: a window of a DEM with craters made on demand (:mod:`dem.ondemand`)
around any point at any pixel size: a cloud-optimised GeoTIFF of heights in the local
gnomonic projection (metres above the sphere of the DEM's radius at the centre), the
window as a mesh, a shaded picture. The input may be an enhanced layer stack (its
``manifest.json`` or folder, ``dem enhance``): the finest layer holding each point is the
base (:class:`dem.ondemand.StackBase`)."""

from __future__ import annotations

import dataclasses
import sys

from craters.cli.kit import CliError
from craters.cli.options import Setting, Values
from latlong.cli.tile import TILE_OUTPUTS, WINDOW, check_outputs

from .options import INPUT, READ, RUN, dem_command, read_input

HELP = {
    "tile": "a window of a DEM with craters made on demand, at any pixel size",
}

__all__ = ["LAYERS", "SITE", "read_site", "register", "scene_of"]

#: The layers made on demand over a DEM: craters, rocks, their seed.
LAYERS = {
    "craters": Setting(help="crater layer c=0.08,k=-2,d_min_m=1,d_max_m=1000[,age_min_gyr,"
                       "age_max_gyr,degradation,kind] (N_cum = c D^k per m^2, D in metres) "
                       "or npf=moon,age_gyr=3.8,d_min_m=10,d_max_m=1000[,equilibrium] (a "
                       "model age; repeatable)", many="append", metavar="SPEC", run=True),
    "boulders": Setting(help="rock layer c=7e-4,k=-2.11,d_min_m=0.05,d_max_m=5[,burial_max] "
                        "(N_cum = c D^k per m^2; faceted rocks in the height field; "
                        "repeatable)", many="append", metavar="SPEC", run=True),
    "seed": Setting(help="random seed of the craters and rocks (non-negative integer)",
                    kind=int, range=(0, 2**63 - 1), run=True, default_text="a fresh one"),
}

#: The input of the on-demand commands: a DEM or a layer stack.
SITE = dataclasses.replace(INPUT, help="a DEM (GeoTIFF, PDS .lbl/.img) or an enhanced layer "
                           "stack (its manifest.json or folder)")
OPTIONS = {"input": SITE, **READ, **WINDOW, **LAYERS, **TILE_OUTPUTS, **RUN}


def read_site(v: Values):
    """The input of ``dem tile`` / ``dem descent``: a DEM, or a layer stack (a manifest
    or its folder)."""
    from pathlib import Path

    path = Path(v["input"])
    if path.is_dir() or path.suffix.lower() == ".json":
        from ..stack import read_stack

        try:
            return read_stack(path)
        except (OSError, ValueError) as exc:
            raise CliError(f"INPUT: {exc}") from None
    return read_input(v)


def scene_of(dem, v: Values):
    """The on-demand scene of a DEM command: a sphere of the DEM's (a stack's coarsest
    layer's) body radius with the options' crater and rock layers and seed."""
    from latlong import Scene

    from ..stack import Stack

    if isinstance(dem, Stack):
        dem = dem.layers[0]

    if not v["craters"] and not v["boulders"]:
        raise CliError("give at least one --craters or --boulders layer (the DEM holds the "
                       "rest)")
    radius = dem.body_radius_m
    if radius is None:
        raise CliError("the DEM's body radius is unknown: give --body-radius-m")
    return Scene.from_settings({"base": "sphere", "radius_m": radius,
                                "body": v.get("body") or "moon", "seed": v["seed"],
                                "craters": v["craters"] or [], "boulders": v["boulders"] or [],
                                "on_demand": True})


def _tile(v: Values) -> int:
    from latlong.ondemand.window import check_window

    # the window's size first, before the DEM is read and the terrain's kernels load
    check_window(v["lat_deg"], v["size_m"], v["pixel_m"], v["min_crater_px"])
    outs = check_outputs(v)
    from latlong.ondemand.tile import write_tile

    from ..ondemand import dem_tile

    dem = read_site(v)
    scene = scene_of(dem, v)
    made = dem_tile(dem, scene, v["lat_deg"], v["lon_deg"], size_m=v["size_m"],
                    pixel_m=v["pixel_m"], min_crater_px=v["min_crater_px"])
    write_tile(made, cog=outs.get("output"), mesh=outs.get("mesh"), picture=outs.get("picture"))
    if not v["quiet"]:
        ny, nx = made.heights_m.shape
        print(f"dem tile: {nx} x {ny} pixels of {made.pixel_m:g} m at ({made.lat_deg:g}, "
              f"{made.lon_deg:g}) deg, {made.n_craters} craters and {made.n_rocks} rocks >= "
              f"{made.min_crater_m:.3g} m, "
              f"seed {scene.seed}", file=sys.stderr)
        for path in outs.values():
            print(f"wrote {path}")
    return 0


def register(sub) -> None:
    """Register ``dem tile``."""
    dem_command(sub, "tile", _tile, OPTIONS,
                HELP["tile"])
