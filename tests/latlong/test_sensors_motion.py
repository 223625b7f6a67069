"""Motion blur and the rolling shutter (latlong.sensors.motion): a camera sliding past
a sphere's limb smears the limb by the distance it moves during the exposure, and a
rolling shutter slants it by the distance it moves during the readout."""

from __future__ import annotations

import numpy as np
import pytest

from latlong import LatLongGrid
from latlong.sensors import Camera, Lambert, Pose, RayMesh, quaternion_to_matrix
from latlong.sensors.motion import pose_at, timed_frame
from latlong.sensors.poses import Poses
from latlong.sensors.render import render
from latlong.sensors.sensor import Sensor

R = 1000.0
Z = 6000.0  # the camera's distance in front of the sphere's centre
CAM = Camera.from_fov(30.0, 160, 64)  # the disc (+-9.6 deg) inside the field (+-15 deg)
SUN = np.array([0.0, 0.0, 1.0])  # behind the camera: a full disc


@pytest.fixture(scope="module")
def sphere():
    g = LatLongGrid(200)
    return RayMesh(g.unit_vectors() * R, g.triangles())


def sliding(speed_m_s: float, n: int = 3) -> Poses:
    """A camera at z = Z looking down -z, sliding along +x at ``speed_m_s``, a frame a
    second."""
    poses = [Pose.look_at([speed_m_s * k, 0.0, Z], [speed_m_s * k, 0.0, 0.0],
                          up=(0.0, 1.0, 0.0), time_s=float(k)) for k in range(n)]
    return Poses.of(poses)


def limb_column(refl: np.ndarray) -> np.ndarray:
    """Per row, the sub-pixel column where the I/F crosses half its disc value on the
    right-hand limb (image x runs along the body's +x here)."""
    half = 0.5 * np.median(refl[refl > 0])
    out = []
    for row in refl:
        c = np.flatnonzero(row[:-1] >= half)
        c = c[c >= CAM.width // 2]
        j = c.max()
        out.append(j + (row[j] - half) / (row[j] - row[j + 1]))
    return np.array(out)


def test_poses_between_frames_are_interpolated():
    poses = sliding(50.0)
    mid = pose_at(poses, 0.25)
    np.testing.assert_allclose(mid.position_m, [12.5, 0.0, Z], atol=1e-12)
    turned = Poses.of([Pose(np.zeros(3), [1.0, 0.0, 0.0, 0.0], 0.0),
                       Pose(np.zeros(3), [np.cos(0.2), 0.0, 0.0, np.sin(0.2)], 2.0)])
    for t, angle in ((0.5, 0.1), (1.0, 0.2), (3.0, 0.6)):  # 0.4 rad in 2 s, carried on
        rot = quaternion_to_matrix(pose_at(turned, t).quaternion_wxyz)
        assert np.arctan2(rot[1, 0], rot[0, 0]) == pytest.approx(angle, abs=1e-12)


def image_shift_px(column: np.ndarray, travel_m: np.ndarray) -> np.ndarray:
    """How far a sideways travel moves the limb in the image, pixels: the direction to
    the sphere's centre turns by travel / Z, which a pinhole maps through 1 / cos^2 of
    the limb's angle off the axis (the limb's own angle asin(R / distance) barely
    changes)."""
    off_axis = np.arctan((column - CAM.cx) / CAM.fx)
    return CAM.fx * travel_m / Z / np.cos(off_axis) ** 2


def test_motion_blur_smears_the_limb_by_the_exposure_travel(sphere):
    speed, exposure = 200.0, 0.5  # 100 m during the exposure
    poses = sliding(speed)
    sensor = Sensor(exposure_s=exposure, bits=32)

    def render_at(camera, pose):
        return render(sphere, camera, pose, SUN, reflectance=Lambert(0.3), sensor=sensor)

    sharp = timed_frame(render_at, poses, 1, CAM, sensor)
    blurred = timed_frame(render_at, poses, 1, CAM, sensor, blur_samples=64)
    rows = slice(24, 40)  # near the equator the limb is vertical
    r, b = sharp.reflectance[rows], blurred.reflectance[rows]
    # far from the sphere the travel moves its image rigidly: the blurred rows are the
    # sharp rows averaged over their shifts during the exposure (the camera moves +x,
    # the image -x), at the instants' (k + 0.5) / 64 of it
    limb = limb_column(r)
    cols = np.arange(CAM.width) + 0.5
    for i in range(len(r)):
        shifts = image_shift_px(limb[i], speed * exposure * (np.arange(64) + 0.5) / 64)
        want = np.mean([np.interp(cols + d, cols, r[i]) for d in shifts], axis=0)
        near = np.abs(cols - limb[i]) < 12  # the limb's neighbourhood
        assert np.abs(b[i, near] - want[near]).max() < 0.02 * r[i].max()
    travel_px = float(image_shift_px(np.median(limb), speed * exposure))
    assert travel_px > 4.0  # a smear of several pixels
    assert np.median(limb - limb_column(b)) > 0.3 * travel_px
    # ground truth of the exposure's start
    np.testing.assert_array_equal(blurred.depth_m, sharp.depth_m)


def test_a_rolling_shutter_slants_the_limb(sphere):
    speed, line_time = 200.0, 5e-3  # each row 1 m of travel after the one above
    poses = sliding(speed)
    sensor = Sensor(exposure_s=1e-4, bits=32)

    def render_at(camera, pose):
        return render(sphere, camera, pose, SUN, reflectance=Lambert(0.3), sensor=sensor)

    sharp = timed_frame(render_at, poses, 1, CAM, sensor)
    rolled = timed_frame(render_at, poses, 1, CAM, sensor, line_time_s=line_time)
    rows = np.arange(20, 44)
    limb = limb_column(sharp.reflectance[rows])
    shift = limb - limb_column(rolled.reflectance[rows])
    # band b (8 rows) is exposed at its middle row's time: the limb has moved -x by the
    # travel until then (within 10 %: the Lambert limb's brightness profile also changes a
    # little as the camera moves, which the rigid-shift model leaves out)
    middle = (rows // 8) * 8 + 3.5
    want = image_shift_px(limb, speed * line_time * middle)
    np.testing.assert_allclose(shift, want, rtol=0.1, atol=0.1)
    assert want.max() - want.min() > 1.0  # a slant, not a shift
