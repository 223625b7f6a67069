"""``dem convert``: any DEM :func:`dem.read` reads (PDS3 .lbl/.img, GeoTIFF, Zarr, any
raster GDAL reads) -> a cloud-optimised GeoTIFF or a Zarr store."""

from __future__ import annotations

from craters.cli.options import Values

from ..core import crs_label
from ..io import DEM_SUFFIXES, write
from .options import DEM_OUTPUT, INPUT, READ, RUN, check_output, dem_command, read_input

HELP = {
    "convert": "convert a DEM (PDS3 .lbl/.img, GeoTIFF, Zarr, any raster GDAL reads) to a "
               "cloud-optimised GeoTIFF or a Zarr store",
}

__all__ = ["register"]

OPTIONS = {"input": INPUT, "output": DEM_OUTPUT, **READ, **RUN}


def _convert(v: Values) -> int:
    """``dem convert``: any DEM :func:`dem.read` reads (PDS3, GeoTIFF, ...) -> GeoTIFF or
    Zarr."""
    check_output(v, DEM_SUFFIXES)
    dem = read_input(v)
    write(dem, v["output"])
    if not v["quiet"]:
        print(f"dem convert: {dem.shape[0]} x {dem.shape[1]} pixels, {crs_label(dem.crs)}, "
              f"{100 * dem.nan_fraction:.3g} % unknown")
        print(f"wrote {v['output']}")
    return 0


def register(sub) -> None:
    """Register ``dem convert``."""
    dem_command(sub, "convert", _convert, OPTIONS,
                HELP["convert"])
