"""Off-screen preview images of a body (pyvista/VTK), lit by a directional sun."""

from __future__ import annotations

import ctypes.util
import math
import os
from pathlib import Path

import numpy as np

from craters._infra import atomic_path, check_finite, check_int

from .body import Body
from .grid import LatLongGrid

__all__ = ["render_preview", "sun_direction"]

#: Bodies above this magnitude are resampled to it for the preview (a picture of
#: 1024 x 768 pixels cannot show more).
PREVIEW_MAX_MAGNITUDE = 600


def _headless_setup() -> None:
    """Prefer EGL off-screen rendering when there is no X display (set before VTK loads)."""
    if os.environ.get("DISPLAY") or os.environ.get("VTK_DEFAULT_OPENGL_WINDOW"):
        return
    if ctypes.util.find_library("EGL"):
        os.environ["VTK_DEFAULT_OPENGL_WINDOW"] = "vtkEGLRenderWindow"
    elif ctypes.util.find_library("OSMesa"):
        os.environ["VTK_DEFAULT_OPENGL_WINDOW"] = "vtkOSOpenGLRenderWindow"


def sun_direction(azimuth_deg: float, elevation_deg: float) -> np.ndarray:
    """Unit vector towards the sun for the preview camera, which looks along +y.

    Azimuth is measured from the camera (0 = sun behind the viewer, full phase; 90 = sun
    to the right of the picture, +x) and elevation above the body's equator (+z).

    Examples
    --------
    >>> sun_direction(90, 0).round(12).tolist()
    [1.0, 0.0, 0.0]
    """
    az = math.radians(check_finite("sun_azimuth_deg", azimuth_deg))
    el = math.radians(check_finite("sun_elevation_deg", elevation_deg))
    if not -90.0 <= math.degrees(el) <= 90.0:
        raise ValueError(f"`sun_elevation_deg` must be in [-90, 90]; got {elevation_deg!r}")
    toward_camera = np.array([0.0, -1.0, 0.0])
    right = np.array([1.0, 0.0, 0.0])
    up = np.array([0.0, 0.0, 1.0])
    return math.cos(el) * (math.cos(az) * toward_camera + math.sin(az) * right) + math.sin(el) * up


def _preview_body(body: Body) -> Body:
    if body.magnitude <= PREVIEW_MAX_MAGNITUDE:
        return body
    small = LatLongGrid(PREVIEW_MAX_MAGNITUDE)
    radii = body.grid.interpolate(body.radii_m, (np.pi / 2) - small.latitudes(),
                                  small.longitudes())
    return Body(small, radii, radius_m=body.radius_m, stretch=body.stretch)


def render_preview(body: Body, path, *, sun_azimuth_deg: float = 60.0,
                   sun_elevation_deg: float = 20.0, width_px: int = 1024,
                   height_px: int = 768) -> Path:
    """Render ``body`` off-screen to a PNG at ``path`` (atomic).

    The camera looks along +y at the centre of the body's bounding box, framing it; the body
    is grey and lit by one directional light (see :func:`sun_direction`) plus a weak
    ambient term so the night side is not pure black.
    """
    if not isinstance(body, Body):
        raise TypeError(f"`body` must be a Body; got {type(body).__name__}")
    path = Path(path)
    if path.suffix.lower() != ".png":
        raise ValueError(f"preview path must end in .png; got {str(path)!r}")
    width_px = check_int("width_px", width_px, 16, 8192)
    height_px = check_int("height_px", height_px, 16, 8192)
    sun = sun_direction(sun_azimuth_deg, sun_elevation_deg)
    _headless_setup()
    import pyvista as pv

    mesh = _preview_body(body).to_pyvista()
    mesh = mesh.compute_normals(cell_normals=False, point_normals=True, split_vertices=False,
                                consistent_normals=False, auto_orient_normals=False)
    lo, hi = mesh.points.min(axis=0), mesh.points.max(axis=0)
    centre = 0.5 * (lo + hi)
    extent = 0.5 * float(np.linalg.norm(hi - lo))  # radius of the bounding sphere
    plotter = pv.Plotter(off_screen=True, window_size=(width_px, height_px), lighting="none")
    try:
        plotter.set_background("black")
        plotter.add_mesh(mesh, color=(0.78, 0.76, 0.72), smooth_shading=True, ambient=0.04,
                         diffuse=1.0, specular=0.0, show_scalar_bar=False)
        light = pv.Light(position=tuple(centre + sun * 10 * extent),
                         focal_point=tuple(centre), light_type="scene light", intensity=1.0)
        light.positional = False
        plotter.add_light(light)
        view_angle = 30.0
        distance = 1.05 * extent / math.tan(math.radians(view_angle / 2))
        plotter.camera_position = [tuple(centre + np.array([0.0, -distance, 0.0])),
                                   tuple(centre), (0.0, 0.0, 1.0)]
        plotter.camera.view_angle = view_angle
        plotter.camera.clipping_range = (distance - 2 * extent, distance + 2 * extent)
        with atomic_path(path) as tmp:
            plotter.screenshot(str(tmp))
    finally:
        plotter.close()
    return path
