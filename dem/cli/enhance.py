"""``dem enhance``: a stack of layers around a site, each 2x finer, with craters (and
boulders) per layer, written layer by layer into a folder (:func:`dem.enhance`); its
options are the fields of :class:`dem.EnhanceConfig`."""

from __future__ import annotations

from craters._shared import about
from craters.cli.kit import CliError
from craters.cli.options import Values

from ..config import EnhanceConfig
from ..enhancefile import enhance_to_folder
from ..stack import check_stack_folder
from .options import DEM, RUN, dem_command, output

HELP = {
    "enhance": "build a stack of layers around a site, each 2x finer, with craters per layer",
}

__all__ = ["OPTIONS", "register"]

OPTIONS = {"input": DEM["input"], "output": output(
    "output folder of the stack (layer GeoTIFFs, crater catalogs, manifest.json)", "DIR"),
    **DEM, **RUN}


def _enhance(v: Values) -> int:
    # the stack's description is validated once, here (every spec parsed once), and the
    # output folder checked once, before any work
    if not v["output"]:
        raise CliError("nothing to write: give -o/--output")
    cfg = EnhanceConfig.from_mapping({key: v[key] for key in EnhanceConfig.keys()})
    with about("output"):
        folder = check_stack_folder(v["output"], force=v["force"],
                                    inputs=(("DEM", v["input"]),
                                            ("config", v.config_file)))
    show = not v["quiet"]
    # layer by layer into the folder (the bytes of enhance + write_stack; memory for
    # about two layers, not all of them)
    stack, manifest = enhance_to_folder(cfg, folder, progress=show)
    if show:
        info = stack.info
        c = info["craters"]
        sizes = stack.pixel_sizes_m()
        small = int(c.get("rejected_below_finest", 0))
        print(f"dem enhance: {len(stack)} layers of {cfg.size} x {cfg.size} pixels, "
              f"{sizes[0]:.4g} m -> {sizes[-1]:.4g} m per pixel, seed {info['seed']}; "
              f"{sum(c['stamped']):,} craters stamped, {sum(c['erased_on_steep_ground']):,} "
              f"erased on steep ground; of the {c['drawn']:,} craters the layers put over "
              f"layer 0's area, {small:,} are too small for the finest layer's pixels and "
              f"{int(c['rejected']) - small:,} fall outside the finer layers or cross "
              "their borders (not stamped)")
        b = info.get("boulders")
        if b:
            print(f"{sum(b['stamped']):,} boulders stamped; of the {b['drawn']:,} drawn, "
                  f"{int(b['rejected']):,} not stamped (below {cfg.min_boulder_px:g} px of "
                  "the finest layer or crossing a layer's border)")
        print(f"wrote {manifest}")
    return 0


def register(sub) -> None:
    """Register ``dem enhance``."""
    dem_command(sub, "enhance", _enhance, OPTIONS,
                HELP["enhance"])
