"""Sensors: a camera (and a LIDAR) that see a body or any mesh through one ray engine.

::

    engine (RayMesh: Embree BVH, float64 refinement; shared by every sensor)
      -> camera (intrinsics, Brown-Conrady distortion, poses, primary rays)
      -> photometry (Lambert, Lommel-Seeliger, lunar-Lambert, Hapke)
      -> render (shading, cast shadows, ground truth) -> sensor (exposure, noise, PSF)

``latlong.render`` is :func:`latlong.sensors.render.render`.
"""

from .camera import Camera, Pose, quaternion_from_matrix, quaternion_to_matrix
from .engine import BUILD_QUALITIES, Hits, RayMesh
from .photometry import (
    HAPKE_PRESETS,
    REFLECTANCES,
    Hapke,
    Lambert,
    LommelSeeliger,
    LunarLambert,
    radiance_factor,
    reflectance_model,
)
from .render import SUN_RADIUS_1AU_DEG, Frame, Sun, camera_inside, render, scene_mesh
from .sensor import Sensor, expose

__all__ = ["BUILD_QUALITIES", "HAPKE_PRESETS", "REFLECTANCES", "SUN_RADIUS_1AU_DEG", "Camera",
           "Frame", "Hapke", "Hits", "Lambert", "LommelSeeliger", "LunarLambert", "Pose",
           "RayMesh", "Sensor", "Sun", "camera_inside", "expose", "quaternion_from_matrix",
           "quaternion_to_matrix", "radiance_factor", "reflectance_model", "render",
           "scene_mesh"]
