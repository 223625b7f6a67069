"""Sensor poses: camera-to-body rotations (unit quaternions w, x, y, z) and positions in
the body frame (metres), one per frame, from arguments or a CSV trajectory.

The sensor frame is OpenCV's (x right, y down, z forward): a direction ``d_s`` in the
sensor frame is ``R @ d_s`` in the body frame, ``R = rotation_matrix(q)``.
"""

from __future__ import annotations

import csv
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from craters._shared import ParameterError

__all__ = ["POSE_COLUMNS", "Poses", "look_at", "quaternion_from_matrix", "read_poses",
           "rotation_matrix"]

#: The header of a trajectory CSV (issue 17's interface).
POSE_COLUMNS = ("time_s", "x_m", "y_m", "z_m", "qw", "qx", "qy", "qz")
#: How far from 1 the norm of a pose quaternion may be.
UNIT_TOLERANCE = 1e-6


def _unit_quaternions(q, name: str) -> np.ndarray:
    q = np.asarray(q, dtype=np.float64)
    if q.ndim == 0 or q.shape[-1] != 4 or not np.isfinite(q).all():
        raise ParameterError(name, f"must be finite quaternions w, x, y, z; got {q.tolist()}")
    norm = np.linalg.norm(q, axis=-1)
    bad = np.abs(norm - 1.0) > UNIT_TOLERANCE
    if bad.any():
        i = int(np.argmax(bad.reshape(-1)))
        raise ParameterError(name, f"must be a unit quaternion (norm 1 within "
                             f"{UNIT_TOLERANCE:g}); got norm {norm.reshape(-1)[i]:.9g} "
                             f"for {q.reshape(-1, 4)[i].tolist()}")
    return q / norm[..., None]


def rotation_matrix(quaternion_wxyz) -> np.ndarray:
    """The rotation matrix (3, 3) (or (n, 3, 3)) of unit quaternion(s) ``w, x, y, z``.

    Examples
    --------
    >>> rotation_matrix([np.cos(np.pi / 4), 0, 0, np.sin(np.pi / 4)]).round(12) + 0.0
    array([[ 0., -1.,  0.],
           [ 1.,  0.,  0.],
           [ 0.,  0.,  1.]])
    """
    w, x, y, z = np.moveaxis(_unit_quaternions(quaternion_wxyz, "quaternion_wxyz"), -1, 0)
    return np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], -1),
        np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], -1),
        np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], -1),
    ], -2)


@dataclass(frozen=True, slots=True)
class Poses:
    """A trajectory: one sensor pose per frame."""

    time_s: np.ndarray
    """(n,) frame times, seconds."""
    position_m: np.ndarray
    """(n, 3) sensor positions in the body frame, metres."""
    quaternion_wxyz: np.ndarray
    """(n, 4) unit quaternions w, x, y, z: sensor (OpenCV frame) to body rotations."""

    def __post_init__(self):
        t = np.array(self.time_s, dtype=np.float64).reshape(-1)
        p = np.array(self.position_m, dtype=np.float64).reshape(-1, 3)
        q = _unit_quaternions(np.reshape(self.quaternion_wxyz, (-1, 4)), "quaternion_wxyz")
        if not (len(t) == len(p) == len(q)) or not len(t):
            raise ParameterError("time_s", f"times, positions and quaternions must be "
                                 f"non-empty and of one length; got {len(t)}, {len(p)}, "
                                 f"{len(q)}")
        if not np.isfinite(t).all():
            raise ParameterError("time_s", "must be finite")
        if not np.isfinite(p).all():
            raise ParameterError("position_m", "must be finite")
        for name, a in (("time_s", t), ("position_m", p), ("quaternion_wxyz", q)):
            a.setflags(write=False)
            object.__setattr__(self, name, a)

    def __len__(self) -> int:
        return len(self.time_s)

    @classmethod
    def one(cls, position_m, quaternion_wxyz, time_s: float = 0.0) -> Poses:
        """A single pose."""
        return cls(np.array([time_s]), np.reshape(position_m, (1, 3)),
                   np.reshape(quaternion_wxyz, (1, 4)))


