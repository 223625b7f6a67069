"""``latlong camera MODEL -o FOLDER``: render camera frames of a body or a mesh, with
their ground truth and the ``frames.json`` manifest (:mod:`latlong.sensors`).

Every input is checked before anything is written (a camera inside the model, a pose
that is not a unit quaternion, a zero sun vector, an unknown reflectance, a mesh that
cannot be read: one line ``error: ...``, exit code 2, no files). Frames are rendered
into a hidden temporary folder next to FOLDER, each file written atomically, and moved
into FOLDER at the end, ``frames.json`` last.
"""

from __future__ import annotations

import argparse
import contextlib
import csv
import os
import re
import shutil
import tempfile
import time
from pathlib import Path

import numpy as np

from craters._shared import ParameterError, ParameterTypeError, progress_bar
from craters._shared.cli import CliError, parse_seed

__all__ = ["add_camera_parser", "read_poses"]

_NUM = r"[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?"
_NUMBER_LIST = rf"^-(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?(,{_NUM})*$"
POSES_HEADER = ["time_s", "x_m", "y_m", "z_m", "qw", "qx", "qy", "qz"]
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


def _numbers(n: int, what: str):
    def parse(text):
        try:
            vals = [float(p) for p in str(text).split(",")]
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected {what}; got {text!r}") from None
        if len(vals) != n or not np.isfinite(vals).all():
            raise argparse.ArgumentTypeError(f"expected {what} ({n} finite numbers); "
                                             f"got {text!r}")
        return vals
    return parse


def _size(text):
    parts = str(text).lower().split("x")
    try:
        w, h = (int(p) for p in parts)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected WxH in pixels, e.g. 1024x768; got "
                                         f"{text!r}") from None
    if not (1 <= w <= 16384 and 1 <= h <= 16384):
        raise argparse.ArgumentTypeError(f"width and height must be in [1, 16384]; got "
                                         f"{text!r}")
    return w, h


@contextlib.contextmanager
def _flagged():
    """Library parameter errors shown under the command's flags."""
    try:
        yield
    except (ParameterError, ParameterTypeError) as exc:
        if exc.name in FLAGS:
            raise CliError(exc.shown_as(FLAGS[exc.name])) from None
        raise


def read_poses(path):
    """The poses of a CSV file with the header ``time_s,x_m,y_m,z_m,qw,qx,qy,qz``."""
    from latlong.sensors import Pose

    path = Path(path)
    if not path.is_file():
        raise CliError(f"--poses {str(path)!r} does not exist")
    poses = []
    with open(path, newline="") as fh:
        rows = [r for r in csv.reader(fh) if r and not r[0].lstrip().startswith("#")]
    if not rows or [c.strip() for c in rows[0]] != POSES_HEADER:
        raise CliError(f"--poses {str(path)!r}: the first line must be "
                       f"{','.join(POSES_HEADER)}")
    if len(rows) < 2:
        raise CliError(f"--poses {str(path)!r} has no poses")
    for k, row in enumerate(rows[1:], start=2):
        try:
            t, x, y, z, qw, qx, qy, qz = (float(c) for c in row)
        except ValueError:
            raise CliError(f"--poses {str(path)!r} line {k}: expected 8 numbers; got "
                           f"{','.join(row)!r}") from None
        try:
            poses.append(Pose([x, y, z], [qw, qx, qy, qz], t))
        except (ParameterError, ParameterTypeError) as exc:
            raise CliError(f"--poses {str(path)!r} line {k}: {exc.shown_as(exc.name)}") \
                from None
    return poses


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


def _poses(args):
    from latlong.sensors import Pose

    if args.poses is not None:
        if args.position_m is not None or args.quaternion is not None:
            raise CliError("give --poses or --position-m/--quaternion, not both")
        return read_poses(args.poses)
    if args.position_m is None or args.quaternion is None:
        raise CliError("give --position-m X,Y,Z and --quaternion W,X,Y,Z, or --poses FILE.csv")
    with _flagged():
        return [Pose(args.position_m, args.quaternion, 0.0)]


def _output_folder(args) -> Path:
    out = Path(args.output)
    if out.is_symlink():
        raise CliError(f"-o/--output {str(out)!r} is a symbolic link; give a real folder")
    if out.exists() and not out.is_dir():
        raise CliError(f"-o/--output {str(out)!r} exists and is not a folder")
    if out.is_dir() and any(out.iterdir()) and not args.force:
        raise CliError(f"-o/--output {str(out)!r} is not empty; use --force to write into it")
    parent = out.parent if str(out.parent) else Path(".")
    if not parent.is_dir():
        raise CliError(f"-o/--output {str(out)!r}: folder {str(parent)!r} does not exist")
    if not os.access(parent, os.W_OK | os.X_OK):
        raise CliError(f"-o/--output {str(out)!r}: folder {str(parent)!r} is not writable")
    return out


