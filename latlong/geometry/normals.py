"""Face and vertex normals of triangle meshes, with named weightings: the one home of the
project's normals.

A vertex normal sums the normals of the facets around the vertex with a weighting
(:data:`WEIGHTINGS`), then scales the sum to unit length:

* ``"area"``: each facet's area vector (half its cross product ``(b - a) x (c - a)``),
  so large facets count more; the body's slopes, boulder placement, the mesh surfaces
  and gravity's evaluation points;
* ``"angle"``: each facet's unit normal times its angle at the vertex (Baerentzen &
  Aanaes 2005, pseudo-normals; the weighting of Thürmer & Wüthrich 1998, which Mitsuba 3
  and Blender use for smooth shading): the shading normals of the camera and of the glTF
  export, so a renderer fed the glTF shades as craterform does; the implicit backend's
  inside/outside test (left unnormalised there);
* ``"max"``: each facet's cross product over the product of the squared lengths of the
  two edges at the vertex (Max 1999, "Weights for computing vertex normals from facet
  normals", J. Graphics Tools 4(2): exact for vertices on a sphere).

Floating-point sums depend on their order, and every caller keeps the order that gives
its outputs' bytes (:data:`ORDERS`): ``"corners"`` adds the facets' contributions to
their first corners, then their second, then their third, each in facet order
(``np.add.at`` per column); ``"corner-sums"`` sums each column on its own first and adds
the three sums (``np.bincount`` per column); ``"faces"`` adds a facet's three
contributions before the next facet's (the streaming order of big bodies, band by band:
:func:`vertex_normals_and_areas`, :func:`lat_long_vertex_normals`).

A lat/long body's area-weighted normals are streamed band by band from its radii by a
numba kernel (:func:`lat_long_vertex_normals`, float32, 12 B a vertex); the glTF
export's ring windows (:mod:`latlong._window_kernels`) reuse its band kernel, bit for bit.
"""

from __future__ import annotations

import numpy as np

__all__ = ["ORDERS", "WEIGHTINGS", "face_normals", "lat_long_vertex_normals", "tangent_frames",
           "triangle_normals", "unit_rows", "vertex_areas", "vertex_normal_sums",
           "vertex_normals", "vertex_normals_and_areas"]

#: Vertex-normal weightings (module notes): name -> what a facet contributes.
WEIGHTINGS = {
    "area": "the facet's area vector, (b - a) x (c - a) / 2",
    "angle": "the facet's unit normal times its angle at the vertex (pseudo-normal)",
    "max": "the facet's cross product over the squared lengths of the vertex's two edges",
}
#: Summation orders (module notes): name -> how the facets' contributions are added.
ORDERS = {
    "corners": "first corners, then second, then third, each in facet order (np.add.at)",
    "corner-sums": "each corner column summed on its own, then the three sums added",
    "faces": "facet after facet, each facet's three corners together",
}
#: The order each weighting uses unless told: its callers' bytes.
DEFAULT_ORDER = {"area": "corner-sums", "angle": "corner-sums", "max": "faces"}


def _check(weighting: str, order: str | None) -> str:
    if weighting not in WEIGHTINGS:
        raise ValueError(f"`weighting` must be one of {', '.join(WEIGHTINGS)}; got "
                         f"{weighting!r}")
    order = DEFAULT_ORDER[weighting] if order is None else order
    if order not in ORDERS:
        raise ValueError(f"`order` must be one of {', '.join(ORDERS)}; got {order!r}")
    if weighting == "max" and order != "faces":
        raise ValueError(f"`order` {order!r}: the max weighting sums facet after facet "
                         "(order 'faces')")
    return order


def triangle_normals(corners, *, unit: bool = False) -> np.ndarray:
    """Normals ``(b - a) x (c - a)`` of triangles given by their corners (..., 3, 3)
    (twice the area along the normal), or unit normals (degenerate triangles: 0).

    Examples
    --------
    >>> triangle_normals(np.eye(3)[None]).tolist()
    [[1.0, 1.0, 1.0]]
    """
    c = np.asarray(corners)
    n = np.cross(c[..., 1, :] - c[..., 0, :], c[..., 2, :] - c[..., 0, :])
    return unit_rows(n, zero=True) if unit else n


