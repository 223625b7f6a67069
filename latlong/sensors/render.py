"""Render a frame: primary rays, hits refined in float64, shading, cast shadows, the
sensor, and the per-pixel ground truth.

For each pixel centre the camera's ray (:meth:`Camera.rays`) is cast into the model's
:class:`RayMesh`. At the hit the *geometric* normal is the facet's and the *shading*
normal is the facet's (``normals="face"``) or the barycentric blend of the mesh's
area-weighted vertex normals (``normals="smooth"``, the default: a tessellated smooth
surface is shaded as the surface, not as its facets); both are turned towards the
camera. cos i, cos e, cos g follow from the shading normal, the sun direction and the
ray. A point is lit when its facet faces the sun and a shadow ray (from the point
lifted by ``2e-6`` of the model's bounding radius along the facet normal, above
float32 rounding) reaches the sun unobstructed: cast shadows always. With a sun of
angular radius > 0 and ``soft_shadow_samples`` > 0 the lit fraction is the mean over
samples drawn uniformly over the solar disk (counter-based per pixel and sample, seeded):
penumbrae. I/F (:mod:`.photometry`) x lit fraction x the optional per-vertex albedo
factor gives the ``reflectance`` image; the :class:`Sensor` turns it into the ``image``.

With ``bounces=1`` each seen point also gets the light the surface sends it once:
``bounce_samples`` cosine-weighted rays about its shading normal (counter-based per
pixel and sample), the I/F of the sunlit facet each ray hits seen back along the ray
(the model at that facet, its albedo factor and cast shadow), averaged and times the
point's normal albedo, as a Lambertian surface receives it (exact for Lambert; an
approximation of the second scattering for the other models). With ``bounces=2`` each
of those rays goes on once from the facet it hit (a cosine-weighted ray about the
facet's normal, a second counter stream): the light that facet received once, times
its albedo as a Lambertian surface, is added to what it sends back. A spherical bowl
gets its closed form (every further bounce is the last times albedo x the bowl's share
of the sphere: Ingersoll, Svitek & Murray 1992) within 3 % for one bounce and 4 % for
the second; a crater's shadowed floor Mitsuba 3's path tracer within 3.5 % for one
bounce (``tests/benchmarks/compare_bounce_mitsuba.py``). ``bounce_filter_px`` > 0
smooths the bounced light over that many pixels around each, on the same surface
(:func:`~.light.filter_bounced`: bounced light changes over metres, the noise of a few
rays from pixel to pixel), and fully sunlit pixels then trace a quarter of the rays
(their bounced light is a few per cent of their direct light); a few rays a pixel then
do the work of hundreds. ``render``'s default is the sun's direct light alone
(``bounces=0``); camera runs (:class:`~.camera_files.CameraSettings`, ``latlong
camera``) default to one bounce of 8 rays a pixel (2 in sunlight) smoothed over 8
pixels. The sky sends nothing but,
with ``planet``, a planet's light (:mod:`.planetshine`): shaded and shadowed as the
sun's, scaled by its irradiance ratio.

Ground truth per pixel (NaN / -1 where the ray misses): ``depth_m`` (camera z) and
``range_m`` (distance) as float32, ``position_m`` (body frame, float64), ``normals``
(shading normal, body frame, float32), ``incidence_deg``, ``emission_deg``,
``phase_deg`` (float32), ``face`` (int64 face index), ``sunlit`` (lit fraction).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field, replace

import numpy as np

from craters._shared import ParameterError, check_int

from .camera import Camera, Pose
from .engine import RayMesh
from .labels import boulder_labels, crater_labels
from .light import (
    SUN_RADIUS_1AU_DEG,
    Sun,
    filter_bounced,
    indirect,
    planet_light,
    shade,
    sunlit,
    vertex_albedo_at,
)
from .photometry import Hapke, Lambert, LommelSeeliger, LunarLambert
from .planetshine import Planet
from .scene_geometry import SceneGeometry, traced_model
from .sensor import Sensor, expose, exposure_for

__all__ = ["BOUNCE_FILTER_PX", "BOUNCE_SAMPLES", "SUN_RADIUS_1AU_DEG", "Frame", "Sun",
           "camera_inside", "render"]

#: Bounce rays a pixel and the radius of their smoothing, pixels, unless asked otherwise
#: (:func:`render` and :class:`~.camera_files.CameraSettings` alike).
BOUNCE_SAMPLES = 8
BOUNCE_FILTER_PX = 8



@dataclass(frozen=True, slots=True)
class Frame:
    """One rendered frame and its ground truth (module notes); images are (H, W)."""

    image: np.ndarray
    """The sensor's image: uint16 / uint8 DN or float32 I/F (:class:`Sensor`); (H, W,
    bands) for a multi-band camera."""
    reflectance: np.ndarray
    """float64 I/F with shadows, before the sensor (0 in shadow and on the sky); (H, W,
    bands) for a multi-band camera."""
    depth_m: np.ndarray
    """float32 distance along the optical axis (camera z), metres; NaN on the sky."""
    range_m: np.ndarray
    """float32 distance from the camera centre, metres; NaN on the sky."""
    position_m: np.ndarray
    """(H, W, 3) float64 surface point, body frame, metres; NaN on the sky."""
    normals: np.ndarray
    """(H, W, 3) float32 unit shading normal (towards the camera), body frame."""
    incidence_deg: np.ndarray
    """float32 incidence angle (shading normal to the sun), degrees."""
    emission_deg: np.ndarray
    """float32 emission angle (shading normal to the camera), degrees."""
    phase_deg: np.ndarray
    """float32 phase angle (sun - surface - camera), degrees."""
    face: np.ndarray
    """int64 index of the face seen; -1 on the sky."""
    sunlit: np.ndarray
    """float32 lit fraction of the solar disk seen from the point, [0, 1]."""
    camera: Camera = field(repr=False)
    """The camera."""
    pose: Pose = field(repr=False)
    """The camera's pose."""
    sun: Sun = field(repr=False)
    """The light."""
    crater_id: np.ndarray | None = None
    """int32 catalog row of the crater whose rim contains the surface point seen, -1 for
    none (:func:`~latlong.sensors.labels.crater_labels`); None without ``ground_truth``."""
    boulder_id: np.ndarray | None = None
    """int32 boulder catalog row of the boulder seen, -1 for none; None without
    ``ground_truth``."""
    exposure_s: float = float("nan")
    """The exposure the sensor took, seconds (auto-exposure's choice, or its own)."""
    albedo: np.ndarray | None = None
    """float32 albedo seen: the reflectance model's normal albedo (1 for Hapke) times the
    per-vertex factor; NaN on the sky; (H, W, bands) for a multi-band camera."""
    bands: tuple[str, ...] = ()
    """The names of a multi-band camera's bands, in the order of the last axis of
    ``image``, ``reflectance`` and ``albedo`` (empty: one band, (H, W) images)."""


