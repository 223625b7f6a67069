"""Dataset files of camera runs (latlong.sensors.datasets) read by the tools that consume
them: pycocotools (COCO instance masks), pycolmap (COLMAP text model), and the
transforms.json convention of nerfstudio against the manifest's poses."""

from __future__ import annotations

import json

import numpy as np
import pytest

import craters
import latlong
from craters._shared import ParameterError
from latlong.sensors import Camera, Pose, quaternion_to_matrix
from latlong.sensors.camera_files import CameraSettings, camera_run
from latlong.sensors.datasets import parse_datasets, rle_counts, write_datasets
from latlong.sensors.poses import Poses

pycocotools = pytest.importorskip("pycocotools")
from pycocotools import mask as mask_utils  # noqa: E402
from pycocotools.coco import COCO  # noqa: E402

# pycocotools 2.0 (Cython) still calls np.array(copy=False) on its RLE objects
pytestmark = pytest.mark.filterwarnings("ignore:__array__ implementation:DeprecationWarning")


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    """A 500 m sphere with four craters seen in two frames, every dataset written."""
    body = latlong.Body.sphere(latlong.LatLongGrid(96), 500.0)
    cat = craters.make_catalog(lat_deg=[0.0, 4.0, -6.0, 1.5], lon_deg=[0.0, 9.0, 6.0, -7.0],
                               diameter_m=[80.0, 50.0, 70.0, 60.0])
    body = latlong.stamp_craters(body, cat, rng=1)
    poses = Poses.of([Pose.look_at([800.0, 0.0, 0.0], [500.0, 20.0, -10.0]),
                      Pose.look_at([760.0, -120.0, 80.0], [500.0, 20.0, -10.0], time_s=1.0)])
    cam = Camera.from_fov(40.0, 160, 120, k1=-0.05, p2=1e-3)
    folder = tmp_path_factory.mktemp("run") / "frames"
    settings = CameraSettings(cam, datasets="coco, colmap,nerf", depth_format="npy")
    doc = camera_run(body, settings, poses, [1.0, 0.3, 0.2], folder)
    return folder, doc


def test_rle_counts_decode_to_the_mask_in_pycocotools():
    rng = np.random.default_rng(2)
    for h, w in ((1, 1), (7, 5), (40, 33)):
        for _ in range(20):
            y0, x0 = rng.integers(0, h), rng.integers(0, w)
            ny, nx = rng.integers(1, h - y0 + 1), rng.integers(1, w - x0 + 1)
            sub = rng.random((ny, nx)) < 0.5
            sub[rng.integers(0, ny), rng.integers(0, nx)] = True
            full = np.zeros((h, w), dtype=bool)
            full[y0:y0 + ny, x0:x0 + nx] = sub
            rle = mask_utils.frPyObjects({"size": [h, w],
                                          "counts": rle_counts(sub, y0, x0, h, w)}, h, w)
            np.testing.assert_array_equal(mask_utils.decode(rle).astype(bool), full)


def test_coco_instances_are_the_labels_seen(run):
    folder, doc = run
    coco = COCO(str(folder / "coco.json"))
    assert {c["name"] for c in coco.loadCats(coco.getCatIds())} == {"crater", "boulder"}
    crater_cat = coco.getCatIds(catNms=["crater"])[0]
    seen_total = 0
    for k, frame in enumerate(doc["frames"]):
        labels = np.load(folder / frame["files"]["crater_id"])
        seen = np.unique(labels[labels >= 0])
        anns = coco.loadAnns(coco.getAnnIds(imgIds=[k + 1], catIds=[crater_cat]))
        assert sorted(a["catalog_row"] for a in anns) == seen.tolist()
        for a in anns:
            np.testing.assert_array_equal(coco.annToMask(a).astype(bool),
                                          labels == a["catalog_row"])
            x, y, w, h = a["bbox"]
            rows, cols = np.nonzero(labels == a["catalog_row"])
            assert (x, y, w, h) == (cols.min(), rows.min(), np.ptp(cols) + 1,
                                    np.ptp(rows) + 1)
            assert a["area"] == len(rows)
        seen_total += len(seen)
        img = coco.loadImgs([k + 1])[0]
        assert img["file_name"] == frame["files"]["display"]
        assert (folder / img["file_name"]).is_file()
    assert seen_total >= 4  # the craters are in view


def test_colmap_model_loads_in_pycolmap_with_the_poses(run):
    pycolmap = pytest.importorskip("pycolmap")
    folder, doc = run
    rec = pycolmap.Reconstruction(str(folder / "colmap"))
    cam = rec.cameras[1]
    assert cam.model.name == "OPENCV"
    i = doc["intrinsics"]
    assert np.allclose(cam.params, [i["fx"], i["fy"], i["cx"], i["cy"], -0.05, 0.0, 0.0,
                                    1e-3], rtol=0, atol=1e-12)
    assert len(rec.images) == len(doc["frames"])
    for k, frame in enumerate(doc["frames"]):
        image = rec.images[k + 1]
        rot = quaternion_to_matrix(frame["quaternion_wxyz"])
        pos = np.asarray(frame["position_m"])
        pose = image.cam_from_world() if callable(image.cam_from_world) \
            else image.cam_from_world
        assert np.abs(pose.rotation.matrix() - rot.T).max() <= 1e-9
        assert np.abs(pose.translation - (-rot.T @ pos)).max() <= 1e-9 * np.linalg.norm(pos)
        assert np.abs(image.projection_center() - pos).max() <= 1e-9 * np.linalg.norm(pos)
        assert image.name == frame["files"]["display"]


