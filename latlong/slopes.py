"""Slopes and radius spectra of bodies and real shape models (Martin 2014, VI.B).

Slope on a small body: the angle between the local surface normal and the radial
direction (from the centre to the point). The paper's per-vertex slope averages the
surface normal over everything within 3 degrees of arc of the vertex first, which
takes out the mesh-scale noise. Here a vertex normal is the area-weighted sum of its
triangles' normals (:mod:`latlong.geometry.normals`, weighting ``"area"``); the cap
average uses each vertex's normal weighted by its area (``weighted=True``) or
unweighted; caps are taken around the grid direction of each vertex and summed ring by
ring from prefix sums, so the cost does not grow with the cap size. Real meshes
(:class:`~latlong.shapes.ShapeModel`) get the same measure with cap sums over the vertex
directions seen from the centre.

The radius spectrum is the degree variance of the radius field's spherical-harmonic
expansion, ``S_l = sum_m |a_lm|^2`` (m^2), computed with an FFT along each ring and
Legendre sums over the rings (ring-zone quadrature).
"""

from __future__ import annotations

import math

import numpy as np

from craters._shared import check_int, check_range
from craters.exact import abs2

from ._slope_kernels import _cap_average_kernel, _direction_cap_sum_kernel, _ring_prefix_kernel
from .body import Body
from .geometry.meshes import centre_point
from .geometry.normals import vertex_areas, vertex_normals_and_areas
from .geometry.normals import vertex_normals as mesh_vertex_normals
from .geometry.stats import area_slope_summary
from .shapes import ShapeModel

__all__ = ["SLOPE_BIN_DEG", "direction_cap_sums", "facet_slopes", "mesh_slopes", "radius_spectrum",
           "slope_summary",
           "slopes", "slopes_and_areas", "vertex_normals"]

#: Cells a cap's chord spans in :func:`direction_cap_sums` (fewer point tests vs more cells).
_CAP_REACH = 3

#: The paper's histogram bins, degrees.
SLOPE_BIN_DEG = 3.0


def _check_body(body) -> Body:
    if not isinstance(body, Body):
        raise TypeError(f"`body` must be a Body; got {type(body).__name__}")
    return body


