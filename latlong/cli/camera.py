"""``latlong camera MODEL -o FOLDER``: render camera frames of a body or a mesh, with
their ground truth and the ``frames.json`` manifest (:func:`latlong.sensors.camera_run`).

Every input is checked before anything is written (a camera inside the model, a pose
that is not a unit quaternion, a zero sun vector, an unknown reflectance, a mesh that
cannot be read: one line ``error: ...``, exit code 2, no files). The options and the
steps are shared with ``dem camera`` (:func:`add_camera_options`, :func:`run_camera`),
which sees a DEM or a layer stack.
"""

from __future__ import annotations

from craters.cli.kit import CliError, parse_seed

from .sensor_options import (
    MODEL_FLAGS,
    add_model_options,
    add_pose_options,
    add_run_options,
    add_sensor_command,
    flagged,
    load_model,
    model_scene,
    numbers,
    output_folder,
    poses_from_args,
    refuse_inside,
    wxh,
)

__all__ = ["FLAGS", "add_camera_options", "add_camera_parser", "run_camera"]

#: Library parameter -> flag, for messages.
FLAGS = {"quaternion_wxyz": "--quaternion", "position_m": "--position-m",
         "sun_direction": "--sun-direction", "fov_deg": "--fov-deg", "fx": "--intrinsics",
         "fy": "--intrinsics", "width": "--size", "height": "--size",
         "reflectance": "--reflectance", "albedo": "--albedo", "preset": "--hapke-preset",
         "angular_radius_deg": "--sun-angular-radius-deg",
         "soft_shadow_samples": "--soft-shadow-samples", "exposure_s": "--exposure-s",
         "flux_e_per_s": "--flux-e-per-s", "full_well_e": "--full-well-e", "gain": "--gain",
         "bits": "--bits", "read_noise_e": "--read-noise-e", "psf_sigma_px": "--psf-sigma-px",
         "k1": "--distortion", "k2": "--distortion", "p1": "--distortion",
         "p2": "--distortion", "k3": "--distortion", "poses": "--poses",
         "bright_ejecta": "--bright-ejecta", "seed": "--seed", **MODEL_FLAGS}


def _camera(args):
    from latlong.sensors import Camera

    w, h = args.size
    dist = dict(zip(("k1", "k2", "p1", "p2", "k3"), args.distortion or [0.0] * 5,
                    strict=True))
    if args.intrinsics is not None:
        if args.fov_deg is not None:
            raise CliError("give --fov-deg or --intrinsics, not both")
        fx, fy, cx, cy = args.intrinsics
        return Camera(fx, fy, cx, cy, w, h, **dist)
    if args.fov_deg is None:
        raise CliError("give --fov-deg F or --intrinsics fx,fy,cx,cy (with --size WxH)")
    return Camera.from_fov(args.fov_deg, w, h, **dist)


def camera_settings(args):
    """The :class:`~latlong.sensors.CameraSettings` the options ask for."""
    from latlong.sensors import CameraSettings, Sensor, reflectance_model

    model = reflectance_model(args.reflectance, albedo=args.albedo,
                              preset=args.hapke_preset if args.reflectance == "hapke"
                              else None)
    sensor = Sensor(exposure_s=args.exposure_s, flux_e_per_s=args.flux_e_per_s,
                    full_well_e=args.full_well_e, gain=args.gain, bits=args.bits,
                    photon_noise=args.photon_noise, read_noise_e=args.read_noise_e,
                    psf_sigma_px=args.psf_sigma_px)
    return CameraSettings(_camera(args), model, sensor,
                          soft_shadow_samples=args.soft_shadow_samples, seed=args.seed,
                          bright_ejecta=args.bright_ejecta, depth_format=args.depth_format,
                          all_ground_truth=args.all_ground_truth)


def run_camera(args, load) -> int:
    """The camera command over the surface ``load(args)`` reads from MODEL."""
    from latlong.sensors import Sun, camera_run

    with flagged(FLAGS):
        out = output_folder(args)
        settings = camera_settings(args)
        poses = poses_from_args(args)
        sun = Sun(args.sun_direction, args.sun_angular_radius_deg)
        geometry, mesh = model_scene(args, load)
        poses = poses if poses is not None else poses_from_args(args, mesh)
        refuse_inside(mesh, poses, args, "camera")
        camera_run(geometry, settings, poses, sun, out, force=args.force,
                   progress=not args.quiet, mesh=mesh, model_name=str(args.model))
    if not args.quiet:
        print(f"wrote {len(poses)} frame(s) and {out / 'frames.json'}")
    return 0


