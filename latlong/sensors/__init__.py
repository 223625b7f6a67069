"""Sensors: a camera (and a LIDAR) that see a body or any mesh through one ray engine.

::

    engine (RayMesh: Embree BVH, float64 refinement; shared by every sensor)
      -> camera (intrinsics, Brown-Conrady distortion, poses, primary rays)
      -> photometry (Lambert, Lommel-Seeliger, lunar-Lambert, Hapke)
      -> render (shading, cast shadows, sensor model, ground truth)
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

__all__ = ["BUILD_QUALITIES", "HAPKE_PRESETS", "REFLECTANCES", "Camera", "Hapke", "Hits",
           "Lambert", "LommelSeeliger", "LunarLambert", "Pose", "RayMesh",
           "quaternion_from_matrix", "quaternion_to_matrix", "radiance_factor",
           "reflectance_model"]
