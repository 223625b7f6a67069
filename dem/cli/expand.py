"""``dem expand``: a DEM (region) doubled in resolution per level by random midpoint
displacement, tile by tile into the output file (outputs bigger than memory; the tiles
as dask tasks with ``--workers`` or ``--scheduler``, the same bytes)."""

from __future__ import annotations

from craters.cli.options import Setting, Values, default_of
from latlong.parallel.backends import CONNECT_TIMEOUT

from ..core import parse_region
from ..expandfile import TILE_PX, expand_to_file
from .options import DEM, DEM_OUTPUT, INPUT, READ, RUN, begin, dem_command, read_input, summary

HELP = {
    "expand": "double the resolution of a DEM (region) by random midpoint displacement",
}

__all__ = ["register"]

OPTIONS = {
    "input": INPUT,
    "output": DEM_OUTPUT,
    "levels": Setting(default_of(expand_to_file, "levels"), "number of 2x expansions (1..16)",
                      metavar="N"),
    "tile_px": Setting(help="largest side of an output tile in pixels (>= 3): the unit of "
                       "memory and of work (one dask task a tile)", kind=int, metavar="PX",
                       default_text=f"{TILE_PX}, about 80 MB a tile"),
    "scheduler": Setting(help="expand the tiles as tasks on the dask scheduler at ADDRESS, "
                         "e.g. tcp://127.0.0.1:8786 (its workers must see the input and "
                         "output paths; the same bytes)", metavar="ADDRESS",
                         default_text="tiles in this process"),
    "workers": Setting(help="expand the tiles as tasks on a local dask cluster of N worker "
                       "processes on 127.0.0.1 (the same bytes)", kind=int, metavar="N",
                       default_text="tiles in this process"),
    "connect_timeout_s": CONNECT_TIMEOUT,
    **{k: DEM[k] for k in ("fractal_dimension", "roughness")},
    "region": Setting(help="square to expand, 2^n+1 pixels: ROW,COL,SIZE in pixels or "
                      "LEFT,BOTTOM,RIGHT,TOP in CRS units", parse=parse_region, commas=True,
                      metavar="REGION", default_text="the whole DEM"),
    "seed": DEM["seed"], **READ, **RUN,
}


def _expand(v: Values) -> int:
    seed, show, bar = begin(v, "expand")
    dem = read_input(v)
    bar.update()
    bar.set_description("expand")
    made = expand_to_file(dem, v["output"], v["levels"], v["fractal_dimension"],
                          v["roughness"], v["region"], rng=seed, tile_px=v["tile_px"],
                          scheduler=v["scheduler"], workers=v["workers"], progress=show,
                          connect_timeout_s=v["connect_timeout_s"])
    bar.update()
    bar.update()
    bar.close()
    summary(v, seed, dem.shape, made.shape, made.parameters)
    return 0


def register(sub) -> None:
    """Register ``dem expand``."""
    dem_command(sub, "expand", _expand, OPTIONS,
                HELP["expand"])