def add_camera_options(c, *, model_help: str, units: bool = True, vertical=None) -> None:
    """The options of a camera command (``latlong camera``, ``dem camera``)."""
    from latlong.sensors import HAPKE_PRESETS, REFLECTANCES

    add_model_options(c, "frames", model_help, units=units)
    p = c.add_argument_group("pose (body frame; camera-to-body rotation, OpenCV camera frame)")
    add_pose_options(p, "camera", vertical=vertical)
    i = c.add_argument_group("intrinsics (pixel centres at integer + 0.5)")
    i.add_argument("--size", type=wxh("in pixels", "1024x768"), required=True,
                   help="image size WxH in pixels (required)")
    i.add_argument("--fov-deg", type=float, help="horizontal field of view, degrees, "
                   "centred square pixels (default: none; or --intrinsics)")
    i.add_argument("--intrinsics", type=numbers(4, "fx,fy,cx,cy"),
                   help="fx,fy,cx,cy in pixels (default: none)")
    i.add_argument("--distortion", type=numbers(5, "k1,k2,p1,p2,k3"),
                   help="Brown-Conrady coefficients k1,k2,p1,p2,k3 as OpenCV (default: none)")
    s = c.add_argument_group("light and surface")
    s.add_argument("--sun-direction", type=numbers(3, "X,Y,Z"), required=True,
                   help="direction towards the sun X,Y,Z, body frame (required)")
    s.add_argument("--sun-angular-radius-deg", type=float, default=0.0,
                   help="angular radius of the sun, degrees; 0.2666 at 1 au (default: 0)")
    s.add_argument("--soft-shadow-samples", type=int, default=0,
                   help="shadow rays per pixel over the solar disk (default: 0 = hard)")
    s.add_argument("--reflectance", default="lommel-seeliger",
                   help=f"{'|'.join(REFLECTANCES)} (default: lommel-seeliger)")
    s.add_argument("--albedo", type=float, help="normal albedo of lambert, lommel-seeliger "
                   "or lunar-lambert (default: 0.12)")
    s.add_argument("--bright-ejecta", type=float, default=0.0,
                   help="albedo contrast of fresh craters' ejecta (0.5 = 50 %% brighter at the "
                   "rim, fading as (r/R)^-3 and with degradation; needs a crater catalog) "
                   "(default: 0 = off)")
    s.add_argument("--hapke-preset", default="s-type",
                   help=f"Hapke parameters: {'|'.join(HAPKE_PRESETS)} (default: s-type)")
    d = c.add_argument_group("sensor")
    d.add_argument("--exposure-s", type=float, default=0.01,
                   help="exposure time, seconds (default: 0.01)")
    d.add_argument("--flux-e-per-s", type=float, default=1.2e7,
                   help="photo-electrons per second of a pixel seeing I/F = 1 (default: 1.2e7)")
    d.add_argument("--full-well-e", type=float, default=40000.0,
                   help="full well, electrons (default: 40000)")
    d.add_argument("--gain", type=float, default=1.0,
                   help="gain relative to full well = full scale (default: 1)")
    d.add_argument("--bits", type=int, default=16,
                   help="8 or 16 (PNG) or 32 (float32 I/F TIFF) (default: 16)")
    d.add_argument("--photon-noise", action="store_true",
                   help="Poisson photon noise (default: off)")
    d.add_argument("--read-noise-e", type=float, default=0.0,
                   help="Gaussian read noise, electrons RMS (default: 0)")
    d.add_argument("--psf-sigma-px", type=float, default=0.0,
                   help="Gaussian PSF sigma, pixels (default: 0 = none)")
    d.add_argument("--seed", type=parse_seed, default=0,
                   help="seed of the noise and of the sun-disk samples (default: 0)")
    o = c.add_argument_group("output")
    o.add_argument("--depth-format", choices=("tif", "npy"), default="tif",
                   help="float32 depth and range files (default: tif)")
    o.add_argument("--all-ground-truth", action="store_true",
                   help="also write incidence, emission, phase, position, face and lit "
                   "fraction per frame (.npy) (default: off)")
    add_run_options(o)


def add_camera_parser(sub) -> None:
    """Register ``latlong camera``."""
    add_sensor_command(sub, "camera", "render camera frames (image, depth, range, normals) "
                       "of a body or a mesh, with a frames.json manifest", add_camera_options,
                       run_camera, load_model, model_help="a body .npz or a mesh file (.ply "
                       ".obj .stl .vtp .vtk .glb)")