def read_poses(path) -> Poses:
    """Read a trajectory CSV with the header ``time_s,x_m,y_m,z_m,qw,qx,qy,qz``.

    Raises ValueError (one line, naming the file and row) on anything else.
    """
    path = Path(path)
    try:
        with open(path, newline="") as fh:
            rows = list(csv.reader(fh))
    except (OSError, UnicodeDecodeError) as exc:
        raise ValueError(f"cannot read poses {str(path)!r}: {exc}") from None
    rows = [r for r in rows if r and any(c.strip() for c in r)]
    if not rows or tuple(c.strip() for c in rows[0]) != POSE_COLUMNS:
        raise ValueError(f"poses {str(path)!r}: the header must be {','.join(POSE_COLUMNS)}")
    if len(rows) < 2:
        raise ValueError(f"poses {str(path)!r} has no rows")
    for i, r in enumerate(rows[1:], 2):
        if len(r) != len(POSE_COLUMNS):
            raise ValueError(f"poses {str(path)!r} line {i}: {len(POSE_COLUMNS)} values "
                             f"needed; got {len(r)}")
    try:
        table = np.array([[float(c) for c in r] for r in rows[1:]], dtype=np.float64)
    except ValueError:
        raise ValueError(f"poses {str(path)!r}: every value must be a number") from None
    try:
        return Poses(table[:, 0], table[:, 1:4], table[:, 4:8])
    except ValueError as exc:
        raise ValueError(f"poses {str(path)!r}: {exc}") from None


def quaternion_from_matrix(matrix) -> np.ndarray:
    """The unit quaternion ``w, x, y, z`` (w >= 0) of a rotation matrix (Shepperd 1978,
    "Quaternion from rotation matrix", J. Guidance Control 1(3): the largest of the four
    squared components is taken first, for accuracy).

    Examples
    --------
    >>> q = [0.5, 0.5, 0.5, 0.5]
    >>> np.allclose(quaternion_from_matrix(rotation_matrix(q)), q)
    True
    """
    m = np.asarray(matrix, dtype=np.float64)
    if m.shape != (3, 3) or not np.isfinite(m).all() \
            or not np.allclose(m @ m.T, np.eye(3), atol=1e-9) or np.linalg.det(m) < 0:
        raise ParameterError("matrix", "must be a 3 x 3 rotation matrix")
    tr = np.trace(m)
    cand = np.array([tr, m[0, 0], m[1, 1], m[2, 2]])
    k = int(np.argmax(cand))
    if k == 0:
        s = 2.0 * np.sqrt(1.0 + tr)
        q = [0.25 * s, (m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s]
    elif k == 1:
        s = 2.0 * np.sqrt(1.0 + m[0, 0] - m[1, 1] - m[2, 2])
        q = [(m[2, 1] - m[1, 2]) / s, 0.25 * s, (m[0, 1] + m[1, 0]) / s, (m[0, 2] + m[2, 0]) / s]
    elif k == 2:
        s = 2.0 * np.sqrt(1.0 + m[1, 1] - m[0, 0] - m[2, 2])
        q = [(m[0, 2] - m[2, 0]) / s, (m[0, 1] + m[1, 0]) / s, 0.25 * s, (m[1, 2] + m[2, 1]) / s]
    else:
        s = 2.0 * np.sqrt(1.0 + m[2, 2] - m[0, 0] - m[1, 1])
        q = [(m[1, 0] - m[0, 1]) / s, (m[0, 2] + m[2, 0]) / s, (m[1, 2] + m[2, 1]) / s, 0.25 * s]
    q = np.array(q)
    q = -q if q[0] < 0 else q
    return q / np.linalg.norm(q)


def look_at(position_m, target_m, up=(0.0, 0.0, 1.0)) -> np.ndarray:
    """The camera-to-body quaternion ``w, x, y, z`` of a sensor at ``position_m`` looking
    at ``target_m`` (OpenCV frame: z forward, y down, so ``up`` points up the picture).

    Examples
    --------
    >>> q = look_at([0, 0, 10.0], [0, 0, 0.0], up=[0, 1.0, 0])
    >>> (rotation_matrix(q) @ [0, 0, 1.0]).round(12) + 0.0
    array([ 0.,  0., -1.])
    """
    p = np.asarray(position_m, dtype=np.float64).reshape(3)
    z = np.asarray(target_m, dtype=np.float64).reshape(3) - p
    if not np.linalg.norm(z) > 0:
        raise ParameterError("target_m", "must differ from position_m")
    z /= np.linalg.norm(z)
    x = np.cross(z, np.asarray(up, dtype=np.float64).reshape(3))
    if not np.linalg.norm(x) > 1e-9:
        raise ParameterError("up", "must not be parallel to the viewing direction")
    x /= np.linalg.norm(x)
    return quaternion_from_matrix(np.stack([x, np.cross(z, x), z], 1))
