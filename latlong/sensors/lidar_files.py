"""LIDAR outputs: LAS 1.4 point clouds (laspy), float32 range images and the ``lidar.json``
manifest of a run (the layout of the camera's ``frames.json``).

A run folder holds, per frame ``k``, ``lidar_k.las`` (``lidar_k.laz``, LASzip-compressed,
with the ``laz`` setting; point format 6: x, y, z in the body
frame, metres; intensity; return number; number of returns; GPS time = the beam's time in
seconds; point source id = frame index; extra dimensions ``crater_id`` and
``boulder_id``, int32, -1 = none; the WKT bit set and the CRS as a WKT VLR:
body-fixed Cartesian on the sphere of the model's mean radius, or a DEM site's local
frame, :func:`las_crs_wkt`) and ``range_k.npy`` ((H, W) float32 first-return range,
NaN = no return), and ``lidar.json``::

    {"format": "craterform.lidar/1", "model": ..., "seed": ..., "settings": {...},
     "intrinsics": {"fx", "fy", "cx", "cy", "width", "height"} (or null: rosette),
     "frames": [{"time_s", "position_m", "quaternion_wxyz", "n_returns",
                 "files": {"points": "lidar_0000.las", "range": "range_0000.npy"}}]}

File names are relative to the folder. The whole run is written into a hidden folder next
to the target and moved into place at the end, so an error leaves nothing behind; the
bytes depend only on the inputs (fixed LAS creation date, no clock in the manifest).
"""

from __future__ import annotations

import dataclasses
import datetime
import json
from pathlib import Path

import numpy as np

from craters._shared import (
    ParameterError,
    atomic_path,
    normalize_rng,
    package_version,
    progress_bar,
)

from ..geometry.meshes import bounds
from .engine import RayMesh
from .lidar import LidarFrame, LidarSettings, lidar_frame
from .poses import Poses
from .runs import check_output_folder, run_folder
from .scene_geometry import ray_scene

__all__ = ["LIDAR_FORMAT", "body_fixed_wkt", "las_crs_wkt", "lidar_run", "settings_json",
           "write_las"]

LIDAR_FORMAT = "craterform.lidar/1"
_LAS_DATE = datetime.date(2000, 1, 1)  # fixed: the same run gives the same bytes
_LAS_SCALE_M = 1e-4  # 0.1 mm steps (coarser only for extents beyond +-200 km)


def body_fixed_wkt(name: str, radius_m: float) -> str:
    """The OGC WKT (1) of a body-fixed Cartesian CRS, metres, on a sphere of ``radius_m``
    named ``name`` (a shape model's body, which no authority codes)."""
    safe = "".join(c for c in str(name) if c not in '"[]') or "body"
    return (f'GEOCCS["{safe} body-fixed",DATUM["{safe}",SPHEROID["{safe}",{radius_m:.6g},0]],'
            'PRIMEM["Reference Meridian",0],UNIT["metre",1],AXIS["Geocentric X",OTHER],'
            'AXIS["Geocentric Y",OTHER],AXIS["Geocentric Z",NORTH]]')


def las_crs_wkt(geometry) -> str:
    """The CRS of a run's points: the surface's own (a DEM site says its local frame)
    or, for a body or a mesh, body-fixed Cartesian on the sphere of its mean radius."""
    own = getattr(geometry, "crs_wkt", "")
    if own:
        return own
    radius = float(np.mean(np.linalg.norm(geometry.vertices, axis=1)))
    return body_fixed_wkt(Path(geometry.source).stem or "body", max(radius, 1e-3))


def write_las(frame: LidarFrame, path, *, point_source_id: int = 0,
              crs_wkt: str | None = None, version: str = "1.4") -> Path:
    """Write one frame's returns to a LAS file, atomically: LAS 1.4 point format 6 with
    the global encoding's WKT bit set (point formats 6-10 require it) or, ``version``
    "1.2", point format 1 for older readers (loaders.gl, deck.gl); with ``crs_wkt`` the
    CRS as an OGC WKT coordinate-system VLR, as PDAL and QGIS read it (a 1.2 file has no
    WKT bit: readers that only take GeoTIFF keys see no CRS). A ``.laz`` path is written
    LASzip-compressed (lazrs)."""
    import laspy
    from laspy.vlrs.known import WktCoordinateSystemVlr

    if version not in ("1.4", "1.2"):
        raise ParameterError("version", f"must be '1.4' or '1.2'; got {version!r}")
    path = Path(path)
    header = laspy.LasHeader(point_format=6 if version == "1.4" else 1, version=version)
    if version == "1.4":
        header.global_encoding.wkt = True
    if crs_wkt:
        header.vlrs.append(WktCoordinateSystemVlr(crs_wkt))
    header.creation_date = _LAS_DATE
    header.system_identifier = "craterform lidar"
    header.generating_software = f"craterform {package_version()}"[:32]
    header.add_extra_dims([laspy.ExtraBytesParams("crater_id", "int32",
                                                  "crater catalog row, -1 none"),
                           laspy.ExtraBytesParams("boulder_id", "int32",
                                                  "boulder catalog row, -1 none")])
    xyz = frame.position_m
    if len(xyz):
        lo, hi = bounds(xyz)
        offset = np.round((lo + hi) / 2.0)
        half = float(np.max(hi - lo)) / 2.0 + 1.0
    else:
        offset, half = np.zeros(3), 1.0
    scale = _LAS_SCALE_M
    while half / scale > 2.0e9:
        scale *= 10.0
    header.offsets = offset
    header.scales = np.full(3, scale)
    las = laspy.LasData(header)
    las.x, las.y, las.z = xyz[:, 0], xyz[:, 1], xyz[:, 2]
    las.intensity = frame.intensity
    if version == "1.2" and len(xyz) and int(np.max(frame.number_of_returns)) > 7:
        raise ParameterError("las_version", f"1.2 holds at most 7 returns a beam; a beam has "
                             f"{int(np.max(frame.number_of_returns))}: use 1.4")
    las.return_number = frame.return_number
    las.number_of_returns = frame.number_of_returns
    las.gps_time = frame.time_s
    las.point_source_id = np.full(len(xyz), point_source_id % 65536, dtype=np.uint16)
    las.crater_id = frame.crater_id
    las.boulder_id = frame.boulder_id
    with atomic_path(path) as tmp:
        las.write(str(tmp), do_compress=path.suffix.lower() == ".laz")
    return path