def camera_inside(mesh: RayMesh, position_m) -> bool:
    """True when a point is inside a closed model (or under an open surface): the first
    hits of rays along the six axes and eight diagonals all see the back of a facet."""
    dirs = np.concatenate([np.eye(3), -np.eye(3),
                           np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1)
                                     for z in (-1, 1)], dtype=np.float64)])
    hits = mesh.intersect(np.asarray(position_m, dtype=np.float64), dirs)
    if not hits.hit.any():
        return False
    n = mesh.face_normals[hits.face[hits.hit]]
    return bool((np.einsum("ij,ij->i", n, dirs[hits.hit]) > 0).all())


def _photometry(reflectance):
    if reflectance is None:
        return LommelSeeliger()
    if not isinstance(reflectance, Lambert | LommelSeeliger | LunarLambert | Hapke):
        raise TypeError("`reflectance` must be a reflectance model (latlong.sensors."
                        f"photometry); got {type(reflectance).__name__}")
    return reflectance


def band_name_ok(name: str) -> bool:
    """A band's name is letters, digits, ``-`` and ``_`` (a file's band description, an
    EXR channel, a TOML value)."""
    return bool(name) and name.replace("_", "").replace("-", "").isalnum()


def _models(reflectance, bands) -> tuple[list, tuple[str, ...]]:
    """(the reflectance model of each band, the band names: () for one band)."""
    if bands is None:
        return [_photometry(reflectance)], ()
    if reflectance is not None:
        raise ParameterError("bands", "give `reflectance` or `bands` (a model per band), "
                             "not both")
    if not isinstance(bands, Mapping) or not 1 <= len(bands) <= 64:
        raise ParameterError("bands", "must map 1 to 64 band names to reflectance models")
    names = tuple(str(k) for k in bands)
    if not all(map(band_name_ok, names)):
        raise ParameterError("bands", f"names must be letters, digits, - and _; got {names}")
    return [_photometry(m) for m in bands.values()], names


