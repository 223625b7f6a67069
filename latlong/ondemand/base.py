"""The base shape of a scene as a function of direction (terrain on demand).

:class:`BaseField` gives the radius of the scene's base (before craters) in any direction,
the same value whatever other directions are asked with it:

* sphere: the radius;
* fBm: the radius plus Perlin fBm evaluated at the point itself (the scene's octaves,
  never the requested resolution); its rotation and offset come from counter words of
  the seed, not from a generator stream;
* faulting and shape models: a fixed base grid (the scene's magnitude, at most
  :data:`MAX_BASE_MAGNITUDE`) interpolated linearly (:meth:`LatLongGrid.interpolate`):
  faults are global and a shape model holds nothing finer than its facets, so both are
  made once per scene and read pointwise; a shape's fBm detail is pointwise.

On a stretched body (axis stretch ``S``) a direction ``w`` of the stretched surface is
the grid direction ``u = S^-1 w / |S^-1 w|`` stretched, so the radius along ``w`` is the
base's radius along ``u`` times ``|S u| = 1 / |S^-1 w|``: everything on demand works in
the surface's own directions, as on any star-shaped body, and a build on the grid asks
for ``w = S u / |S u|`` (:func:`grid_directions`).

It also gives what crater statistics need from the base: the surface area over a solid
angle and the "up" slopes are measured against (radial; the stretched sphere's normal
``S^-2 w`` on a stretched body, as the sequential stamp; or against the self-gravity of
a shape model, from a coarse grid of :func:`latlong.mesh.down_directions`).
"""

from __future__ import annotations

import functools
import math

import numpy as np

from craters.counter import philox4x64, uniform_from_words

from ..faulting import FaultingParams, two_phase_faulting
from ..grid import LatLongGrid
from ..mesh.cratering import down_directions
from ..perlin import FbmParams, fbm3
from ..scene import Scene
from ..settings import ShapeBase, SphereBase
from ..shapes import from_shape_model

__all__ = ["MAX_BASE_MAGNITUDE", "BaseField", "base_field", "grid_catalog", "grid_directions"]

#: Largest magnitude of the base grid of faulting and shape-model bases.
MAX_BASE_MAGNITUDE = 1024
_GRAVITY_MAGNITUDE = 48  # the grid of "up" directions on a shape model
_BASE_KEY = 0x6261736500000000  # "base"


def _rotation_offset(seed: int) -> tuple[np.ndarray, np.ndarray]:
    """A uniformly random rotation (Shoemake's quaternion from three uniforms) and an
    offset in [0, 256)^3 from the counter words of ``seed``."""
    w = uniform_from_words(philox4x64([0, 0, 0, 1], [seed, _BASE_KEY]))[0]
    o = uniform_from_words(philox4x64([0, 0, 0, 2], [seed, _BASE_KEY]))[0]
    u1, u2, u3 = (float(x) for x in w[:3])
    a, b = math.sqrt(1.0 - u1), math.sqrt(u1)
    qw, qx, qy, qz = (a * math.sin(2 * math.pi * u2), a * math.cos(2 * math.pi * u2),
                      b * math.sin(2 * math.pi * u3), b * math.cos(2 * math.pi * u3))
    rot = np.array([
        [1 - 2 * (qy * qy + qz * qz), 2 * (qx * qy - qz * qw), 2 * (qx * qz + qy * qw)],
        [2 * (qx * qy + qz * qw), 1 - 2 * (qx * qx + qz * qz), 2 * (qy * qz - qx * qw)],
        [2 * (qx * qz - qy * qw), 2 * (qy * qz + qx * qw), 1 - 2 * (qx * qx + qy * qy)]])
    return rot, 256.0 * o[:3]


