"""Sensors: a camera (and a LIDAR) that see a body or any mesh through one ray engine.

::

    engine (RayMesh: Embree BVH, float64 refinement; shared by every sensor)
      -> camera (intrinsics, Brown-Conrady distortion, poses, primary rays)
      -> photometry (Lambert, Lommel-Seeliger, lunar-Lambert, Hapke)
      -> render (shading, cast shadows, sensor model, ground truth)
"""

from .camera import Camera, Pose, quaternion_from_matrix, quaternion_to_matrix
from .engine import BUILD_QUALITIES, Hits, RayMesh

__all__ = ["BUILD_QUALITIES", "Camera", "Hits", "Pose", "RayMesh", "quaternion_from_matrix",
           "quaternion_to_matrix"]