def face_normals(vertices, faces, *, unit: bool = False) -> np.ndarray:
    """Normals of a mesh's faces (F, 3): ``(b - a) x (c - a)`` (twice the area along the
    normal), or unit normals with ``unit`` (degenerate faces: 0)."""
    v = np.asarray(vertices)
    f = np.asarray(faces)
    a, b, c = (v[f[:, k]] for k in range(3))
    n = np.cross(b - a, c - a)
    return unit_rows(n, zero=True) if unit else n


def unit_rows(vectors, *, zero: bool = False) -> np.ndarray:
    """The rows (last axis) of ``vectors`` scaled to unit length; rows of length 0 stay 0
    (``zero`` also sets rows whose squared length underflows to exactly 0)."""
    a = np.asarray(vectors)
    norm = np.linalg.norm(a, axis=-1, keepdims=True)
    out = a / np.where(norm > 0, norm, 1.0)
    return np.where(norm > 0, out, 0.0) if zero else out


def _corner_weights(v: np.ndarray, f: np.ndarray, weighting: str) -> list[np.ndarray]:
    """What each facet gives to its corner k (k = 0, 1, 2): (F, 3) each."""
    if weighting == "area":
        half = 0.5 * face_normals(v, f)
        return [half, half, half]
    corners = [v[f[:, k]] for k in range(3)]
    cross = np.cross(corners[1] - corners[0], corners[2] - corners[0])
    norm = np.linalg.norm(cross, axis=1, keepdims=True)
    unit = np.where(norm > 0, cross / np.where(norm > 0, norm, 1.0), 0.0)
    out = []
    for k in range(3):  # the corner's angle atan2(|cross|, dot): |cross| is the facet's
        u = corners[(k + 1) % 3] - corners[k]
        w = corners[(k + 2) % 3] - corners[k]
        angle = np.arctan2(norm[:, 0], np.einsum("ij,ij->i", u, w))
        out.append(np.stack([angle * unit[:, d] for d in range(3)], axis=1))
    return out


def vertex_normal_sums(vertices, faces, weighting: str = "area", *,
                       order: str | None = None) -> np.ndarray:
    """The weighted sums of the facet normals at every vertex, before scaling (V, 3)
    float64 (module notes; ``"area"``: area vectors, m^2). ``order`` defaults to the
    weighting's :data:`DEFAULT_ORDER`; the max weighting has unit normals only
    (:func:`vertex_normals`)."""
    from ._normal_kernels import (  # numba loads here
        _angle_normals_kernel,
        _area_normals_kernel,
        _scatter_add_kernel,
    )
    order = _check(weighting, order)
    if weighting == "max":
        raise ValueError("`weighting` 'max' has no sums here: use vertex_normals")
    v = np.ascontiguousarray(vertices, dtype=np.float64)
    f = np.ascontiguousarray(faces, dtype=np.int64)
    out = np.zeros_like(v)
    if order == "faces" and weighting == "area":
        _area_normals_kernel(v, f, out, np.empty(0))
        return out
    if order == "faces" and weighting == "angle":  # 20x numpy's time on 2 M triangles
        _angle_normals_kernel(v, f, out)
        return out
    w = _corner_weights(v, f, weighting)
    if order == "corner-sums":
        for k in range(3):
            for d in range(3):
                out[:, d] += np.bincount(f[:, k], weights=w[k][:, d], minlength=len(v))
    elif order == "corners":
        for k in range(3):
            _scatter_add_kernel(np.ascontiguousarray(f[:, k]), w[k], out)
    else:
        _scatter_add_kernel(f.ravel(), np.stack(w, axis=1).reshape(-1, 3), out)
    return out


def vertex_normals(vertices, faces, weighting: str = "area", *,
                   order: str | None = None) -> np.ndarray:
    """Unit vertex normals (V, 3) float64 with a named weighting (module notes); rows of
    vertices no facet touches are 0. ``vertices`` may hold a batch of meshes that share
    ``faces``, (n, V, 3) (boulders).

    Examples
    --------
    >>> v = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
    >>> f = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    >>> vertex_normals(v, f, "area")[3].round(3).tolist()
    [0.0, 0.0, 1.0]
    """
    from ._normal_kernels import _max_normals_kernel  # numba loads here
    v = np.asarray(vertices, dtype=np.float64)
    if v.ndim == 3:
        return np.stack([vertex_normals(x, faces, weighting, order=order) for x in v])
    order = _check(weighting, order)
    if weighting == "max":
        out = np.empty_like(np.ascontiguousarray(v))
        _max_normals_kernel(np.ascontiguousarray(v), np.asarray(faces), out)
        return out
    return unit_rows(vertex_normal_sums(v, faces, weighting, order=order))


