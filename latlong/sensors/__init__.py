"""Sensors: a camera and a LIDAR that see any surface through one ray engine.

::

    any surface (latlong.geometry.Surface: a Body, a mesh surface, a mesh file from
        latlong.load_surface, a dem.DemSurface of a DEM or a layer stack)
      -> scene_geometry (SceneGeometry: mesh, boulder ids, catalogs; map catalogs draped)
      -> engine (RayMesh: Embree BVH built once, float64 refinement; shared by every sensor)
      -> camera (intrinsics, Brown-Conrady distortion, Pose, primary rays)
      -> photometry (Lambert, Lommel-Seeliger, lunar-Lambert, Hapke)
      -> render (one frame: shading, cast shadows, ground truth) -> sensor (exposure,
         noise, PSF) -> camera_files (CameraSettings, camera_run: frames + frames.json)
      -> lidar (LidarSettings, lidar_frame: one frame)
         -> lidar_files (lidar_run: LAS 1.4, range images, lidar.json)
      -> labels (crater_labels, boulder_labels, rim_curves, rim_ellipses)
    poses (Poses, read_poses, approach): trajectories; OpenCV sensor frame,
        sensor-to-body unit quaternions w, x, y, z, positions in the body frame (metres)
    runs: output folders written whole (a temporary folder moved into place)

One call per frame, one per run, the same for both sensors and for every surface::

    render(surface, camera, pose, sun)        lidar_frame(surface, settings, position, q)
    camera_run(surface, settings, poses, sun, folder)
                                              lidar_run(surface, settings, poses, folder)

The sensors use only the members of a surface that :mod:`.scene_geometry` names, and
import nothing of ``latlong`` but :mod:`latlong.geometry` and :mod:`latlong.meshio`.
``latlong.render`` is :func:`latlong.sensors.render.render`.
"""

from .albedo import ejecta_albedo
from .camera import Camera, Pose, quaternion_from_matrix, quaternion_to_matrix
from .camera_files import CameraSettings, camera_run
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
from .render import SUN_RADIUS_1AU_DEG, Frame, Sun, camera_inside, render
from .scene_geometry import (
    SceneGeometry,
    drape_catalog,
    ray_scene,
    scene_geometry,
    scene_mesh,
)
from .sensor import Sensor, expose

__all__ = ["BUILD_QUALITIES", "ELLIPSE_DTYPE", "HAPKE_PRESETS", "LIDAR_FORMAT",
           "LIDAR_PATTERNS", "REFLECTANCES", "SUN_RADIUS_1AU_DEG", "Camera", "CameraSettings",
           "Frame", "Hapke", "Hits", "Lambert", "LidarFrame", "LidarSettings",
           "LommelSeeliger", "LunarLambert", "Pose", "Poses", "RayMesh", "SceneGeometry",
           "Sensor", "Sun", "beam_pattern", "boulder_labels", "camera_inside", "camera_run",
           "crater_labels", "drape_catalog", "ejecta_albedo", "expose", "lidar_frame",
           "lidar_run", "quaternion_from_matrix", "quaternion_to_matrix", "radiance_factor",
           "ray_scene", "read_poses", "reflectance_model", "render", "rim_curves",
           "rim_ellipses", "scene_geometry", "scene_mesh", "write_las"]
