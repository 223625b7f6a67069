"""``dem camera`` and ``dem lidar``: the sensors of ``latlong camera`` / ``latlong lidar``
over a site, a layer stack (its folder or ``manifest.json``, as ``dem enhance`` writes it)
or one DEM file, without meshing it to a file first (:class:`dem.DemSurface`).

The option tables and the steps are latlong's (:mod:`latlong.cli.camera`,
:mod:`latlong.cli.lidar`: ``dem -> latlong``); here MODEL is a site, the crater catalog
is the stack's own (every layer's, draped on the surface), a generated approach's local
vertical is the site's up (0,0,1) and there is no ``--units`` (sites are in metres).
"""

from __future__ import annotations

from latlong.cli import camera, lidar
from latlong.cli.sensor_options import sensor_command

HELP = {
    "camera": "render camera frames (image, depth, range, normals, crater and boulder ids) of a "
              "stack or a DEM, with a frames.json manifest",
    "lidar": "simulate a LIDAR (flash or scanning) over a stack or a DEM: LAS 1.4 point "
             "clouds, range images and lidar.json",
}

__all__ = ["register"]

_VERTICAL = (0.0, 0.0, 1.0)  # a site's up; sites are in metres (no --units)
_MODEL = "a layer stack (its folder or manifest.json) or a DEM file"


def _load(v):
    from ..surface import DemSurface

    return DemSurface.read(v.model, progress=not v.quiet)


def register(sub) -> None:
    """Add ``camera`` and ``lidar`` to the sub-command parser."""
    sensor_command(sub, "camera", HELP["camera"],
                   camera.camera_options(_MODEL, units=False, vertical=_VERTICAL),
                   camera.run_camera, _load, camera.GROUPS)
    sensor_command(sub, "lidar", HELP["lidar"],
                   lidar.lidar_options(_MODEL, units=False, vertical=_VERTICAL),
                   lidar.run_lidar, _load, lidar.GROUPS)
