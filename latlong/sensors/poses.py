"""Sensor poses: camera-to-body rotations (unit quaternions w, x, y, z) and positions in
the body frame (metres), one per frame, from arguments or a CSV trajectory.

The sensor frame is OpenCV's (x right, y down, z forward): a direction ``d_s`` in the
sensor frame is ``R @ d_s`` in the body frame, ``R = quaternion_to_matrix(q)``.
"""

from __future__ import annotations

import csv
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from craters._shared import ParameterError, check_finite, check_int, check_positive, check_range
from craters._shared.files import check_regular_file

from .camera import Pose, unit_quaternions

__all__ = ["POSE_COLUMNS", "Poses", "approach", "read_poses", "read_poses_toml", "surface_point"]

#: The header of a trajectory CSV (issue 17's interface).
#: Largest trajectory file read, bytes (~10 million poses as CSV).
MAX_POSES_BYTES = 1 << 30
POSE_COLUMNS = ("time_s", "x_m", "y_m", "z_m", "qw", "qx", "qy", "qz")
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
        q = unit_quaternions(np.reshape(self.quaternion_wxyz, (-1, 4)))
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

    def __getitem__(self, k: int) -> Pose:
        """Frame ``k`` as a :class:`~latlong.sensors.camera.Pose`."""
        return Pose(self.position_m[k], self.quaternion_wxyz[k], float(self.time_s[k]))

    @classmethod
    def of(cls, poses) -> Poses:
        """The trajectory of a sequence of :class:`~latlong.sensors.camera.Pose`."""
        poses = list(poses)
        if not all(isinstance(p, Pose) for p in poses):
            raise TypeError("`poses` must be Pose objects")
        return cls(np.array([p.time_s for p in poses]),
                   np.array([p.position_m for p in poses]).reshape(-1, 3),
                   np.array([p.quaternion_wxyz for p in poses]).reshape(-1, 4))

    @classmethod
    def one(cls, position_m, quaternion_wxyz, time_s: float = 0.0) -> Poses:
        """A single pose."""
        return cls(np.array([time_s]), np.reshape(position_m, (1, 3)),
                   np.reshape(quaternion_wxyz, (1, 4)))


def read_poses(path) -> Poses:
    """Read a trajectory CSV with the header ``time_s,x_m,y_m,z_m,qw,qx,qy,qz`` (lines
    starting with ``#`` are comments), or a ``.toml`` file (:func:`read_poses_toml`).

    Raises ValueError (one line, naming the file and row) on anything else.
    """
    path = Path(path)
    if path.suffix.lower() == ".toml":
        return read_poses_toml(path)
    check_regular_file(path, "poses file", MAX_POSES_BYTES)
    try:
        with open(path, newline="") as fh:
            rows = list(csv.reader(fh))
    except (OSError, UnicodeDecodeError, csv.Error) as exc:  # csv: a field over 128 KiB
        raise ValueError(f"cannot read poses {str(path)!r}: {exc}") from None
    rows = [r for r in rows
            if r and any(c.strip() for c in r) and not r[0].lstrip().startswith("#")]
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


def read_poses_toml(path) -> Poses:
    """Read a trajectory TOML: ``[[frame]]`` tables with ``time_s``, ``position_m = [x, y,
    z]`` and ``quaternion_wxyz = [w, x, y, z]`` (unknown keys are errors)."""
    import tomllib

    path = check_regular_file(path, "poses file", MAX_POSES_BYTES)
    try:
        with open(path, "rb") as fh:
            doc = tomllib.load(fh)
    except (OSError, tomllib.TOMLDecodeError, RecursionError) as exc:
        raise ValueError(f"cannot read poses {str(path)!r}: {exc}") from None
    frames = doc.get("frame")
    if set(doc) != {"frame"} or not isinstance(frames, list) or not frames:
        raise ValueError(f"poses {str(path)!r}: expected only [[frame]] tables; got keys "
                         f"{sorted(doc)}")
    keys = {"time_s", "position_m", "quaternion_wxyz"}
    for i, f in enumerate(frames, 1):
        if set(f) != keys:
            raise ValueError(f"poses {str(path)!r} frame {i}: needs exactly {sorted(keys)}; "
                             f"got {sorted(f)}")
    try:
        return Poses(*(np.array([f[k] for f in frames], dtype=np.float64)
                       for k in ("time_s", "position_m", "quaternion_wxyz")))
    except (TypeError, ValueError) as exc:
        raise ValueError(f"poses {str(path)!r}: {exc}") from None