def las_name(stem: str, settings: LidarSettings | None) -> str:
    """``stem`` with the point files' suffix: ``.laz`` when ``settings.laz``, else ``.las``."""
    return f"{stem}.laz" if settings is not None and settings.laz else f"{stem}.las"


def settings_json(settings: LidarSettings) -> dict:
    """The LIDAR's settings as JSON values (a run's manifest)."""
    out = {}
    for f in dataclasses.fields(settings):
        v = getattr(settings, f.name)
        out[f.name] = list(v) if isinstance(v, tuple) else v
    return out


def _seed_of(rng) -> int:
    if isinstance(rng, int | np.integer) and not isinstance(rng, bool):
        normalize_rng(rng)  # validates
        return int(rng)
    return int(normalize_rng(rng).integers(0, 2**63))


def lidar_run(model, settings: LidarSettings, poses: Poses, folder, *, craters=None,
              rng=None, force: bool = False, progress: bool = False,
              mesh: RayMesh | None = None, model_name: str = "") -> dict:
    """Simulate every frame of ``poses`` and write the run folder (module notes); the
    manifest.

    ``model`` is any surface (a body, a mesh surface or file, a DEM site) or its
    :class:`~latlong.sensors.scene_geometry.SceneGeometry`; ``craters`` a catalog (or
    CSV) to label the returns instead of the surface's own
    (:func:`~latlong.sensors.scene_geometry.scene_geometry`); ``mesh`` its
    :class:`RayMesh` if built already. The range noise of frame ``k`` is keyed by
    ``(seed, k)``: ``rng`` as an int is the seed (recorded in the manifest); a Generator
    or None draws one. ``model_name`` names the model in the manifest (default: the
    surface's source).
    """
    if not isinstance(settings, LidarSettings):
        raise TypeError(f"`settings` must be LidarSettings; got {type(settings).__name__}")
    if not isinstance(poses, Poses):
        raise TypeError(f"`poses` must be Poses; got {type(poses).__name__}")
    folder = check_output_folder(folder, force=force)
    seed = _seed_of(rng)
    geometry, mesh = ray_scene(model, craters=craters, mesh=mesh)
    crs_wkt = las_crs_wkt(geometry)
    with run_folder(folder, "lidar.json") as tmp:
        frames = []
        for k in progress_bar(range(len(poses)), enabled=progress, desc="lidar frames"):
            fr = lidar_frame(mesh, settings, poses.position_m[k], poses.quaternion_wxyz[k],
                             time_s=float(poses.time_s[k]), rng=np.random.default_rng([seed, k]),
                             ground_truth=geometry)
            names = {"points": las_name(f"lidar_{k:04d}", settings),
                     "range": f"range_{k:04d}.npy"}
            write_las(fr, tmp / names["points"], point_source_id=k, crs_wkt=crs_wkt,
                      version=settings.las_version)
            np.save(tmp / names["range"], fr.range_image, allow_pickle=False)
            frames.append({"time_s": fr.frame_time_s, "position_m": fr.pose["position_m"],
                           "quaternion_wxyz": fr.pose["quaternion_wxyz"],
                           "n_returns": len(fr), "files": names})
        manifest = {"format": LIDAR_FORMAT, "generator": f"craterform {package_version()}",
                    "model": model_name or geometry.source, "seed": seed,
                    "settings": settings_json(settings), "intrinsics": settings.intrinsics(),
                    "crs_wkt": crs_wkt,
                    "frames": frames}
        with open(tmp / "lidar.json", "w") as fh:
            json.dump(manifest, fh, indent=1)
            fh.write("\n")
    return manifest
