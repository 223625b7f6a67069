"""Sensors (issue 17): what a camera or a LIDAR sees of a body or a mesh.

::

    scene_geometry (SceneGeometry: mesh, boulder ids, catalogs)
        -> engine (RayMesh: Embree BVH built once; Hits refined in float64)
        -> lidar (LidarSettings, lidar_frame) -> lidar_files (LAS 1.4, range images,
           lidar.json: lidar_run)
        -> labels (crater_labels, boulder_labels, rim_curves, rim_ellipses)
    poses (Poses, read_poses, rotation_matrix, look_at): OpenCV sensor frame,
        sensor-to-body unit quaternions w, x, y, z, positions in the body frame (metres)
"""

from .engine import Hits, RayMesh
from .labels import ELLIPSE_DTYPE, boulder_labels, crater_labels, rim_curves, rim_ellipses
from .lidar import LIDAR_PATTERNS, LidarFrame, LidarSettings, beam_pattern, lidar_frame
from .lidar_files import LIDAR_FORMAT, lidar_run, write_las
from .poses import Poses, look_at, quaternion_from_matrix, read_poses, rotation_matrix
from .scene_geometry import SceneGeometry, scene_geometry

__all__ = ["ELLIPSE_DTYPE", "LIDAR_FORMAT", "LIDAR_PATTERNS", "Hits", "LidarFrame",
           "LidarSettings", "Poses", "RayMesh", "SceneGeometry", "beam_pattern",
           "boulder_labels", "crater_labels", "lidar_frame", "lidar_run", "look_at",
           "quaternion_from_matrix", "read_poses", "rim_curves", "rim_ellipses",
           "rotation_matrix", "scene_geometry", "write_las"]