def _vertex_normals(mesh: RayMesh, normals):
    """The vertex normals to blend (None: the facets' own)."""
    if isinstance(normals, str):
        if normals not in ("smooth", "face"):
            raise ParameterError("normals", f"must be 'smooth', 'face' or (n, 3) vertex "
                                 f"normals; got {normals!r}")
        return mesh.vertex_normals if normals == "smooth" else None
    n = np.ascontiguousarray(normals, dtype=np.float64)
    if n.shape != mesh.vertices.shape or not np.isfinite(n).all():
        raise ParameterError("normals", f"must be 'smooth', 'face' or {mesh.vertices.shape} "
                             "finite vertex normals")
    return n


def _primary(mesh: RayMesh, camera: Camera, pose: Pose):
    """(origin (1, 3), unit directions (n, 3), hits) of the pixels' rays; a pixel beyond
    the distortion model's fold is cast along the axis and counts as a miss."""
    origin, dirs = camera.rays(pose)
    dirs = dirs.reshape(-1, 3)
    valid = ~np.isnan(dirs[:, 0])
    if not valid.all():
        dirs[~valid] = pose.rotation[:, 2]
    origin = origin.reshape(1, 3)
    hits = mesh.intersect(origin, dirs)
    if not valid.all():
        hits.face[~valid] = -1
    return origin, dirs, hits


def render(model, camera: Camera, pose: Pose, sun, *, reflectance=None,
           sensor: Sensor | None = None, normals="smooth", vertex_albedo=None,
           soft_shadow_samples: int = 0, seed: int = 0,
           ground_truth: SceneGeometry | None = None, bounces: int = 0,
           bounce_samples: int = BOUNCE_SAMPLES, bounce_filter_px: int = BOUNCE_FILTER_PX,
           planet: Planet | None = None, bands: Mapping[str, object] | None = None) -> Frame:
    """Render one frame of ``model`` seen by ``camera`` at ``pose``, lit by ``sun`` (a
    :class:`Sun` or a direction towards it). See the module notes.

    ``model`` is any surface (a body, a mesh surface or file, a DEM site) or its
    :class:`SceneGeometry`, whose catalogs then label the frame; or, for many frames, its
    :class:`RayMesh` built once (:func:`~latlong.sensors.scene_geometry.ray_scene`) and
    shared, with ``ground_truth`` (the :class:`SceneGeometry` the mesh was built from:
    same triangles, with its catalogs) for the labels. ``reflectance`` defaults to
    Lommel–Seeliger with normal albedo 0.12; ``sensor`` to :class:`Sensor` ();
    ``normals`` is ``"smooth"``, ``"face"`` or an (n, 3) array of vertex normals to blend
    (e.g. a sphere's exact radial directions); ``vertex_albedo`` an optional (n,) factor
    per vertex; ``seed`` keys the sun-disk samples and the sensor noise. With ground
    truth the frame has the crater-id and boulder-id label images. ``bounces``,
    ``bounce_samples``, ``bounce_filter_px``: light bounced between surfaces (module
    notes; 0 here, 1 in camera runs). ``planet`` adds a
    :class:`~latlong.sensors.planetshine.Planet`'s light (its disk sampled like the sun's
    with ``soft_shadow_samples``). ``bands`` (instead of ``reflectance``) makes a
    multi-band camera: {name: reflectance model} in band order; the rays are shared, one
    exposure is taken for all bands (the shutter is one) and the sensor noise differs
    between them.
    """
    from ._render_kernels import _ground_truth_kernel, _surface_kernel  # numba loads here
    if not isinstance(camera, Camera):
        raise TypeError(f"`camera` must be a Camera; got {type(camera).__name__}")
    if not isinstance(pose, Pose):
        raise TypeError(f"`pose` must be a Pose; got {type(pose).__name__}")
    sun = sun if isinstance(sun, Sun) else Sun(sun)
    models, names = _models(reflectance, bands)
    sensor = Sensor() if sensor is None else sensor
    if not isinstance(sensor, Sensor):
        raise TypeError(f"`sensor` must be a Sensor; got {type(sensor).__name__}")
    if planet is not None and not isinstance(planet, Planet):
        raise TypeError(f"`planet` must be a Planet; got {type(planet).__name__}")
    samples = check_int("soft_shadow_samples", soft_shadow_samples, 0, 1024)
    light = {"bounces": check_int("bounces", bounces, 0, 2),
             "bounce_samples": check_int("bounce_samples", bounce_samples, 1, 4096),
             "bounce_filter_px": check_int("bounce_filter_px", bounce_filter_px, 0, 64),
             "seed": check_int("seed", seed, 0, 2**63 - 1), "planet": planet,
             "planet_samples": samples, "vertex_albedo": vertex_albedo}
    mesh, ground_truth = traced_model(model, ground_truth)
    h, w = camera.height, camera.width
    origin, dirs, hits = _primary(mesh, camera, pose)
    face = hits.face
    n = len(face)
    pos, ng, ns, cosines = (np.empty((n, 3)) for _ in range(4))
    facing = np.empty(n, dtype=np.bool_)
    vnormals = _vertex_normals(mesh, normals)
    _surface_kernel(origin, dirs, hits.t_m, face, hits.u, hits.v, mesh.vertices,
                    mesh.faces, np.zeros((1, 3)) if vnormals is None else vnormals,
                    vnormals is not None, sun.direction, pos, ng, ns, cosines, facing)
    lit = sunlit(mesh, pos, ng, facing, sun,
                 samples if sun.angular_radius_deg > 0.0 else 0, light["seed"])
    albedo = vertex_albedo_at(mesh, vertex_albedo, hits)
    refl = _reflectance(mesh, models, (origin, dirs, hits, vnormals), (pos, ng, ns, cosines),
                        lit, albedo, sun, image_shape=(h, w), **light)
    shape = (h, w) if not names else (h, w, len(names))
    refl = refl[:, 0].reshape(h, w) if not names else refl.reshape(shape)
    depth, rng_m, lit32 = (np.empty(n, dtype=np.float32) for _ in range(3))
    angles, normals32 = (np.empty((n, 3), dtype=np.float32) for _ in range(2))
    _ground_truth_kernel(hits.t_m, face, dirs, np.ascontiguousarray(pose.rotation[:, 2]),
                         cosines, ns, lit, depth, rng_m, angles, normals32, lit32)
    exposure = exposure_for(refl, sensor)
    seen = np.stack([np.where(face >= 0, albedo * getattr(m, "albedo", 1.0), np.nan)
                     for m in models], axis=-1)
    return Frame(image=expose(refl, replace(sensor, exposure_s=exposure), seed=light["seed"]),
                 reflectance=refl, exposure_s=exposure, bands=names,
                 albedo=seen.astype(np.float32).reshape(shape),
                 depth_m=depth.reshape(h, w), range_m=rng_m.reshape(h, w),
                 position_m=pos.reshape(h, w, 3), normals=normals32.reshape(h, w, 3),
                 incidence_deg=angles[:, 0].reshape(h, w),
                 emission_deg=angles[:, 1].reshape(h, w),
                 phase_deg=angles[:, 2].reshape(h, w), face=face.reshape(h, w),
                 sunlit=lit32.reshape(h, w), camera=camera, pose=pose, sun=sun,
                 **_labels(ground_truth, pos, face, h, w))


