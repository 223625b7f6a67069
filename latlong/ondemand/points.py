"""Terrain on demand at arbitrary points: :func:`heights_at` (latitudes and longitudes in
degrees) and :func:`units_of` (their unit vectors)."""

from __future__ import annotations

import numpy as np

from craters._shared import check_positive

from ..scene import Scene
from .field import heights_at_units

__all__ = ["heights_at", "units_of"]


def units_of(lat_deg, lon_deg) -> np.ndarray:
    """Unit vectors (n, 3) of latitudes and longitudes in degrees (the grid's
    directions: planetocentric on an unstretched body; on a stretched one, the surface's
    own directions, :mod:`latlong.ondemand.base`)."""
    lat = np.radians(np.asarray(lat_deg, dtype=np.float64).ravel())
    lon = np.radians(np.asarray(lon_deg, dtype=np.float64).ravel())
    if lat.shape != lon.shape:
        raise ValueError(f"`lat_deg` and `lon_deg` must have the same size; got {lat.size} "
                         f"and {lon.size}")
    if lat.size and not (np.isfinite(lat).all() and np.isfinite(lon).all()
                         and np.abs(lat).max() <= np.pi / 2):
        raise ValueError("`lat_deg` must be finite in [-90, 90] and `lon_deg` finite")
    c = np.cos(lat)
    return np.stack([c * np.cos(lon), c * np.sin(lon), np.sin(lat)], axis=1)


def heights_at(scene: Scene, lat_deg, lon_deg, *, resolution_m: float) -> np.ndarray:
    """Radii (metres) of the scene's surface at arbitrary points, with every crater at
    least 3 ``resolution_m`` across; the same values whatever other points are asked
    with them.

    Examples
    --------
    >>> from latlong import Scene
    >>> scene = Scene.from_settings({"preset": "fbm-cratered", "seed": 1})
    >>> r = heights_at(scene, [10.0, -30.0], [20.0, 200.0], resolution_m=0.5)
    >>> r.shape, bool((abs(r - 100.0) < 10.0).all())
    ((2,), True)
    """
    if not isinstance(scene, Scene):
        raise TypeError(f"`scene` must be a latlong.Scene; got {type(scene).__name__}")
    if scene.seed is None:
        raise ValueError("`scene` needs a seed for terrain on demand (a surface that is a "
                         "function of position); set seed")
    resolution_m = check_positive("resolution_m", resolution_m)
    return heights_at_units(scene, units_of(lat_deg, lon_deg), resolution_m=resolution_m)
