"""Sensor poses and the sun from SPICE kernels (NASA NAIF's toolkit, through spiceypy), as
mission teams get their trajectories, attitudes and ephemerides.

For each time of a sequence (UTC ``START,STOP,STEP_S``, or ephemeris times):

* the sensor's position: the observer (the spacecraft) relative to the target body, in
  the target's body-fixed ``frame`` (the frame the model is in, e.g. ``IAU_MOON``), km
  -> metres (:func:`spiceypy.spkpos`);
* its orientation: the rotation from the ``camera_frame`` to ``frame``
  (:func:`spiceypy.pxform`), the camera frame taken in the OpenCV convention (+Z the
  boresight, +X right and +Y down in the image, as most instrument kernels define it);
* the sun: the unit direction from the target's centre to the sun in ``frame``;
* with ``planet`` (planetshine, :mod:`.planetshine`): its direction the same way and its
  angular radius from its mean radius (``BODYnnn_RADII``) and distance.

``abcorr`` is SPICE's aberration correction (``NONE``: geometric). Kernels are a
meta-kernel (``.tm``) or kernel files; each is checked before it is loaded, and every
SPICE error becomes a one-line ``ValueError`` naming the kernel or the body. The kernels
are unloaded afterwards: SPICE's kernel pool is global to the process.
"""

from __future__ import annotations

import contextlib
import dataclasses
from collections.abc import Iterator, Sequence
from pathlib import Path

import numpy as np

from craters._shared import ParameterError

from .camera import quaternion_from_matrix
from .planetshine import Planet
from .poses import Poses

__all__ = ["MAX_SPICE_FRAMES", "SpiceSequence", "parse_utc_range", "spice_camera",
           "spice_sequence"]

#: Most frames a SPICE sequence gives (a typo in STEP_S should not start a million).
MAX_SPICE_FRAMES = 100_000


@dataclasses.dataclass(frozen=True)
class SpiceSequence:
    """Poses and sun directions of a SPICE time sequence (module notes)."""

    poses: Poses
    """Sensor poses; ``time_s`` is the ephemeris time (TDB seconds past J2000)."""
    sun_directions: np.ndarray
    """(n, 3) unit directions towards the sun, body-fixed frame."""
    utc: tuple[str, ...]
    """ISO UTC of each frame (``YYYY-MM-DDTHH:MM:SS.ffffff``)."""
    body_to_j2000: np.ndarray
    """(n, 3, 3) rotations from the body-fixed frame to J2000 (for the stars)."""
    planet_directions: np.ndarray | None = None
    """(n, 3) unit directions from the target's centre towards the ``planet``'s, body-fixed
    frame (None without a planet)."""
    planet_radii_deg: np.ndarray | None = None
    """(n,) angular radius of the planet seen from the target's centre, degrees (its mean
    radius from the kernels' ``BODYnnn_RADII``)."""

    def planets(self, geometric_albedo: float) -> list[Planet] | None:
        """The :class:`~latlong.sensors.planetshine.Planet` of each frame (None without)."""
        if self.planet_directions is None or self.planet_radii_deg is None:
            return None
        return [Planet(d, float(r), geometric_albedo)
                for d, r in zip(self.planet_directions, self.planet_radii_deg, strict=True)]

    def frame_info(self) -> list[dict]:
        """Per frame ``{"et_s", "utc"}`` for the run's manifest."""
        return [{"et_s": float(t), "utc": u} for t, u in zip(self.poses.time_s, self.utc,
                                                              strict=True)]


def parse_utc_range(spec) -> tuple[str, str, float]:
    """``"START,STOP,STEP_S"`` -> (start, stop, step in seconds > 0)."""
    parts = [p.strip() for p in str(spec).split(",")]
    if len(parts) != 3 or not all(parts):
        raise ParameterError("utc", f"must be START,STOP,STEP_S (UTC, UTC, seconds); got "
                             f"{spec!r}")
    try:
        step = float(parts[2])
    except ValueError:
        raise ParameterError("utc", f"STEP_S must be a number of seconds; got "
                             f"{parts[2]!r}") from None
    if not 0.0 < step < np.inf:
        raise ParameterError("utc", f"STEP_S must be > 0 seconds; got {parts[2]}")
    return parts[0], parts[1], step


def _short(exc) -> str:
    """One line of a SpiceyError: its short code and the first sentence of its text."""
    text = " ".join(str(getattr(exc, "long", "") or exc).split())
    return f"{getattr(exc, 'short', '') or 'SPICE error'}: {text.split('. ')[0][:300]}"


