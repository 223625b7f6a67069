"""``latlong tile``: a window of terrain on demand (:mod:`latlong.ondemand`) around any
point at any pixel size, from the same scene options as ``latlong build``: a Cloud
Optimized GeoTIFF of heights in the local gnomonic projection, the window as a mesh in
the body's frame, and a shaded picture.
"""

from __future__ import annotations

import sys
from pathlib import Path

from craters._shared import check_output_path
from craters.cli.kit import CliError, wrote_line
from craters.cli.options import FORCE, QUIET, Setting, Values, command, declared_keys

from ..meshio.sizes import GEOTIFF_BYTES_PER_PIXEL, check_free_space, mesh_file_bytes
from ..meshio.writers import MESH_SUFFIXES
from ..scene import SETTING_PARTS, SETTINGS, Scene
from .build import GROUPS

HELP = {
    "tile": "a window of terrain on demand at any pixel size (GeoTIFF, mesh, picture)",
}

__all__ = ["OPTIONS", "TILE_OUTPUTS", "WINDOW", "on_demand_options", "register"]

#: A window of terrain on demand (``latlong tile``, ``dem tile``).
WINDOW = {
    "lat_deg": Setting(help="latitude of the window's centre", unit="deg", range=(-90.0, 90.0),
                       kind=float, required=True, run=True),
    "lon_deg": Setting(help="longitude of the window's centre", unit="deg", range="finite",
                       kind=float, required=True, run=True),
    "size_m": Setting(help="side of the square window", unit="m", range=">0", kind=float,
                      required=True, run=True),
    "pixel_m": Setting(help="pixel size", unit="m", range=">0", kind=float, required=True,
                       run=True),
    "min_crater_px": Setting(3.0, "smallest crater drawn, in pixels across", range=(1.0, 1000.0),
                             run=True),
}
#: What a window is written as (``latlong tile``, ``dem tile``).
TILE_OUTPUTS = {
    "output": Setting(help="heights as a Cloud Optimized GeoTIFF (.tif, float32 metres above "
                      "the sphere of the base's radius at the centre)", flag="-o/--output",
                      run=True),
    "mesh": Setting(help=f"the window as a mesh in the body's frame ({' '.join(MESH_SUFFIXES)})",
                    run=True),
    "picture": Setting(help="shaded picture of the window (.png, plane removed, sun from the "
                       "west at 20 degrees)", run=True),
}


def on_demand_options(group: str, table: dict) -> dict:
    """The options of a command on terrain on demand: the scene's settings (less those of
    whole-body builds and of the implicit backend), ``table`` as ``group``, --quiet and
    --force."""
    return {k: s for k, s in declared_keys(
        *(part for part in SETTING_PARTS if part[0] not in ("implicit", "render")),
        (group, table), ("output", {"quiet": QUIET, "force": FORCE})).items()
        if k not in ("on_demand", "max_memory_gb", "radii_on_disk", "surface", "spacing_m")}


#: Every option of ``latlong tile``: the scene's settings, the window, the outputs.
OPTIONS = on_demand_options("tile", {**WINDOW, **TILE_OUTPUTS})
_GROUPS = {"tile": "window and outputs", **GROUPS}


def check_outputs(v: Values) -> dict[str, Path]:
    """The outputs of a window command (``latlong tile``, ``dem tile``) by key, checked
    before any work: suffixes, nothing overwritten without ``--force``, room on the disk."""
    outs = {}
    for key, suffixes in (("output", (".tif", ".tiff")), ("mesh", MESH_SUFFIXES),
                          ("picture", (".png",))):
        if v[key]:
            try:
                outs[key] = check_output_path(v[key], force=v["force"], suffixes=suffixes)
            except ValueError as exc:
                raise CliError(f"--{key}: {exc}") from None
    if not outs:
        raise CliError("nothing to write: give -o/--output, --mesh or --picture")
    check_tile_disk(v, outs)
    return outs


def check_tile_disk(v: Values, outs: dict) -> None:
    """Refuse up front a window whose files do not fit the disk: the GeoTIFF and the mesh
    (a vertex a pixel; :mod:`latlong.meshio.sizes`)."""
    n = max(1, round(v["size_m"] / v["pixel_m"])) ** 2
    needs = [(outs["output"], GEOTIFF_BYTES_PER_PIXEL * n)] if outs.get("output") else []
    if outs.get("mesh"):
        needs.append((outs["mesh"], mesh_file_bytes(outs["mesh"], n)))
    check_free_space(needs, hint="a larger --pixel-m, a smaller --size-m or another folder")


def _tile(v: Values) -> int:
    from ..ondemand.window import check_window

    # the window's size first: a window this machine cannot hold is refused before the
    # terrain's kernels (numba) load
    check_window(v["lat_deg"], v["size_m"], v["pixel_m"], v["min_crater_px"])
    scene = Scene.from_settings({**{k: v[k] for k in SETTINGS if k in v.given},
                                 "on_demand": True})
    outs = check_outputs(v)
    from ..ondemand.tile import tile, write_tile
    made = tile(scene, v["lat_deg"], v["lon_deg"], size_m=v["size_m"], pixel_m=v["pixel_m"],
                min_crater_px=v["min_crater_px"])
    write_tile(made, cog=outs.get("output"), mesh=outs.get("mesh"),
               picture=outs.get("picture"))
    if not v["quiet"]:
        ny, nx = made.heights_m.shape
        print(f"tile: {nx} x {ny} pixels of {made.pixel_m:g} m at ({made.lat_deg:g}, "
              f"{made.lon_deg:g}) deg, heights {made.heights_m.min():.4g}..."
              f"{made.heights_m.max():.4g} m, {made.n_craters} craters and "
              f"{made.n_rocks} rocks >= {made.min_crater_m:.3g} m, seed {scene.seed}",
              file=sys.stderr)
        for path in outs.values():
            print(wrote_line(path))
    return 0


def register(sub) -> None:
    """Register ``latlong tile``."""
    command(sub, "tile", _tile, OPTIONS, groups=_GROUPS, config=True, prog="latlong",
            help=HELP["tile"])
