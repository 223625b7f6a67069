"""``latlong camera MODEL -o FOLDER``: render camera frames of a body or a mesh, with
their ground truth and the ``frames.json`` manifest (:mod:`latlong.sensors`).

Every input is checked before anything is written (a camera inside the model, a pose
that is not a unit quaternion, a zero sun vector, an unknown reflectance, a mesh that
cannot be read: one line ``error: ...``, exit code 2, no files). Frames are rendered
into a hidden temporary folder next to FOLDER, each file written atomically, and moved
into FOLDER at the end, ``frames.json`` last.
"""

from __future__ import annotations

import contextlib
import shutil
import time
from pathlib import Path

from craters._shared import (
    ParameterError,
    ParameterTypeError,
    progress_bar,
    replace_output,
    temp_folder,
)
from craters.cli.kit import CliError, parse_seed

from .sensor_options import (
    add_pose_options,
    allow_negative_lists,
    numbers,
    output_folder,
    poses_from_args,
    refuse_inside,
    wxh,
)

__all__ = ["add_camera_parser"]

#: library parameter -> flag, for messages
FLAGS = {"quaternion_wxyz": "--quaternion", "position_m": "--position-m",
         "sun_direction": "--sun-direction", "fov_deg": "--fov-deg", "fx": "--intrinsics",
         "fy": "--intrinsics", "width": "--size", "height": "--size",
         "reflectance": "--reflectance", "albedo": "--albedo", "preset": "--hapke-preset",
         "angular_radius_deg": "--sun-angular-radius-deg", "units": "--units",
         "soft_shadow_samples": "--soft-shadow-samples", "exposure_s": "--exposure-s",
         "flux_e_per_s": "--flux-e-per-s", "full_well_e": "--full-well-e", "gain": "--gain",
         "bits": "--bits", "read_noise_e": "--read-noise-e", "psf_sigma_px": "--psf-sigma-px",
         "k1": "--distortion", "k2": "--distortion", "p1": "--distortion",
         "p2": "--distortion", "k3": "--distortion", "poses": "--poses"}


@contextlib.contextmanager
def _flagged():
    """Library parameter errors shown under the command's flags."""
    try:
        yield
    except (ParameterError, ParameterTypeError) as exc:
        if exc.name in FLAGS:
            raise CliError(exc.shown_as(FLAGS[exc.name])) from None
        raise


def _camera(args):
    from latlong.sensors import Camera

    w, h = args.size
    dist = dict(zip(("k1", "k2", "p1", "p2", "k3"), args.distortion or [0.0] * 5,
                    strict=True))
    with _flagged():
        if args.intrinsics is not None:
            if args.fov_deg is not None:
                raise CliError("give --fov-deg or --intrinsics, not both")
            fx, fy, cx, cy = args.intrinsics
            return Camera(fx, fy, cx, cy, w, h, **dist)
        if args.fov_deg is None:
            raise CliError("give --fov-deg F or --intrinsics fx,fy,cx,cy (with --size WxH)")
        return Camera.from_fov(args.fov_deg, w, h, **dist)


def _move_into(tmp: Path, out: Path) -> None:
    """Move the rendered files into ``out`` (``frames.json`` last)."""
    if not out.exists():
        replace_output(tmp, out)
        return
    names = sorted(p.name for p in tmp.iterdir())
    names.sort(key=lambda n: n == "frames.json")
    for name in names:
        replace_output(tmp / name, out / name)
    tmp.rmdir()


