r"""Sensors: a camera and a LIDAR that see any surface through one ray engine.

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

From the command line: ``latlong camera`` and ``latlong lidar``
---------------------------------------------------------------
The commands run as written from the repository's folder, in order, into
``out/sensors/`` (``tests/test_readme_commands.py`` runs them at small sizes):

.. code-block:: bash

    mkdir -p out/sensors
    # a crater-saturated asteroid to look at (latlong: Martin 2014 Fig. 8)
    latlong build --preset fbm-cratered --magnitude 400 --seed 1 -o out/sensors/a.npz

    # a 6-frame descent onto it: a straight line 30 deg off the local vertical from 150 m
    # to 25 m range, low sun, Hapke S-type photometry; per frame a 16-bit image, depth and
    # range (float32 .tif), normals, crater-id and boulder-id label images, and
    # frames.json (intrinsics, poses, sun, files, the projected rim ellipses of the
    # craters seen)
    latlong camera out/sensors/a.npz -o out/sensors/descent --target-lat-lon 10,30 \
        --range-m 150,25 --frames 6 --path-angle-deg 30 --fov-deg 40 --size 512x512 \
        --sun-direction=-0.26,0.96,0.05 --reflectance hapke --hapke-preset s-type

    # a scanning LIDAR over the same site: 128 x 96 beams, 1 mrad divergence (4 rays per
    # footprint), 2 cm range noise; LAS 1.4 point clouds (body frame), range images,
    # lidar.json
    latlong lidar out/sensors/a.npz -o out/sensors/scan --target-lat-lon 10,30 \
        --range-m 120,40 --frames 4 --pattern scan --beams 128x96 --fov-deg 30 \
        --divergence-mrad 1 --rays-per-beam 4 --range-noise-m 0.02 --seed 1

Both sensors look at a body ``.npz`` or any mesh file (PLY/OBJ/STL/VTP/GLB: shape models,
``--surface mesh`` bodies, ``dem mesh`` outputs with ``--units``) -- and, as ``dem camera``
and ``dem lidar`` with the same options, at a layer stack or a DEM file (a
``dem.DemSurface``: no mesh file needed, the stack's catalogs label the frames) -- through
one ray engine:
Embree (the ``embreex`` wheel) builds the BVH once per model, every hit is refined in
float64 (ranges exact to ~1e-12 relative), shading and sampling run in numba, and the
same seed gives the same bytes for any thread count. Conventions: OpenCV's camera frame
(x right, y down, z forward), poses as camera-to-body unit quaternions ``w,x,y,z`` plus
the position in the body frame (metres), pixel centres at integer + 0.5. Poses come from
one ``--position-m X,Y,Z --quaternion W,X,Y,Z``, a trajectory file ``--poses FILE`` (CSV
with the header ``time_s,x_m,y_m,z_m,qw,qx,qy,qz``, or TOML ``[[frame]]`` tables), or a
generated approach (``--target-lat-lon`` or ``--target-m``, ``--range-m START,END``
spaced geometrically, ``--frames``, ``--path-angle-deg``, ``--path-azimuth-deg``,
``--duration-s``), or SPICE kernels (``--spice``, :mod:`.spice`: poses, the sun and the
UTC of each frame, as missions deliver them). The camera takes ``--fov-deg`` or
``--intrinsics fx,fy,cx,cy`` with ``--size WxH``, Brown-Conrady ``--distortion`` as
OpenCV defines it, ``--reflectance lambert|lommel-seeliger|lunar-lambert|hapke``
(``--hapke-preset moon|s-type|c-type``), cast shadows always (soft with
``--sun-angular-radius-deg`` and ``--soft-shadow-samples``), and a sensor model
(auto-exposure by default, or ``--exposure-s``; gain, linear 8/16-bit PNG or float TIFF
plus an 8-bit sRGB ``display_NNNN.png`` for people, photon and read noise, PSF; ground
truth as TIFF, NPY or OpenEXR with ``--depth-format``; ``--datasets`` for COCO, COLMAP,
nerfstudio and optical flow, :mod:`.datasets`). In Python, the same for any surface (a
:class:`latlong.Body`, a mesh surface, ``latlong.load_surface(path)``, a
``dem.DemSurface``): :func:`camera_run` (a :class:`CameraSettings`) and :func:`lidar_run`
write a run, :func:`render` and :func:`lidar_frame` make one frame; for many frames of
one model build its ray mesh once with :func:`ray_scene` and pass it with
``ground_truth=geometry``. Previews (``latlong render``, ``--preview``) go through
the same engine and cast shadows. ``python examples/plot_descent_strip.py`` and
``plot_lidar_sweep.py`` draw frames and scans.
"""

from typing import TYPE_CHECKING

from craters._shared.lazy import lazy_package

if TYPE_CHECKING:  # at run time each name is imported on first use (lazy_package)
    from .albedo import ejecta_albedo, regolith_albedo, regolith_normals
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
    from .planetshine import Planet
    from .poses import Poses, read_poses
    from .render import SUN_RADIUS_1AU_DEG, Frame, Sun, camera_inside, render
    from .scene_geometry import (
        SceneGeometry,
        drape_catalog,
        ray_scene,
        scene_geometry,
        scene_mesh,
    )
    from .sensor import Sensor, display_image, expose, exposure_for

__all__ = ["BUILD_QUALITIES", "ELLIPSE_DTYPE", "HAPKE_PRESETS", "LIDAR_FORMAT",
           "LIDAR_PATTERNS", "REFLECTANCES", "SUN_RADIUS_1AU_DEG", "Camera", "CameraSettings",
           "Frame", "Hapke", "Hits", "Lambert", "LidarFrame", "LidarSettings",
           "LommelSeeliger", "LunarLambert", "Planet", "Pose", "Poses", "RayMesh", "SceneGeometry",
           "Sensor", "Sun", "beam_pattern", "boulder_labels", "camera_inside", "camera_run",
           "crater_labels", "display_image", "drape_catalog", "ejecta_albedo", "expose",
           "exposure_for", "lidar_frame",
           "lidar_run", "quaternion_from_matrix", "quaternion_to_matrix", "radiance_factor",
           "ray_scene", "read_poses", "reflectance_model", "regolith_albedo", "regolith_normals",
           "render",
           "rim_curves", "rim_ellipses", "scene_geometry", "scene_mesh", "write_las"]
lazy_package(__name__)
