"""Terrain on demand over a real DEM: the DEM as the base shape of a local crater field
(:mod:`latlong.ondemand`), so that a window around any point, at any pixel size, holds
the DEM's relief plus exactly the craters the scene draws there, the same whichever
window or pixel size asks for them.

:class:`DemBase` gives the radius of the body's sphere plus the DEM's height in any
direction (Catmull-Rom bicubic through the pixel centres, C1; a DEM in a geographic CRS,
longitude and latitude in degrees); :func:`dem_tile` makes a window of it and
:func:`dem_descent` flies a descent over it. Below the DEM's pixel the base is its smooth
interpolant: the craters make the finer relief.

:class:`StackBase` does the same over an enhanced layer stack (:func:`dem.enhance`, its
``manifest.json``): at each point the finest layer that holds it, blended into the next
coarser one over the finer layer's outer :data:`EDGE_PX` pixels (no seam where a layer
ends; the layers of a stack agree where they overlap, so the blend only hides their
interpolants' difference). The stack is the coarse truth, craters and rocks included:
give on-demand layers that continue below what the stack holds.
"""

from __future__ import annotations

import numpy as np

from craters._shared import ParameterError
from latlong import Scene
from latlong.ondemand.base import BaseField, lat_lon_of
from latlong.ondemand.field import CraterField
from latlong.ondemand.tile import Tile, tile_of_field
from latlong.ondemand.window import check_window

from .core import Dem
from .stack import Stack

__all__ = ["EDGE_PX", "DemBase", "StackBase", "dem_descent", "dem_tile"]

#: Pixels of a finer stack layer over which it is blended into the coarser one.
EDGE_PX = 8.0


class DemBase(BaseField):
    """A DEM as the base of a local crater field: radius = the sphere's + the DEM's
    height (module notes)."""

    def __init__(self, dem: Dem, *, seed: int, radius_m: float | None = None):
        if not isinstance(dem, Dem):
            raise TypeError(f"`dem` must be a dem.Dem; got {type(dem).__name__}")
        radius = dem.body_radius_m if radius_m is None else float(radius_m)
        if radius is None:
            raise ParameterError("radius_m", "is needed: the DEM's CRS names no body radius")
        h = np.asarray(dem.heights, dtype=np.float64)
        if not np.isfinite(h).all():
            raise ParameterError("dem", "must have no unknown (NaN) pixels: fill its gaps "
                                 "first (dem fill)")
        _raster_base(self, seed, float(radius), float(radius + h.min()))
        self.dem = dem
        self._h = np.ascontiguousarray(h)
        if dem.crs is not None and not dem.crs.is_geographic:
            raise ParameterError("dem", "must be in a geographic CRS (longitude, latitude in "
                                 "degrees) for terrain on demand; reproject it first (e.g. "
                                 "gdalwarp -t_srs with the body's geographic CRS)")

    def _pixels(self, lat_deg: np.ndarray, lon_deg: np.ndarray):
        """(row, col) fractional pixel-centre coordinates of points."""
        t = self.dem.transform
        lon = t.c + np.mod(lon_deg - t.c, 360.0)  # into the DEM's longitude range
        return (lat_deg - t.f) / t.e - 0.5, (lon - t.c) / t.a - 0.5

    def radius(self, unit) -> np.ndarray:
        return self.radius_at(*lat_lon_of(unit))

    def radius_at(self, lat_deg: np.ndarray, lon_deg: np.ndarray) -> np.ndarray:
        """:meth:`radius` at latitudes and longitudes (degrees)."""
        row, col = self._pixels(lat_deg, lon_deg)
        ny, nx = self._h.shape
        if not ((row >= 0) & (row <= ny - 1) & (col >= 0) & (col <= nx - 1)).all():
            raise ParameterError("lat_deg", "and {} ask for points outside the DEM's pixel "
                                 "centres", see=("lon_deg",))
        i0 = np.minimum(np.floor(row).astype(np.int64), max(ny - 2, 0))
        j0 = np.minimum(np.floor(col).astype(np.int64), max(nx - 2, 0))
        wy = _catmull_rom(row - i0)
        wx = _catmull_rom(col - j0)
        h = self._h
        out = np.zeros(len(row))
        for a in range(4):  # a fixed order of sums: the same bytes for any batch
            ii = np.clip(i0 + a - 1, 0, ny - 1)
            acc = np.zeros(len(row))
            for b in range(4):
                acc += wx[b] * h[ii, np.clip(j0 + b - 1, 0, nx - 1)]
            out += wy[a] * acc
        return self.radius_m + out