def cmd_camera(args) -> int:
    from latlong.sensors import (
        Sensor,
        Sun,
        ejecta_albedo,
        reflectance_model,
        render,
        scene_geometry,
        scene_mesh,
    )
    from latlong.sensors.labels import FittedRims
    from latlong.sensors.output import frame_entry, manifest, write_frame, write_manifest

    out = output_folder(args)
    camera = _camera(args)
    poses = poses_from_args(args)
    with _flagged():
        sun = Sun(args.sun_direction, args.sun_angular_radius_deg)
        model = reflectance_model(args.reflectance, albedo=args.albedo,
                                  preset=args.hapke_preset if args.reflectance == "hapke"
                                  else None)
        sensor = Sensor(exposure_s=args.exposure_s, flux_e_per_s=args.flux_e_per_s,
                        full_well_e=args.full_well_e, gain=args.gain, bits=args.bits,
                        photon_noise=args.photon_noise, read_noise_e=args.read_noise_e,
                        psf_sigma_px=args.psf_sigma_px)
        if not 0 <= args.soft_shadow_samples <= 1024:
            raise CliError(f"--soft-shadow-samples must be in [0, 1024]; got "
                           f"{args.soft_shadow_samples}")
        try:
            geometry = scene_geometry(args.model, units=args.units)
            t0 = time.perf_counter()
            mesh = scene_mesh(geometry)
            t_bvh = time.perf_counter() - t0
            geometry = scene_geometry(geometry, craters=args.catalog, mesh=mesh)
        except ValueError as exc:
            raise CliError(str(exc).replace("`model`", "MODEL")) from None
    poses = poses if poses is not None else poses_from_args(args, mesh)
    refuse_inside(mesh, poses, args, "camera")
    albedo = None
    if args.bright_ejecta:
        try:
            albedo = ejecta_albedo(geometry, contrast=args.bright_ejecta)
        except (ParameterError, ParameterTypeError) as exc:
            raise CliError(exc.shown_as("--bright-ejecta")) from None
    rims = None  # the rims of the craters seen, fitted to the surface once each
    if geometry.craters is not None and len(geometry.craters):
        rims = FittedRims(geometry.craters, geometry)
    if not args.quiet:
        print(f"model {args.model}: {len(mesh.faces)} triangles, BVH built in "
              f"{t_bvh:.1f} s")
    tmp = temp_folder(out)
    try:
        entries = []
        for k in progress_bar(range(len(poses)), enabled=not args.quiet, desc="frames"):
            frame = render(mesh, camera, poses[k], sun, reflectance=model, sensor=sensor,
                           soft_shadow_samples=args.soft_shadow_samples, seed=args.seed,
                           ground_truth=geometry, vertex_albedo=albedo)
            files = write_frame(tmp, k, frame, depth_format=args.depth_format,
                                extra=args.all_ground_truth)
            entries.append(frame_entry(frame, files, craters=geometry.craters, rims=rims))
        doc = manifest(camera, entries, model=str(args.model), reflectance=args.reflectance,
                       reflectance_parameters={k: getattr(model, k)
                                               for k in model.__dataclass_fields__},
                       sun_angular_radius_deg=sun.angular_radius_deg,
                       soft_shadow_samples=args.soft_shadow_samples, seed=args.seed,
                       sensor={k: getattr(sensor, k) for k in sensor.__dataclass_fields__})
        write_manifest(tmp, doc)
        _move_into(tmp, out)
    finally:
        if tmp.exists():
            shutil.rmtree(tmp, ignore_errors=True)
    if not args.quiet:
        print(f"wrote {len(poses)} frame(s) and {out / 'frames.json'}")
    return 0


def add_camera_parser(sub) -> None:
    """Register ``camera``."""
    from latlong.sensors import HAPKE_PRESETS, REFLECTANCES

    c = sub.add_parser("camera", help="render camera frames (image, depth, range, normals) "
                       "of a body or a mesh, with a frames.json manifest")
    # "--position-m -3000,0,0": a comma list of numbers starting with "-" is a value
    allow_negative_lists(c)
    c.add_argument("model", help="a body .npz or a mesh file (.ply .obj .stl .vtp .vtk .glb)")
    c.add_argument("-o", "--output", required=True, help="output folder (required)")
    c.add_argument("--units", choices=("m", "km"), default="m",
                   help="units of a mesh file's coordinates (default: m)")
    c.add_argument("--catalog", help="crater catalog CSV that labels the frames (default: "
                   "the body's own; a mesh file has none)")
    p = c.add_argument_group("pose (body frame; camera-to-body rotation, OpenCV camera frame)")
    add_pose_options(p, "camera")
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
    o.add_argument("--force", action="store_true",
                   help="write into a folder that is not empty (default: off)")
    o.add_argument("-q", "--quiet", action="store_true",
                   help="no progress bars or messages (default: off)")
    c.set_defaults(func=cmd_camera)