def _kernel_files(kernels) -> list[Path]:
    paths = [kernels] if isinstance(kernels, str | Path) else list(kernels)
    if isinstance(kernels, str) and "," in kernels:
        paths = [p.strip() for p in kernels.split(",") if p.strip()]
    if not paths:
        raise ParameterError("spice", "needs at least one kernel or meta-kernel")
    out = []
    for p in map(Path, paths):
        if not p.is_file():
            raise FileNotFoundError(f"SPICE kernel {str(p)!r} does not exist")
        out.append(p)
    return out


@contextlib.contextmanager
def _loaded(kernels) -> Iterator[None]:
    """The kernels loaded, each checked first (SPICE would take a file that is no kernel
    as an empty text kernel), and unloaded again afterwards (the pool is the process's);
    a kernel that fails is named in a one-line ValueError."""
    import spiceypy as sp
    from spiceypy.utils.exceptions import SpiceyError

    loaded: list[str] = []
    try:
        for path in map(str, _kernel_files(kernels)):
            try:
                if sp.getfat(path)[0] == "?":
                    raise ValueError(f"SPICE kernel {path!r} is not a SPICE kernel (no KPL/ "
                                     f"identification word, not a DAF or DAS file)")
                sp.furnsh(path)
            except SpiceyError as exc:
                sp.unload(path)  # a meta-kernel stays loaded when a kernel it lists fails
                raise ValueError(f"SPICE kernel {path!r}: {_short(exc)}") from None
            loaded.append(path)
        yield
    finally:
        for path in reversed(loaded):
            sp.unload(path)


def spice_sequence(kernels, *, target: str, observer: str, frame: str, camera_frame: str,
                   utc=None, et: Sequence[float] | None = None,
                   abcorr: str = "NONE", planet: str | None = None) -> SpiceSequence:
    """The poses and sun directions of the times ``utc`` (``"START,STOP,STEP_S"``) or
    ``et`` (ephemeris seconds) from SPICE ``kernels`` (module notes); with ``planet`` (a
    SPICE body name or id) also its direction and angular radius."""
    import spiceypy as sp
    from spiceypy.utils.exceptions import SpiceyError

    if (utc is None) == (et is None):
        raise ParameterError("utc", "give the times as utc START,STOP,STEP_S or as et")
    with _loaded(kernels):
        times = _times(sp, SpiceyError, utc, et)
        pos, rot, sun, inertial = _geometry(sp, SpiceyError, times, target=target,
                                            observer=observer, frame=frame,
                                            camera_frame=camera_frame, abcorr=abcorr)
        stamps = tuple(sp.et2utc(float(t), "ISOC", 6) for t in times)
        shine = {} if planet is None else _planet(sp, SpiceyError, times, planet=planet,
                                                  target=target, frame=frame, abcorr=abcorr)
    poses = Poses(times, pos, np.array([quaternion_from_matrix(r) for r in rot]))
    return SpiceSequence(poses, sun, stamps, inertial, **shine)


def spice_camera(kernels, instrument: str, **distortion):
    """The :class:`~latlong.sensors.camera.Camera` of ``instrument`` (SPICE name or id)
    from its instrument kernel: ``INS<id>_PIXEL_SAMPLES`` x ``INS<id>_PIXEL_LINES``
    pixels, the focal length in pixels ``INS<id>_FOCAL_LENGTH / INS<id>_PIXEL_PITCH``
    (both in mm) or else from the field of view (``getfov``: the widest bound vector's
    angles from the +Z boresight across x and y), the principal point from
    ``INS<id>_CCD_CENTER`` (sample, line) taken as given in this package's convention
    (pixel centres at integer + 0.5; an IK whose pixel centres are integers needs 0.5
    added: give ``--intrinsics`` instead), else the image's centre. Distortion keywords
    differ between missions (their models, units and directions) and are not read:
    ``distortion`` as :class:`Camera`'s."""
    import spiceypy as sp
    from spiceypy.utils.exceptions import SpiceyError

    from .camera import Camera

    with _loaded(kernels):
        try:
            ident = int(instrument) if str(instrument).lstrip("-").isdigit() \
                else int(sp.bods2c(str(instrument)))
        except SpiceyError:
            raise ValueError(f"SPICE does not know the instrument {instrument!r} (a name "
                             f"needs NAIF_BODY_NAME/CODE in a kernel, or give its id)") from None

        def number(key: str, required: bool = True):
            name = f"INS{ident}_{key}"
            try:
                return float(sp.gdpool(name, 0, 1)[0])
            except SpiceyError:
                if required:
                    raise ValueError(f"the instrument kernel of {instrument!r} has no "
                                     f"{name}") from None
                return None

        width, height = int(number("PIXEL_SAMPLES")), int(number("PIXEL_LINES"))
        focal, pitch = number("FOCAL_LENGTH", False), number("PIXEL_PITCH", False)
        if focal and pitch:
            fx = fy = focal / pitch
        else:
            try:
                bounds = sp.getfov(ident, 10)[4]
            except SpiceyError as exc:
                raise ValueError(f"instrument {instrument!r}: no focal length and pitch, "
                                 f"and no field of view: {_short(exc)}") from None
            b = np.asarray(bounds, dtype=float)
            tx = np.abs(b[:, 0] / b[:, 2]).max()
            ty = np.abs(b[:, 1] / b[:, 2]).max()
            fx, fy = 0.5 * width / tx, 0.5 * height / ty
        try:
            cx, cy = (float(c) for c in sp.gdpool(f"INS{ident}_CCD_CENTER", 0, 2))
        except SpiceyError:
            cx, cy = 0.5 * width, 0.5 * height
        except ValueError:
            raise ValueError(f"the instrument kernel of {instrument!r} has an "
                             f"INS{ident}_CCD_CENTER without two values") from None
    return Camera(fx, fy, cx, cy, width, height, **distortion)


