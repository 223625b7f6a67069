"""``dem fill``: the unknown pixels of a DEM filled with fractal terrain, outside in, and
with craters in gaps large enough to hold them; a DEM bigger than memory is filled tile
by tile from the file (the same bytes)."""

from __future__ import annotations

from craters.cli.options import Setting, Values, default_of
from latlong.meshio.sizes import check_free_space

from ..frame import crater_target
from ..gaps import fill_gaps
from ..io import write
from ..tiledfill import MEMORY_SHARE, fill_to_file, fits_whole, raster_shape
from .options import DEM, DEM_OUTPUT, INPUT, READ, RUN, begin, dem_command, read_input, summary

HELP = {
    "fill": "fill the unknown pixels of a DEM with fractal terrain, outside in",
}

__all__ = ["register"]

OPTIONS = {
    "input": INPUT,
    "output": DEM_OUTPUT,
    "craters": Setting(default_of(fill_gaps, "craters"), "craters in gaps large enough to hold "
                       "them (4 px and their ejecta): auto (at the density the crater "
                       "detector finds around each gap), none, or a crater layer c=..,k=..,"
                       "d_min_m=..,d_max_m=.. (N_cum = c D^k per m^2, D in metres)",
                       metavar="SPEC"),
    "max_memory_gb": Setting(help="memory the fill may use: a DEM whose whole-raster fill "
                             "would need more is filled tile by tile from the file (the same "
                             "bytes); a gap too large to fill within it is refused", unit="GB",
                             kind=float, metavar="GB",
                             default_text=f"{MEMORY_SHARE:g} x this machine's memory"),
    **{k: DEM[k] for k in ("fractal_dimension", "roughness", "seed")},
    **READ, "gravity_m_s2": DEM["gravity_m_s2"], **RUN,
}


def _fill(v: Values) -> int:
    seed, show, bar = begin(v, "fill")
    head = read_input(v, window=(0, 0, 1, 1), allow_unknown=True)
    shape_in = raster_shape(v["input"])
    check_free_space([(v["output"], 4.0 * shape_in[0] * shape_in[1])],  # float32 heights
                     hint=f"the filled DEM has {shape_in[0]} x {shape_in[1]} pixels: another "
                     f"folder")
    if not fits_whole(shape_in, v["max_memory_gb"]):
        # bigger than memory: tile by tile from the file (the same bytes)
        bar.close()
        made = fill_to_file(v["input"], v["output"], v["roughness"],
                            fractal_dimension=v["fractal_dimension"], craters=v["craters"],
                            rng=seed, target=crater_target(head, v["body"], v["gravity_m_s2"]),
                            band=v["band"], pixel_size_m=v["pixel_size_m"],
                            body_radius_m=v["body_radius_m"], body=v["body"],
                            max_memory_gb=v["max_memory_gb"], progress=show)
        summary(v, seed, shape_in, made.shape, made.parameters)
        return 0
    dem = read_input(v)
    bar.update()
    bar.set_description("fill")
    target = crater_target(dem, v["body"], v["gravity_m_s2"])
    out = fill_gaps(dem, v["roughness"], fractal_dimension=v["fractal_dimension"],
                    craters=v["craters"], rng=seed, target=target)
    bar.update()
    bar.set_description(f"write {v['output']}")
    write(out, v["output"])
    bar.update()
    bar.close()
    summary(v, seed, dem.shape, out.shape, out.history[-1]["parameters"])
    return 0


def register(sub) -> None:
    """Register ``dem fill``."""
    dem_command(sub, "fill", _fill, OPTIONS,
                HELP["fill"])