def vertex_areas(vertices, faces) -> np.ndarray:
    """Area of every vertex, m^2: a third of each incident facet's (summed per corner
    column, in facet order)."""
    from ._normal_kernels import _scatter_add_kernel  # numba loads here
    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces, dtype=np.int64)
    third = np.linalg.norm(0.5 * face_normals(v, f), axis=1) / 3.0
    area = np.zeros(len(v))
    for k in range(3):  # np.bincount's order, column by column
        part = np.zeros(len(v))
        _scatter_add_kernel(np.ascontiguousarray(f[:, k]), third, part)
        area += part
    return area


def vertex_normals_and_areas(vertices, face_chunks) -> tuple[np.ndarray, np.ndarray]:
    """Unit area-weighted vertex normals (V, 3) and vertex areas (V,) m^2 of a mesh whose
    faces come in chunks (a body's bands), summed facet after facet (``"faces"``)."""
    from ._normal_kernels import _area_normals_kernel  # numba loads here
    v = np.ascontiguousarray(vertices, dtype=np.float64)
    acc = np.zeros_like(v)
    area = np.zeros(len(v))
    for tri in face_chunks:
        _area_normals_kernel(v, np.ascontiguousarray(tri), acc, area)
    return unit_rows(acc), area


def lat_long_vertex_normals(grid, radii, stretch=(1.0, 1.0, 1.0), *,
                            lon_table: np.ndarray | None = None,
                            weighting: str = "area") -> np.ndarray:
    """Unit vertex normals, float32 (N, 3), ``"area"`` or ``"angle"`` weighted, of the
    lat/long mesh of
    ``grid`` (a :class:`~latlong.LatLongGrid`) whose vertex ``i`` is
    ``stretch * radii[i] * u_i``: accumulated band by band in float32 (12 B a vertex, no
    triangle array, and 8 B a vertex of longitude cosines and sines while it runs; pass
    ``lon_table`` - ``latlong._grid_kernels.lon_table(M, ring_offsets)`` - to reuse one)
    and normalised in place."""
    from .._grid_kernels import lon_table as make_lon_table
    from ._normal_kernels import (  # numba loads here
        _normalize_rows_kernel,
        _normals_from_radii_kernel,
    )

    if weighting not in ("area", "angle"):
        raise ValueError(f"`weighting` must be 'area' or 'angle'; got {weighting!r}")
    m = grid.magnitude
    radii = np.ascontiguousarray(radii, dtype=np.float64)
    if radii.shape != (grid.n_vertices,):
        raise ValueError(f"`radii` must have shape ({grid.n_vertices},); got {radii.shape}")
    table = make_lon_table(m, grid.ring_offsets()) if lon_table is None else lon_table
    if table.shape != (3 * m * (m + 1), 2) or table.dtype != np.float64:
        raise ValueError("`lon_table` must be the grid's longitude table "
                         f"({3 * m * (m + 1)}, 2) float64")
    acc = np.zeros((grid.n_vertices, 3), dtype=np.float32)
    _normals_from_radii_kernel(m, grid.ring_offsets(), grid.band_offsets(), radii,
                               np.ascontiguousarray(stretch, dtype=np.float64), table, acc,
                               weighting == "angle")
    _normalize_rows_kernel(acc)
    return acc


def tangent_frames(up) -> np.ndarray:
    """Orthonormal frames (n, 3, 3) whose rows are east, north, up for unit ``up``
    vectors (n, 3): east = z x up (x x up within 1e-12 of the poles), north = up x east.

    Examples
    --------
    >>> tangent_frames([[1.0, 0.0, 0.0]])[0].tolist()
    [[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]]
    """
    u = unit_rows(np.asarray(up, dtype=np.float64).reshape(-1, 3))
    east = np.cross([0.0, 0.0, 1.0], u)
    polar = np.linalg.norm(east, axis=1) < 1e-12
    east[polar] = np.cross([1.0, 0.0, 0.0], u[polar])
    east = unit_rows(east)
    return np.stack([east, np.cross(u, east), u], axis=1)