def _times(sp, error, utc, et) -> np.ndarray:
    if et is not None:
        times = np.asarray(et, dtype=np.float64).reshape(-1)
        if not len(times) or not np.isfinite(times).all():
            raise ParameterError("et", "must be one or more finite ephemeris times")
        return times
    start, stop, step = parse_utc_range(utc)
    try:
        t0, t1 = sp.str2et(start), sp.str2et(stop)
    except error as exc:
        raise ValueError(f"utc {start!r} / {stop!r}: {_short(exc)} (a leapseconds "
                         f"kernel must be among the kernels)") from None
    if t1 < t0:
        raise ParameterError("utc", f"STOP {stop!r} is before START {start!r}")
    n = int(np.floor((t1 - t0) / step + 1e-9)) + 1
    if n > MAX_SPICE_FRAMES:
        raise ParameterError("utc", f"gives {n} frames; at most {MAX_SPICE_FRAMES} (raise "
                             f"STEP_S)")
    return t0 + step * np.arange(n)


def _geometry(sp, error, times, *, target, observer, frame, camera_frame, abcorr):
    n = len(times)
    pos, sun, rot = np.empty((n, 3)), np.empty((n, 3)), np.empty((n, 3, 3))
    inertial = np.empty((n, 3, 3))
    for k, t in enumerate(times):
        what = f"observer {observer!r} relative to target {target!r} in frame {frame!r}"
        try:
            pos[k] = np.asarray(sp.spkpos(observer, t, frame, abcorr, target)[0]) * 1000.0
            what = f"the sun relative to target {target!r}"
            s = np.asarray(sp.spkpos("SUN", t, frame, abcorr, target)[0])
            what = f"the rotation from camera frame {camera_frame!r} to {frame!r}"
            rot[k] = np.asarray(sp.pxform(camera_frame, frame, t))
            what = f"the rotation from {frame!r} to J2000"
            inertial[k] = np.asarray(sp.pxform(frame, "J2000", t))
        except error as exc:
            raise ValueError(f"SPICE has no {what} at {sp.et2utc(float(t), 'ISOC', 3)} UTC "
                             f"in the kernels loaded: {_short(exc)}") from None
        sun[k] = s / np.linalg.norm(s)
    return pos, rot, sun, inertial


def _planet(sp, error, times, *, planet, target, frame, abcorr) -> dict:
    """{planet_directions, planet_radii_deg} of ``planet`` seen from ``target``."""
    try:
        radius_km = float(np.mean(sp.bodvrd(planet, "RADII", 3)[1]))
    except error as exc:
        raise ValueError(f"SPICE has no radii of planet {planet!r} in the kernels loaded "
                         f"(BODYnnn_RADII of a PCK): {_short(exc)}") from None
    d = np.empty((len(times), 3))
    for k, t in enumerate(times):
        try:
            d[k] = np.asarray(sp.spkpos(planet, t, frame, abcorr, target)[0])
        except error as exc:
            raise ValueError(f"SPICE has no planet {planet!r} relative to target {target!r} "
                             f"at {sp.et2utc(float(t), 'ISOC', 3)} UTC in the kernels loaded: "
                             f"{_short(exc)}") from None
    dist = np.linalg.norm(d, axis=1)
    if not (dist > radius_km).all():
        raise ValueError(f"planet {planet!r} is not outside target {target!r}'s centre by "
                         "more than its radius")
    return {"planet_directions": d / dist[:, None],
            "planet_radii_deg": np.degrees(np.arcsin(radius_km / dist))}
