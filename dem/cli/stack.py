"""``dem enhance`` and ``dem mesh``: layer stacks around a site and their meshes."""

from __future__ import annotations

from pathlib import Path

from craters._shared import about
from craters.cli.kit import CliError

from ..config import EnhanceConfig
from ..enhancefile import enhance_to_folder
from ..mesh import MESH_SUFFIXES, to_mesh
from ..stack import check_stack_folder, read_stack
from .options import Settings, add_command, check_output, read_input


def _enhance(s: Settings) -> int:
    # the stack's description is validated once, here (every spec parsed once), and the
    # output folder checked once, before any work
    if not s["output"]:
        raise CliError("nothing to write: give -o/--output")
    cfg = EnhanceConfig.from_mapping({key: s[key] for key in EnhanceConfig.keys()})
    with about("output"):
        folder = check_stack_folder(s["output"], force=s["force"],
                                    inputs=(("DEM", s["input"]), ("config", s.config)))
    show = not s["quiet"]
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


def _mesh(s: Settings) -> int:
    check_output(s, MESH_SUFFIXES)
    show = not s["quiet"]
    if Path(s["input"]).suffix.lower() == ".json":
        src = read_stack(s["input"], progress=show)
    else:
        src = read_input(s)
    path = to_mesh(src, s["output"], progress=show, boulders=not s["no_boulders"])
    if show:
        n = len(src) if hasattr(src, "layers") else 1
        print(f"dem mesh: {n} layer(s), {path.stat().st_size / 2**20:.1f} MiB")
        print(f"wrote {path}")
    return 0


def register(sub) -> None:
    """Add ``enhance`` and ``mesh`` to the sub-command parser."""
    add_command(sub, "enhance", _enhance,
                "build a stack of layers around a site, each 2x finer, with craters per layer")
    add_command(sub, "mesh", _mesh,
                "write the multi-resolution triangle mesh of a stack (or a DEM) as PLY or VTP")
