"""``latlong camera MODEL -o FOLDER``: render camera frames of a body or a mesh, with
their ground truth and the ``frames.json`` manifest (:func:`latlong.sensors.camera_run`).

Every input is checked before anything is written (a camera inside the model, a pose
that is not a unit quaternion, a zero sun vector, an unknown reflectance, a mesh that
cannot be read: one line ``error: ...``, exit code 2, no files). The options (one table,
:func:`camera_options`: the settings of :class:`~latlong.sensors.CameraSettings` and the
defaults of the detector, the sun and the pose functions) and the steps
(:func:`run_camera`) are shared with ``dem camera``, which sees a DEM or a layer stack.
"""

from __future__ import annotations

import dataclasses

from craters.cli.kit import CliError, parse_seed
from craters.cli.options import Setting, Values, declared_keys, default_of, shown_value
from latlong.sensors import (
    HAPKE_PRESETS,
    REFLECTANCES,
    CameraSettings,
    LommelSeeliger,
    Planet,
    Sensor,
    Sun,
)

from .sensor_options import (
    RUN,
    load_model,
    model_options,
    model_scene,
    numbers,
    output_folder,
    pose_options,
    poses_of,
    refuse_inside,
    sensor_command,
    spice_of,
    wxh,
)

HELP = {
    "camera": "render camera frames (image, depth, range, normals) of a body or a mesh, with a "
              "frames.json manifest",
}

__all__ = ["GROUPS", "camera_options", "register", "run_camera"]

#: The sections of the camera's options.
GROUPS = {"pose": "pose (body frame; camera-to-body rotation, OpenCV camera frame)",
          "intrinsics": "intrinsics (pixel centres at integer + 0.5)",
          "light": "light and surface", "sensor": "sensor", "output": "output"}
_DISTORTION = ("k1", "k2", "p1", "p2", "k3")


def _detector(key: str, help: str, **kw) -> Setting:
    return Setting(default_of(Sensor, key), help, group="sensor", **kw)


#: The detector's settings (:class:`~latlong.sensors.Sensor`, whose defaults they take).
SENSOR = {
    "exposure_s": _detector("exposure_s", "exposure time (auto: the lit pixels' "
                            "--exposure-percentile at --exposure-target of full scale)",
                            unit="s", kind=float, default_text="auto"),
    "exposure_percentile": _detector("exposure_percentile", "auto-exposure: percentile of "
                                     "the lit pixels' I/F put at the target",
                                     range=(50.0, 100.0)),
    "exposure_target": _detector("exposure_target", "auto-exposure: where that percentile "
                                 "lands, share of full scale", range=(0.0, 1.0)),
    "flux_e_per_s": _detector("flux_e_per_s", "photo-electrons per second of a pixel seeing "
                              "I/F = 1", unit="e/s"),
    "full_well_e": _detector("full_well_e", "full well", unit="electrons"),
    "gain": _detector("gain", "gain relative to full well = full scale"),
    "bits": _detector("bits", "8 or 16 (PNG) or 32 (float32 I/F TIFF)"),
    "photon_noise": _detector("photon_noise", "Poisson photon noise"),
    "read_noise_e": _detector("read_noise_e", "Gaussian read noise", unit="electrons RMS"),
    "psf_sigma_px": _detector("psf_sigma_px", "Gaussian PSF sigma (0: none)", unit="px"),
}


