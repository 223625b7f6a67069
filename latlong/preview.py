"""Quick pictures of a body: Lambertian shading, one directional sun, cast shadows.

Rendered by the sensors' ray engine (:func:`latlong.sensors.render`, Embree): every
pixel's ray finds the surface, a shadow ray towards the sun decides whether it is lit,
and the grey surface (0.78, 0.76, 0.72) takes ``0.03 + cos(incidence)`` where lit and
0.03 in shadow (smooth shading normals), black sky.

The camera looks at the centre of the body's bounding box from the direction
(``view_lat_deg``, ``view_lon_deg``) in the body-fixed frame, at ``camera_distance_m``
(default: the body's silhouette fills the picture with a small margin). The sun is
given relative to the camera: azimuth 0 = behind the viewer (full phase), 90 = from
the right of the picture; elevation above the picture's horizontal plane. ``views=6``
writes a contact sheet of six views along +x, -x, +y, -y, +z, -z with the same sun geometry.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from craters._shared import ParameterError, atomic_path, check_finite
from craters._shared.settings import check_declared, setting

from .geometry.surface import Resamplable, Surface

__all__ = ["PreviewSettings", "VIEW_DIRECTIONS", "camera_frame", "preview_view",
           "render_preview", "sun_direction"]

#: Bodies above this magnitude are resampled to it for pictures (a picture of a few
#: thousand pixels cannot show more, and the renderer's memory stays bounded).
PREVIEW_MAX_MAGNITUDE = 1000
#: The vertices of that grid: surfaces that can resample themselves
#: (:class:`~latlong.geometry.surface.Resamplable`) are resampled to at most these.
PREVIEW_MAX_VERTICES = 6 * PREVIEW_MAX_MAGNITUDE**2 + 2
#: The six views of a contact sheet: (label, view latitude, view longitude) in degrees.
VIEW_DIRECTIONS = (("+x", 0.0, 0.0), ("-x", 0.0, 180.0), ("+y", 0.0, 90.0),
                   ("-y", 0.0, -90.0), ("+z", 90.0, 0.0), ("-z", -90.0, 0.0))


@dataclass(frozen=True, slots=True)
class PreviewSettings:
    """Camera, sun and size of a preview picture (module notes)."""

    sun_azimuth_deg: float = setting(
        60.0, "sun azimuth from the viewer (0 = behind the camera, 90 = from the right)",
        unit="deg", range="finite")
    """Sun azimuth from the viewer, degrees (0 = behind the camera, 90 = from the right)."""
    sun_elevation_deg: float = setting(
        20.0, "sun elevation above the picture's horizontal plane", unit="deg",
        range=(-90.0, 90.0))
    """Sun elevation above the picture's horizontal plane, degrees, [-90, 90]."""
    view_lon_deg: float = setting(-90.0, "longitude of the camera direction (body-fixed)",
                                  unit="deg", range="finite")
    """Longitude of the camera direction (body-fixed), degrees."""
    view_lat_deg: float = setting(0.0, "latitude of the camera direction", unit="deg",
                                  range=(-90.0, 90.0))
    """Latitude of the camera direction, degrees, [-90, 90]."""
    camera_distance_m: float | None = setting(
        None, "camera distance from the body centre", unit="m", range=">0",
        default_text="frame the body")
    """Camera distance from the body centre, metres (default: frame the body)."""
    width_px: int = setting(1024, "picture width", unit="px", range=(16, 8192))
    """Picture width, pixels, [16, 8192]."""
    height_px: int = setting(768, "picture height", unit="px", range=(16, 8192))
    """Picture height, pixels, [16, 8192]."""
    views: int = setting(1, "1 = one view; 6 = a contact sheet from +x, -x, +y, -y, +z, -z",
                         range=(1, 6))
    """1 = one view; 6 = a contact sheet from +x, -x, +y, -y, +z, -z."""

    def __post_init__(self):
        check_declared(self)
        if self.views not in (1, 6):
            raise ParameterError("views", f"must be 1 or 6; got {self.views}")