def _move_into(tmp: Path, out: Path) -> None:
    """Move the rendered files into ``out`` (``frames.json`` last)."""
    if not out.exists():
        os.replace(tmp, out)
        return
    names = sorted(p.name for p in tmp.iterdir())
    names.sort(key=lambda n: n == "frames.json")
    for name in names:
        os.replace(tmp / name, out / name)
    tmp.rmdir()


def cmd_camera(args) -> int:
    from latlong.sensors import Sensor, Sun, camera_inside, reflectance_model, render, scene_mesh
    from latlong.sensors.output import (
        frame_entry,
        manifest,
        read_model,
        write_frame,
        write_manifest,
    )

    out = _output_folder(args)
    camera = _camera(args)
    poses = _poses(args)
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
        geometry = read_model(args.model, units=args.units)
        t0 = time.perf_counter()
        mesh = scene_mesh(geometry)
    for k, pose in enumerate(poses):
        if camera_inside(mesh, pose.position_m):
            where = "--position-m" if args.poses is None else f"--poses frame {k}"
            raise CliError(f"{where}: the camera at {pose.position_m.tolist()} is inside "
                           f"the model {str(args.model)!r}")
    if not args.quiet:
        print(f"model {args.model}: {len(mesh.faces)} triangles, BVH built in "
              f"{time.perf_counter() - t0:.1f} s")
    parent = out.parent if str(out.parent) else Path(".")
    tmp = Path(tempfile.mkdtemp(prefix=f".{out.name}.", dir=parent))
    try:
        entries = []
        for k, pose in progress_bar(list(enumerate(poses)), enabled=not args.quiet,
                                    desc="frames"):
            frame = render(mesh, camera, pose, sun, reflectance=model, sensor=sensor,
                           soft_shadow_samples=args.soft_shadow_samples, seed=args.seed)
            files = write_frame(tmp, k, frame, depth_format=args.depth_format,
                                extra=args.all_ground_truth)
            entries.append(frame_entry(frame, files))
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
    c._negative_number_matcher = re.compile(_NUMBER_LIST)
    c.add_argument("model", help="a body .npz or a mesh file (.ply .obj .stl .vtp .vtk .glb)")
    c.add_argument("-o", "--output", required=True, help="output folder (required)")
    c.add_argument("--units", choices=("m", "km"), default="m",
                   help="units of a mesh file's coordinates (default: m)")
    p = c.add_argument_group("pose (body frame; camera-to-body rotation, OpenCV camera frame)")
    p.add_argument("--position-m", type=_numbers(3, "X,Y,Z"),
                   help="camera position X,Y,Z in metres (default: none; or --poses)")
    p.add_argument("--quaternion", type=_numbers(4, "W,X,Y,Z"),
                   help="camera-to-body unit quaternion W,X,Y,Z (default: none)")
    p.add_argument("--poses", help="CSV of poses with the header time_s,x_m,y_m,z_m,qw,qx,"
                   "qy,qz (default: none)")
    i = c.add_argument_group("intrinsics (pixel centres at integer + 0.5)")
    i.add_argument("--size", type=_size, required=True, help="image size WxH in pixels "
                   "(required)")
    i.add_argument("--fov-deg", type=float, help="horizontal field of view, degrees, "
                   "centred square pixels (default: none; or --intrinsics)")
    i.add_argument("--intrinsics", type=_numbers(4, "fx,fy,cx,cy"),
                   help="fx,fy,cx,cy in pixels (default: none)")
    i.add_argument("--distortion", type=_numbers(5, "k1,k2,p1,p2,k3"),
                   help="Brown-Conrady coefficients k1,k2,p1,p2,k3 as OpenCV (default: none)")
    s = c.add_argument_group("light and surface")
    s.add_argument("--sun-direction", type=_numbers(3, "X,Y,Z"), required=True,
                   help="direction towards the sun X,Y,Z, body frame (required)")
    s.add_argument("--sun-angular-radius-deg", type=float, default=0.0,
                   help="angular radius of the sun, degrees; 0.2666 at 1 au (default: 0)")
    s.add_argument("--soft-shadow-samples", type=int, default=0,
                   help="shadow rays per pixel over the solar disk (default: 0 = hard)")
    s.add_argument("--reflectance", default="lommel-seeliger",
                   help=f"{'|'.join(REFLECTANCES)} (default: lommel-seeliger)")
    s.add_argument("--albedo", type=float, help="normal albedo of lambert, lommel-seeliger "
                   "or lunar-lambert (default: 0.12)")
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