def camera_options(model_help: str, *, units: bool = True, vertical=None) -> dict[str, Setting]:
    """The options of a camera command (``latlong camera``, ``dem camera``)."""
    def into(group, s):
        return dataclasses.replace(s, group=group)

    own = declared_keys(CameraSettings)
    reflectance = default_of(CameraSettings, "reflectance")
    return {
        **model_options("frames", model_help, units=units),
        **pose_options("camera", vertical=vertical),
        "size": Setting(help="image size WxH", unit="px", parse=wxh("in pixels", "1024x768"),
                        metavar="WxH", also=("width", "height"), group="intrinsics",
                        default_text="required; or --instrument"),
        "instrument": Setting(help="SPICE instrument whose kernel gives the image size and "
                              "focal length (with --spice)", metavar="NAME",
                              group="intrinsics"),
        "fov_deg": Setting(help="horizontal field of view, centred square pixels", unit="deg",
                           kind=float, default_text="none; or --intrinsics",
                           group="intrinsics"),
        "intrinsics": Setting(help="fx,fy,cx,cy", unit="px", parse=numbers(4, "fx,fy,cx,cy"),
                              metavar="FX,FY,CX,CY", also=("fx", "fy", "cx", "cy"),
                              group="intrinsics"),
        "distortion": Setting(help="Brown-Conrady coefficients k1,k2,p1,p2,k3 as OpenCV",
                              parse=numbers(5, "k1,k2,p1,p2,k3"), metavar="K1,K2,P1,P2,K3",
                              also=_DISTORTION, group="intrinsics"),
        "sun_direction": Setting(help="direction towards the sun X,Y,Z, body frame",
                                 parse=numbers(3, "X,Y,Z"), metavar="X,Y,Z", group="light",
                                 default_text="required; with --spice: from the kernels"),
        "sun_angular_radius_deg": Setting(default_of(Sun, "angular_radius_deg"),
                                          "angular radius of the sun (0.2666 at 1 au)",
                                          unit="deg", also=("angular_radius_deg",),
                                          group="light"),
        "planet_direction": Setting(help="planetshine: direction towards a planet X,Y,Z, body "
                                    "frame (the Earth for the Moon's night side)",
                                    parse=numbers(3, "X,Y,Z"), metavar="X,Y,Z", group="light",
                                    default_text="none"),
        "planet": Setting(help="planetshine from SPICE: the planet's name or id (with --spice; "
                          "direction and size from the kernels)", metavar="NAME",
                          group="light"),
        "planet_radius_deg": Setting(default_of(Planet, "angular_radius_deg"), "planetshine: "
                                     "the planet's angular radius (the Earth from the Moon)",
                                     unit="deg", group="light", range=(0.0, 60.0)),
        "planet_albedo": Setting(default_of(Planet, "geometric_albedo"), "planetshine: the "
                                 "planet's geometric albedo (the Earth as a Lambert sphere of Bond "
                                 "albedo 0.30)", group="light",
                                 range=(0.0, 1.0)),
        "soft_shadow_samples": into("light", own["soft_shadow_samples"]),
        "bounces": into("light", own["bounces"]),
        "bounce_samples": into("light", own["bounce_samples"]),
        "bounce_filter_px": into("light", own["bounce_filter_px"]),
        "blur_samples": into("sensor", own["blur_samples"]),
        "line_time_s": into("sensor", own["line_time_s"]),
        "stars": into("light", own["stars"]),
        "reflectance": Setting(next(k for k, m in REFLECTANCES.items()
                                    if type(reflectance) is m), "reflectance model",
                               choices=tuple(REFLECTANCES), group="light"),
        "albedo": Setting(help="normal albedo of lambert, lommel-seeliger or lunar-lambert",
                          kind=float, group="light",
                          default_text=shown_value(default_of(LommelSeeliger, "albedo"))),
        "bright_ejecta": into("light", own["bright_ejecta"]),
        "bands": into("light", own["bands"]),
        "hapke_preset": Setting(help="Hapke parameters", choices=tuple(HAPKE_PRESETS),
                                default_text="s-type", also=("preset",), group="light"),
        **SENSOR,
        "seed": dataclasses.replace(own["seed"], group="sensor", parse=parse_seed),
        "depth_format": into("output", own["depth_format"]),
        "all_ground_truth": into("output", own["all_ground_truth"]),
        "datasets": into("output", own["datasets"]),
        **{k: into("output", s) for k, s in RUN.items()},
    }