def camera_frame(view_lat_deg: float = 0.0, view_lon_deg: float = -90.0):
    """(toward_camera, right, up) unit vectors for a camera in direction (lat, lon).

    Examples
    --------
    >>> [v.round(12).tolist() for v in camera_frame(0.0, -90.0)]
    [[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]
    """
    la = math.radians(check_finite("view_lat_deg", view_lat_deg))
    lo = math.radians(check_finite("view_lon_deg", view_lon_deg))
    v = np.array([math.cos(la) * math.cos(lo), math.cos(la) * math.sin(lo), math.sin(la)])
    ref = np.array([0.0, 0.0, 1.0]) if abs(v[2]) < 0.999 else np.array([0.0, 1.0, 0.0])
    right = np.cross(ref, v)
    right /= np.linalg.norm(right)
    up = np.cross(v, right)
    return v, right, up


def sun_direction(azimuth_deg: float, elevation_deg: float, view_lat_deg: float = 0.0,
                  view_lon_deg: float = -90.0) -> np.ndarray:
    """Unit vector towards the sun, given relative to the camera (module notes).

    Examples
    --------
    >>> sun_direction(90, 0).round(12).tolist()
    [1.0, 0.0, 0.0]
    """
    az = math.radians(check_finite("sun_azimuth_deg", azimuth_deg))
    el_deg = check_finite("sun_elevation_deg", elevation_deg)
    if not -90.0 <= el_deg <= 90.0:
        raise ValueError(f"`sun_elevation_deg` must be in [-90, 90]; got {elevation_deg!r}")
    el = math.radians(el_deg)
    v, right, up = camera_frame(view_lat_deg, view_lon_deg)
    return math.cos(el) * (math.cos(az) * v + math.sin(az) * right) + math.sin(el) * up


#: The preview camera's vertical field of view, degrees.
VIEW_ANGLE_DEG = 30.0
#: The surface colour (RGB in [0, 1]) and the ambient share of the light.
SURFACE_RGB = (0.78, 0.76, 0.72)
AMBIENT = 0.03


def preview_view(vertices, view, width_px: int, height_px: int,
                 camera_distance_m: float | None = None):
    """The preview's camera and pose for ``vertices`` (n, 3) seen along ``view``
    (:func:`camera_frame`): the centre of the bounding box at the centre of the picture
    and, unless ``camera_distance_m`` is given, the silhouette filling it with an 8 %
    margin (vertical field of view :data:`VIEW_ANGLE_DEG`)."""
    from ._preview_kernels import _extent_kernel  # numba loads here
    from .sensors import Camera, Pose

    v, right, up = (np.ascontiguousarray(a, dtype=np.float64) for a in view)
    vertices = np.ascontiguousarray(vertices, dtype=np.float64)
    lo, hi = vertices.min(axis=0), vertices.max(axis=0)
    centre = 0.5 * (lo + hi)
    ext = np.empty(3)
    _extent_kernel(vertices, centre, v, right, up, ext)
    tan_v = math.tan(math.radians(VIEW_ANGLE_DEG / 2))
    tan_h = tan_v * width_px / height_px
    fit = float(ext[0]) + 1.08 * max(float(ext[1]) / tan_h, float(ext[2]) / tan_v)
    distance = camera_distance_m if camera_distance_m else fit
    f = 0.5 * height_px / tan_v
    camera = Camera(f, f, 0.5 * width_px, 0.5 * height_px, width_px, height_px)
    return camera, Pose.look_at(centre + v * distance, centre, up)


def _render(mesh, *, sun, view, width_px, height_px, camera_distance_m) -> np.ndarray:
    from .sensors import Sun, render

    camera, pose = preview_view(mesh.vertices, view, width_px, height_px, camera_distance_m)
    frame = render(mesh, camera, pose, Sun(sun))
    cos_i = np.cos(np.radians(frame.incidence_deg.astype(np.float64)))
    light = np.where(frame.face >= 0, AMBIENT + np.clip(cos_i, 0.0, None) * frame.sunlit, 0.0)
    rgb = np.clip(light[..., None] * np.array(SURFACE_RGB) * 255.0 + 0.5, 0.0, 255.0)
    return rgb.astype(np.uint8)


