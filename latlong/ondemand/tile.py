"""Windows of terrain on demand: a square of the surface around a point, sampled on a
regular grid of the gnomonic projection tangent at its centre (PROJ ``+proj=gnom`` on
the sphere of the base shape's radius at the centre), at any pixel size.

A pixel's value is the surface's radius in the direction of its projected point minus
that sphere's radius (metres). The gnomonic projection maps great circles to straight
lines and is exact at the centre; across a window of a few degrees its scale grows by
``1 / cos^2(angle)`` (0.3 % at 3 degrees from the centre).
"""

from __future__ import annotations

import dataclasses
import functools
from pathlib import Path

import numpy as np

from craters._shared import ParameterError, atomic_path

from ..scene import Scene
from . import _cell_kernels
from .base import tangent_frame
from .field import CraterField, crater_field
from .points import units_of
from .window import MAX_TILE_PX, check_window

__all__ = ["MAX_TILE_PX", "Tile", "hillshade", "tile", "tile_mesh", "tile_of_field",
           "write_cog", "write_tile"]


@dataclasses.dataclass(frozen=True)
class Tile:
    """A window of terrain: heights (metres above the reference sphere), rows from north
    to south, columns from west to east, and where it is."""

    heights_m: np.ndarray
    lat_deg: float
    lon_deg: float
    pixel_m: float
    radius_m: float
    """The projection sphere's radius: the base shape's radius at the centre (m)."""
    min_crater_m: float = 0.0
    """The smallest crater diameter drawn (m)."""
    n_craters: int = 0
    """Craters that make the window (with those around it that shape their bases)."""
    n_rocks: int = 0
    """Rocks drawn around the window (:mod:`.rocks`)."""

    @property
    def crs_proj4(self) -> str:
        """The tile's projection as a PROJ string."""
        return (f"+proj=gnom +lat_0={self.lat_deg!r} +lon_0={self.lon_deg!r} "
                f"+R={self.radius_m!r} +units=m +no_defs")

    @property
    def transform(self) -> tuple[float, float, float, float, float, float]:
        """GDAL geotransform (x0, dx, 0, y0, 0, -dy) of the top-left corner."""
        ny, nx = self.heights_m.shape
        return (-0.5 * nx * self.pixel_m, self.pixel_m, 0.0, 0.5 * ny * self.pixel_m, 0.0,
                -self.pixel_m)


def tile_units(lat_deg: float, lon_deg: float, size_px: int, pixel_m: float,
               radius_m: float) -> np.ndarray:
    """Directions (size_px, size_px, 3) of the pixel centres of a gnomonic window."""
    c = units_of([lat_deg], [lon_deg])
    e, n = tangent_frame(c)
    coords = (np.arange(size_px) + 0.5 - 0.5 * size_px) * pixel_m / radius_m
    out = np.empty((size_px, size_px, 3))
    _cell_kernels._window_kernel(c[0], e[0], n[0], coords, out)
    return out


def tile(scene: Scene, lat_deg: float, lon_deg: float, *, size_m: float, pixel_m: float,
         min_crater_px: float = 3.0) -> Tile:
    """The terrain of a square window ``size_m`` wide centred at (lat, lon), pixels of
    ``pixel_m``, with the craters at least ``min_crater_px`` pixels across (module
    notes)."""
    if not isinstance(scene, Scene):
        raise TypeError(f"`scene` must be a latlong.Scene; got {type(scene).__name__}")
    if scene.seed is None:
        raise ParameterError("seed", "is required for terrain on demand")
    size_px, pixel_m, min_crater_px = check_window(lat_deg, size_m, pixel_m, min_crater_px)
    return tile_of_field(crater_field(scene), lat_deg, lon_deg, size_px, pixel_m,
                         min_crater_px)


def tile_of_field(field: CraterField, lat_deg: float, lon_deg: float, size_px: int,
                  pixel_m: float, min_crater_px: float) -> Tile:
    """:func:`tile` of a crater field (any base: a scene's, a DEM's), arguments checked."""
    # the projection's sphere: the base's radius at the centre, so pixels are metres on
    # the ground there (an elongated body's ends are far from its mean radius)
    radius = float(field.base.radius(units_of([lat_deg], [lon_deg]))[0])
    size_m = size_px * pixel_m
    if size_m / radius > 0.5:
        raise ParameterError("size_m", f"must be at most half the reference radius "
                             f"({0.5 * radius:g} m) for a gnomonic window; got {size_m:g}")
    units = tile_units(lat_deg, lon_deg, size_px, pixel_m, radius).reshape(-1, 3)
    d_min = min_crater_px * pixel_m
    r = field.radii(units, d_min)
    return Tile((r - radius).reshape(size_px, size_px), float(lat_deg), float(lon_deg),
                pixel_m, radius, d_min, len(field.last["craters"]),
                len(field.rocks.last["diameter_m"]))