def _camera(v: Values):
    from latlong.sensors import Camera

    dist = dict(zip(_DISTORTION, v.distortion or [0.0] * 5, strict=True))
    if v.instrument is not None:
        if v.spice is None or v.size or v.fov_deg or v.intrinsics:
            raise CliError("--instrument takes the camera from the --spice kernels: give it "
                           "without --size, --fov-deg and --intrinsics")
        from latlong.sensors.spice import spice_camera

        try:
            return spice_camera(v.spice, v.instrument, **dist)
        except (ValueError, FileNotFoundError) as exc:
            raise CliError(str(exc)) from None
    if v.size is None:
        raise CliError("give --size WxH (or --instrument with --spice)")
    w, h = v.size
    if v.intrinsics is not None:
        if v.fov_deg is not None:
            raise CliError("give --fov-deg or --intrinsics, not both")
        fx, fy, cx, cy = v.intrinsics
        return Camera(fx, fy, cx, cy, w, h, **dist)
    if v.fov_deg is None:
        raise CliError("give --fov-deg F or --intrinsics fx,fy,cx,cy (with --size WxH)")
    return Camera.from_fov(v.fov_deg, w, h, **dist)


def camera_settings(v: Values) -> CameraSettings:
    """The :class:`~latlong.sensors.CameraSettings` the options ask for."""
    from latlong.sensors import reflectance_model

    model = reflectance_model(v.reflectance, albedo=v.albedo,
                              preset=v.hapke_preset if v.reflectance == "hapke" else None)
    sensor = Sensor(**{k: v[k] for k in SENSOR})
    return CameraSettings(_camera(v), model, sensor,
                          **{k: v[k] for k in declared_keys(CameraSettings)})


def run_camera(v: Values, load) -> int:
    """The camera command over the surface ``load(v)`` reads from MODEL."""
    from latlong.sensors import camera_run

    out = output_folder(v)
    settings = camera_settings(v)
    if (v.sun_direction is None) == (v.spice is None):
        raise CliError("give --sun-direction X,Y,Z, or --spice (the sun from the kernels)"
                       if v.spice is None else "give --sun-direction or --spice, not both")
    seq = spice_of(v)
    poses = seq.poses if seq is not None else poses_of(v)
    sun = Sun(v.sun_direction, v.sun_angular_radius_deg) if seq is None else \
        [Sun(d, v.sun_angular_radius_deg) for d in seq.sun_directions]
    geometry, mesh = model_scene(v, load)
    poses = poses if poses is not None else poses_of(v, mesh)
    refuse_inside(mesh, poses, v, "camera")
    camera_run(geometry, settings, poses, sun, out, force=v.force, progress=not v.quiet,
               mesh=mesh, model_name=str(v.model),
               frame_info=None if seq is None else seq.frame_info(),
               body_to_j2000=None if seq is None else seq.body_to_j2000,
               planet=_planet(v, seq))
    if not v.quiet:
        print(f"wrote {len(poses)} frame(s) and {out / 'frames.json'}")
    return 0


def _planet(v: Values, seq):
    """The planet of ``--planet-direction`` (or each frame's from ``--planet`` with
    ``--spice``), or None."""
    if v.planet is not None and v.planet_direction is not None:
        raise CliError("give --planet-direction or --planet (with --spice), not both")
    if v.planet is None:
        return None if v.planet_direction is None else \
            Planet(v.planet_direction, v.planet_radius_deg, v.planet_albedo)
    if seq is None:
        raise CliError("--planet NAME takes the planet from the --spice kernels; without "
                       "them give --planet-direction X,Y,Z")
    return seq.planets(v.planet_albedo)


def register(sub) -> None:
    """Register ``latlong camera``."""
    sensor_command(sub, "camera", HELP["camera"],
                   camera_options("a body .npz or a mesh file (.ply .obj .stl .vtp .vtk "
                                  ".glb)"), run_camera, load_model, GROUPS)
