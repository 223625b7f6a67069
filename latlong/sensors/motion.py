"""The camera's timing: motion blur over the exposure and a rolling shutter.

A frame of a trajectory (:class:`~latlong.sensors.poses.Poses`) is first rendered sharp
at its own pose (its ground truth: depth, labels, ... are of that instant) and exposed
(auto-exposure picks the exposure from it). With ``blur_samples`` S >= 2, the exposure
``[t, t + exposure_s]`` is then sampled at S instants (midpoints of S equal parts) and
the I/F images of the poses there are averaged; with ``line_time_s`` > 0 (a rolling
shutter) image row r starts its exposure ``r x line_time_s`` after row 0, rendered in
bands of :data:`BAND_ROWS` rows, each at its band's middle row's time. The pose at a
time between two frames is interpolated: linearly in position, spherically (slerp) in
rotation; before the first or after the last frame the two nearest frames' motion is
carried on. The image is the sensor's exposure of the blurred I/F, at the sharp frame's
exposure.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from craters._shared import ParameterError

from .camera import Camera, Pose
from .poses import Poses
from .sensor import expose

__all__ = ["BAND_ROWS", "pose_at", "timed_frame"]

#: Rows rendered at one time under a rolling shutter.
BAND_ROWS = 8


def _slerp(q0: np.ndarray, q1: np.ndarray, s: float) -> np.ndarray:
    """The geodesic from q0 (s = 0) to q1 (s = 1), continued for s outside [0, 1]."""
    dot = float(np.dot(q0, q1))
    if dot < 0.0:
        q1, dot = -q1, -dot
    if dot > 0.9995:
        q = q0 + s * (q1 - q0)
        return q / np.linalg.norm(q)
    theta = np.arccos(dot)
    return (np.sin((1.0 - s) * theta) * q0 + np.sin(s * theta) * q1) / np.sin(theta)


def pose_at(poses: Poses, time_s: float) -> Pose:
    """The pose at ``time_s`` (module notes); a single pose stands still."""
    t = poses.time_s
    if len(t) == 1:
        return poses[0]
    k = int(np.clip(np.searchsorted(t, time_s, side="right") - 1, 0, len(t) - 2))
    span = t[k + 1] - t[k]
    if not span > 0.0:
        raise ParameterError("time_s", f"frames {k} and {k + 1} have the same time; motion "
                             f"needs increasing frame times")
    s = (time_s - t[k]) / span
    pos = poses.position_m[k] + s * (poses.position_m[k + 1] - poses.position_m[k])
    q = _slerp(poses.quaternion_wxyz[k], poses.quaternion_wxyz[k + 1], s)
    return Pose(pos, q / np.linalg.norm(q), float(time_s))


def timed_frame(render_at, poses: Poses, k: int, camera: Camera, sensor, *,
                blur_samples: int = 0, line_time_s: float = 0.0, seed: int = 0):
    """Frame ``k`` with motion blur and a rolling shutter (module notes).
    ``render_at(camera, pose)`` renders one sharp frame (a
    :class:`~latlong.sensors.render.Frame`) of ``camera`` at ``pose``."""
    sharp = render_at(camera, poses[k])
    if blur_samples < 2 and not line_time_s > 0.0:
        return sharp
    t0, exposure = float(poses.time_s[k]), sharp.exposure_s
    n = max(blur_samples, 1)
    instants = (np.arange(n) + 0.5) / n * exposure
    h = camera.height
    rows = BAND_ROWS if line_time_s > 0.0 else h
    refl = np.zeros(sharp.reflectance.shape)  # (H, W) or (H, W, bands)
    for r0 in range(0, h, rows):
        r1 = min(h, r0 + rows)
        # the band's rows as a camera of their own: same rays, principal point shifted
        sub = dataclasses.replace(camera, cy=camera.cy - r0, height=r1 - r0)
        delay = line_time_s * 0.5 * (r0 + r1 - 1)
        for dt in instants:
            refl[r0:r1] += render_at(sub, pose_at(poses, t0 + delay + dt)).reflectance
    refl /= len(instants)
    image = expose(refl, dataclasses.replace(sensor, exposure_s=exposure), seed=seed)
    return dataclasses.replace(sharp, image=image, reflectance=refl)
