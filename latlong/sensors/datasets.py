"""Dataset files of a camera run for the tools of vision and reconstruction pipelines,
all from the run's own ground truth (``frames.json`` and the label images):

* ``coco.json`` (COCO instances; read with pycocotools): one image per frame (its sRGB
  ``display`` PNG; ``linear_file_name`` names the sensor's linear image), categories
  ``crater`` (1) and ``boulder`` (2), one annotation per crater or boulder seen in the
  frame: its pixels as an uncompressed RLE mask (column-major run lengths from a run of
  zeros, COCO's ``counts`` list), ``bbox`` [x, y, width, height] in pixels, ``area`` in
  pixels, ``iscrowd`` 0, and ``catalog_row`` (the crater or boulder catalog row, the
  label images' value).
* ``colmap/cameras.txt``, ``images.txt``, ``points3D.txt`` (a COLMAP text model; read
  with ``pycolmap.Reconstruction`` or COLMAP's own reader): one camera (``PINHOLE``,
  ``OPENCV`` with k1, k2, p1, p2, or ``FULL_OPENCV`` when k3 is set; COLMAP and the
  manifest both put pixel centres at integer + 0.5, so fx, fy, cx, cy carry over), each
  frame's world-to-camera rotation (quaternion w, x, y, z) and translation
  ``t = -R p``, the body frame as the world; no 3-D points.
* ``transforms.json`` (nerfstudio / instant-ngp): intrinsics, distortion and per frame
  the 4 x 4 camera-to-world matrix in their OpenGL camera convention (x right, y up,
  z backwards: the OpenCV axes with y and z negated), metres of the body frame, and the
  depth image's name.
* ``flow_NNNN.flo`` (or ``.exr`` with ``depth_format="exr"``): the optical flow from
  frame N to frame N + 1 from the known geometry (:func:`optical_flow`): each pixel's
  surface point projected into the next frame (distortion included), minus the pixel
  centre, in pixels; unknown (1e10 in ``.flo``, NaN in the EXR channels ``U``, ``V``)
  where the pixel sees the sky or the point leaves the next frame or is hidden in it.
  Middlebury ``.flo``: ``PIEH`` (the float 202021.25), width and height as int32, then
  u, v float32 interleaved row by row (read by OpenCV's ``readOpticalFlow``).

:func:`write_datasets` writes the first three into a finished run folder (``latlong
camera --datasets coco,colmap,nerf`` does it before the run is moved into place); the
flow needs the frames' surface points, so a camera run writes it (``--datasets flow``).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from craters._shared import ParameterError, atomic_path

from .camera import quaternion_to_matrix

__all__ = ["DATASETS", "FLOW_UNKNOWN", "coco_document", "colmap_text", "nerf_transforms",
           "optical_flow", "parse_datasets", "rle_counts", "write_datasets", "write_flow"]

#: The dataset files of a camera run (``flow`` is written by the run itself).
DATASETS = ("coco", "colmap", "nerf", "flow")
#: Flow of unknown pixels in ``.flo`` files (Middlebury: above 1e9 is unknown).
FLOW_UNKNOWN = 1e10
#: A point is hidden in the next frame when its depth there exceeds the depth that frame
#: sees at its nearest pixel by more than this share.
OCCLUSION_TOLERANCE = 0.02
_CATEGORIES = (("crater_id", 1, "crater"), ("boulder_id", 2, "boulder"))


def parse_datasets(spec) -> tuple[str, ...]:
    """``"coco,colmap"`` (or a sequence) -> the dataset names, checked."""
    names = [s.strip() for s in spec.split(",")] if isinstance(spec, str) else list(spec)
    names = [n for n in names if n]
    bad = [n for n in names if n not in DATASETS]
    if bad:
        raise ParameterError("datasets", f"unknown {', '.join(map(repr, bad))}; allowed: "
                             f"{', '.join(DATASETS)}")
    return tuple(dict.fromkeys(names))


def rle_counts(sub: np.ndarray, y0: int, x0: int, height: int, width: int) -> list[int]:
    """COCO's uncompressed RLE ``counts`` of a ``height`` x ``width`` mask that is False
    outside the box whose top-left pixel is (``y0``, ``x0``) and equals the bool array
    ``sub`` inside it: run lengths of the column-major pixels, zeros first."""
    ny, nx = sub.shape
    cols = np.zeros((height, nx), dtype=bool)
    cols[y0:y0 + ny] = sub
    flat = cols.ravel(order="F")
    change = np.flatnonzero(flat[1:] != flat[:-1]) + 1
    counts = np.diff(np.concatenate([[0], change, [flat.size]])).tolist()
    if flat[0]:
        counts.insert(0, 0)
    counts[0] += x0 * height  # the columns left of the box
    tail = (width - x0 - nx) * height
    if tail and flat[-1]:
        counts.append(tail)
    elif tail:
        counts[-1] += tail
    return [int(c) for c in counts]


def _read_image(path: Path) -> np.ndarray:
    if path.suffix == ".npy":
        return np.load(path, allow_pickle=False)
    if path.suffix == ".exr":
        import OpenEXR

        with OpenEXR.File(str(path)) as exr:
            channels = exr.channels()
            a = next(iter(channels.values())).pixels
        return a.view(np.int32) if a.dtype == np.uint32 else a
    from PIL import Image

    with Image.open(path) as im:
        return np.asarray(im)


def _annotations(labels: np.ndarray, image_id: int, category: int, first_id: int) -> list:
    from scipy.ndimage import find_objects

    h, w = labels.shape
    out: list[dict] = []
    shifted = np.where(labels >= 0, labels.astype(np.int64) + 1, 0)
    for row, box in enumerate(find_objects(shifted)):
        if box is None:
            continue
        sub = shifted[box] == row + 1
        ys, xs = box
        ny, nx = sub.shape
        out.append({"id": first_id + len(out), "image_id": image_id, "category_id": category,
                    "segmentation": {"size": [h, w],
                                     "counts": rle_counts(sub, ys.start, xs.start, h, w)},
                    "area": int(sub.sum()), "bbox": [xs.start, ys.start, nx, ny],
                    "iscrowd": 0, "catalog_row": row})
    return out


def coco_document(folder, manifest: dict) -> dict:
    """The ``coco.json`` document of the run in ``folder`` (module notes)."""
    folder = Path(folder)
    intr = manifest["intrinsics"]
    images: list[dict] = []
    annotations: list[dict] = []
    for k, frame in enumerate(manifest["frames"]):
        files = frame["files"]
        images.append({"id": k + 1, "file_name": files.get("display", files["image"]),
                       "linear_file_name": files["image"], "width": intr["width"],
                       "height": intr["height"], "time_s": frame["time_s"]})
        for key, category, _ in _CATEGORIES:
            if files.get(key):
                annotations += _annotations(_read_image(folder / files[key]), k + 1,
                                            category, len(annotations) + 1)
    return {"info": {"description": "craterform camera run: craters and boulders seen",
                     "version": "1.0"},
            "images": images, "annotations": annotations,
            "categories": [{"id": c, "name": n, "supercategory": "terrain"}
                           for _, c, n in _CATEGORIES]}


def _camera_line(manifest: dict) -> str:
    i = manifest["intrinsics"]
    d = manifest.get("distortion") or {}
    k = [float(d.get(n, 0.0)) for n in ("k1", "k2", "p1", "p2", "k3")]
    base = [i["width"], i["height"], i["fx"], i["fy"], i["cx"], i["cy"]]
    if k[4]:
        model, params = "FULL_OPENCV", base + k + [0.0, 0.0, 0.0]
    elif any(k):
        model, params = "OPENCV", base + k[:4]
    else:
        model, params = "PINHOLE", base
    return "1 " + model + " " + " ".join(repr(p) for p in params)


def _camera_to_body(frame: dict) -> tuple[np.ndarray, np.ndarray]:
    rot = quaternion_to_matrix(np.asarray(frame["quaternion_wxyz"], dtype=np.float64))
    return rot, np.asarray(frame["position_m"], dtype=np.float64)


def colmap_text(manifest: dict) -> dict[str, str]:
    """{file name: text} of the COLMAP text model of a run (module notes)."""
    lines = ["# IMAGE_ID, QW, QX, QY, QZ, TX, TY, TZ, CAMERA_ID, NAME", "# POINTS2D (none)"]
    for k, frame in enumerate(manifest["frames"]):
        rot, pos = _camera_to_body(frame)
        q = np.asarray(frame["quaternion_wxyz"], dtype=np.float64)
        q = q / np.linalg.norm(q)
        q_w2c = np.array([q[0], -q[1], -q[2], -q[3]])  # the inverse rotation
        t = -rot.T @ pos
        name = frame["files"].get("display", frame["files"]["image"])
        lines.append(" ".join([str(k + 1), *(repr(float(v)) for v in (*q_w2c, *t)), "1",
                               name]))
        lines.append("")
    return {"cameras.txt": "# CAMERA_ID, MODEL, WIDTH, HEIGHT, PARAMS[]\n"
                           + _camera_line(manifest) + "\n",
            "images.txt": "\n".join(lines) + "\n",
            "points3D.txt": "# POINT3D_ID, X, Y, Z, R, G, B, ERROR, TRACK[]\n"}


def nerf_transforms(manifest: dict) -> dict:
    """The ``transforms.json`` document of a run (module notes)."""
    i = manifest["intrinsics"]
    d = manifest.get("distortion") or {}
    frames = []
    for frame in manifest["frames"]:
        rot, pos = _camera_to_body(frame)
        c2w = np.eye(4)
        c2w[:3, :3] = rot * np.array([1.0, -1.0, -1.0])  # OpenCV -> OpenGL camera axes
        c2w[:3, 3] = pos
        files = frame["files"]
        frames.append({"file_path": files.get("display", files["image"]),
                       "depth_file_path": files["depth"], "time_s": frame["time_s"],
                       "transform_matrix": c2w.tolist()})
    return {"camera_model": "OPENCV", "fl_x": i["fx"], "fl_y": i["fy"], "cx": i["cx"],
            "cy": i["cy"], "w": i["width"], "h": i["height"],
            **{k: float(d.get(k, 0.0)) for k in ("k1", "k2", "p1", "p2", "k3")},
            "depth_unit_scale_factor": 1.0, "frames": frames}


def optical_flow(frame, following) -> np.ndarray:
    """(H, W, 2) float32 flow (u, v) in pixels from :class:`~latlong.sensors.render.Frame`
    ``frame`` to ``following`` (module notes); NaN where unknown."""
    h, w = frame.depth_m.shape
    pos = frame.position_m.reshape(-1, 3)
    seen = np.isfinite(pos[:, 0])
    flow = np.full((h * w, 2), np.nan)
    px, z = following.camera.project(pos[seen], following.pose)
    j, i = np.divmod(np.flatnonzero(seen), w)
    col, row = np.floor(px[:, 0]), np.floor(px[:, 1])
    inside = (z > 0) & (col >= 0) & (col < w) & (row >= 0) & (row < h)
    there = np.full(len(z), np.nan)
    there[inside] = following.depth_m[row[inside].astype(np.int64),
                                      col[inside].astype(np.int64)]
    with np.errstate(invalid="ignore"):
        ok = inside & (z <= there * (1.0 + OCCLUSION_TOLERANCE))
    idx = np.flatnonzero(seen)[ok]
    flow[idx, 0] = px[ok, 0] - (i[ok] + 0.5)
    flow[idx, 1] = px[ok, 1] - (j[ok] + 0.5)
    return flow.reshape(h, w, 2).astype(np.float32)


def write_flow(path, flow: np.ndarray) -> Path:
    """Write an (H, W, 2) flow as Middlebury ``.flo`` (NaN -> :data:`FLOW_UNKNOWN`) or
    OpenEXR ``.exr`` (float32 ``U``, ``V``), atomically."""
    path = Path(path)
    flow = np.asarray(flow, dtype=np.float32)
    with atomic_path(path) as tmp:
        if path.suffix == ".exr":
            import OpenEXR

            channels = {c: np.ascontiguousarray(flow[:, :, k]) for k, c in enumerate("UV")}
            header = {"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage}
            with OpenEXR.File(header, channels) as exr:
                exr.write(str(tmp))
        else:
            with open(tmp, "wb") as fh:
                np.array([202021.25], dtype="<f4").tofile(fh)
                np.array([flow.shape[1], flow.shape[0]], dtype="<i4").tofile(fh)
                np.nan_to_num(flow, nan=FLOW_UNKNOWN).astype("<f4").tofile(fh)
    return path


def write_datasets(folder, datasets=DATASETS, manifest: dict | None = None) -> list[Path]:
    """Write the ``datasets`` (names of :data:`DATASETS`; ``flow`` is left to the run) of
    the run in ``folder`` (its ``frames.json``, or ``manifest``), each file atomically;
    the paths written."""
    folder = Path(folder)
    names = parse_datasets(datasets)
    if manifest is None:
        path = folder / "frames.json"
        if not path.is_file():
            raise FileNotFoundError(f"{str(path)!r}: not a camera run folder (no "
                                    f"frames.json)")
        manifest = json.loads(path.read_text())
    docs: dict[Path, str] = {}
    if "coco" in names:
        docs[folder / "coco.json"] = json.dumps(coco_document(folder, manifest))
    if "colmap" in names:
        (folder / "colmap").mkdir(exist_ok=True)
        for name, text in colmap_text(manifest).items():
            docs[folder / "colmap" / name] = text
    if "nerf" in names:
        docs[folder / "transforms.json"] = json.dumps(nerf_transforms(manifest), indent=1)
    for path, text in docs.items():
        with atomic_path(path) as tmp:
            tmp.write_text(text)
    return list(docs)