def surface_point(mesh, lat_deg: float, lon_deg: float) -> np.ndarray:
    """The outermost surface point of ``mesh`` (a :class:`~latlong.sensors.engine.RayMesh`)
    in the direction (``lat_deg``, ``lon_deg``) from the body-frame origin, metres."""
    lat, lon = np.radians(check_range("lat_deg", lat_deg, -90.0, 90.0)), \
        np.radians(check_finite("lon_deg", lon_deg))
    d = np.array([np.cos(lat) * np.cos(lon), np.cos(lat) * np.sin(lon), np.sin(lat)])
    centre, radius = mesh.bounding_sphere
    start = d * (np.linalg.norm(centre) + 2.0 * radius)
    hits = mesh.intersect(start[None], -d[None])
    if not hits.hit[0]:
        raise ParameterError("lat_deg", f"no surface in the direction ({lat_deg}, {lon_deg})")
    return start - hits.t_m[0] * d


def approach(target_m, *, n_frames: int = 10, start_range_m: float, end_range_m: float,
             path_angle_deg: float = 0.0, path_azimuth_deg: float = 0.0,
             duration_s: float | None = None, up=(0.0, 0.0, 1.0), vertical=None) -> Poses:
    """A straight approach or descent towards ``target_m`` (a surface point, body frame,
    metres): ``n_frames`` cameras looking at the target along one line, at ranges spaced
    geometrically from ``start_range_m`` to ``end_range_m`` (equal ratios between frames,
    as a descent slows down). The line leaves the target ``path_angle_deg`` from its local
    vertical towards ``path_azimuth_deg`` (from local north towards east; 0 = straight
    down). The local vertical is ``vertical`` (body frame) or, by default, the target's
    radial direction from the origin (a body); give ``vertical=(0, 0, 1)`` for an open
    surface in a local frame with z up, such as a ``dem mesh`` (x east, y north). North
    points towards the body's +z axis (+y where the vertical is +z: x is then east).
    Times run 0 .. ``duration_s`` (default: one second per
    frame). ``up`` (body frame) points up the pictures (another axis if along the view).
    ``n_frames`` is 10 unless given.

    Examples
    --------
    >>> p = approach([1000.0, 0, 0], n_frames=3, start_range_m=400, end_range_m=100)
    >>> p.position_m[:, 0].round(6).tolist(), p.time_s.tolist()
    ([1400.0, 1200.0, 1100.0], [0.0, 1.0, 2.0])
    """
    target = np.asarray(target_m, dtype=np.float64).reshape(3)
    if not np.isfinite(target).all() or (vertical is None and not np.linalg.norm(target) > 0):
        raise ParameterError("target_m", f"must be a finite point (off the origin without "
                             f"`vertical`); got {target.tolist()}")
    n = check_int("n_frames", n_frames, 1, 100_000)
    r0 = check_positive("start_range_m", start_range_m)
    r1 = check_positive("end_range_m", end_range_m)
    angle = np.radians(check_range("path_angle_deg", path_angle_deg, 0.0, 89.0))
    az = np.radians(check_finite("path_azimuth_deg", path_azimuth_deg))
    duration = float(n - 1) if duration_s is None else check_positive("duration_s", duration_s)
    if vertical is None:
        vertical = target / np.linalg.norm(target)
    else:
        vertical = np.asarray(vertical, dtype=np.float64).reshape(-1)
        if vertical.shape != (3,) or not np.isfinite(vertical).all() \
                or not np.linalg.norm(vertical) > 0:
            raise ParameterError("vertical", "must be 3 finite numbers, not all zero")
        vertical = vertical / np.linalg.norm(vertical)
    east = np.cross([0.0, 0.0, 1.0], vertical)
    east = east / np.linalg.norm(east) if np.linalg.norm(east) > 1e-12 else np.array(
        [1.0, 0.0, 0.0])
    north = np.cross(vertical, east)
    line = np.cos(angle) * vertical + np.sin(angle) * (np.cos(az) * north + np.sin(az) * east)
    ranges = r0 * (r1 / r0) ** (np.arange(n) / max(n - 1, 1))
    times = np.linspace(0.0, duration, n) if n > 1 else np.zeros(1)
    poses = [Pose.look_at(target + r * line, target, up, time_s=t)
             for r, t in zip(ranges, times, strict=True)]
    return Poses.of(poses)
