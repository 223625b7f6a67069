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

#: Triangles per step of :func:`band_areas` (~250 B each while a step runs); each band's
#: area is summed over the band alone, so the steps never change a value.
_TRIANGLES_PER_STEP = 1 << 18


def _triangle_areas(body: Body, band_lo: int, band_hi: int):
    """Triangles of bands band_lo..band_hi-1 and their actual areas (m^2)."""
    t = body.grid.band_triangles(band_lo, band_hi)
    v0, v1 = int(t.min()), int(t.max()) + 1
    p = body.vertices(v0, v1)[t - v0]
    return t, 0.5 * np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1)


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
        _, a = _triangle_areas(body, lo, hi)
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
    cum = np.cumsum(areas)
    total = float(cum[-1])
    u = rng.random(n) * total
    a, b = rng.random(n), rng.random(n)
    flip = a + b > 1
    a[flip], b[flip] = 1 - a[flip], 1 - b[flip]
    band = np.minimum(np.searchsorted(cum, u, side="right"), len(cum) - 1)
    resid = u - np.concatenate([[0.0], cum[:-1]])[band]
    p = np.empty((n, 3))
    order = np.argsort(band, kind="stable")
    starts = np.searchsorted(band[order], np.arange(len(areas) + 1))
    for bnd in np.flatnonzero(np.diff(starts)):
        sel = order[starts[bnd]:starts[bnd + 1]]
        t, area = _triangle_areas(body, int(bnd), int(bnd) + 1)
        k = np.minimum(np.searchsorted(np.cumsum(area), resid[sel], side="right"), len(t) - 1)
        tri = t[k]
        v = body.vertices(int(tri.min()), int(tri.max()) + 1)
        v0, v1, v2 = (v[tri[:, c] - tri.min()] for c in range(3))
        p[sel] = v0 + a[sel, None] * (v1 - v0) + b[sel, None] * (v2 - v0)
    q = p / np.asarray(body.stretch)
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    lat = np.degrees(np.arcsin(np.clip(q[:, 2], -1, 1)))
    lon = np.mod(np.degrees(np.arctan2(q[:, 1], q[:, 0])), 360.0)
    return lat, lon, total


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
