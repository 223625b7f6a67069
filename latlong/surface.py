"""Points uniform on a body's actual surface (its triangle mesh, stretch included).

Crater and boulder populations draw their counts from the body's true area and their
positions uniformly on it: a latitude band is chosen with probability proportional to its
area, then a triangle of the band, then a uniform point inside it, so nothing ever holds
the whole triangulation.
"""

from __future__ import annotations

import numpy as np

from craters._shared import check_int, normalize_rng

from .body import Body

__all__ = ["band_areas", "sample_surface_points", "surface_positions"]

#: Triangles per step of :func:`band_areas` (8 B each while a step runs: 32 MB, dozens of
#: bands for the threads to share even at M = 13 000); each band's area is summed over
#: the band alone, so the steps never change a value.
_TRIANGLES_PER_STEP = 1 << 22


def _triangle_areas(body: Body, band_lo: int, band_hi: int) -> np.ndarray:
    """Actual areas (m^2) of the triangles of bands band_lo..band_hi-1, in
    :meth:`LatLongGrid.band_triangles` order: the bits of
    ``0.5 * norm(cross(p1 - p0, p2 - p0))`` over :meth:`Body.vertices` (a numba kernel,
    bands in parallel when there are many; tests compare it with that expression)."""
    from ._surface_kernels import (  # numba loads here
        band_triangle_areas,
        band_triangle_areas_serial,
    )
    g = body.grid
    bo = g.band_offsets()
    out = np.empty(int(bo[band_hi] - bo[band_lo]))
    many = band_hi - band_lo > 1 and bo[band_hi] - bo[band_lo] > 100_000
    kernel = band_triangle_areas if many else band_triangle_areas_serial
    kernel(g.magnitude, g.ring_offsets(), bo, body.radii_m,
           np.ascontiguousarray(body.stretch, dtype=np.float64), band_lo, band_hi, out)
    return out


def band_areas(body: Body) -> np.ndarray:
    """Actual surface area of every latitude band of triangles (m^2), streamed a few
    bands at a time; their sum is the body's area.

    Examples
    --------
    >>> from latlong import LatLongGrid
    >>> a = band_areas(Body.sphere(LatLongGrid(16), 1.0))
    >>> a.shape, round(float(a.sum() / (4 * np.pi)), 3)
    ((32,), 0.998)
    """
    n_bands = 2 * body.grid.magnitude
    totals = np.empty(n_bands)
    bo = body.grid.band_offsets()
    lo = 0
    while lo < n_bands:  # whole bands, about _TRIANGLES_PER_STEP triangles at a time
        hi = min(max(lo + 1, int(np.searchsorted(bo, bo[lo] + _TRIANGLES_PER_STEP,
                                                 side="right")) - 1), n_bands)
        a = _triangle_areas(body, lo, hi)
        totals[lo:hi] = np.add.reduceat(a, bo[lo:hi] - bo[lo])
        lo = hi
    return totals


def sample_surface_points(body: Body, areas: np.ndarray, n: int,
                          rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray, float]:
    """``n`` points uniform on ``body`` given its :func:`band_areas` ``areas``, drawn from
    the Generator ``rng``: (lat_deg, lon_deg, total area in m^2), the grid
    latitude/longitude of each point's direction in the unstretched frame.

    For callers that already hold the band areas (one computation per body); the
    stream of ``rng`` draws is the same whatever the body.
    """
    from ._surface_kernels import sample_in_bands  # numba loads here
    total, a, b, band, resid = _draws(areas, n, rng)
    p = np.empty((n, 3))
    order = np.argsort(band, kind="stable")
    starts = np.searchsorted(band[order], np.arange(len(areas) + 1))
    g = body.grid
    sample_in_bands(g.magnitude, g.ring_offsets(), body.radii_m,
                    np.ascontiguousarray(body.stretch, dtype=np.float64),
                    np.flatnonzero(np.diff(starts)), starts, order, resid, a, b, p)
    return (*_grid_lat_lon(body, p), total)


def _draws(areas: np.ndarray, n: int, rng: np.random.Generator):
    """The random part of :func:`sample_surface_points`: (total area, barycentric a and b
    folded into the triangle, each point's band, its area left within the band)."""
    cum = np.cumsum(areas)
    total = float(cum[-1])
    u = rng.random(n) * total
    a, b = rng.random(n), rng.random(n)
    flip = a + b > 1
    a[flip], b[flip] = 1 - a[flip], 1 - b[flip]
    band = np.minimum(np.searchsorted(cum, u, side="right"), len(cum) - 1)
    resid = u - np.concatenate([[0.0], cum[:-1]])[band]
    return total, a, b, band, resid


def _grid_lat_lon(body: Body, p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Grid (lat_deg, lon_deg) of points ``p`` (m): their directions with the stretch undone."""
    q = p / np.asarray(body.stretch)
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    lat = np.degrees(np.arcsin(np.clip(q[:, 2], -1, 1)))
    lon = np.mod(np.degrees(np.arctan2(q[:, 1], q[:, 0])), 360.0)
    return lat, lon


def surface_positions(body: Body, n: int, *, rng=None) -> tuple[np.ndarray, np.ndarray, float]:
    """``n`` points uniform on the body's actual surface, as grid (lat_deg, lon_deg).

    Triangles are chosen with probability proportional to their area (a band first, then
    a triangle of it: nothing holds the whole triangulation) and a uniform point is taken
    inside; the point's direction in the unstretched frame gives the grid
    latitude/longitude. Returns (lat_deg, lon_deg, total area in m^2).

    Examples
    --------
    >>> from latlong import LatLongGrid
    >>> lat, lon, area = surface_positions(Body.sphere(LatLongGrid(8), 10.0), 5, rng=1)
    >>> lat.shape, bool((np.abs(lat) <= 90).all())
    ((5,), True)
    """
    if not isinstance(body, Body):
        raise TypeError(f"`body` must be a Body; got {type(body).__name__}")
    n = check_int("n", n, 0, 10**9)
    return sample_surface_points(body, band_areas(body), n, normalize_rng(rng))