def _reflectance(mesh: RayMesh, models, rays, surface, lit, albedo, sun: Sun, *,
                 bounces: int, bounce_samples: int, bounce_filter_px: int, seed: int,
                 planet: Planet | None, planet_samples: int, vertex_albedo,
                 image_shape: tuple[int, int]) -> np.ndarray:
    """(n, bands) I/F of the pixels: the sun's light, bounced light and planetshine."""
    origin, dirs, hits, vnormals = rays
    pos, ng, ns, cosines = surface
    refl = shade(models, cosines, lit, albedo)
    if bounces:
        seen = hits.face >= 0
        smooth = None
        if bounce_filter_px:
            def smooth(received, rays):
                return filter_bounced(received, seen.reshape(image_shape),
                                      pos.reshape(*image_shape, 3),
                                      ns.reshape(*image_shape, 3), bounce_filter_px, rays)
        refl[seen] += indirect(mesh, models, pos[seen], ng[seen], ns[seen], albedo[seen],
                               vertex_albedo, sun, bounce_samples, seed, bounces,
                               smooth=smooth, sunlit_full=lit[seen] >= 1.0)
    if planet is not None:
        refl += planet_light(mesh, models, origin, dirs, hits, vnormals, planet, sun, albedo,
                             planet_samples, seed)
    return refl


def _labels(geometry: SceneGeometry | None, pos, face, h: int, w: int) -> dict:
    """The crater-id and boulder-id images of the points seen (none without catalogs)."""
    if geometry is None:
        return {}
    boulder = boulder_labels(face, geometry.face_boulder_id).astype(np.int32)
    crater = np.full(len(face), -1, dtype=np.int32)
    if geometry.craters is not None and len(geometry.craters):
        rows = np.flatnonzero(face >= 0)  # a boulder inside a rim carries both ids
        crater[rows] = crater_labels(pos[rows], geometry.craters)
    return {"crater_id": crater.reshape(h, w), "boulder_id": boulder.reshape(h, w)}
