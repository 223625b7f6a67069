"""Models in, frames out: reading what a sensor looks at, writing frames and the
``frames.json`` manifest (issue 17's interface).

* :func:`read_model`: a body ``.npz`` (a :class:`latlong.Body`, with its catalogs) or any
  triangle mesh that pyvista reads (PLY, OBJ, STL, VTP, VTK, GLB ...; open surfaces such
  as ``dem mesh`` outputs too) as ``(vertices, faces)`` in metres.
* :func:`write_frame`: one frame's files, each written atomically: the image (16- or
  8-bit PNG, or float32 TIFF for a float sensor), depth and range (float32 ``.tif`` or
  ``.npy``), normals (float32 (H, W, 3) ``.npy``) and, on request, the other ground
  truth (incidence / emission / phase angles, position, face id, lit fraction, as .npy).
* :func:`manifest`: the ``frames.json`` document: ``{"intrinsics": {fx, fy, cx, cy, width,
  height}, "frames": [{"time_s", "position_m", "quaternion_wxyz", "sun_direction",
  "files": {"image", "depth", "range", "normals", "crater_id", "boulder_id", ...}}]}``,
  file names relative to the folder (``crater_id`` / ``boulder_id`` are null: labels are
  not rendered yet), plus the distortion, the conventions and the settings used.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from craters._shared import ParameterError, atomic_path

from .camera import Camera
from .render import Frame

__all__ = ["MESH_SUFFIXES", "frame_entry", "manifest", "read_model", "write_frame",
           "write_manifest"]

#: Mesh files a sensor can look at (read through pyvista).
MESH_SUFFIXES = (".ply", ".obj", ".stl", ".vtp", ".vtk", ".glb", ".gltf")
UNITS = {"m": 1.0, "km": 1000.0}
CONVENTIONS = ("OpenCV camera frame (x right, y down, z forward); quaternion_wxyz rotates "
               "camera-frame vectors into the body frame; position_m and sun_direction "
               "(towards the sun) in the body frame; pixel centres at integer + 0.5 "
               "(OpenCV's cx = cx - 0.5); depth = camera z, range = distance, metres, NaN "
               "where no surface; normals = unit shading normals in the body frame.")


def read_model(path, *, units: str = "m"):
    """A body ``.npz`` as a :class:`latlong.Body`, or a mesh file as ``(vertices (n, 3)
    float64 metres, faces (m, 3) int64)`` (``units`` of its coordinates: m or km)."""
    path = Path(path)
    if units not in UNITS:
        raise ParameterError("units", f"must be m or km; got {units!r}")
    if not path.is_file():
        raise ValueError(f"model {str(path)!r} does not exist")
    suffix = path.suffix.lower()
    if suffix == ".npz":
        from ..body import load

        try:
            return load(path)
        except (OSError, KeyError, ValueError) as exc:
            raise ValueError(f"cannot read body {str(path)!r}: {exc}") from None
    if suffix not in MESH_SUFFIXES:
        raise ValueError(f"model {str(path)!r}: unknown format {suffix!r}; allowed: .npz "
                         f"{' '.join(MESH_SUFFIXES)}")
    import warnings

    import pyvista as pv

    try:
        with warnings.catch_warnings(), pv.vtk_verbosity("off"):
            warnings.simplefilter("ignore")
            from vtkmodules.vtkCommonCore import vtkObject

            shown = vtkObject.GetGlobalWarningDisplay()
            vtkObject.GlobalWarningDisplayOff()
            try:
                mesh = pv.read(path)
            finally:
                vtkObject.SetGlobalWarningDisplay(shown)
        if isinstance(mesh, pv.MultiBlock):
            mesh = mesh.combine()
        if not isinstance(mesh, pv.PolyData):
            mesh = mesh.extract_surface(algorithm="dataset_surface")
        mesh = mesh.triangulate()
    except Exception as exc:  # noqa: BLE001 - VTK raises many kinds
        raise ValueError(f"cannot read mesh {str(path)!r}: {exc}") from None
    faces = np.asarray(mesh.faces).reshape(-1, 4)[:, 1:].astype(np.int64) if mesh.n_cells \
        else np.zeros((0, 3), np.int64)
    verts = np.asarray(mesh.points, dtype=np.float64) * UNITS[units]
    if not len(faces) or not np.isfinite(verts).all():
        raise ValueError(f"cannot read mesh {str(path)!r}: no triangles or non-finite "
                         "coordinates")
    return verts, faces


def _save(path: Path, array: np.ndarray) -> None:
    from PIL import Image

    with atomic_path(path) as tmp:
        if path.suffix == ".npy":
            with open(tmp, "wb") as fh:
                np.save(fh, array, allow_pickle=False)
        elif path.suffix == ".tif":
            Image.fromarray(np.ascontiguousarray(array, dtype=np.float32)).save(
                tmp, format="TIFF")
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
    for key, name in files.items():
        _save(folder / name, arrays[key])
    return {**files, "crater_id": None, "boulder_id": None}


def frame_entry(frame: Frame, files: dict) -> dict:
    """The manifest's record of one frame."""
    return {"time_s": frame.pose.time_s,
            "position_m": [float(v) for v in frame.pose.position_m],
            "quaternion_wxyz": [float(v) for v in frame.pose.quaternion_wxyz],
            "sun_direction": [float(v) for v in frame.sun.direction],
            "files": files}


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
