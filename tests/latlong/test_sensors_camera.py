"""Cameras (latlong.sensors.camera): intrinsics, Brown-Conrady distortion, poses, rays."""

from __future__ import annotations

import math

import numpy as np
import pytest

from craters._shared import ParameterError
from latlong.sensors import Camera, Pose, quaternion_from_matrix, quaternion_to_matrix
from latlong.sensors._camera_kernels import _undistort_kernel

DISTORTIONS = [dict(k1=-0.28, k2=0.07, p1=1e-3, p2=-5e-4, k3=-0.01),
               dict(k1=0.1, k2=0.0, p1=0.0, p2=0.0, k3=0.0)]


def random_rotation(rng):
    q = rng.normal(size=4)
    return q / np.linalg.norm(q)


def numpy_undistort(xd, yd, k1, k2, p1, p2, k3, iterations=200):
    """Reference: OpenCV's fixed-point iteration (cvUndistortPointsInternal)."""
    x, y = xd.copy(), yd.copy()
    for _ in range(iterations):
        r2 = x * x + y * y
        icdist = 1.0 / (1 + ((k3 * r2 + k2) * r2 + k1) * r2)
        dx = 2 * p1 * x * y + p2 * (r2 + 2 * x * x)
        dy = p1 * (r2 + 2 * y * y) + 2 * p2 * x * y
        x = (xd - dx) * icdist
        y = (yd - dy) * icdist
    return x, y


@pytest.mark.parametrize("dist", DISTORTIONS)
def test_undistort_kernel_matches_numpy_and_inverts(rng, dist):
    cam = Camera(800, 820, 512, 384, 1024, 768, **dist)
    xd = rng.uniform(-0.6, 0.6, 2000)
    yd = rng.uniform(-0.45, 0.45, 2000)
    x, y, ok = np.empty(2000), np.empty(2000), np.empty(2000, bool)
    _undistort_kernel(xd, yd, *cam.distortion, 50, x, y, ok)
    assert ok.all()
    xr, yr = numpy_undistort(xd, yd, *cam.distortion)
    np.testing.assert_allclose(x, xr, atol=1e-12)
    np.testing.assert_allclose(y, yr, atol=1e-12)
    back = cam.distort(x, y)
    np.testing.assert_allclose(back[0], xd, atol=1e-13)
    np.testing.assert_allclose(back[1], yd, atol=1e-13)


@pytest.mark.parametrize("dist", DISTORTIONS + [{}])
def test_projection_matches_opencv(rng, dist):
    cv2 = pytest.importorskip("cv2")
    cam = Camera(900.0, 905.0, 330.0, 250.0, 640, 480, **dist)
    pose = Pose([1.0, -2.0, 3.0], random_rotation(rng))
    pts_cam = np.column_stack([rng.uniform(-3, 3, (300, 2)), rng.uniform(5, 20, 300)])
    pts = pts_cam @ pose.rotation.T + pose.position_m
    uv, depth = cam.project(pts, pose)
    np.testing.assert_allclose(depth, pts_cam[:, 2], rtol=1e-12)
    rvec, _ = cv2.Rodrigues(pose.rotation.T)  # body -> camera
    tvec = -pose.rotation.T @ pose.position_m
    ref, _ = cv2.projectPoints(pts, rvec, tvec, cam.opencv_matrix(), np.array(cam.distortion))
    # OpenCV's pixel centres are at integers: ours are at + 0.5
    np.testing.assert_allclose(uv, ref.reshape(-1, 2) + 0.5, atol=1e-7)


