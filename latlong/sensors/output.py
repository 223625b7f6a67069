"""Models in, frames out: reading what a sensor looks at, writing frames and the
``frames.json`` manifest (issue 17's interface).

Models are read by :func:`latlong.sensors.scene_geometry.scene_geometry`.
* :func:`write_frame`: one frame's files, each written atomically: the image (16- or
  8-bit PNG, or float32 TIFF for a float sensor), depth and range (float32 ``.tif`` or
  ``.npy``), normals (float32 (H, W, 3) ``.npy``) and, on request, the other ground
  truth (incidence / emission / phase angles, position, face id, lit fraction, as .npy);
  the crater-id and boulder-id label images (int32, -1 = none, in the depth format) when
  the frame has them.
* :func:`manifest`: the ``frames.json`` document: ``{"intrinsics": {fx, fy, cx, cy, width,
  height}, "frames": [{"time_s", "position_m", "quaternion_wxyz", "sun_direction",
  "files": {"image", "depth", "range", "normals", "crater_id", "boulder_id", ...}}]}``,
  file names relative to the folder (``crater_id`` / ``boulder_id`` null when the model
  has no catalogs), and per frame the projected rim ellipses of the craters seen, plus
  the distortion, the conventions and the settings used.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from craters._shared import ParameterError, atomic_path

from .camera import Camera
from .labels import ELLIPSE_DTYPE, rim_ellipses
from .render import Frame

__all__ = ["frame_entry", "manifest", "write_frame", "write_manifest"]

CONVENTIONS = ("OpenCV camera frame (x right, y down, z forward); quaternion_wxyz rotates "
               "camera-frame vectors into the body frame; position_m and sun_direction "
               "(towards the sun) in the body frame; pixel centres at integer + 0.5 "
               "(OpenCV's cx = cx - 0.5); depth = camera z, range = distance, metres, NaN "
               "where no surface; normals = unit shading normals in the body frame.")


def _save(path: Path, array: np.ndarray) -> None:
    from PIL import Image

    with atomic_path(path) as tmp:
        if path.suffix == ".npy":
            with open(tmp, "wb") as fh:
                np.save(fh, array, allow_pickle=False)
        elif path.suffix == ".tif":
            kind = np.int32 if array.dtype == np.int32 else np.float32
            Image.fromarray(np.ascontiguousarray(array, dtype=kind)).save(tmp, format="TIFF")
        else:
            Image.fromarray(np.ascontiguousarray(array)).save(tmp, format="PNG")


def write_frame(folder, index: int, frame: Frame, *, depth_format: str = "tif",
                extra: bool = False) -> dict:
    """Write frame ``index``'s files into ``folder``; their names (relative)."""
    if depth_format not in ("tif", "npy"):
        raise ParameterError("depth_format", f"must be tif or npy; got {depth_format!r}")
    folder = Path(folder)
    tag = f"{index:04d}"
    image_name = f"image_{tag}.tif" if frame.image.dtype == np.float32 else f"image_{tag}.png"
    files = {"image": image_name, "depth": f"depth_{tag}.{depth_format}",
             "range": f"range_{tag}.{depth_format}", "normals": f"normals_{tag}.npy"}
    arrays = {"image": frame.image, "depth": frame.depth_m, "range": frame.range_m,
              "normals": frame.normals}
    if extra:
        for key, arr in (("incidence", frame.incidence_deg), ("emission", frame.emission_deg),
                         ("phase", frame.phase_deg), ("position", frame.position_m),
                         ("face", frame.face), ("sunlit", frame.sunlit)):
            files[key] = f"{key}_{tag}.npy"
            arrays[key] = arr
    for key, arr in (("crater_id", frame.crater_id), ("boulder_id", frame.boulder_id)):
        if arr is not None:
            files[key] = f"{key}_{tag}.{depth_format}"
            arrays[key] = arr
    for key, name in files.items():
        _save(folder / name, arrays[key])
    return {"crater_id": None, "boulder_id": None, **files}


def frame_entry(frame: Frame, files: dict, *, craters=None, rims=None) -> dict:
    """The manifest's record of one frame; with the crater catalog, the projected rim
    ellipses (pinhole, pixels) of the craters whose id is in the frame's label image,
    their rims from ``rims`` (a :class:`~latlong.sensors.labels.FittedRims` shared by
    the frames) when given, else the catalog rule."""
    entry = {"time_s": frame.pose.time_s,
             "position_m": [float(v) for v in frame.pose.position_m],
             "quaternion_wxyz": [float(v) for v in frame.pose.quaternion_wxyz],
             "sun_direction": [float(v) for v in frame.sun.direction],
             "files": files}
    if craters is not None and frame.crater_id is not None:
        cam = frame.camera
        seen = np.unique(frame.crater_id[frame.crater_id >= 0])
        ell = rim_ellipses(craters, (cam.fx, cam.fy, cam.cx, cam.cy), frame.pose.position_m,
                           frame.pose.quaternion_wxyz, ids=seen,
                           rims=None if rims is None else rims(seen))
        entry["rim_ellipses"] = [{k: (int(e[k]) if k == "crater_id" else float(e[k]))
                                  for k in ELLIPSE_DTYPE.names} for e in ell]
    return entry


def manifest(camera: Camera, entries: list, **settings) -> dict:
    """The ``frames.json`` document (module notes); ``settings`` are recorded as given."""
    return {"intrinsics": camera.intrinsics(),
            "distortion": dict(zip(("k1", "k2", "p1", "p2", "k3"), camera.distortion,
                                   strict=True)),
            "conventions": CONVENTIONS, "settings": settings, "frames": entries}


def write_manifest(folder, document: dict) -> Path:
    """Write ``frames.json`` atomically."""
    path = Path(folder) / "frames.json"
    with atomic_path(path) as tmp:
        tmp.write_text(json.dumps(document, indent=1) + "\n")
    return path