def _preview_mesh(body):
    """The ray mesh of a surface with its boulders (resampled to at most
    :data:`PREVIEW_MAX_VERTICES` when it can be), a ``pyvista.PolyData`` or a
    ``(vertices, faces)`` pair."""
    from .sensors import RayMesh

    # a preview traces one frame (or six): Embree's fastest (Morton) build pays off, 1.4 s
    # instead of 5.3 s for 12 M triangles here, for about the same frame time
    if isinstance(body, Resamplable):
        body = body.resampled(PREVIEW_MAX_VERTICES)
    if isinstance(body, Surface):
        vertices, faces, _ = body.mesh_source().arrays()
        return RayMesh(vertices, faces, build_quality="low")
    if isinstance(body, tuple) and len(body) == 2:
        return RayMesh(*body, build_quality="low")
    if type(body).__name__ == "PolyData":
        mesh = body.triangulate()
        faces = np.asarray(mesh.faces).reshape(-1, 4)[:, 1:]
        return RayMesh(np.asarray(mesh.points, dtype=np.float64), faces, build_quality="low")
    raise TypeError(f"`body` must be a Body (any Surface), a pyvista.PolyData or (vertices, "
                    f"faces); got {type(body).__name__}")


def render_preview(body, path, settings: PreviewSettings | None = None, **kwargs) -> Path:
    """Render ``body`` (a Body or any :class:`~latlong.geometry.surface.Surface`, a closed
    ``pyvista.PolyData`` mesh or ``(vertices, faces)`` in metres) to a PNG at ``path``
    (atomic); see the module notes. The camera and
    sun are ``settings`` (:class:`PreviewSettings`) or its fields as keyword arguments."""
    if settings is None:
        settings = PreviewSettings(**kwargs)
    elif kwargs:
        settings = dataclasses.replace(settings, **kwargs)
    if not isinstance(settings, PreviewSettings):
        raise TypeError(f"`settings` must be a PreviewSettings; got {type(settings).__name__}")
    sun_azimuth_deg, sun_elevation_deg = settings.sun_azimuth_deg, settings.sun_elevation_deg
    view_lat_deg, view_lon_deg = settings.view_lat_deg, settings.view_lon_deg
    width_px, height_px, views = settings.width_px, settings.height_px, settings.views
    camera_distance_m = settings.camera_distance_m
    path = Path(path)
    if path.suffix.lower() != ".png":
        raise ValueError(f"picture path must end in .png; got {str(path)!r}")
    mesh = _preview_mesh(body)
    if views == 1:
        directions = [("", view_lat_deg, view_lon_deg)]
    else:
        directions = list(VIEW_DIRECTIONS)
    images = []
    for _, la, lo_deg in directions:
        frame = camera_frame(la, lo_deg)
        sun = sun_direction(sun_azimuth_deg, sun_elevation_deg, la, lo_deg)
        images.append(_render(mesh, sun=sun, view=frame, width_px=width_px,
                              height_px=height_px, camera_distance_m=camera_distance_m))
    if views == 1:
        sheet = images[0]
    else:
        sheet = _contact_sheet(images, [d[0] for d in directions])
    from PIL import Image

    with atomic_path(path) as tmp:
        Image.fromarray(sheet).save(tmp, format="PNG")
    return path


def _contact_sheet(images, labels) -> np.ndarray:
    """Six equal RGB pictures in 2 rows of 3, each labelled in its corner."""
    from PIL import Image, ImageDraw

    h, w = images[0].shape[:2]
    sheet = Image.new("RGB", (3 * w, 2 * h))
    for k, (img, label) in enumerate(zip(images, labels, strict=True)):
        tile = Image.fromarray(np.ascontiguousarray(img[..., :3]))
        ImageDraw.Draw(tile).text((8, 6), f"view from {label}", fill=(230, 230, 230))
        sheet.paste(tile, ((k % 3) * w, (k // 3) * h))
    return np.asarray(sheet)
