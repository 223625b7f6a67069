"""Sensors: a camera and a LIDAR that see a body or any mesh through one ray engine.

::

    scene_geometry (SceneGeometry: mesh, boulder ids, catalogs)
      -> engine (RayMesh: Embree BVH built once, float64 refinement; shared by every sensor)
      -> camera (intrinsics, Brown-Conrady distortion, Pose, primary rays)
      -> photometry (Lambert, Lommel-Seeliger, lunar-Lambert, Hapke)
      -> render (shading, cast shadows, ground truth) -> sensor (exposure, noise, PSF)
      -> lidar (LidarSettings, lidar_frame) -> lidar_files (LAS 1.4, range images, lidar.json)
      -> labels (crater_labels, boulder_labels, rim_curves, rim_ellipses)
    poses (Poses, read_poses): trajectories; OpenCV sensor frame, sensor-to-body unit
        quaternions w, x, y, z, positions in the body frame (metres)

``latlong.render`` is :func:`latlong.sensors.render.render`.
"""

from .albedo import ejecta_albedo
from .camera import Camera, Pose, quaternion_from_matrix, quaternion_to_matrix
from .engine import BUILD_QUALITIES, Hits, RayMesh
from .labels import ELLIPSE_DTYPE, boulder_labels, crater_labels, rim_curves, rim_ellipses
from .lidar import LIDAR_PATTERNS, LidarFrame, LidarSettings, beam_pattern, lidar_frame
from .lidar_files import LIDAR_FORMAT, lidar_run, write_las
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
from .poses import Poses, read_poses
from .render import SUN_RADIUS_1AU_DEG, Frame, Sun, camera_inside, render, scene_mesh
from .scene_geometry import SceneGeometry, scene_geometry
from .sensor import Sensor, expose

__all__ = ["BUILD_QUALITIES", "ELLIPSE_DTYPE", "HAPKE_PRESETS", "LIDAR_FORMAT",
           "LIDAR_PATTERNS", "REFLECTANCES", "SUN_RADIUS_1AU_DEG", "Camera", "Frame", "Hapke",
           "Hits", "Lambert", "LidarFrame", "LidarSettings", "LommelSeeliger", "LunarLambert",
           "Pose", "Poses", "RayMesh", "SceneGeometry", "Sensor", "Sun", "beam_pattern",
           "boulder_labels", "camera_inside", "crater_labels", "ejecta_albedo", "expose",
           "lidar_frame",
           "lidar_run", "quaternion_from_matrix", "quaternion_to_matrix", "radiance_factor",
           "read_poses", "reflectance_model", "render", "rim_curves", "rim_ellipses",
           "scene_geometry", "scene_mesh", "write_las"]