def tile_mesh(t: Tile) -> tuple[np.ndarray, np.ndarray]:
    """(vertices (n, 3) in the body's frame, metres; triangles (m, 3)) of a tile: each
    pixel centre at its radius, two triangles a pixel square, outward (counter-clockwise
    seen from above)."""
    ny, nx = t.heights_m.shape
    units = tile_units(t.lat_deg, t.lon_deg, nx, t.pixel_m, t.radius_m).reshape(-1, 3)
    verts = units * (t.radius_m + t.heights_m.reshape(-1, 1))
    return verts, _grid_faces(ny, nx)


@functools.lru_cache(maxsize=2)
def _grid_faces(ny: int, nx: int) -> np.ndarray:
    """The triangles of an ny x nx pixel grid (read-only: a descent's frames share them)."""
    idx = np.arange(ny * nx).reshape(ny, nx)
    a, b = idx[:-1, :-1].ravel(), idx[:-1, 1:].ravel()   # north row: west, east
    c, d = idx[1:, :-1].ravel(), idx[1:, 1:].ravel()     # south row
    faces = np.concatenate([np.stack([a, c, b], 1), np.stack([b, c, d], 1)])
    faces.flags.writeable = False
    return faces


def hillshade(heights_m: np.ndarray, pixel_m: float, *, azimuth_deg: float = 270.0,
              elevation_deg: float = 20.0) -> np.ndarray:
    """Lambertian shading (0..1) of a height grid lit from ``azimuth_deg`` (clockwise from
    north, the top of the grid) at ``elevation_deg``."""
    gy, gx = np.gradient(np.asarray(heights_m, dtype=np.float64), pixel_m)
    az = np.radians(azimuth_deg)
    el = np.radians(elevation_deg)
    light = np.array([np.sin(az) * np.cos(el), np.cos(az) * np.cos(el), np.sin(el)])
    # rows run north to south: d/dy(north) = -d/drow
    nx, ny, nz = -gx, gy, np.ones_like(gx)
    norm = np.sqrt(nx * nx + ny * ny + nz * nz)
    return np.clip((nx * light[0] + ny * light[1] + nz * light[2]) / norm, 0.0, 1.0)


def write_cog(t: Tile, path) -> Path:
    """The tile's heights as a float32 Cloud Optimized GeoTIFF (atomic)."""
    import rasterio
    from rasterio.crs import CRS
    from rasterio.transform import Affine

    h = t.heights_m.astype(np.float32)
    x0, dx, _, y0, _, dy = t.transform
    profile = {"driver": "COG", "width": h.shape[1], "height": h.shape[0], "count": 1,
               "dtype": "float32", "crs": CRS.from_proj4(t.crs_proj4),
               "transform": Affine(dx, 0.0, x0, 0.0, dy, y0), "compress": "deflate",
               "predictor": 3, "nodata": None}
    with atomic_path(path) as tmp:
        with rasterio.open(tmp, "w", **profile) as dst:
            dst.write(h, 1)
            dst.update_tags(units="m", reference_radius_m=repr(t.radius_m),
                            generator="craterform tile (terrain on demand)")
    return Path(path)


def write_tile(t: Tile, *, cog=None, mesh=None, picture=None) -> None:
    """Write a tile: heights as a COG (:func:`write_cog`), the window as a mesh in the
    body's frame (any mesh suffix, ``height_m`` per vertex), a shaded picture (plane
    removed, sun from the west at 20 degrees); each atomic."""
    if cog:
        write_cog(t, cog)
    if mesh:
        from ..meshio.writers import array_source, write_mesh

        verts, faces = tile_mesh(t)
        write_mesh(array_source(verts, faces, "craterform tile (terrain on demand)",
                                height_m=t.heights_m.ravel()), mesh)
    if picture:
        from PIL import Image

        from craters.exact import plane_residual

        shade = hillshade(plane_residual(t.heights_m), t.pixel_m)
        with atomic_path(picture) as tmp:
            Image.fromarray((255.0 * shade).astype(np.uint8)).save(tmp, format="PNG")
