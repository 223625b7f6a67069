"""``dem mesh``: the multi-resolution triangle mesh of a stack (or of one DEM) as PLY or
VTP."""

from __future__ import annotations

import dataclasses
from pathlib import Path

from craters._shared import staged_path
from craters.cli.options import Setting, Values

from ..mesh import MESH_SUFFIXES, to_mesh
from ..stack import read_stack
from .options import INPUT, READ, RUN, check_output, dem_command, output, read_input

HELP = {
    "mesh": "write the multi-resolution triangle mesh of a stack (or a DEM) as PLY or VTP",
}

__all__ = ["register"]

OPTIONS = {
    "input": dataclasses.replace(INPUT, help="input stack manifest (.json) or DEM"),
    "output": output("output mesh (.ply or .vtp)"),
    "no_boulders": Setting(False, "leave the stack's boulders out of the mesh", run=True),
    **READ, **RUN,
}


def _mesh(v: Values) -> int:
    check_output(v, MESH_SUFFIXES)
    show = not v["quiet"]
    if Path(v["input"]).suffix.lower() == ".json":
        src = read_stack(v["input"], progress=show)
    else:
        src = read_input(v)
    path = to_mesh(src, v["output"], progress=show, boulders=not v["no_boulders"])
    if show:
        n = len(src) if hasattr(src, "layers") else 1
        print(f"dem mesh: {n} layer(v), {staged_path(path).stat().st_size / 2**20:.1f} MiB")
        print(f"wrote {path}")
    return 0


def register(sub) -> None:
    """Register ``dem mesh``."""
    dem_command(sub, "mesh", _mesh, OPTIONS,
                HELP["mesh"])