def test_nerf_transforms_are_the_poses_in_the_opengl_convention(run):
    folder, doc = run
    tf = json.loads((folder / "transforms.json").read_text())
    i = doc["intrinsics"]
    assert (tf["fl_x"], tf["cx"], tf["w"], tf["h"]) == (i["fx"], i["cx"], i["width"],
                                                        i["height"])
    assert tf["k1"] == -0.05 and tf["p2"] == 1e-3
    for frame, entry in zip(doc["frames"], tf["frames"], strict=True):
        c2w = np.array(entry["transform_matrix"])
        rot = quaternion_to_matrix(frame["quaternion_wxyz"])
        # OpenGL: the camera looks down its -z, y up: the OpenCV z axis and -y
        assert np.allclose(c2w[:3, 2], -rot[:, 2], atol=1e-12)
        assert np.allclose(c2w[:3, 1], -rot[:, 1], atol=1e-12)
        assert np.allclose(c2w[:3, 3], frame["position_m"], atol=0)
        assert np.allclose(c2w[3], [0, 0, 0, 1])
        assert (folder / entry["depth_file_path"]).is_file()


def test_dataset_names_and_folders_are_checked(tmp_path):
    assert parse_datasets("coco,,nerf,coco") == ("coco", "nerf")
    with pytest.raises(ParameterError, match="datasets.*'voc'"):
        parse_datasets("coco,voc")
    with pytest.raises(ParameterError, match="datasets"):
        CameraSettings(Camera.from_fov(40.0, 8, 8), datasets="bop")
    with pytest.raises(FileNotFoundError, match="frames.json"):
        write_datasets(tmp_path)


def read_flo(path) -> np.ndarray:
    """Middlebury .flo, as its specification reads."""
    raw = np.fromfile(path, dtype="<f4")
    assert raw[0] == np.float32(202021.25)
    w, h = np.frombuffer(raw[1:3].tobytes(), dtype="<i4")
    return raw[3:].reshape(h, w, 2)


@pytest.mark.parametrize("fmt", ["npy", "exr"])
def test_optical_flow_carries_each_surface_point_to_where_the_next_frame_sees_it(
        tmp_path, fmt):
    body = latlong.Body.sphere(latlong.LatLongGrid(96), 500.0)
    target = [500.0, 20.0, -10.0]
    poses = Poses.of([Pose.look_at([800.0, 0.0, 0.0], target),
                      Pose.look_at([780.0, -60.0, 40.0], target, time_s=1.0)])
    cam = Camera.from_fov(30.0, 96, 80, k1=-0.03)
    settings = CameraSettings(cam, datasets="flow", depth_format=fmt, all_ground_truth=True)
    doc = camera_run(body, settings, poses, [1.0, 0.3, 0.2], tmp_path / "run")
    name = doc["frames"][0]["files"]["flow"]
    assert "flow" not in doc["frames"][1]["files"]
    if fmt == "exr":
        import OpenEXR

        with OpenEXR.File(str(tmp_path / "run" / name)) as f:
            ch = f.channels()
            flow = np.stack([ch["U"].pixels, ch["V"].pixels], axis=-1)
        known = np.isfinite(flow[:, :, 0])
    else:
        flow = read_flo(tmp_path / "run" / name)
        known = flow[:, :, 0] < 1e9
    pos_a = np.load(tmp_path / "run" / doc["frames"][0]["files"]["position"])
    pos_b = np.load(tmp_path / "run" / doc["frames"][1]["files"]["position"])
    # unknown only on the sky and off the next frame: most of the seen sphere is known
    assert known.sum() >= 0.8 * np.isfinite(pos_a[:, :, 0]).sum() > 1000
    assert not known[~np.isfinite(pos_a[:, :, 0])].any()
    j, i = np.nonzero(known)
    x = i + 0.5 + flow[j, i, 0]
    y = j + 0.5 + flow[j, i, 1]
    # the next frame sees the same surface point at the pixel the flow points to: within
    # a pixel's footprint (range x pixel angle) of its own point there
    col = np.clip(np.floor(x).astype(int), 0, cam.width - 1)
    row = np.clip(np.floor(y).astype(int), 0, cam.height - 1)
    miss = np.linalg.norm(pos_b[row, col] - pos_a[j, i], axis=1)
    footprint = np.linalg.norm(pos_a[j, i] - poses[1].position_m, axis=1) / cam.fx
    assert np.all(miss <= 1.5 * footprint)
    assert np.abs(flow[known]).max() > 3.0  # the camera moved: the flow is not zero