class BaseField:
    """The radius of a scene's base shape in any direction (module notes)."""

    def __init__(self, scene: Scene):
        if not isinstance(scene, Scene):
            raise TypeError(f"`scene` must be a latlong.Scene; got {type(scene).__name__}")
        self.scene: Scene | None = scene
        assert scene.seed is not None  # Scene.__post_init__ draws one when none is given
        self.seed = int(scene.seed)
        base = scene.base
        self._fbm: tuple[float, int, float, float, float] | None = None
        self._grid: LatLongGrid | None = None
        self._radii: np.ndarray | None = None
        self.gravity = isinstance(base, ShapeBase)
        self.stretch = np.asarray(scene.body.stretch, dtype=np.float64)
        self._stretched = bool((self.stretch != 1.0).any())
        rng = np.random.default_rng([self.seed, 1])
        reference = scene.body.radius_m
        if base is None or isinstance(base, SphereBase):
            assert reference is not None  # Scene.__post_init__ sets it for these bases
            self.radius_m = float(reference)
        elif isinstance(base, FbmParams):
            assert reference is not None
            self.radius_m = float(reference)
            assert base.amplitude_m is not None  # Scene sets it from the fraction
            self._fbm = (base.frequency, base.octaves, base.persistence, base.lacunarity,
                         base.amplitude_m)
        elif isinstance(base, FaultingParams):
            assert reference is not None
            self.radius_m = float(reference)
            self._grid = LatLongGrid(min(scene.body.magnitude, MAX_BASE_MAGNITUDE))
            self._radii = self.radius_m + two_phase_faulting(self._grid, self.radius_m, base,
                                                             rng=rng)
        else:
            assert isinstance(base, ShapeBase)
            self._grid = LatLongGrid(min(scene.body.magnitude, MAX_BASE_MAGNITUDE))
            shaped = from_shape_model(base.model, self._grid.magnitude, center=base.center,
                                      crossings=base.crossings, smooth=base.smooth)
            self._radii = np.ascontiguousarray(shaped.radii_m)
            self.radius_m = float(shaped.radius_m)
            if base.detail_amplitude_m:
                assert base.detail_frequency is not None  # ShapeBase sets it
                self._fbm = (base.detail_frequency, base.detail_octaves,
                             base.detail_persistence, base.detail_lacunarity,
                             base.detail_amplitude_m)
        if self._fbm is not None:
            self._rot, self._offset = _rotation_offset(self.seed)
        # the smallest radius bounds every angle a distance on the surface can span
        self.min_radius_m = self.radius_m if self._radii is None else float(self._radii.min())
        if self._fbm is not None:
            self.min_radius_m -= abs(float(self._fbm[4]))
        self.min_radius_m *= float(self.stretch.min())

    def radius(self, unit) -> np.ndarray:
        """Base radius (m) in each direction ``unit`` (n, 3) (unit vectors) of the surface
        (module notes on stretched bodies)."""
        w = np.ascontiguousarray(np.asarray(unit, dtype=np.float64).reshape(-1, 3))
        if not self._stretched:
            return self._grid_radius(w)
        v = w / self.stretch
        nv = np.sqrt(v[:, 0] * v[:, 0] + v[:, 1] * v[:, 1] + v[:, 2] * v[:, 2])
        return self._grid_radius(v / nv[:, None]) / nv

    def _grid_radius(self, u: np.ndarray) -> np.ndarray:
        """The unstretched base's radius along grid directions ``u``."""
        if self._radii is not None:
            assert self._grid is not None
            colat = np.arctan2(np.hypot(u[:, 0], u[:, 1]), u[:, 2])
            lon = np.mod(np.arctan2(u[:, 1], u[:, 0]), 2.0 * np.pi)
            r = self._grid.interpolate(self._radii, colat, lon)
        else:
            r = np.full(len(u), self.radius_m)
        if self._fbm is not None:
            freq, octaves, persistence, lacunarity, amplitude = self._fbm
            # explicit sums, not BLAS: the rounding never depends on the batch
            xs, ys, zs = ((u[:, 0] * self._rot[a, 0] + u[:, 1] * self._rot[a, 1]
                           + u[:, 2] * self._rot[a, 2]) * freq + self._offset[a]
                          for a in range(3))
            r = r + amplitude * fbm3(xs, ys, zs, octaves, persistence, lacunarity)
        return r

    def area_factor(self, unit, step_rad: float) -> np.ndarray:
        """Surface area per steradian (m^2/sr) of the base in each direction: ``r^2 /
        cos(tilt)``, the tilt from central differences ``step_rad`` apart."""
        u = np.asarray(unit, dtype=np.float64).reshape(-1, 3)
        e, n = tangent_frame(u)
        r = self.radius(u)
        s = float(step_rad)
        grads = []
        for t in (e, n):
            rp = self.radius(_normalized(u + s * t))
            rm = self.radius(_normalized(u - s * t))
            grads.append((rp - rm) / (2.0 * s * r))  # d ln r / d angle = tan(tilt) part
        tan2 = grads[0] ** 2 + grads[1] ** 2
        return r * r * np.sqrt(1.0 + tan2)

    @functools.cached_property
    def _up_grid(self):
        grid = LatLongGrid(_GRAVITY_MAGNITUDE)
        radii = self.radius(grid.unit_vectors())
        verts = grid.unit_vectors() * radii[:, None]
        up = -down_directions(verts, grid.triangles(), verts, block=64)
        return grid, [np.ascontiguousarray(up[:, k]) for k in range(3)]

    def up(self, unit) -> np.ndarray:
        """The direction slopes are measured against at each direction: radial, or for a
        shape model against its constant-density self-gravity (interpolated from a
        magnitude-48 grid)."""
        u = np.ascontiguousarray(np.asarray(unit, dtype=np.float64).reshape(-1, 3))
        if not self.gravity:
            if not self._stretched:
                return u.copy()
            g = u / (self.stretch * self.stretch)  # the stretched sphere's normal
            return g / np.sqrt((g * g).sum(axis=1, keepdims=True))
        grid, comps = self._up_grid
        colat = np.arctan2(np.hypot(u[:, 0], u[:, 1]), u[:, 2])
        lon = np.mod(np.arctan2(u[:, 1], u[:, 0]), 2.0 * np.pi)
        g = np.stack([grid.interpolate(c, colat, lon) for c in comps], axis=1)
        return g / np.linalg.norm(g, axis=1, keepdims=True)


