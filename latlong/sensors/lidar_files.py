"""LIDAR outputs: LAS 1.4 point clouds (laspy), float32 range images and the ``lidar.json``
manifest of a run (the layout of the camera's ``frames.json``).

A run folder holds, per frame ``k``, ``lidar_k.las`` (point format 6: x, y, z in the body
frame, metres; intensity; return number; number of returns; GPS time = the beam's time in
seconds; point source id = frame index; extra dimensions ``crater_id`` and
``boulder_id``, int32, -1 = none) and ``range_k.npy`` ((H, W) float32 first-return range,
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

import contextlib
import dataclasses
import datetime
import json
import os
import shutil
from pathlib import Path

import numpy as np

from craters._shared import (
    atomic_path,
    normalize_rng,
    package_version,
    progress_bar,
    replace_output,
    sweep_temporaries,
    temp_folder,
)

from .engine import RayMesh
from .lidar import LidarFrame, LidarSettings, lidar_frame
from .poses import Poses
from .scene_geometry import SceneGeometry

__all__ = ["LIDAR_FORMAT", "check_output_folder", "lidar_run", "write_las"]

LIDAR_FORMAT = "craterform.lidar/1"
_LAS_DATE = datetime.date(2000, 1, 1)  # fixed: the same run gives the same bytes
_LAS_SCALE_M = 1e-4  # 0.1 mm steps (coarser only for extents beyond +-200 km)


def write_las(frame: LidarFrame, path, *, point_source_id: int = 0) -> Path:
    """Write one frame's returns to a LAS 1.4 file (point format 6), atomically."""
    import laspy

    path = Path(path)
    header = laspy.LasHeader(point_format=6, version="1.4")
    header.creation_date = _LAS_DATE
    header.system_identifier = "craterform lidar"
    header.generating_software = f"craterform {package_version()}"[:32]
    header.add_extra_dims([laspy.ExtraBytesParams("crater_id", "int32",
                                                  "crater catalog row, -1 none"),
                           laspy.ExtraBytesParams("boulder_id", "int32",
                                                  "boulder catalog row, -1 none")])
    xyz = frame.position_m
    if len(xyz):
        lo, hi = xyz.min(axis=0), xyz.max(axis=0)
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
    las.return_number = frame.return_number
    las.number_of_returns = frame.number_of_returns
    las.gps_time = frame.time_s
    las.point_source_id = np.full(len(xyz), point_source_id % 65536, dtype=np.uint16)
    las.crater_id = frame.crater_id
    las.boulder_id = frame.boulder_id
    with atomic_path(path) as tmp:
        las.write(str(tmp))
    return path


def check_output_folder(folder, *, force: bool) -> Path:
    """An output folder: not a symlink, not a file, its parent exists; an existing folder
    only with ``force`` (ValueError otherwise)."""
    folder = Path(folder)
    if folder.is_symlink():
        raise ValueError(f"output folder {str(folder)!r} is a symbolic link; give a real "
                         "folder")
    if folder.exists() and not folder.is_dir():
        raise ValueError(f"output {str(folder)!r} exists and is not a folder")
    parent = folder.parent if str(folder.parent) else Path(".")
    if not parent.is_dir():
        raise ValueError(f"output folder {str(folder)!r}: {str(parent)!r} does not exist")
    if not os.access(parent, os.W_OK | os.X_OK):
        raise ValueError(f"output folder {str(folder)!r}: {str(parent)!r} is not writable")
    if folder.exists() and any(folder.iterdir()) and not force:
        raise ValueError(f"output folder {str(folder)!r} exists and is not empty; use "
                         "--force to write into it")
    sweep_temporaries(parent)
    return folder


def _settings_json(settings: LidarSettings) -> dict:
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


def lidar_run(geometry: SceneGeometry, settings: LidarSettings, poses: Poses, folder, *,
              rng=None, force: bool = False, progress: bool = False,
              mesh: RayMesh | None = None, model_name: str = "") -> dict:
    """Simulate every frame of ``poses`` and write the run folder (module notes).

    The range noise of frame ``k`` is keyed by ``(seed, k)``: ``rng`` as an int is the
    seed (recorded in the manifest); a Generator or None draws one. Returns the manifest.
    """
    if not isinstance(geometry, SceneGeometry):
        raise TypeError(f"`geometry` must be a SceneGeometry; got {type(geometry).__name__}")
    if not isinstance(poses, Poses):
        raise TypeError(f"`poses` must be Poses; got {type(poses).__name__}")
    folder = check_output_folder(folder, force=force)
    seed = _seed_of(rng)
    mesh = mesh if mesh is not None else RayMesh(geometry.vertices, geometry.faces)
    tmp = temp_folder(folder)
    try:
        frames = []
        for k in progress_bar(range(len(poses)), enabled=progress, desc="lidar frames"):
            fr = lidar_frame(mesh, settings, poses.position_m[k], poses.quaternion_wxyz[k],
                             time_s=float(poses.time_s[k]), rng=np.random.default_rng([seed, k]),
                             geometry=geometry)
            names = {"points": f"lidar_{k:04d}.las", "range": f"range_{k:04d}.npy"}
            write_las(fr, tmp / names["points"], point_source_id=k)
            np.save(tmp / names["range"], fr.range_image, allow_pickle=False)
            frames.append({"time_s": fr.frame_time_s, "position_m": fr.pose["position_m"],
                           "quaternion_wxyz": fr.pose["quaternion_wxyz"],
                           "n_returns": len(fr), "files": names})
        manifest = {"format": LIDAR_FORMAT, "generator": f"craterform {package_version()}",
                    "model": model_name or geometry.source, "seed": seed,
                    "settings": _settings_json(settings), "intrinsics": settings.intrinsics(),
                    "frames": frames}
        with open(tmp / "lidar.json", "w") as fh:
            json.dump(manifest, fh, indent=1)
            fh.write("\n")
        _move_into(tmp, folder)
    finally:
        with contextlib.suppress(FileNotFoundError):
            shutil.rmtree(tmp)
    return manifest


def _move_into(tmp: Path, folder: Path) -> None:
    """Move the finished run into ``folder``: a rename when it does not exist yet, else
    file by file with the manifest last."""
    for p in tmp.iterdir():
        os.chmod(p, 0o644)
    if not folder.exists():
        os.chmod(tmp, 0o755)
        replace_output(tmp, folder)
        return
    names = sorted(p.name for p in tmp.iterdir())
    names.remove("lidar.json")
    for name in [*names, "lidar.json"]:
        replace_output(tmp / name, folder / name)