def vertex_normals(body: Body) -> tuple[np.ndarray, np.ndarray]:
    """Unit vertex normals (area-weighted triangle normals, float64, summed triangle after
    triangle: :func:`latlong.geometry.normals.vertex_normals_and_areas`) and vertex areas
    (m^2, a third of each incident triangle)."""
    body = _check_body(body)
    grid = body.grid
    step = max(1, (2 * grid.magnitude) // 16)
    bands = (grid.band_triangles(lo, min(lo + step, 2 * grid.magnitude))
             for lo in range(0, 2 * grid.magnitude, step))
    return vertex_normals_and_areas(body.vertices(), bands)


def _angle_deg(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Angle between row vectors (any length), degrees, robust near 0 and 180."""
    cross = np.linalg.norm(np.cross(u, v), axis=1)
    dot = np.einsum("ij,ij->i", u, v)
    return np.degrees(np.arctan2(cross, dot))


def slopes(body: Body, radius_deg: float = 3.0, *, weighted: bool = True) -> np.ndarray:
    """Per-vertex slope in degrees: the cap-averaged normal against the radial direction.

    Parameters
    ----------
    body : Body
    radius_deg : float
        Angular radius of the averaging cap (degrees of arc around each vertex's grid
        direction); 0 uses each vertex's own normal.
    weighted : bool
        Weight each vertex normal by its area in the average (else plain mean).

    Examples
    --------
    >>> from latlong import LatLongGrid
    >>> s = slopes(Body.sphere(LatLongGrid(200), 10.0))  # a sphere is flat
    >>> bool(s.max() < 0.1)
    True
    """
    return slopes_and_areas(body, radius_deg, weighted=weighted)[0]


def _down(gravity, pos: np.ndarray) -> np.ndarray:
    """The reference "up" the slope is measured against: radial (geometric) or minus the
    effective gravity of a :class:`~latlong.gravity.GravityField` (gravitational)."""
    if gravity is None:
        return pos
    up = -np.asarray(gravity.effective_m_s2)
    if up.shape != pos.shape:
        raise ValueError(f"`gravity` has {len(up)} vertices; the surface has {len(pos)}")
    return up


def slopes_and_areas(body: Body, radius_deg: float = 3.0, *, weighted: bool = True,
                     gravity=None):
    """:func:`slopes` and the vertex areas (m^2) used to weight them in statistics.

    With ``gravity`` (a :class:`~latlong.gravity.GravityField` of this body) the slope is
    the angle between the cap-averaged normal and minus the effective gravity
    (gravitational slope) instead of the radial direction (geometric slope)."""
    body = _check_body(body)
    radius_deg = check_range("radius_deg", radius_deg, 0.0, 90.0)
    normals, area = vertex_normals(body)
    grid = body.grid
    verts = body.vertices()
    if radius_deg == 0:
        avg = normals
    else:
        w = normals * (area[:, None] if weighted else 1.0)
        prefix = np.zeros((grid.n_vertices + grid.n_rings, 3))
        _ring_prefix_kernel(grid.ring_offsets(), np.ascontiguousarray(w), prefix)
        avg = np.empty((grid.n_vertices, 3))
        _cap_average_kernel(grid.magnitude, grid.ring_offsets(), prefix,
                            math.radians(radius_deg), avg)
    return _angle_deg(avg, _down(gravity, verts)), area


def facet_slopes(body: Body) -> tuple[np.ndarray, np.ndarray]:
    """Slope of every triangle (degrees; normal vs the radial direction of its centroid)
    and its area (m^2), in the order of ``grid.triangles()``."""
    body = _check_body(body)
    grid = body.grid
    verts = body.vertices()
    out_s, out_a = [], []
    step = max(1, (2 * grid.magnitude) // 16)
    for lo in range(0, 2 * grid.magnitude, step):
        t = grid.band_triangles(lo, min(lo + step, 2 * grid.magnitude))
        a, b, c = verts[t[:, 0]], verts[t[:, 1]], verts[t[:, 2]]
        n = np.cross(b - a, c - a)
        out_s.append(_angle_deg(n, (a + b + c) / 3.0))
        out_a.append(0.5 * np.linalg.norm(n, axis=1))
    return np.concatenate(out_s), np.concatenate(out_a)


def mesh_slopes(model: ShapeModel, radius_deg: float = 3.0, *, weighted: bool = True,
                center="volume-centroid", gravity=None) -> tuple[np.ndarray, np.ndarray]:
    """Per-vertex slopes (degrees) and vertex areas (m^2) of any closed mesh.

    The same measure as :func:`slopes`: vertex normals averaged over the vertices whose
    directions from ``center`` lie within ``radius_deg`` (:func:`direction_cap_sums`:
    memory linear in the mesh size), against the radial direction from ``center`` or,
    with ``gravity`` (its :class:`~latlong.gravity.GravityField`), against minus the
    effective gravity.
    """
    if not isinstance(model, ShapeModel):
        raise TypeError(f"`model` must be a ShapeModel; got {type(model).__name__}")
    radius_deg = check_range("radius_deg", radius_deg, 0.0, 90.0)
    v = model.vertices - centre_point(model, center)
    f = model.faces
    normals = mesh_vertex_normals(v, f, "area", order="corners")
    area = vertex_areas(v, f)
    up = _down(gravity, v)
    if radius_deg == 0:
        return _angle_deg(normals, up), area
    dirs = v / np.linalg.norm(v, axis=1, keepdims=True)
    chord = 2.0 * math.sin(math.radians(radius_deg) / 2.0)
    w = normals * (area[:, None] if weighted else 1.0)
    return _angle_deg(direction_cap_sums(dirs, w, chord), up), area


def direction_cap_sums(dirs: np.ndarray, values: np.ndarray, chord: float) -> np.ndarray:
    """Sum of ``values`` (N, k) over every point's cap: the points whose unit direction
    (``dirs``, N x 3) lies within the chord ``chord`` of its own (distance <= chord).

    Memory O(N) (a cell grid over the unit ball, no neighbour lists), so meshes of
    millions of vertices fit: the cap sums the former k-d tree neighbour lists gave, in
    a fixed order whatever the thread count.
    """
    dirs = np.ascontiguousarray(dirs, dtype=np.float64)
    values = np.ascontiguousarray(values, dtype=np.float64)
    reach = _CAP_REACH
    side = max(chord * (1.0 + 1e-9) / reach, 2.0 ** -19)  # >= chord / reach; keys fit int64
    nc = int(2.0 / side) + 1
    cells = np.clip(np.floor((dirs + 1.0) / side), 0, nc - 1).astype(np.int64)
    key = (cells[:, 0] * nc + cells[:, 1]) * nc + cells[:, 2]
    order = np.argsort(key, kind="stable")
    key = key[order]
    values_sorted = values[order]
    first = np.flatnonzero(np.r_[True, key[1:] != key[:-1]])
    sums = np.empty_like(values)
    _direction_cap_sum_kernel(dirs[order], values_sorted, cells[order], key[first],
                              np.r_[first, len(key)].astype(np.int64),
                              np.add.reduceat(values_sorted, first, axis=0), nc, side, reach,
                              chord * chord, sums)
    out = np.empty_like(values)
    out[order] = sums
    return out


def slope_summary(slopes_deg, areas, *, bin_deg: float = SLOPE_BIN_DEG) -> dict:
    """Area-weighted slope statistics: histogram, cumulative share above each angle.

    Returns a dict with ``edges_deg`` (bin edges), ``area_fraction`` (per bin, sums to
    1), ``above_percent`` (share of the area steeper than each edge), ``median_deg``,
    ``mean_deg`` and ``percent_above`` for 10, 20 and 30 degrees (the same summary as
    ``dem.slope_distribution``).
    """
    return area_slope_summary(slopes_deg, areas, bin_deg=bin_deg)


def radius_spectrum(body: Body, l_max: int | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Spherical-harmonic degree variance of the radius field, ``S_l = sum_m |a_lm|^2``.

    ``a_lm`` of the radius (metres, distance of each vertex from the centre) with
    orthonormal harmonics, by an FFT along every ring and quadrature over the rings
    (each vertex weighted by its zone area); degrees up to ``l_max`` (default: 2M/3).
    The relief r - R (R: the area-weighted mean radius) is transformed and the mean's
    exact ``a_00 = R sqrt(4 pi)`` added back, so the quadrature error of the large
    constant does not leak into the other degrees.
    Returns ``(l, S_l)``; the wavelength of degree l is ``2 pi R / sqrt(l (l + 1))``.

    Examples
    --------
    >>> from latlong import LatLongGrid
    >>> l, s = radius_spectrum(Body.sphere(LatLongGrid(12), 2.0), 4)
    >>> round(float(s[0]), 3), bool(s[1:].max() < 1e-3 * s[0])  # 4 pi R^2, nothing else
    (50.265, True)
    """
    from scipy.special import sph_legendre_p_all

    body = _check_body(body)
    grid = body.grid
    l_max = check_int("l_max", l_max if l_max is not None else (2 * grid.magnitude) // 3, 0,
                      2 * grid.magnitude)
    w = grid.vertex_areas()
    r = np.linalg.norm(body.vertices(), axis=1)
    # transform r - R, not r: the quadrature is not exact for the (large) constant, whose
    # leakage would swamp the small relief's high degrees (issue 16: up to 61 % error in
    # degrees 11-40 and spurious power above); the constant's a_00 is exact: R sqrt(4 pi)
    mean_r = float(np.sum(w * r) / np.sum(w))
    r = r - mean_r
    offs, sizes, theta = grid.ring_offsets(), grid.ring_sizes(), grid.ring_colatitudes()
    coeff = np.zeros((l_max + 1, l_max + 1), dtype=np.complex128)  # [l, m], m >= 0
    chunk = max(1, int(2e7 // ((l_max + 1) * (2 * l_max + 1))))
    for r0 in range(0, grid.n_rings, chunk):
        rings = np.arange(r0, min(r0 + chunk, grid.n_rings))
        plm = sph_legendre_p_all(l_max, l_max, theta[rings])[0]  # (l, 2l+1 orders, rings)
        for k, ring in enumerate(rings):
            o, n = offs[ring], sizes[ring]
            f = np.fft.fft(r[o:o + n]) * w[o]  # sum_j f_j e^{-i m lambda_j} dA
            mmax = min(l_max, (n - 1) // 2) if n > 1 else 0
            ms = np.arange(mmax + 1)
            coeff[:, :mmax + 1] += plm[:, ms, k] * f[ms][None, :]
    coeff[0, 0] += mean_r * math.sqrt(4.0 * math.pi)
    power = abs2(coeff[:, 0]) + 2.0 * abs2(coeff[:, 1:]).sum(axis=1)
    return np.arange(l_max + 1), power