@pytest.mark.parametrize("dist", DISTORTIONS + [{}])
def test_rays_go_through_pixel_centres(rng, dist):
    cam = Camera(300.0, 310.0, 64.0, 40.0, 128, 80, **dist)
    pose = Pose([10.0, 20.0, -5.0], random_rotation(rng))
    o, d = cam.rays(pose)
    assert d.shape == (80, 128, 3) and np.isfinite(d).all()
    np.testing.assert_allclose(np.linalg.norm(d, axis=2), 1.0, atol=1e-14)
    uv, depth = cam.project(o + 7.0 * d.reshape(-1, 3), pose)
    jj, ii = np.mgrid[0:80, 0:128]
    np.testing.assert_allclose(uv[:, 0], ii.ravel() + 0.5, atol=1e-9)
    np.testing.assert_allclose(uv[:, 1], jj.ravel() + 0.5, atol=1e-9)
    assert (depth > 0).all()


def test_field_of_view_and_centre():
    cam = Camera.from_fov(60.0, 200, 100)
    assert cam.cx == 100.0 and cam.cy == 50.0 and cam.fx == cam.fy
    pose = Pose([0, 0, 0], [1, 0, 0, 0])  # camera frame = body frame
    # the left edge of the picture (u = 0) is 30 degrees off the axis
    uv, _ = cam.project([[-math.tan(math.radians(30)), 0.0, 1.0]], pose)
    assert abs(uv[0, 0]) < 1e-12 and abs(uv[0, 1] - 50.0) < 1e-12
    assert cam.intrinsics() == {"fx": cam.fx, "fy": cam.fy, "cx": 100.0, "cy": 50.0,
                                "width": 200, "height": 100}
    with pytest.raises(ParameterError, match="fov_deg"):
        Camera.from_fov(180.0, 10, 10)
    with pytest.raises(ParameterError, match="fx"):
        Camera(0.0, 1.0, 0, 0, 10, 10)
    with pytest.raises(ParameterError, match="width"):
        Camera(1.0, 1.0, 0, 0, 0, 10)


def test_quaternions(rng):
    for _ in range(200):
        q = random_rotation(rng)
        m = quaternion_to_matrix(q)
        np.testing.assert_allclose(m @ m.T, np.eye(3), atol=1e-14)
        assert abs(np.linalg.det(m) - 1) < 1e-14
        q2 = quaternion_from_matrix(m)
        np.testing.assert_allclose(q2, q * np.sign(q[0]), atol=1e-14)
    # 90 degrees about z turns x into y
    m = quaternion_to_matrix([math.cos(math.pi / 4), 0, 0, math.sin(math.pi / 4)])
    np.testing.assert_allclose(m @ [1, 0, 0], [0, 1, 0], atol=1e-15)


def test_pose_checks_and_look_at():
    with pytest.raises(ParameterError, match="unit quaternion"):
        Pose([0, 0, 0], [1.0, 0.1, 0, 0])
    with pytest.raises(ParameterError, match="quaternion_wxyz"):
        Pose([0, 0, 0], [1.0, 0, 0])
    with pytest.raises(ParameterError, match="position_m"):
        Pose([0, np.nan, 0], [1.0, 0, 0, 0])
    p = Pose([0, 0, 0], [1.0 + 5e-7, 0, 0, 0])  # CSV rounding is accepted, normalised
    assert np.linalg.norm(p.quaternion_wxyz) == 1.0
    cam = Camera.from_fov(40.0, 64, 48)
    for up in ([0, 0, 1], [1, 0, 0]):
        pose = Pose.look_at([100.0, 50.0, 30.0], [1.0, 2.0, 3.0], up, time_s=2.5)
        uv, depth = cam.project([[1.0, 2.0, 3.0]], pose)
        np.testing.assert_allclose(uv[0], [32.0, 24.0], atol=1e-9)
        assert depth[0] > 0 and pose.time_s == 2.5
    # looking along the up vector still gives a pose
    pose = Pose.look_at([0, 0, 10], [0, 0, 0])
    np.testing.assert_allclose(pose.rotation[:, 2], [0, 0, -1], atol=1e-15)
    with pytest.raises(ParameterError, match="target_m"):
        Pose.look_at([1, 2, 3], [1, 2, 3])
