"""A LIDAR: flash and scanning beam patterns, beam divergence, range noise, multiple returns.

Beams (sensor frame = OpenCV's: x right, y down, z forward):

* ``flash``: a grid of W x H beams fired at once, through the pixel centres (integer +
  0.5) of a pinhole with ``fx = fy = (W / 2) / tan(fov / 2)``, ``cx = W / 2``,
  ``cy = H / 2`` (``fov_deg`` across the W beams);
* ``scan``: the same grid fired one beam after the other, row by row, alternate rows
  reversed (a boustrophedon raster), one beam every ``1 / pulse_rate_hz`` seconds;
* ``rosette``: W x H beams along the rosette of a Risley-prism pair (two wedges turning
  25 and -17 times per frame, as non-repetitive solid-state scanners do), off-axis
  angles up to ``fov_deg / 2``, one beam every ``1 / pulse_rate_hz`` seconds.

Each beam is ``rays_per_beam`` sub-rays over its footprint: a Gaussian beam whose full
divergence ``divergence_mrad`` is taken at 1/e^2, sampled on a Vogel (sunflower) spiral
out to that radius (the spiral's x and y along the sensor's x and y), sub-ray weight
``w = exp(-2 (rho / rho_e)^2)``. A sub-ray that hits
at range R with incidence i returns the energy of an extended Lambertian target,
``w cos(i) / R^2`` (the lidar equation for extended targets, e.g. Höfle & Pfeifer 2007,
ISPRS J. Photogramm. 62, 415, eq. 1; reflectance uniform). A **return** is a group of
sub-ray hits (one group, or with ``multiple_returns`` groups separated in range by more
than ``return_separation_m`` plus the range step between neighbouring sub-rays on the
same tilted surface, ``R tan(i) 2 r_e / sqrt(N)`` with ``r_e`` the 1/e^2 half-angle and
``i`` capped at 85 degrees: distinct surfaces in one footprint, at most 15): its
range is the mean of the sub-ray ranges **weighted by their return energy** (the
centroid of the received pulse), plus Gaussian noise of ``range_noise_m`` (counter-based:
keyed by run seed, frame, beam, return number), measured along the beam axis: the point
is ``position + range x axis``; its intensity is the range-normalised energy
``65535 sum(w cos i) / sum(w)`` over all the beam's sub-rays. Sub-rays beyond
``max_range_m`` see nothing. Poses are per frame: a scanning frame is taken from one
pose (no motion within a frame); each beam's time is the frame time plus its firing
offset.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass, field, fields

import numpy as np

from craters._shared import ParameterError, check_int, check_range, normalize_rng
from craters._shared.settings import check_declared, setting

from .camera import quaternion_to_matrix
from .engine import RayMesh
from .labels import boulder_labels, crater_labels
from .scene_geometry import SceneGeometry, traced_model

__all__ = ["LIDAR_PATTERNS", "MAX_RETURNS", "LidarFrame", "LidarSettings", "beam_pattern",
           "footprint_rays", "lidar_frame"]

LIDAR_PATTERNS = ("flash", "scan", "rosette")
#: Most returns per beam (LAS 1.4 point format 6: 4-bit return numbers).
MAX_RETURNS = 15
_SUBRAYS_PER_CHUNK = 1 << 20
_ROSETTE = (25, -17)  # prism turns per frame
_GOLDEN_ANGLE = np.pi * (3.0 - np.sqrt(5.0))
_COS_85 = np.cos(np.radians(85.0))  # steeper surfaces count as 85 degrees for the slack


@dataclass(frozen=True, slots=True)
class LidarSettings:
    """What the LIDAR is (module notes)."""

    pattern: str = setting("flash", "flash (a grid of beams at once), scan (the grid as a "
                           "raster, one beam after the other) or rosette", choices=LIDAR_PATTERNS)
    """Beam pattern: flash, scan or rosette."""
    beams: tuple[int, int] = setting((128, 128), "beams WxH: the range image size",
                                     metavar="WxH", default_text="128x128")
    """Beams W x H (the range image's width and height), each in [1, 16384]."""
    fov_deg: float = setting(20.0, "field of view across the W beams (rosette: its diameter); "
                             "in [1e-06, 170] (rosette: 180)", unit="deg")
    """Field of view, degrees: across the W beams (flash, scan); the rosette's diameter."""
    divergence_mrad: float = setting(0.0, "full beam divergence at 1/e^2 (0 = a thin beam)",
                                     unit="mrad", range=(0.0, 200.0))
    """Full beam divergence at 1/e^2, milliradians (0 = a thin beam)."""
    rays_per_beam: int = setting(1, "sub-rays averaged over each footprint (> 1 needs a "
                                 "divergence)", range=(1, 1024))
    """Sub-rays per beam footprint (> 1 needs a divergence)."""
    range_noise_m: float = setting(0.0, "range noise standard deviation", unit="m", range=">=0")
    """Standard deviation of the range noise, metres."""
    max_range_m: float = setting(10_000.0, "longest range that returns", unit="m", range=">0")
    """Longest range that returns, metres."""
    multiple_returns: bool = setting(False, "report distinct surfaces in a footprint as "
                                     "separate returns")
    """Split a footprint into returns from distinct surfaces (otherwise one return)."""
    return_separation_m: float = setting(1.0, "range gap between two returns of one beam",
                                         unit="m", range=">0")
    """Range gap that separates two returns of one beam, metres."""
    pulse_rate_hz: float = setting(100_000.0, "beams per second of scan and rosette",
                                   unit="Hz", range=">0")
    """Beams per second of the scanning patterns (scan, rosette)."""
    las_version: str = setting("1.4", "LAS files: 1.4 (point format 6, CRS as WKT) or 1.2 "
                               "(point format 1, for older readers)", choices=("1.4", "1.2"))
    """The LAS files' version (:func:`~latlong.sensors.lidar_files.write_las`)."""
    laz: bool = setting(False, "compress the point files: LAZ (.laz, LASzip through lazrs) "
                        "instead of LAS")
    """Write the point files as LAZ (``lidar_NNNN.laz``: the same points, header and VLRs,
    LASzip-compressed) instead of LAS."""

    def __post_init__(self):
        # values kept as given (lidar.json records them); the beams as a tuple of ints
        check_declared(self, keep=tuple(f.name for f in fields(self)))
        beams = tuple(self.beams) if np.ndim(self.beams) == 1 else ()
        if len(beams) != 2:
            raise ParameterError("beams", f"must be two counts W, H; got {self.beams!r}")
        beams = tuple(check_int("beams", b, 1, 16384) for b in beams)
        object.__setattr__(self, "beams", beams)
        hi = 180.0 if self.pattern == "rosette" else 170.0
        check_range("fov_deg", self.fov_deg, 1e-6, hi)
        if self.rays_per_beam > 1 and self.divergence_mrad == 0:
            raise ParameterError("rays_per_beam", f"> 1 needs a beam divergence "
                                 f"({{}} > 0); got {self.rays_per_beam}",
                                 see=("divergence_mrad",))

    @property
    def n_beams(self) -> int:
        return self.beams[0] * self.beams[1]

    def intrinsics(self) -> dict | None:
        """The pinhole of the grid patterns (``fx, fy, cx, cy, width, height``, pixels)
        or None for the rosette."""
        if self.pattern == "rosette":
            return None
        w, h = self.beams
        f = (w / 2.0) / np.tan(np.radians(self.fov_deg) / 2.0)
        return {"fx": float(f), "fy": float(f), "cx": w / 2.0, "cy": h / 2.0, "width": w,
                "height": h}


def beam_pattern(settings: LidarSettings) -> tuple[np.ndarray, np.ndarray]:
    """Beam axes in the sensor frame (n, 3) unit vectors, row-major over the W x H range
    image, and each beam's firing time after the frame time (n,) seconds (read-only
    arrays, computed once per settings)."""
    if not isinstance(settings, LidarSettings):
        raise TypeError(f"`settings` must be LidarSettings; got {type(settings).__name__}")
    return _beam_pattern(settings)


@functools.lru_cache(maxsize=4)
def _beam_pattern(settings: LidarSettings) -> tuple[np.ndarray, np.ndarray]:
    dirs, dt = _beam_arrays(settings)
    dirs.setflags(write=False)
    dt.setflags(write=False)
    return dirs, dt


def _beam_arrays(settings: LidarSettings) -> tuple[np.ndarray, np.ndarray]:
    w, h = settings.beams
    n = w * h
    if settings.pattern == "rosette":
        s = np.arange(n) / n
        a1, a2 = 2 * np.pi * _ROSETTE[0] * s, 2 * np.pi * _ROSETTE[1] * s
        half = np.radians(settings.fov_deg) / 2.0
        ax = 0.5 * half * (np.cos(a1) + np.cos(a2))
        ay = 0.5 * half * (np.sin(a1) + np.sin(a2))
        off, az = np.hypot(ax, ay), np.arctan2(ay, ax)
        dirs = np.stack([np.sin(off) * np.cos(az), np.sin(off) * np.sin(az), np.cos(off)], 1)
        return dirs, np.arange(n) / settings.pulse_rate_hz
    k = settings.intrinsics()
    assert k is not None  # the grid patterns have a pinhole (the rosette returned above)
    i, j = np.meshgrid(np.arange(w) + 0.5, np.arange(h) + 0.5)
    dirs = np.stack([(i - k["cx"]) / k["fx"], (j - k["cy"]) / k["fy"], np.ones_like(i)],
                    -1).reshape(-1, 3)
    dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
    if settings.pattern == "flash":
        return dirs, np.zeros(n)
    col = np.arange(w)
    order = np.where(np.arange(h)[:, None] % 2, w - 1 - col[None], col[None])
    fired = np.arange(h)[:, None] * w + order  # firing index of each grid beam
    return dirs, fired.reshape(-1) / settings.pulse_rate_hz


def footprint_rays(rays_per_beam: int, divergence_mrad: float):
    """Sub-ray offsets in a beam footprint: ``(offsets (N, 2) radians off the axis along
    two perpendicular directions, weights (N,))`` (module notes)."""
    n = check_int("rays_per_beam", rays_per_beam, 1, 1024)
    if n == 1:
        return np.zeros((1, 2)), np.ones(1)
    k = np.arange(n)
    rho = np.sqrt((k + 0.5) / n)  # in units of the 1/e^2 radius
    psi = k * _GOLDEN_ANGLE
    half = 0.5e-3 * divergence_mrad
    return np.stack([rho * np.cos(psi), rho * np.sin(psi)], 1) * half, np.exp(-2.0 * rho**2)


@dataclass(frozen=True, slots=True)
class LidarFrame:
    """The returns of one frame (one row per return, beams in order, nearest first)."""

    position_m: np.ndarray
    """(n, 3) float64 points in the body frame, metres."""
    range_m: np.ndarray
    """(n,) float64 ranges along the beam axes, metres."""
    intensity: np.ndarray
    """(n,) uint16 range-normalised intensity (module notes)."""
    return_number: np.ndarray
    """(n,) uint8 1 = nearest return of its beam."""
    number_of_returns: np.ndarray
    """(n,) uint8 returns of its beam."""
    beam: np.ndarray
    """(n,) int64 beam index (row-major over the range image)."""
    time_s: np.ndarray
    """(n,) float64 firing time: frame time plus the beam's offset, seconds."""
    crater_id: np.ndarray
    """(n,) int32 crater catalog row at the return's strongest sub-ray hit, -1 none."""
    boulder_id: np.ndarray
    """(n,) int32 boulder catalog row there, -1 none."""
    range_image: np.ndarray
    """(H, W) float32 first-return range per beam, metres; NaN where nothing returned."""
    frame_time_s: float = 0.0
    """Time of the frame, seconds."""
    pose: dict = field(default_factory=dict)
    """``position_m`` and ``quaternion_wxyz`` of the sensor."""

    def __len__(self) -> int:
        return len(self.range_m)


def _perpendiculars(a):
    """Two unit vectors across each sensor-frame beam axis ``a``: along the sensor's x and
    y for the central beam (so a footprint is fixed to the sensor, not to the body)."""
    p1 = np.cross([0.0, 1.0, 0.0], a)
    p1 /= np.linalg.norm(p1, axis=1, keepdims=True)
    return p1, np.cross(a, p1)


def lidar_frame(model, settings: LidarSettings, position_m, quaternion_wxyz, *,
                time_s: float = 0.0, rng=None,
                ground_truth: SceneGeometry | None = None) -> LidarFrame:
    """Simulate one LIDAR frame from a pose (module notes).

    Parameters
    ----------
    model : surface, SceneGeometry or RayMesh
        What the LIDAR sees, as for :func:`~latlong.sensors.render.render`: any surface
        or its :class:`SceneGeometry` (whose catalogs label the returns), or its
        :class:`RayMesh` built once and shared by the frames.
    settings : LidarSettings
    position_m, quaternion_wxyz
        Sensor position in the body frame (metres) and sensor-to-body rotation.
    time_s : float
        Frame time, seconds.
    rng : int, Generator or None
        Range noise key (only drawn from when ``range_noise_m`` > 0).
    ground_truth : SceneGeometry, optional
        With a RayMesh: the geometry it was built from, whose crater catalog and
        per-triangle boulder ids label the returns.
    """
    if not isinstance(settings, LidarSettings):
        raise TypeError(f"`settings` must be LidarSettings; got {type(settings).__name__}")
    rot = quaternion_to_matrix(quaternion_wxyz)
    origin = np.asarray(position_m, dtype=np.float64).reshape(-1)
    if origin.shape != (3,) or not np.isfinite(origin).all():
        raise ParameterError("position_m", f"must be three finite numbers; got "
                             f"{np.asarray(position_m).tolist()}")
    mesh, ground_truth = traced_model(model, ground_truth)
    key = np.uint64(normalize_rng(rng).integers(0, 2**63)) if settings.range_noise_m > 0 \
        else np.uint64(0)
    axes_s, offsets_s = beam_pattern(settings)
    axes = _rotated(axes_s, rot)
    traced = _trace_beams(mesh, settings, origin, rot, axes_s, axes, key,
                          labelled=ground_truth is not None)
    counts, rng_out = traced.counts, traced.range_m
    beam, ks = np.nonzero(np.arange(rng_out.shape[1])[None] < counts[:, None])
    rng_m = rng_out[beam, ks]
    labels_c, labels_b = _return_labels(traced, origin, beam, ks, ground_truth)
    image = np.full(len(axes), np.nan, dtype=np.float32)
    image[counts > 0] = rng_out[counts > 0, 0]
    time_s = float(time_s)
    return LidarFrame(
        position_m=origin + rng_m[:, None] * axes[beam],
        range_m=rng_m,
        intensity=np.round(np.clip(traced.energy[beam, ks] / traced.total_weight, 0.0, 1.0)
                           * 65535).astype(np.uint16),
        return_number=(ks + 1).astype(np.uint8),
        number_of_returns=np.repeat(counts, counts).astype(np.uint8),
        beam=beam.astype(np.int64),
        time_s=time_s + offsets_s[beam],
        crater_id=labels_c.astype(np.int32),
        boulder_id=labels_b.astype(np.int32),
        range_image=image.reshape(settings.beams[1], settings.beams[0]),
        frame_time_s=time_s,
        pose={"position_m": origin.tolist(),
              "quaternion_wxyz": np.asarray(quaternion_wxyz, dtype=np.float64).tolist()},
    )


@dataclass(frozen=True, slots=True)
class _Traced:
    """The returns of every beam of a frame, before they become points."""

    counts: np.ndarray
    """(nb,) returns per beam."""
    range_m: np.ndarray
    """(nb, nmax) range of each return, metres."""
    energy: np.ndarray
    """(nb, nmax) return energy, sum of w cos i over its sub-rays."""
    total_weight: float
    """Sum of the sub-ray weights of a beam."""
    best_t: np.ndarray | None = None
    """(nb, nmax) range of the strongest sub-ray hit of each return (with labels)."""
    best_face: np.ndarray | None = None
    """(nb, nmax) face of that hit."""
    best_dir: np.ndarray | None = None
    """(nb, nmax, 3) direction of that sub-ray."""


def _sub_ray_directions(axes_s, rot, sub) -> np.ndarray:
    """(k * N, 3) body-frame directions of the sub-rays of the sensor-frame beam axes."""
    p1, p2 = _perpendiculars(axes_s)
    d = axes_s[:, None] + np.tan(sub[None, :, :1]) * p1[:, None] \
        + np.tan(sub[None, :, 1:]) * p2[:, None]
    return _rotated((d / np.linalg.norm(d, axis=2, keepdims=True)).reshape(-1, 3), rot)


def _rotated(v: np.ndarray, rot: np.ndarray) -> np.ndarray:
    """``v @ rot.T`` for (k, 3) vectors, elementwise rather than through BLAS: a BLAS
    product wakes OpenBLAS's worker threads, which spin on after it returns and took the
    cores from the ray kernel that follows (a 512^2 flash frame 0.114 s instead of 0.080 s
    on 2 cores); elementwise products and sums also round alike on every CPU."""
    return v[:, 0:1] * rot[:, 0] + v[:, 1:2] * rot[:, 1] + v[:, 2:3] * rot[:, 2]


def _trace_beams(mesh: RayMesh, settings: LidarSettings, origin, rot, axes_s, axes, key,
                 *, labelled: bool) -> _Traced:
    """Cast every sub-ray of every beam (in chunks of about ``_SUBRAYS_PER_CHUNK``) and
    group the hits into returns (:func:`_returns_kernel`)."""
    from ._lidar_kernels import _returns_kernel  # numba loads here
    sub, weight = footprint_rays(settings.rays_per_beam, settings.divergence_mrad)
    nr = len(weight)
    spacing = 1e-3 * settings.divergence_mrad / np.sqrt(nr)
    nmax = MAX_RETURNS if settings.multiple_returns else 1
    nb = len(axes)
    counts = np.zeros(nb, dtype=np.int64)
    rng_out, lam_out = np.zeros((nb, nmax)), np.zeros((nb, nmax))
    best_out = np.zeros((nb, nmax), dtype=np.int64)
    best: tuple = (np.zeros((nb, nmax)), np.full((nb, nmax), -1, dtype=np.int64),
            np.zeros((nb, nmax, 3))) if labelled else (None, None, None)
    step = max(1, _SUBRAYS_PER_CHUNK // nr)
    for s in range(0, nb, step):
        e = min(s + step, nb)
        d = axes[s:e] if nr == 1 else _sub_ray_directions(axes_s[s:e], rot, sub)
        hits = mesh.intersect(np.broadcast_to(origin, d.shape), d, settings.max_range_m)
        _returns_kernel(hits.t_m.reshape(e - s, nr), hits.face.reshape(e - s, nr), d,
                        mesh.face_normals, weight, spacing, _COS_85, settings.multiple_returns,
                        float(settings.return_separation_m), nmax,
                        float(settings.range_noise_m), key, s, counts[s:e], rng_out[s:e],
                        lam_out[s:e], best_out[s:e])
        if labelled:
            rows, ks = np.nonzero(np.arange(nmax)[None] < counts[s:e, None])
            flat = rows * nr + best_out[s:e][rows, ks]
            best[0][s + rows, ks] = hits.t_m[flat]
            best[1][s + rows, ks] = hits.face[flat]
            best[2][s + rows, ks] = d[flat]
    return _Traced(counts, rng_out, lam_out, weight.sum(), *best)


def _return_labels(traced: _Traced, origin, beam, ks, ground_truth):
    """Crater and boulder ids of the returns (at each return's strongest sub-ray hit)."""
    labels_c = np.full(len(beam), -1)
    labels_b = np.full(len(beam), -1)
    if ground_truth is not None:  # then the frame was traced labelled: best_* are set
        assert traced.best_t is not None and traced.best_dir is not None \
            and traced.best_face is not None
        if ground_truth.craters is not None:
            pts = origin + traced.best_t[beam, ks, None] * traced.best_dir[beam, ks]
            labels_c = crater_labels(pts, ground_truth.craters)
        labels_b = boulder_labels(traced.best_face[beam, ks], ground_truth.face_boulder_id)
    return labels_c, labels_b