class StackBase(BaseField):
    """An enhanced layer stack as the base of a local crater field (module notes)."""

    def __init__(self, stack: Stack, *, seed: int, radius_m: float | None = None):
        if not isinstance(stack, Stack):
            raise TypeError(f"`stack` must be a dem.Stack; got {type(stack).__name__}")
        self.levels = [DemBase(d, seed=seed, radius_m=radius_m) for d in stack.layers]
        _raster_base(self, seed, self.levels[0].radius_m,
                     min(b.min_radius_m for b in self.levels))
        self.dem = stack.layers[0]

    def radius(self, unit) -> np.ndarray:
        lat, lon = lat_lon_of(unit)
        r = self.levels[0].radius_at(lat, lon)  # refuses points outside the coarsest layer
        for level in self.levels[1:]:
            row, col = level._pixels(lat, lon)
            ny, nx = level._h.shape
            edge = np.minimum(np.minimum(row, ny - 1 - row), np.minimum(col, nx - 1 - col))
            t = np.clip(edge / EDGE_PX, 0.0, 1.0)
            w = t * t * (3.0 - 2.0 * t)  # smoothstep: C1 into the coarser layer
            inside = np.flatnonzero(w > 0.0)
            if len(inside):
                r[inside] += w[inside] * (level.radius_at(lat[inside], lon[inside])
                                          - r[inside])
        return r


def _raster_base(base: BaseField, seed: int, radius_m: float, min_radius_m: float) -> None:
    """The :class:`BaseField` state of a raster base: no scene, a sphere of ``radius_m``
    under the raster's heights, radial "up", no stretch, no grid or fBm of a scene."""
    base.scene = None
    base.seed = int(seed)
    base.radius_m = radius_m
    base.min_radius_m = min_radius_m
    base.gravity = False
    base.stretch = np.ones(3)
    base._stretched = False
    base._fbm = None
    base._grid = None
    base._radii = None


def _catmull_rom(t: np.ndarray) -> list[np.ndarray]:
    """The four Catmull-Rom weights of the samples at -1, 0, 1, 2 for fractions ``t``
    (a C1 surface through the pixel centres: no facets at the DEM's pixel)."""
    t2 = t * t
    t3 = t2 * t
    return [0.5 * (-t3 + 2.0 * t2 - t), 0.5 * (3.0 * t3 - 5.0 * t2 + 2.0),
            0.5 * (-3.0 * t3 + 4.0 * t2 + t), 0.5 * (t3 - t2)]


def dem_tile(dem: Dem | Stack, scene: Scene, lat_deg: float, lon_deg: float, *,
             size_m: float, pixel_m: float, min_crater_px: float = 3.0,
             radius_m: float | None = None) -> Tile:
    """A window of the DEM with the scene's craters on demand (module notes): the scene
    gives the crater layers, the body (their shapes) and the seed; the DEM the base."""
    if not isinstance(scene, Scene):
        raise TypeError(f"`scene` must be a latlong.Scene; got {type(scene).__name__}")
    size_px, pixel_m, min_crater_px = check_window(lat_deg, size_m, pixel_m, min_crater_px)
    assert scene.seed is not None  # Scene draws one
    field = _field(dem, scene, radius_m)
    return tile_of_field(field, lat_deg, lon_deg, size_px, pixel_m, min_crater_px)


_FIELDS: list = []


def _field(dem: Dem | Stack, scene: Scene, radius_m) -> CraterField:
    """The crater field of (DEM, scene), made once."""
    for d, s, r, field in _FIELDS:
        if d is dem and s is scene and r == radius_m:
            return field
    assert scene.seed is not None
    base = StackBase(dem, seed=scene.seed, radius_m=radius_m) if isinstance(dem, Stack) \
        else DemBase(dem, seed=scene.seed, radius_m=radius_m)
    field = CraterField(scene, base)
    _FIELDS.insert(0, (dem, scene, radius_m, field))
    del _FIELDS[2:]
    return field


def dem_descent(dem: Dem | Stack, scene: Scene, lat_deg: float, lon_deg: float,
                altitudes_m, *, radius_m: float | None = None, **camera):
    """Frames of a vertical descent over a DEM site with the scene's craters on demand
    (:func:`latlong.ondemand.descent.descent`; ``camera``: its keyword options). Every
    frame's window must lie inside the DEM."""
    from latlong.ondemand.descent import descent

    return descent(_field(dem, scene, radius_m), lat_deg, lon_deg, altitudes_m, **camera)
