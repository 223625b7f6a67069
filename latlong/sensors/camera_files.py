"""Camera runs: :func:`camera_run` renders every pose of a trajectory and writes the
frames and the ``frames.json`` manifest (issue 17's interface) into a run folder, as
:func:`~latlong.sensors.lidar_files.lidar_run` does for the LIDAR; what the camera is
and how its frames are written is one :class:`CameraSettings` record.

* :func:`write_frame`: one frame's files, each written atomically: the image (16- or
  8-bit PNG of linear DN, or float32 TIFF of I/F for a float sensor; for a multi-band
  camera one TIFF of all bands, each band's name its description), an 8-bit sRGB
  ``display`` PNG of it for people (:func:`~latlong.sensors.sensor.display_image`; the
  first three bands as red, green, blue),
  depth and range (float32 ``.tif``, ``.npy`` or ``.exr``), normals (float32 (H, W, 3)
  ``.npy``, or ``.exr``) and, on request, the other ground truth (incidence / emission /
  phase angles, position, face id, lit fraction, albedo, as .npy); the crater-id and
  boulder-id label images (int32, -1 = none, in the depth format) when the frame has
  them.
* OpenEXR (``depth_format="exr"``, for ML pipelines; the `OpenEXR` package, the
  Academy Software Foundation's own binding, ZIP-compressed scanlines): depth and range
  in a float32 channel ``Z`` (metres, NaN on the sky), normals in float32 ``X``, ``Y``,
  ``Z``, the albedo seen in float32 ``Y`` (``albedo_NNNN.exr``, always with exr), label
  images in a uint32 channel ``id`` (4294967295, the bits of -1, where none).
* :func:`manifest`: the ``frames.json`` document: ``{"intrinsics": {fx, fy, cx, cy, width,
  height}, "frames": [{"time_s", "position_m", "quaternion_wxyz", "sun_direction", "seed",
  "files": {"image", "depth", "range", "normals", "crater_id", "boulder_id", ...}}]}``,
  file names relative to the folder (``crater_id`` / ``boulder_id`` null when the model
  has no catalogs), and per frame the projected rim ellipses of the craters seen, plus
  the distortion, the conventions and the settings used; with planetshine, per frame
  its ``planet``: direction, angular radius, geometric albedo, phase and irradiance
  ratio.

The run is written into a hidden temporary folder next to the target, each file
atomically, and moved into place at the end with ``frames.json`` last
(:func:`~latlong.sensors.runs.run_folder`): an error leaves nothing behind.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, fields
from pathlib import Path

import numpy as np

from craters._shared import (
    ParameterError,
    atomic_path,
    human_bytes,
    physical_memory_bytes,
    progress_bar,
)
from craters._shared.settings import check_declared, setting

from ..meshio.sizes import check_free_space
from .albedo import ejecta_albedo
from .camera import Camera
from .datasets import optical_flow, parse_datasets, write_datasets, write_flow
from .engine import RayMesh
from .labels import ELLIPSE_DTYPE, FittedRims, rim_ellipses
from .motion import timed_frame
from .photometry import REFLECTANCES, LommelSeeliger, Photometry, with_albedo
from .planetshine import Planet
from .poses import Poses
from .render import BOUNCE_FILTER_PX, BOUNCE_SAMPLES, Frame, Sun, band_name_ok, render
from .runs import check_output_folder, run_folder
from .scene_geometry import ray_scene
from .sensor import Sensor, display_image
from .stars import with_stars

__all__ = ["DEPTH_FORMATS", "CameraSettings", "camera_run", "frame_entry", "manifest",
           "write_frame", "write_manifest"]

#: Formats of the float32 depth and range images (and the label images).
DEPTH_FORMATS = ("tif", "npy", "exr")
_NAMES = {model: name for name, model in REFLECTANCES.items()}

CONVENTIONS = ("OpenCV camera frame (x right, y down, z forward); quaternion_wxyz rotates "
               "camera-frame vectors into the body frame; position_m and sun_direction "
               "(towards the sun) in the body frame; pixel centres at integer + 0.5 "
               "(OpenCV's cx = cx - 0.5); depth = camera z, range = distance, metres, NaN "
               "where no surface; normals = unit shading normals in the body frame.")


def _save(path: Path, array: np.ndarray, channel: str | tuple[str, ...] = "Z") -> None:
    """One file of a frame by its suffix; ``channel`` names an EXR's float channel, or
    the bands of an (H, W, bands) image (TIFF band descriptions, EXR channels)."""
    from PIL import Image

    with atomic_path(path) as tmp:
        if path.suffix == ".npy":
            with open(tmp, "wb") as fh:
                np.save(fh, array, allow_pickle=False)
        elif path.suffix == ".exr":
            _save_exr(tmp, array, channel)
        elif path.suffix == ".tif" and isinstance(channel, tuple):
            _save_bands(tmp, array, channel)
        elif path.suffix == ".tif":
            kind = np.int32 if array.dtype == np.int32 else np.float32
            Image.fromarray(np.ascontiguousarray(array, dtype=kind)).save(tmp, format="TIFF")
        else:
            Image.fromarray(np.ascontiguousarray(array)).save(tmp, format="PNG")


def _save_bands(path: Path, array: np.ndarray, names: tuple[str, ...]) -> None:
    """An (H, W, bands) image as one TIFF of that many bands (rasterio: any band count
    and uint8 / uint16 / float32, each band's name as its description)."""
    import warnings

    import rasterio
    from rasterio.errors import NotGeoreferencedWarning

    h, w, count = array.shape
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", NotGeoreferencedWarning)
        with rasterio.open(path, "w", driver="GTiff", width=w, height=h, count=count,
                           dtype=array.dtype.name, compress="deflate") as out:
            out.write(np.moveaxis(array, 2, 0))
            out.descriptions = names


def _save_exr(path: Path, array: np.ndarray, channel: str | tuple[str, ...] = "Z") -> None:
    """One OpenEXR image (module notes): (H, W, 3) as X, Y, Z (or as the ``channel``
    names given); int32 labels as uint32 ``id``; else float32 ``channel``."""
    import OpenEXR

    if array.ndim == 3:
        names = channel if isinstance(channel, tuple) else tuple("XYZ")
        channels = {c: np.ascontiguousarray(array[:, :, i], dtype=np.float32)
                    for i, c in enumerate(names)}
    elif array.dtype == np.int32:
        channels = {"id": np.ascontiguousarray(array).view(np.uint32)}
    else:
        channels = {str(channel): np.ascontiguousarray(array, dtype=np.float32)}
    header = {"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage}
    with OpenEXR.File(header, channels) as exr:
        exr.write(str(path))


def _display(frame: Frame) -> np.ndarray:
    """The sRGB picture of a frame: grey, or the first three bands as red, green, blue."""
    picture = display_image(frame.image)
    if picture.ndim == 3:
        return picture[:, :, :3] if picture.shape[2] >= 3 else picture[:, :, 0]
    return picture


def write_frame(folder, index: int, frame: Frame, *, depth_format: str = "tif",
                extra: bool = False) -> dict:
    """Write frame ``index``'s files into ``folder``; their names (relative)."""
    if depth_format not in DEPTH_FORMATS:
        raise ParameterError("depth_format", f"must be one of {', '.join(DEPTH_FORMATS)}; "
                             f"got {depth_format!r}")
    folder = Path(folder)
    tag = f"{index:04d}"
    tif = frame.image.dtype == np.float32 or bool(frame.bands)
    image_name = f"image_{tag}.tif" if tif else f"image_{tag}.png"
    exr = depth_format == "exr"
    files = {"image": image_name, "display": f"display_{tag}.png",
             "depth": f"depth_{tag}.{depth_format}", "range": f"range_{tag}.{depth_format}",
             "normals": f"normals_{tag}.{'exr' if exr else 'npy'}"}
    arrays = {"image": frame.image, "display": _display(frame),
              "depth": frame.depth_m, "range": frame.range_m, "normals": frame.normals}
    if (exr or extra) and frame.albedo is not None:
        files["albedo"] = f"albedo_{tag}.{'exr' if exr else 'npy'}"
        arrays["albedo"] = frame.albedo
    if extra:
        for key, arr in (("incidence", frame.incidence_deg), ("emission", frame.emission_deg),
                         ("phase", frame.phase_deg), ("position", frame.position_m),
                         ("face", frame.face), ("sunlit", frame.sunlit)):
            files[key] = f"{key}_{tag}.npy"
            arrays[key] = arr
    for key, ids in (("crater_id", frame.crater_id), ("boulder_id", frame.boulder_id)):
        if ids is not None:
            files[key] = f"{key}_{tag}.{depth_format}"
            arrays[key] = ids
    for key, name in files.items():
        channel = frame.bands if frame.bands and key in ("image", "albedo") else \
            "Y" if key == "albedo" else "Z"
        _save(folder / name, arrays[key], channel)
    return {"crater_id": None, "boulder_id": None, **files}


def frame_entry(frame: Frame, files: dict, *, craters=None, rims=None) -> dict:
    """The manifest's record of one frame; with the crater catalog, the projected rim
    ellipses (pinhole, pixels) of the craters whose id is in the frame's label image,
    their rims from ``rims`` (a :class:`~latlong.sensors.labels.FittedRims` shared by
    the frames) when given, else the catalog rule."""
    entry = {"time_s": frame.pose.time_s, "exposure_s": frame.exposure_s,
             "position_m": [float(v) for v in frame.pose.position_m],
             "quaternion_wxyz": [float(v) for v in frame.pose.quaternion_wxyz],
             "sun_direction": [float(v) for v in frame.sun.direction],
             "files": files}
    if craters is not None and frame.crater_id is not None:
        cam = frame.camera
        seen = np.unique(frame.crater_id[frame.crater_id >= 0])
        ell = rim_ellipses(craters, (cam.fx, cam.fy, cam.cx, cam.cy), frame.pose.position_m,
                           frame.pose.quaternion_wxyz, ids=seen,
                           rims=None if rims is None else rims(seen))
        entry["rim_ellipses"] = [{k: (int(e[k]) if k == "crater_id" else float(e[k]))
                                  for k in ELLIPSE_DTYPE.names or ()} for e in ell]
    return entry


def manifest(camera: Camera, entries: list, **settings) -> dict:
    """The ``frames.json`` document (module notes); ``settings`` are recorded as given."""
    return {"intrinsics": camera.intrinsics(),
            "distortion": dict(zip(("k1", "k2", "p1", "p2", "k3"), camera.distortion,
                                   strict=True)),
            "conventions": CONVENTIONS, "settings": settings, "frames": entries}


def write_manifest(folder, document: dict) -> Path:
    """Write ``frames.json`` atomically."""
    path = Path(folder) / "frames.json"
    with atomic_path(path) as tmp:
        tmp.write_text(json.dumps(document, indent=1) + "\n")
    return path


#: Peak memory of a frame, bytes a pixel and band (measured: 1.48 GB for one band at 2048^2
#: with the default outputs, 0.55 GB at 1024^2: ~300 bytes a pixel above the model).
FRAME_BYTES_PER_PIXEL = 320


#: Bytes a pixel a frame's files hold at the least: depth, range, crater-id and boulder-id
#: (uncompressed 32-bit TIFF) and normals (3 float32 in .npy); the pictures compress.
FRAME_FILE_BYTES_PER_PIXEL = 28


def check_frames_disk(folder, width: int, height: int, n_frames: int) -> None:
    """Refuse up front (one line) frames whose files cannot fit the disk of ``folder``."""
    check_free_space([(folder, FRAME_FILE_BYTES_PER_PIXEL * width * height * n_frames)],
                     hint=f"{n_frames} frames of {width}x{height} px: fewer frames, a smaller "
                     f"--size or another folder")


def check_frame_memory(width: int, height: int, bands: int = 1) -> None:
    """Refuse up front (one line naming ``--size``) a frame this machine cannot hold."""
    need = FRAME_BYTES_PER_PIXEL * width * height * bands
    have = physical_memory_bytes()
    if need > 0.8 * have:
        raise ParameterError("size", f"{width}x{height} px ({bands} band(s)) needs about "
                             f"{human_bytes(need)} of memory a frame; this machine has "
                             f"{human_bytes(have)}: choose a smaller frame")


@dataclass(frozen=True, slots=True)
class CameraSettings:
    """What the camera is and how its frames are written (the LIDAR's
    :class:`~latlong.sensors.lidar.LidarSettings`)."""

    camera: Camera
    """Intrinsics and distortion."""
    reflectance: Photometry = LommelSeeliger()
    """The surface's reflectance model (:mod:`~latlong.sensors.photometry`)."""
    sensor: Sensor = Sensor()
    """Exposure, bit depth, noise and PSF of the detector."""
    soft_shadow_samples: int = setting(0, "shadow rays per pixel over the solar disk (0: hard "
                                       "shadows)", range=(0, 1024))
    """Shadow rays per pixel over the solar disk, [0, 1024] (0: hard shadows)."""
    bounces: int = setting(1, "bounces of light between surfaces (1: crater floors in shadow "
                           "lit by the sunlit walls; 2: and by what those walls received; "
                           "0: direct sunlight only)", range=(0, 2))
    """Bounces of light between surfaces, 0, 1 or 2 (:func:`~latlong.sensors.render.render`)."""
    bounce_samples: int = setting(BOUNCE_SAMPLES, "rays a pixel for the bounced light (its "
                                  "noise falls as 1 / sqrt of this; a quarter in full sun "
                                  "when smoothed)", range=(1, 4096))
    """Cosine-weighted rays a pixel for the bounced light, [1, 4096] (with
    ``bounce_filter_px`` > 0, a quarter of them for fully sunlit pixels)."""
    bounce_filter_px: int = setting(BOUNCE_FILTER_PX, "radius of the bounced light's "
                                    "smoothing on the same surface (0: each pixel's own "
                                    "rays)", unit="px", range=(0, 64))
    """Radius of the bounced light's smoothing, pixels, [0, 64]
    (:func:`~latlong.sensors.light.filter_bounced`; 0: none)."""
    blur_samples: int = setting(0, "motion blur: instants sampled over each frame's exposure "
                                "along the trajectory (0: a sharp frame)", range=(0, 256))
    """Motion blur: instants over the exposure, [0, 256] (:mod:`~latlong.sensors.motion`;
    0 or 1: none)."""
    line_time_s: float = setting(0.0, "rolling shutter: delay of each image row after the "
                                 "one above (0: a global shutter)", range=(0.0, 1.0))
    """Rolling shutter: each row's delay after the row above, seconds, [0, 1]."""
    stars: bool = setting(False, "stars (Yale Bright Star Catalogue, V <= 6) where no "
                          "surface is seen; J2000 = the body frame unless SPICE says")
    """Stars where no surface is seen (:mod:`~latlong.sensors.stars`)."""
    seed: int = setting(0, "seed of the noise, the sun-disk samples and the bounce rays (new "
                        "draws in each frame)", range=(0, 2**63 - 1))
    """Key of the sensor noise, the sun-disk samples and the bounce rays, [0, 2^63 - 1]; frame
    k draws with :func:`frame_seed` (seed, k), recorded as the frame's ``seed``."""
    bright_ejecta: float = setting(0.0, "albedo contrast of fresh craters' ejecta (0.5 = 50 % "
                                   "brighter at the rim, fading as (r/R)^-3 and with "
                                   "degradation; needs a crater catalog; 0: off)",
                                   range=(0.0, 10.0))
    """Albedo contrast of fresh craters' ejecta (:func:`~latlong.sensors.albedo.
    ejecta_albedo`), [0, 10] (0: off)."""
    bands: str = setting("", "multi-band camera: NAME=ALBEDO,... one band each, in order, "
                         "with the reflectance model's albedo (w for hapke) of that band; "
                         "the first three are the display picture's red, green and blue",
                         default_text="one band")
    """A multi-band camera (``R=0.14,G=0.12,B=0.10``): each band's albedo for the
    reflectance model (:func:`~latlong.sensors.photometry.with_albedo`); "" for one band.
    The image is then one multi-band TIFF a frame (module notes)."""
    depth_format: str = setting("tif", "files of the float32 depth and range images and of "
                                "the label images", choices=DEPTH_FORMATS)
    """Files of the float32 depth and range images and of the label images: tif, npy or
    exr (OpenEXR, with the normals and the albedo seen: module notes)."""
    all_ground_truth: bool = setting(False, "also write incidence, emission, phase, position, "
                                     "face and lit fraction per frame (.npy)")
    """Also write incidence, emission, phase, position, face and lit fraction (.npy)."""
    datasets: str = setting("", "dataset files to write into the run: comma-separated coco "
                            "(instance masks), colmap (text model), nerf (transforms.json), "
                            "flow (optical flow to the next frame)", default_text="none")
    """Dataset files written into the run (:mod:`~latlong.sensors.datasets`): any of coco,
    colmap, nerf, flow, comma-separated ("" for none)."""

    def __post_init__(self):
        for name, kind in (("camera", Camera), ("reflectance", Photometry),
                           ("sensor", Sensor)):
            if not isinstance(getattr(self, name), kind):
                raise TypeError(f"`{name}` must be a {name} model of latlong.sensors; got "
                                f"{type(getattr(self, name)).__name__}")
        object.__setattr__(self, "all_ground_truth", bool(self.all_ground_truth))
        object.__setattr__(self, "datasets", ",".join(parse_datasets(self.datasets)))
        bands = parse_bands(self.bands)  # checked here, kept as written
        for albedo in bands.values():
            with_albedo(self.reflectance, albedo)  # in the model's range
        object.__setattr__(self, "bands", ",".join(f"{k}={v!r}" for k, v in bands.items()))
        check_declared(self)  # every declared range and choice, named by the field
        check_frame_memory(self.camera.width, self.camera.height, max(1, len(bands)))

    def band_models(self) -> dict | None:
        """{band: reflectance model} of a multi-band camera (None for one band)."""
        bands = parse_bands(self.bands)
        return {k: with_albedo(self.reflectance, a) for k, a in bands.items()} or None

    def record(self, sun: Sun) -> dict:
        """The ``settings`` of the manifest (without ``model``)."""
        model = self.reflectance
        return {"reflectance": _NAMES[type(model)],
                "reflectance_parameters": {f.name: getattr(model, f.name)
                                           for f in fields(model)},
                "sun_angular_radius_deg": sun.angular_radius_deg,
                "soft_shadow_samples": self.soft_shadow_samples, "seed": self.seed,
                "bounces": self.bounces, "bounce_samples": self.bounce_samples,
                "bounce_filter_px": self.bounce_filter_px,
                "blur_samples": self.blur_samples, "line_time_s": self.line_time_s,
                "stars": self.stars, "bands": parse_bands(self.bands),
                "sensor": {f.name: getattr(self.sensor, f.name)
                           for f in fields(self.sensor)}}


def parse_bands(spec: str) -> dict[str, float]:
    """{name: albedo} of a ``NAME=ALBEDO,...`` bands spec ("" for one band)."""
    if not isinstance(spec, str):
        raise ParameterError("bands", f"must be a NAME=ALBEDO,... string; got {spec!r}")
    out: dict[str, float] = {}
    for item in filter(None, (i.strip() for i in spec.split(","))):
        name, sep, value = item.partition("=")
        name = name.strip()
        if not sep or not band_name_ok(name):
            raise ParameterError("bands", f"items are NAME=ALBEDO (a name of letters, digits, "
                                 f"- and _); got {item!r}")
        if name in out:
            raise ParameterError("bands", f"band {name!r} is given twice")
        try:
            out[name] = float(value)
        except ValueError:
            raise ParameterError("bands", f"the albedo of band {name!r} must be a number; "
                                 f"got {value.strip()!r}") from None
    if len(out) > 64:
        raise ParameterError("bands", f"at most 64 bands; got {len(out)}")
    return out


def frame_seed(seed: int, k: int) -> int:
    """The counter key of frame ``k`` of a run of ``seed``: each frame its own sensor noise,
    sun-disk samples and bounce rays (a real detector's noise is new in every exposure; one
    key for all frames would repeat one pattern at fixed pixels, which a feature tracker
    follows), the same for the same (seed, k) on any machine (numpy's SeedSequence hash,
    as the LIDAR's frames)."""
    state = np.random.SeedSequence([int(seed), int(k)]).generate_state(1, np.uint64)[0]
    return int(state) >> 1


def _per_pose(planet, n: int) -> list[Planet | None]:
    """One :class:`Planet` (or None) per pose."""
    if planet is None or isinstance(planet, Planet):
        return [planet] * n
    planets = list(planet)
    if len(planets) != n or not all(isinstance(p, Planet) for p in planets):
        raise ParameterError("planet", f"must be a Planet or {n} Planet, one per pose")
    return planets


def _planet_entry(planet: Planet, sun: Sun) -> dict:
    """The planet of a frame in its manifest entry."""
    return {"direction": planet.direction.tolist(),
            "angular_radius_deg": planet.angular_radius_deg,
            "geometric_albedo": planet.geometric_albedo,
            "phase_deg": planet.phase_deg(sun.direction),
            "irradiance_ratio": planet.irradiance_ratio(sun.direction)}


def _frame(mesh: RayMesh, geometry, settings: CameraSettings, bands, albedo, poses: Poses,
           k: int, sun: Sun, planet: Planet | None, seed: int, body_to_j2000) -> Frame:
    """Frame ``k`` of a camera run (its key ``seed``; ``bands`` the run's band models):
    rendered over its exposure, with stars when asked."""

    def render_at(camera, pose):
        return render(mesh, camera, pose, sun, reflectance=None if bands else settings.reflectance,
                      bands=bands, sensor=settings.sensor,
                      soft_shadow_samples=settings.soft_shadow_samples, seed=seed,
                      ground_truth=geometry, vertex_albedo=albedo, bounces=settings.bounces,
                      bounce_samples=settings.bounce_samples,
                      bounce_filter_px=settings.bounce_filter_px, planet=planet)

    frame = timed_frame(render_at, poses, k, settings.camera, settings.sensor,
                        blur_samples=settings.blur_samples, line_time_s=settings.line_time_s,
                        seed=seed)
    if settings.stars:
        frame = with_stars(frame, settings.sensor, seed=seed, body_to_j2000=body_to_j2000)
    return frame


def camera_run(model, settings: CameraSettings, poses: Poses, sun, folder, *, craters=None,
               force: bool = False, progress: bool = False, mesh: RayMesh | None = None,
               model_name: str = "", frame_info: list[dict] | None = None,
               body_to_j2000: np.ndarray | None = None, planet=None) -> dict:
    """Render every frame of ``poses`` and write the run folder (module notes); the
    ``frames.json`` document.

    ``model`` is any surface (a body, a mesh surface or file, a DEM site) or its
    :class:`~latlong.sensors.scene_geometry.SceneGeometry`; ``sun`` a :class:`Sun` or a
    direction towards it (or a list of :class:`Sun`, one per pose); ``craters`` a catalog
    (or CSV) to label the frames instead of the surface's own
    (:func:`~latlong.sensors.scene_geometry.scene_geometry`); ``mesh`` its
    :class:`RayMesh` if built already; ``model_name`` names the model in the manifest
    (default: the surface's source); ``frame_info`` a dict per frame added to its
    manifest entry (e.g. SPICE's ``et_s`` and ``utc``); ``body_to_j2000`` (n, 3, 3) the
    body frame's orientation per frame for the stars (default: J2000); ``planet`` a
    :class:`~latlong.sensors.planetshine.Planet` (or one per pose) whose light is added
    (planetshine). The same shape as :func:`~latlong.sensors.lidar_files.lidar_run`.
    """
    if not isinstance(settings, CameraSettings):
        raise TypeError(f"`settings` must be CameraSettings; got {type(settings).__name__}")
    if not isinstance(poses, Poses):
        raise TypeError(f"`poses` must be Poses; got {type(poses).__name__}")
    suns = list(sun) if isinstance(sun, list | tuple) and sun and isinstance(sun[0], Sun) \
        else [sun if isinstance(sun, Sun) else Sun(sun)] * len(poses)
    if len(suns) != len(poses) or not all(isinstance(s, Sun) for s in suns):
        raise ParameterError("sun", f"must be a Sun, a direction, or {len(poses)} Sun, one "
                             f"per pose; got {len(suns)}")
    planets = _per_pose(planet, len(poses))
    if frame_info is not None and len(frame_info) != len(poses):
        raise ParameterError("frame_info", f"must hold {len(poses)} dicts, one per pose")
    folder = check_output_folder(folder, force=force)
    check_frames_disk(folder, settings.camera.width, settings.camera.height, len(poses))
    geometry, mesh = ray_scene(model, craters=craters, mesh=mesh)
    albedo = ejecta_albedo(geometry, contrast=settings.bright_ejecta) \
        if settings.bright_ejecta else None
    bands = settings.band_models()
    rims = None  # the rims of the craters seen, fitted to the surface once each
    if geometry.craters is not None and len(geometry.craters):
        rims = FittedRims(geometry.craters, geometry)
    with run_folder(folder, "frames.json") as tmp:
        entries: list[dict] = []
        flow = "flow" in settings.datasets.split(",")
        previous = None
        for k in progress_bar(range(len(poses)), enabled=progress, desc="frames"):
            seed = frame_seed(settings.seed, k)
            frame = _frame(mesh, geometry, settings, bands, albedo, poses, k, suns[k],
                           planets[k], seed, None if body_to_j2000 is None else body_to_j2000[k])
            files = write_frame(tmp, k, frame, depth_format=settings.depth_format,
                                extra=settings.all_ground_truth)
            if flow and previous is not None:  # the flow from the frame before to this one
                name = f"flow_{k - 1:04d}.{'exr' if settings.depth_format == 'exr' else 'flo'}"
                write_flow(tmp / name, optical_flow(previous, frame))
                entries[-1]["files"]["flow"] = name
            previous = frame if flow else None
            entries.append(frame_entry(frame, files, craters=geometry.craters, rims=rims))
            entries[-1]["seed"] = seed  # render(..., seed=) of this frame (frame_seed)
            if frame_info is not None:
                entries[-1].update(frame_info[k])
            if planets[k] is not None:
                entries[-1]["planet"] = _planet_entry(planets[k], suns[k])
        doc = manifest(settings.camera, entries, model=model_name or geometry.source,
                       **settings.record(suns[0]))
        if settings.datasets:
            write_datasets(tmp, settings.datasets, manifest=doc)
        write_manifest(tmp, doc)
    return doc
