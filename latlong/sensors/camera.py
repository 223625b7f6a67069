"""Pinhole cameras with Brown–Conrady distortion, poses, primary rays and projection.

Conventions (DESIGN §2):

* **Camera frame**: OpenCV's, x right, y down, z forward (the optical axis).
* **Intrinsics** ``fx, fy, cx, cy`` in pixels; a point (x, y, z) of the camera frame
  goes to the normalised point (x/z, y/z), through the distortion, to the pixel
  coordinates u = fx xd + cx, v = fy yd + cy.
* **Pixel centres at integer + 0.5**: pixel (column i, row j) covers [i, i+1) x [j, j+1)
  and its centre is (i + 0.5, j + 0.5); a centred camera has cx = width / 2. OpenCV puts
  centres at integers: its matrix is ours with cx - 0.5, cy - 0.5
  (:meth:`Camera.opencv_matrix`).
* **Distortion**: Brown (1966) – Conrady (1919) radial k1, k2, k3 and tangential p1, p2
  exactly as OpenCV's ``projectPoints`` / ``undistortPoints`` define them (same order of
  coefficients); rays are cast through the undistorted direction of each pixel centre
  (Newton's method, converged to 1e-14).
* **Pose**: the camera's position in the body frame (metres) and the rotation from the
  camera frame to the body frame as a unit quaternion (w, x, y, z): a direction d_cam
  seen by the camera is R(q) d_cam in the body frame.

Examples
--------
>>> cam = Camera.from_fov(90.0, 4, 2)
>>> cam.fx, cam.cx, cam.cy
(2.0, 2.0, 1.0)
>>> pose = Pose.look_at([10, 0, 0], [0, 0, 0])  # body +z up in the picture
>>> o, d = cam.rays(pose)
>>> d.shape, d[0, 0].round(4).tolist()  # the top-left pixel looks left (-y) and up
((2, 4, 3), [-0.7845, -0.5883, 0.1961])
>>> cam.project([[0.0, 0.0, 0.0]], pose)[0].round(6).tolist()
[[2.0, 1.0]]
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from craters._shared import ParameterError, check_finite, check_int, check_positive

__all__ = ["Camera", "Pose", "quaternion_from_matrix", "quaternion_to_matrix", "unit_direction",
           "unit_quaternions"]


def unit_direction(parameter: str, value) -> np.ndarray:
    """``value`` as a read-only unit (3,) float64 vector; ValueError naming ``parameter``
    unless it is 3 finite numbers, not all zero."""
    try:
        d = np.array(value, dtype=np.float64).reshape(-1)
    except (TypeError, ValueError):
        raise ParameterError(parameter, f"must be 3 numbers; got {value!r}") from None
    if d.shape != (3,) or not np.isfinite(d).all():
        raise ParameterError(parameter, f"must be 3 finite numbers; got {value!r}")
    big = float(np.abs(d).max())
    if not big > 0:
        raise ParameterError(parameter, "must not be the zero vector")
    d = d / big  # 1e308 components do not overflow the norm
    d = d / np.linalg.norm(d)
    d.flags.writeable = False
    return d

#: How far a quaternion's norm may be from 1 (CSV files round to ~1e-7).
QUATERNION_TOLERANCE = 1e-6


def unit_quaternions(q, name: str = "quaternion_wxyz") -> np.ndarray:
    """``q`` (..., 4) as float64 unit quaternions w, x, y, z; a norm further than
    ``QUATERNION_TOLERANCE`` from 1 (or a non-finite value) is a :class:`ParameterError`
    naming ``name``."""
    try:
        q = np.array(q, dtype=np.float64)
    except (TypeError, ValueError):
        raise ParameterError(name, f"must be quaternions w, x, y, z; got {q!r}") from None
    if q.ndim == 0 or q.shape[-1] != 4 or not np.isfinite(q).all():
        raise ParameterError(name, f"must be finite quaternions w, x, y, z; got {q.tolist()}")
    norm = np.linalg.norm(q, axis=-1)
    bad = np.abs(norm - 1.0) > QUATERNION_TOLERANCE
    if bad.any():
        i = int(np.argmax(bad.reshape(-1)))
        raise ParameterError(name, f"must be a unit quaternion (norm within "
                             f"{QUATERNION_TOLERANCE:g} of 1); got norm "
                             f"{norm.reshape(-1)[i]:.9g} for {q.reshape(-1, 4)[i].tolist()}")
    return q / norm[..., None]


def quaternion_to_matrix(q) -> np.ndarray:
    """Rotation matrix (3, 3) (or (..., 3, 3)) of unit quaternion(s) (w, x, y, z) (Hamilton
    convention); a quaternion whose norm is not 1 within 1e-6 is an error.

    Examples
    --------
    >>> quaternion_to_matrix([math.cos(math.pi / 4), 0, 0, math.sin(math.pi / 4)]).round(12)
    array([[ 0., -1.,  0.],
           [ 1.,  0.,  0.],
           [ 0.,  0.,  1.]])
    """
    w, x, y, z = np.moveaxis(unit_quaternions(q), -1, 0)
    return np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], -1),
        np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], -1),
        np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], -1),
    ], -2)


def quaternion_from_matrix(m) -> np.ndarray:
    """Unit quaternion (w, x, y, z), w >= 0, of a rotation matrix (Shepperd 1978's
    numerically stable choice of the largest component).

    Examples
    --------
    >>> quaternion_from_matrix(np.eye(3)).tolist()
    [1.0, 0.0, 0.0, 0.0]
    """
    m = np.asarray(m, dtype=np.float64)
    tr = m[0, 0] + m[1, 1] + m[2, 2]
    cand = np.array([tr, m[0, 0], m[1, 1], m[2, 2]])
    k = int(np.argmax(cand))
    if k == 0:
        s = 2.0 * math.sqrt(1.0 + tr)
        q = [0.25 * s, (m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s]
    elif k == 1:
        s = 2.0 * math.sqrt(1.0 + m[0, 0] - m[1, 1] - m[2, 2])
        q = [(m[2, 1] - m[1, 2]) / s, 0.25 * s, (m[0, 1] + m[1, 0]) / s, (m[0, 2] + m[2, 0]) / s]
    elif k == 2:
        s = 2.0 * math.sqrt(1.0 + m[1, 1] - m[0, 0] - m[2, 2])
        q = [(m[0, 2] - m[2, 0]) / s, (m[0, 1] + m[1, 0]) / s, 0.25 * s, (m[1, 2] + m[2, 1]) / s]
    else:
        s = 2.0 * math.sqrt(1.0 + m[2, 2] - m[0, 0] - m[1, 1])
        q = [(m[1, 0] - m[0, 1]) / s, (m[0, 2] + m[2, 0]) / s, (m[1, 2] + m[2, 1]) / s, 0.25 * s]
    quat = np.array(q)
    quat /= np.linalg.norm(quat)
    return quat if quat[0] >= 0 else -quat


def _vector(name: str, value, n: int) -> np.ndarray:
    try:
        arr = np.array(value, dtype=np.float64).reshape(-1)
    except (TypeError, ValueError):
        raise ParameterError(name, f"must be {n} numbers; got {value!r}") from None
    if arr.shape != (n,) or not np.isfinite(arr).all():
        raise ParameterError(name, f"must be {n} finite numbers; got {value!r}")
    arr.flags.writeable = False
    return arr


@dataclass(frozen=True, slots=True)
class Pose:
    """Where a camera is and how it is turned, in the body frame (module notes)."""

    position_m: np.ndarray
    """(3,) camera centre in the body frame, metres."""
    quaternion_wxyz: np.ndarray
    """(4,) unit quaternion (w, x, y, z) of the camera-to-body rotation (its norm must be
    within 1e-6 of 1; stored normalised)."""
    time_s: float = 0.0
    """Time of the frame, seconds (recorded in the manifest)."""
    rotation: np.ndarray = field(init=False, repr=False, compare=False)
    """(3, 3) camera-to-body rotation matrix (columns: the camera's x, y, z axes)."""

    def __post_init__(self):
        object.__setattr__(self, "position_m", _vector("position_m", self.position_m, 3))
        q = unit_quaternions(_vector("quaternion_wxyz", self.quaternion_wxyz, 4))
        q.flags.writeable = False
        object.__setattr__(self, "quaternion_wxyz", q)
        object.__setattr__(self, "time_s", check_finite("time_s", self.time_s))
        rot = quaternion_to_matrix(q)
        rot.flags.writeable = False
        object.__setattr__(self, "rotation", rot)

    @classmethod
    def look_at(cls, position_m, target_m, up=(0.0, 0.0, 1.0), *, time_s: float = 0.0) -> Pose:
        """A camera at ``position_m`` whose optical axis points at ``target_m`` and whose
        picture has ``up`` (body frame) towards its top edge (another axis if ``up`` is
        along the view)."""
        p = _vector("position_m", position_m, 3)
        z = _vector("target_m", target_m, 3) - p
        if not np.linalg.norm(z) > 0:
            raise ParameterError("target_m", "must differ from `position_m`")
        z = z / np.linalg.norm(z)
        up = _vector("up", up, 3)
        y = -(up - (up @ z) * z)
        if np.linalg.norm(y) < 1e-9 * max(float(np.linalg.norm(up)), 1e-300):
            alt = np.eye(3)[int(np.argmin(np.abs(z)))]
            y = -(alt - (alt @ z) * z)
        y /= np.linalg.norm(y)
        x = np.cross(y, z)
        return cls(p, quaternion_from_matrix(np.column_stack([x, y, z])), time_s)

    def to_camera(self, points_m) -> np.ndarray:
        """(k, 3) body-frame points in the camera frame, metres."""
        pts = np.asarray(points_m, dtype=np.float64).reshape(-1, 3)
        return (pts - self.position_m) @ self.rotation


@dataclass(frozen=True, slots=True)
class Camera:
    """Pinhole intrinsics and Brown–Conrady distortion (module notes)."""

    fx: float
    """Focal length along x, pixels (> 0)."""
    fy: float
    """Focal length along y, pixels (> 0)."""
    cx: float
    """Principal point x, pixels (pixel centres at integer + 0.5; centred: width / 2)."""
    cy: float
    """Principal point y, pixels (centred: height / 2)."""
    width: int
    """Image width, pixels, [1, 16384]."""
    height: int
    """Image height, pixels, [1, 16384]."""
    k1: float = 0.0
    """Radial distortion coefficient of r^2 (OpenCV's k1)."""
    k2: float = 0.0
    """Radial distortion coefficient of r^4 (OpenCV's k2)."""
    p1: float = 0.0
    """Tangential distortion coefficient p1 (OpenCV's)."""
    p2: float = 0.0
    """Tangential distortion coefficient p2 (OpenCV's)."""
    k3: float = 0.0
    """Radial distortion coefficient of r^6 (OpenCV's k3)."""

    def __post_init__(self):
        for key in ("fx", "fy"):
            object.__setattr__(self, key, check_positive(key, getattr(self, key)))
        for key in ("cx", "cy", "k1", "k2", "p1", "p2", "k3"):
            object.__setattr__(self, key, check_finite(key, getattr(self, key)))
        for key in ("width", "height"):
            object.__setattr__(self, key, check_int(key, getattr(self, key), 1, 16384))

    @classmethod
    def from_fov(cls, fov_deg: float, width: int, height: int, **distortion) -> Camera:
        """A centred camera with square pixels whose *horizontal* field of view (across
        the width) is ``fov_deg`` degrees, in (0, 180)."""
        fov = check_finite("fov_deg", fov_deg)
        if not 0.0 < fov < 180.0:
            raise ParameterError("fov_deg", f"must be in (0, 180) degrees; got {fov_deg!r}")
        width = check_int("width", width, 1, 16384)
        height = check_int("height", height, 1, 16384)
        f = 0.5 * width / math.tan(math.radians(fov) / 2.0)
        return cls(f, f, 0.5 * width, 0.5 * height, width, height, **distortion)

    @property
    def distortion(self) -> tuple[float, float, float, float, float]:
        """(k1, k2, p1, p2, k3): OpenCV's ``distCoeffs`` order."""
        return (self.k1, self.k2, self.p1, self.p2, self.k3)

    @property
    def distorted(self) -> bool:
        return any(self.distortion)

    def intrinsics(self) -> dict:
        """fx, fy, cx, cy, width, height (the manifest's ``intrinsics``)."""
        return {"fx": self.fx, "fy": self.fy, "cx": self.cx, "cy": self.cy,
                "width": self.width, "height": self.height}

    def opencv_matrix(self) -> np.ndarray:
        """OpenCV's 3 x 3 camera matrix (pixel centres at integers: cx - 0.5, cy - 0.5)."""
        return np.array([[self.fx, 0.0, self.cx - 0.5], [0.0, self.fy, self.cy - 0.5],
                         [0.0, 0.0, 1.0]])

    def pixel_directions(self) -> tuple[np.ndarray, np.ndarray]:
        """(height, width, 3) unit directions of the pixel centres in the camera frame,
        and (height, width) bool: the distortion model is invertible there."""
        u = np.arange(self.width) + 0.5
        v = np.arange(self.height) + 0.5
        xd = np.broadcast_to((u - self.cx) / self.fx, (self.height, self.width))
        yd = np.broadcast_to(((v - self.cy) / self.fy)[:, None], (self.height, self.width))
        x, y, ok = self.undistort(xd.ravel(), yd.ravel())
        d = np.empty((self.height * self.width, 3))
        d[:, 0], d[:, 1], d[:, 2] = x, y, 1.0
        d /= np.linalg.norm(d, axis=1, keepdims=True)
        return d.reshape(self.height, self.width, 3), ok.reshape(self.height, self.width)

    def undistort(self, xd, yd) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Normalised undistorted (x, y) of distorted normalised points, and where the
        inversion converged."""
        from ._camera_kernels import _undistort_kernel  # numba loads here
        xd = np.ascontiguousarray(xd, dtype=np.float64).ravel()
        yd = np.ascontiguousarray(yd, dtype=np.float64).ravel()
        if not self.distorted:
            return xd.copy(), yd.copy(), np.ones(len(xd), dtype=bool)
        x, y = np.empty_like(xd), np.empty_like(yd)
        ok = np.empty(len(xd), dtype=np.bool_)
        _undistort_kernel(xd, yd, *self.distortion, 50, x, y, ok)
        return x, y, ok

    def distort(self, x, y) -> tuple[np.ndarray, np.ndarray]:
        """Distorted normalised coordinates of undistorted ones (OpenCV's model)."""
        from ._camera_kernels import _distort  # numba loads here
        x = np.asarray(x, dtype=np.float64)
        y = np.asarray(y, dtype=np.float64)
        xd, yd = _distort(x, y, *self.distortion)[:2]
        return xd, yd

    def rays(self, pose: Pose) -> tuple[np.ndarray, np.ndarray]:
        """The camera centre (3,) and the (height, width, 3) unit body-frame directions
        through the pixel centres (NaN where the distortion cannot be inverted)."""
        from ._camera_kernels import _pixel_rays_kernel  # numba loads here
        if not isinstance(pose, Pose):
            raise TypeError(f"`pose` must be a Pose; got {type(pose).__name__}")
        d = np.empty((self.height, self.width, 3))
        _pixel_rays_kernel(self.fx, self.fy, self.cx, self.cy, *self.distortion,
                           self.distorted, pose.rotation, d)
        return pose.position_m.copy(), d

    def project(self, points_m, pose: Pose) -> tuple[np.ndarray, np.ndarray]:
        """Pixel coordinates (k, 2) of body-frame points (pixel centres at integer + 0.5)
        and their depth along the optical axis (k,), metres (<= 0: behind the camera)."""
        pc = pose.to_camera(points_m)
        z = pc[:, 2]
        with np.errstate(divide="ignore", invalid="ignore"):
            xd, yd = self.distort(pc[:, 0] / z, pc[:, 1] / z)
        return np.column_stack([self.fx * xd + self.cx, self.fy * yd + self.cy]), z