def grid_directions(base: BaseField, units: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(surface directions ``w = S u / |S u|``, ``|S u|``) of grid directions ``units``
    on the base's body (``units`` and ones when unstretched): a grid vertex's radius
    ``R(w) / |S u|`` puts it where the stretched body has it."""
    u = np.asarray(units, dtype=np.float64).reshape(-1, 3)
    if not base._stretched:
        return u, np.ones(len(u))
    v = u * base.stretch
    n = np.sqrt(v[:, 0] * v[:, 0] + v[:, 1] * v[:, 1] + v[:, 2] * v[:, 2])
    return v / n[:, None], n


def grid_catalog(base: BaseField, catalog: np.ndarray) -> np.ndarray:
    """``catalog`` with ``lat_deg``/``lon_deg`` of the grid directions ``u = S^-1 w /
    |S^-1 w|`` of its centres (a stretched Body's catalogues, as the sequential stamp's,
    name grid directions); the same array when unstretched."""
    if not base._stretched or not len(catalog):
        return catalog
    lat, lon = np.radians(catalog["lat_deg"]), np.radians(catalog["lon_deg"])
    v = np.stack([np.cos(lat) * np.cos(lon), np.cos(lat) * np.sin(lon), np.sin(lat)],
                 axis=1) / base.stretch
    out = catalog.copy()
    out["lat_deg"] = np.degrees(np.arctan2(v[:, 2], np.hypot(v[:, 0], v[:, 1])))
    out["lon_deg"] = np.degrees(np.arctan2(v[:, 1], v[:, 0]))
    return out


def _normalized(v: np.ndarray) -> np.ndarray:
    return v / np.sqrt((v * v).sum(axis=1, keepdims=True))


def lat_lon_of(units) -> tuple[np.ndarray, np.ndarray]:
    """Latitudes and longitudes (degrees, longitude in [-180, 180]) of directions
    ``units`` (n, 3): the inverse of :func:`latlong.ondemand.units_of`."""
    u = np.asarray(units, dtype=np.float64).reshape(-1, 3)
    return (np.degrees(np.arcsin(np.clip(u[:, 2], -1.0, 1.0))),
            np.degrees(np.arctan2(u[:, 1], u[:, 0])))


def tangent_frame(u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """East and north unit vectors at directions ``u`` (x as east at the poles), by the
    stamping kernel's formulas (east = z x u, north = u x east)."""
    e = np.stack([-u[:, 1], u[:, 0], np.zeros(len(u))], axis=1)
    en = np.sqrt(e[:, 0] ** 2 + e[:, 1] ** 2)
    pole = en < 1e-12
    e[pole] = (1.0, 0.0, 0.0)
    en[pole] = 1.0
    e /= en[:, None]
    n = np.stack([u[:, 1] * e[:, 2] - u[:, 2] * e[:, 1], u[:, 2] * e[:, 0] - u[:, 0] * e[:, 2],
                  u[:, 0] * e[:, 1] - u[:, 1] * e[:, 0]], axis=1)
    return e, n


def per_scene(store: list, scene: Scene, make):
    """``make(scene)`` once per scene (by identity: scenes are frozen, and those holding a
    shape model's arrays cannot be hashed), the last four kept in ``store``."""
    for held, value in store:
        if held is scene:
            return value
    value = make(scene)
    store.insert(0, (scene, value))
    del store[4:]
    return value


_BASE_FIELDS: list = []


def base_field(scene: Scene) -> BaseField:
    """The scene's :class:`BaseField`, made once per scene."""
    return per_scene(_BASE_FIELDS, scene, BaseField)
