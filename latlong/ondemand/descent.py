"""Descents: camera frames from orbit to touchdown over terrain made on demand for each
frame at the resolution that frame needs.

A frame at altitude ``h`` above the site looks straight down (the optical axis along the
base's radial direction at the site, north towards the top of the picture). Its ground
footprint is ``2 h tan(fov / 2)`` wide; the terrain under it is generated with pixels of
the frame's ground pixel size and craters at least 3 of them across (:mod:`.tile`): a
window 1.6 footprints wide in the gnomonic projection at the site, or, when that would
be more than half the site's radius, every vertex of a lat/long grid whose spacing is the
ground pixel (the body as a whole). A crater seen at 10 km is the same crater at 100 m
(:mod:`.field`: the terrain is a function of position), now with its smaller craters.
Shadows are cast by what the window holds. With a LIDAR (``lidar``: its
:class:`~latlong.sensors.LidarSettings`) each frame also fires it from the camera's pose
over the same terrain (:func:`latlong.sensors.lidar_frame`): returns labelled with the
frame's craters, range noise keyed by (``lidar_seed``, frame), its beams inside the
frame's terrain window.

Albedo (issue 36): each frame's terrain carries the brighter ejecta of its fresh craters
(``bright_ejecta``, :func:`latlong.sensors.ejecta_albedo`: fresh ejecta brighter than the
matured terrain, darkening with degradation) times the regolith's mottling (``mottling``,
:func:`latlong.sensors.regolith_albedo`: a function of position, octaves from 2 m down
to the frame's pixels, keyed by the scene's seed), both 0 to leave the albedo uniform.

Relief below the pixels: each frame shades its terrain with vertex normals tilted by the
relief its smallest stamped craters (3 pixels) leave out
(:func:`latlong.sensors.regolith_normals`; geometry, depth and LIDAR keep the stamped
terrain), ``microrelief_deg`` RMS at a 1 m pixel, tan(tilt) ~ p^(H - 1) at pixels p metres
wide with ``microrelief_hurst`` H, by default 1: the same tilt at every scale. The lunar
maria's LOLA deviogram has H = 0.76 from 17 to 530 m (Rosenburg et al. 2011, Table 2);
carried down to the last frames of a descent to 1 m (0.5 mm pixels: a tilt of 15 deg) it
gave a sandpaper picture whose finest octave held 4.6 times the image power share of the
10 km frame (the consistency check asks at most 3); nothing measured here says how the
relief goes on below the NAC's pixels. The default is measured on LROC NAC pictures: four
0.5 m crops of the Von Karman crater floor near the Chang'e 4 site (calibrated NAC
frames M115143943RE, M1183658592LE, M1229577647LE, M1309534046LE, as cropped in the
public crater-detection set github.com/yizuifangxiuyh/Lunar_Crater_Detection_Data)
hold 0.037-0.083 of their image power (mean removed, Hann window) in the finest octave of
spatial frequency and 0.080-0.163 in the next; a 1000^2 descent frame at 0.5 m (sun 30
deg, the mare scene of ``tests/benchmarks/measure_ondemand.py``) without the relief
0.015 / 0.056 (its soil smooth where the real regolith is granular), with 2.5 deg
0.040 / 0.094 (with the mottling, 0.05: 0.037 / 0.120). Carrying the maria deviogram
itself (2 deg at 17 m) down to 1 m gives 5.8 deg, which made 0.147 / 0.230: a sandpaper
texture that drowned the small craters.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Iterator
from typing import TYPE_CHECKING

import numpy as np

from craters._shared import ParameterError, check_int, check_range

from ..grid import LatLongGrid
from ..scene import Scene
from ._rock_kernels import _face_rocks_kernel
from .base import tangent_frame
from .field import CraterField, crater_field
from .points import units_of
from .tile import tile_mesh, tile_of_field
from .window import DESCENT_MARGIN, MAX_TILE_PX, check_descent_memory

if TYPE_CHECKING:
    from ..sensors import LidarFrame, LidarSettings
    from ..sensors.render import Frame

__all__ = ["MICRORELIEF_DEG", "MICRORELIEF_HURST", "DescentFrame", "descent",
           "descent_altitudes", "display", "write_descent"]

_MAX_MAGNITUDE = 1500
#: Hurst exponent of the relief below the pixels (1: the same tilt at every scale; module
#: notes).
MICRORELIEF_HURST = 1.0
#: RMS tilt of that relief at a 1 m pixel, degrees (measured on LROC NAC pictures: module
#: notes).
MICRORELIEF_DEG = 2.5


@dataclasses.dataclass(frozen=True)
class DescentFrame:
    """One frame of a descent."""

    altitude_m: float
    """Height of the camera above the terrain at the site (as the frame's terrain has it)."""
    ground_pixel_m: float
    """The footprint of a pixel at the site (the terrain's pixel)."""
    frame: Frame
    """The rendered :class:`latlong.sensors.render.Frame`."""
    n_craters: int
    """Craters that made the frame's terrain."""
    n_rocks: int
    """Rocks drawn for the frame's terrain."""
    terrain: str
    """``window`` or ``body``."""
    craters: np.ndarray
    """The craters of the frame's terrain that show (oldest first; the row of a crater is
    its id in the frame's ``crater_id`` label image): :meth:`CraterField.catalog`'s
    columns."""
    lidar: LidarFrame | None = None
    """The LIDAR's returns from the camera's pose (with ``descent(lidar=...)``), labelled
    with :attr:`craters`."""
    crs_wkt: str = ""
    """The CRS of the positions (body-fixed Cartesian on the body's sphere), OGC WKT: the
    LAS files' CRS."""
    rocks: np.ndarray | None = None
    """The rocks that show in the frame's terrain (the row of a rock is its id in the
    frame's ``boulder_id`` label image): :meth:`RockField.last_catalog`'s columns."""


def descent_altitudes(start_m: float, stop_m: float, frames: int) -> np.ndarray:
    """``frames`` altitudes from ``start_m`` down to ``stop_m``, evenly spaced in log."""
    start_m = check_range("start_m", start_m, 0.01, 1e9)
    stop_m = check_range("stop_m", stop_m, 0.001, start_m)
    frames = check_int("frames", frames, 1, 100_000)
    return np.geomspace(start_m, stop_m, frames)


def _rock_faces(field: CraterField, faces: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(each face's rock label, -1 on the ground; the catalog of the labelled rocks, row =
    label) of the terrain of the field's last query: a face is a rock's where two of its
    vertices stand on that rock (the tallest at each, :attr:`RockField.last_which`): the
    labelled area then matches the rocks' share of the vertices (all three left a quarter
    of a 5 mm-pixel tile's rock cover unlabelled, 0.23 % of the faces for 0.32 %)."""
    rock = np.empty(len(faces), dtype=np.int64)  # the rock two vertices share (-1: none)
    _face_rocks_kernel(field.rocks.last_which, np.ascontiguousarray(faces, dtype=np.int64),
                       rock)
    on = np.flatnonzero(rock >= 0)
    shown, label = np.unique(rock[on], return_inverse=True)
    face_rock = np.full(len(faces), -1, dtype=np.int32)
    face_rock[on] = label
    return face_rock, field.rocks.last_catalog(shown)


def _terrain(field: CraterField, lat_deg, lon_deg, size_m, pixel_m, site_radius):
    """(vertices, faces, (craters, rocks), kind, (face rock labels, rock catalog)) of a
    frame's terrain."""
    if size_m <= 0.5 * site_radius:
        size_px = min(MAX_TILE_PX, max(1, int(round(size_m / pixel_m))))
        t = tile_of_field(field, lat_deg, lon_deg, size_px, pixel_m, 3.0)
        verts, faces = tile_mesh(t)
        return verts, faces, (t.n_craters, t.n_rocks), "window", _rock_faces(field, faces)
    if field.base.scene is None:
        raise ParameterError("altitudes_m", f"must keep the frames' ground within a window "
                             f"(footprint x {DESCENT_MARGIN} <= half the site's radius) over a DEM")
    m = int(min(_MAX_MAGNITUDE, max(16, math.ceil(math.pi * field.base.radius_m / (2 * pixel_m)))))
    grid = LatLongGrid(m)
    units = grid.unit_vectors()
    d_min = 3.0 * grid.spacing(field.base.radius_m)
    radii = field.radii(units, d_min)
    counts = len(field.last["craters"]), len(field.rocks.last["diameter_m"])
    faces = grid.triangles()
    return units * radii[:, None], faces, counts, "body", _rock_faces(field, faces)


def _field_of(scene: Scene | CraterField) -> CraterField:
    """The crater field of a scene, or the field itself (e.g. over a DEM, dem.ondemand)."""
    if isinstance(scene, Scene):
        return crater_field(scene)
    if isinstance(scene, CraterField):
        return scene
    raise TypeError(f"`scene` must be a latlong.Scene or a CraterField; got "
                    f"{type(scene).__name__}")


def descent(scene: Scene | CraterField, lat_deg: float, lon_deg: float, altitudes_m, *,
            fov_deg: float = 30.0, width_px: int = 512, sun_azimuth_deg: float = 90.0,
            sun_elevation_deg: float = 25.0, reflectance=None,
            lidar: LidarSettings | None = None, lidar_seed: int = 0,
            bright_ejecta: float = 0.5, mottling: float = 0.05,
            microrelief_deg: float = MICRORELIEF_DEG,
            microrelief_hurst: float = MICRORELIEF_HURST,
            bounces: int = 0) -> Iterator[DescentFrame]:
    """Frames of a vertical descent over (lat, lon) at ``altitudes_m`` (module notes) of a
    scene, or of a crater field (any base, e.g. a DEM's), square pictures ``width_px``
    wide, the sun at ``sun_azimuth_deg`` (clockwise from north) and ``sun_elevation_deg``
    above the site's horizon; with ``lidar`` also that LIDAR's returns per frame, range
    noise keyed by (``lidar_seed``, frame); ``bright_ejecta`` and ``mottling`` the albedo's
    contrasts; ``microrelief_deg`` the RMS tilt at a 1 m pixel of the relief below each
    frame's stamped craters, shown as shading (``latlong.sensors.regolith_normals``; 0:
    none), ``microrelief_hurst`` its Hurst exponent: the tilt at a pixel p metres wide is
    ``atan(tan(microrelief_deg) p^(H - 1))`` (module notes); ``bounces`` 1 or 2 lights
    the shadows with the light the terrain sends itself (the camera's defaults of
    :class:`~latlong.sensors.CameraSettings`: 8 rays a pixel smoothed over 8 pixels, new
    rays in each frame; 0, the default: the sun's direct light only, ~2.5 s less a
    1024^2 frame: 2.7-3.9 s against 5.4-6.6 s on 2026-12-08)."""
    from ..sensors import Camera, LidarSettings, Pose, lidar_frame, render
    from ..sensors.camera_files import frame_seed
    from ..sensors.engine import RayMesh
    from ..sensors.lidar_files import body_fixed_wkt
    from ..sensors.scene_geometry import SceneGeometry

    field = _field_of(scene)
    check_range("fov_deg", fov_deg, 1.0, 120.0)
    width_px = check_int("width_px", width_px, 16, 8192)
    bounces = check_int("bounces", bounces, 0, 2)
    check_descent_memory(width_px)
    shading = _Shading.checked(field.base.seed, bright_ejecta, mottling, microrelief_deg,
                               microrelief_hurst)
    alts = np.asarray(altitudes_m, dtype=np.float64).ravel()
    if not len(alts) or not (np.isfinite(alts).all() and (alts > 0).all()):
        raise ParameterError("altitudes_m", "must be positive numbers")
    u0 = units_of([lat_deg], [lon_deg])
    east, north = (a[0] for a in tangent_frame(u0))
    up = u0[0]
    site_radius = float(field.base.radius(u0)[0])
    az, el = math.radians(sun_azimuth_deg), math.radians(sun_elevation_deg)
    sun = (math.cos(el) * (math.sin(az) * east + math.cos(az) * north) + math.sin(el) * up)
    camera = Camera.from_fov(fov_deg, width_px, width_px)
    tan_half = math.tan(math.radians(fov_deg) / 2.0)
    if lidar is not None:
        if not isinstance(lidar, LidarSettings):
            raise TypeError(f"`lidar` must be LidarSettings; got {type(lidar).__name__}")
        _check_lidar_inside(lidar, fov_deg)
        lidar_seed = check_int("lidar_seed", lidar_seed, 0, 2**63 - 1)
    crs_wkt = body_fixed_wkt("craterform body", field.base.radius_m)  # the LAS files' CRS
    for i, h in enumerate(alts):
        footprint = 2.0 * h * tan_half
        pixel = footprint / width_px
        verts, faces, counts, kind, (face_rock, rocks) = _terrain(
            field, lat_deg, lon_deg, DESCENT_MARGIN * footprint, pixel, site_radius)
        catalog = field.last_catalog()  # the terrain's craters (oldest first)
        catalog = catalog[catalog["slope_factor"] > 0]  # those erased by slope show nothing
        # the altitude is above the terrain at the site as this frame's terrain has it
        ground = up * float(field.radii(u0, 3.0 * pixel)[0])
        pose = Pose.look_at(ground + h * up, ground, up=north)
        # one frame per mesh: Embree's quick build pays (a medium BVH costs more than
        # the rays it saves on one frame)
        mesh = RayMesh(verts, faces, build_quality="low")
        truth = SceneGeometry(verts, faces, face_rock, craters=catalog, boulders=rocks,
                              source="terrain on demand")
        albedo, normals = shading.of(truth, mesh, pixel)
        frame = render(mesh, camera, pose, sun, reflectance=reflectance, ground_truth=truth,
                       vertex_albedo=albedo, normals=normals, bounces=bounces,
                       seed=frame_seed(shading.seed, i))
        returns = None if lidar is None else lidar_frame(
            mesh, lidar, pose.position_m, pose.quaternion_wxyz,
            rng=np.random.default_rng([lidar_seed, i]), ground_truth=truth)
        n_craters, n_rocks = counts
        yield DescentFrame(float(h), pixel, frame, int(n_craters), int(n_rocks), kind,
                           catalog, returns, crs_wkt, rocks)


@dataclasses.dataclass(frozen=True)
class _Shading:
    """What a descent frame's pictures show beyond the terrain's geometry (module notes):
    the albedo (bright ejecta times mottling) and the normals (the relief below the
    pixels)."""

    seed: int
    bright_ejecta: float
    mottling: float
    microrelief_deg: float
    microrelief_hurst: float

    @classmethod
    def checked(cls, seed: int, bright_ejecta: float, mottling: float,
                microrelief_deg: float, microrelief_hurst: float) -> _Shading:
        return cls(seed, check_range("bright_ejecta", bright_ejecta, 0.0, 10.0),
                   check_range("mottling", mottling, 0.0, 2.0),
                   check_range("microrelief_deg", microrelief_deg, 0.0, 45.0),
                   check_range("microrelief_hurst", microrelief_hurst, 0.0, 1.0))

    def of(self, truth, mesh, pixel_m: float):
        """(vertex albedo, vertex normals or "smooth") of a frame's terrain ``truth`` (a
        SceneGeometry) and its ray mesh, ``pixel_m`` on the ground."""
        from ..sensors import ejecta_albedo, regolith_albedo, regolith_normals

        albedo = ejecta_albedo(truth, contrast=self.bright_ejecta) * regolith_albedo(
            truth.vertices, seed=self.seed, contrast=self.mottling, pixel_m=pixel_m)
        if self.microrelief_deg <= 0.0:
            return albedo, "smooth"
        return albedo, regolith_normals(truth.vertices, mesh.vertex_normals, seed=self.seed,
                                        pixel_m=pixel_m, tilt_1m_deg=self.microrelief_deg,
                                        hurst=self.microrelief_hurst)


def _check_lidar_inside(lidar: LidarSettings, fov_deg: float) -> None:
    """Refuse a LIDAR whose beams (with their divergence) leave the frames' terrain window
    (``DESCENT_MARGIN`` camera footprints wide): they would see its edge, not the ground."""
    from ..sensors import beam_pattern

    axes, _ = beam_pattern(lidar)
    half = np.arctan(np.max(np.abs(axes[:, :2]), axis=1) / axes[:, 2]).max() \
        + 0.5e-3 * lidar.divergence_mrad
    limit = math.atan(DESCENT_MARGIN * math.tan(math.radians(fov_deg) / 2.0))
    if not (axes[:, 2] > 0).all() or half > limit:
        raise ParameterError("lidar", f"beams must stay within {math.degrees(limit):.4g} deg "
                             f"of the axis (the terrain window: {DESCENT_MARGIN} x the camera's "
                             f"footprint at {{}} {fov_deg:g}); the LIDAR's reach "
                             f"{math.degrees(half):.4g} deg", see=("fov_deg",))


def display(reflectance: np.ndarray, scale: float) -> np.ndarray:
    """An 8-bit picture of an I/F image: ``scale`` to white, gamma 1/2.2."""
    return (255.0 * np.clip(reflectance / scale, 0.0, 1.0) ** (1.0 / 2.2) + 0.5).astype(np.uint8)


def write_descent(frames, out, *, seed, site_lat_lon_deg, report=None, lidar=None,
                  lidar_seed=None, bounces: int = 0) -> int:
    """Write the :class:`DescentFrame` s of ``frames`` (an iterable, e.g. :func:`descent`)
    into the new folder ``out`` (written whole or not at all,
    :func:`latlong.sensors.runs.run_folder`): per frame the camera's files (image, depth,
    range, normals, the crater-id and boulder-id label images), the craters that show in
    the frame's terrain ``craters_NNNN.csv`` (row = label id), its rocks that show
    ``rocks_NNNN.csv`` (row = boulder label id; when there are any) and an 8-bit
    ``picture_NNNN.png`` exposed on its own lit pixels (the 99.5th percentile to white, as
    a descent camera's auto-exposure would);
    ``strip.png`` puts the pictures side by side; ``frames.json`` the intrinsics and per
    frame the altitude, ground pixel, exposure, terrain, craters, rocks, pose, sun and
    files; frames with LIDAR returns add ``lidar_NNNN.las`` (LAS 1.4 unless the settings
    say 1.2, ``.laz`` with ``laz``; crater labels as extra bytes) and
    ``lidar_range_NNNN.npy`` (first-return range image), and the manifest the LIDAR's
    settings ``lidar`` and ``lidar_seed``; ``bounces``, the frames' (:func:`descent`), is
    recorded in the manifest. ``report(i, frame)`` is
    called as frames are written. Returns the number of frames."""
    from PIL import Image

    from craters._shared import atomic_path
    from craters.catalog import write_catalog

    from ..sensors.camera_files import write_frame, write_manifest
    from ..sensors.lidar_files import las_name, settings_json, write_las
    from ..sensors.runs import run_folder

    entries, pictures = [], []
    f = None
    with run_folder(out, "frames.json") as tmp:
        for i, f in enumerate(frames):
            files = write_frame(tmp, i, f.frame)
            r = f.frame.reflectance
            lit = r[r > 0]
            scale = float(np.percentile(lit, 99.5)) if len(lit) else 1.0
            pic = display(r, scale)
            files["picture"] = f"picture_{i:04d}.png"
            with atomic_path(tmp / files["picture"]) as p:
                Image.fromarray(pic).save(p, format="PNG")
            files["craters"] = f"craters_{i:04d}.csv"
            write_catalog(f.craters, tmp / files["craters"])
            if f.rocks is not None and len(f.rocks):
                files["rocks"] = f"rocks_{i:04d}.csv"
                write_catalog(f.rocks, tmp / files["rocks"])
            pictures.append(pic)
            extra = {}
            if f.lidar is not None:
                files["lidar"] = las_name(f"lidar_{i:04d}", lidar)
                files["lidar_range"] = f"lidar_range_{i:04d}.npy"
                write_las(f.lidar, tmp / files["lidar"], point_source_id=i,
                          crs_wkt=f.crs_wkt or None,
                          version="1.4" if lidar is None else lidar.las_version)
                np.save(tmp / files["lidar_range"], f.lidar.range_image, allow_pickle=False)
                extra["lidar_returns"] = len(f.lidar)
            entries.append({"altitude_m": f.altitude_m, "ground_pixel_m": f.ground_pixel_m,
                            "picture_white_if": scale,
                            "terrain": f.terrain, "craters": f.n_craters, "rocks": f.n_rocks,
                            "position_m": [float(x) for x in f.frame.pose.position_m],
                            "quaternion_wxyz": [float(x) for x in
                                                f.frame.pose.quaternion_wxyz],
                            "sun_direction": [float(x) for x in f.frame.sun.direction],
                            **extra, "files": files})
            if report is not None:
                report(i, f)
        if f is None:
            raise ParameterError("frames", "must hold at least one frame")
        gap = np.zeros((pictures[0].shape[0], 4), np.uint8)
        strip = np.concatenate([x for p in pictures for x in (p, gap)][:-1], axis=1)
        with atomic_path(tmp / "strip.png") as p:
            Image.fromarray(strip).save(p, format="PNG")
        lidar_keys = {} if lidar is None else {"lidar": settings_json(lidar),
                                                "lidar_intrinsics": lidar.intrinsics(),
                                                "lidar_seed": lidar_seed}
        write_manifest(tmp, {"intrinsics": f.frame.camera.intrinsics(), "seed": seed,
                             "bounces": int(bounces),
                             "site_lat_lon_deg": [float(x) for x in site_lat_lon_deg],
                             **lidar_keys, "frames": entries})
    return len(entries)
