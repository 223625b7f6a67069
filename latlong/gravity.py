"""Gravity of constant-density bodies and shape models, for slopes against local gravity.

The attraction and potential of a homogeneous polyhedron have exact closed forms (Werner
& Scheeres 1997, Celest. Mech. 65, 313; Tsoulis 2012, Geophysics 77, F1), evaluated here
by the ``polyhedral-gravity`` package (Schuhmacher et al. 2024, JOSS 9, 6384; the
optional ``gravity`` extra, GPL-3.0). Effective gravity adds the centrifugal acceleration
of uniform rotation about an axis through the centre of mass (the volume centroid):
``omega^2 x_perp`` with potential ``omega^2 |x_perp|^2 / 2``. Slopes against it are what
small-body papers plot (e.g. Zuber et al. 2000, Science 289, 2097, for Eros).

The direct sum costs O(facets x points). A body is therefore evaluated on a coarse
lat/long level of detail (the flat triangles sampled at a coarser grid's directions) at
that level's own vertices and the field is interpolated bilinearly to every vertex; the
acceleration varies on the body's scale, so the interpolation error is second order in
the coarse spacing (measured in ``tests/latlong/test_gravity.py`` and the issue-16 note).
A mesh is evaluated exactly at its vertices when ``facets x vertices <= max_pairs``;
larger meshes are evaluated at a subset of vertices (at least 2000; the mesh decimated
only if its facets times 2000 exceed the budget) and carried to the others by a local
linear fit from the nearest evaluated vertices. Points are evaluated ``1e-7`` of the body's size
outside the surface: the library's formula is singular on a vertex (results differ by a
relative ~2e-7 from the surface value).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from craters._shared import ParameterError, check_positive

from ._gravity_kernels import _local_linear_kernel
from .body import Body
from .geometry.meshes import volume_centroid
from .geometry.normals import vertex_normals
from .geometry.surface import Surface
from .grid import LatLongGrid

__all__ = ["GRAVITATIONAL_CONSTANT", "GravityField", "gravity", "polyhedron_gravity"]

#: CODATA 2018 (Tiesinga et al. 2021), m^3 kg^-1 s^-2: the polyhedral-gravity package's value.
GRAVITATIONAL_CONSTANT = 6.67430e-11
_OFFSET = 1e-7  # evaluation points this fraction of the body's size outside the surface
_NEIGHBOURS = 10  # evaluated vertices in a mesh vertex's local linear fit
_MIN_POINTS = 2000  # a large mesh is evaluated at least at this many of its vertices


@dataclass(frozen=True, slots=True)
class GravityField:
    """Gravity at the vertices of a body or mesh (body frame, metres from its origin)."""

    acceleration_m_s2: np.ndarray
    """(N, 3) gravitational attraction (towards the mass), m/s^2."""
    potential_m2_s2: np.ndarray
    """(N,) gravitational potential, geodetic sign: positive, attraction = its gradient."""
    effective_m_s2: np.ndarray
    """(N, 3) attraction plus the centrifugal acceleration ("down" for slopes), m/s^2."""
    effective_potential_m2_s2: np.ndarray
    """(N,) potential plus the centrifugal potential omega^2 |x_perp|^2 / 2, m^2/s^2."""
    density_kg_m3: float
    """Constant bulk density, kg/m^3."""
    period_h: float
    """Rotation period, hours (inf: not rotating)."""
    spin_axis: tuple[float, float, float]
    """Unit spin axis, through the volume centroid."""
    source_facets: int
    """Facets of the polyhedron the formula was evaluated on (the level of detail)."""
    evaluated_points: int
    """Points where the formula was evaluated (the others interpolated)."""


def _evaluator(vertices, faces, density):
    try:
        import polyhedral_gravity as pg
    except ImportError:  # pragma: no cover - the optional extra
        raise ImportError("gravity needs the polyhedral-gravity package: "
                          "pip install 'craterform[gravity]'") from None
    poly = pg.Polyhedron((np.ascontiguousarray(vertices, dtype=np.float64),
                          np.ascontiguousarray(faces, dtype=np.int64)), float(density),
                         integrity_check=pg.PolyhedronIntegrity.DISABLE)
    return pg.GravityEvaluable(poly)


def polyhedron_gravity(vertices, faces, density_kg_m3: float, points,
                       chunk: int = 4096) -> tuple[np.ndarray, np.ndarray]:
    """Potential (m^2/s^2, positive) and attraction (m/s^2) of a closed outward-oriented
    constant-density triangle mesh (metres) at ``points`` (P, 3): the exact polyhedron
    formula, in chunks (each point's sum is independent: thread-count independent)."""
    density_kg_m3 = check_positive("density_kg_m3", density_kg_m3)
    pts = np.ascontiguousarray(points, dtype=np.float64).reshape(-1, 3)
    ev = _evaluator(vertices, faces, density_kg_m3)
    pot = np.empty(len(pts))
    acc = np.empty((len(pts), 3))
    for s in range(0, len(pts), chunk):
        out = ev(pts[s:s + chunk], parallel=True)
        pot[s:s + chunk] = [o[0] for o in out]
        acc[s:s + chunk] = [o[1] for o in out]
    if not (np.isfinite(pot).all() and np.isfinite(acc).all()):
        raise ValueError("polyhedron gravity is not finite at some points (a point almost "
                         "on a vertex or edge?)")
    return pot, acc


def _spin(spin_axis) -> np.ndarray:
    k = np.asarray(spin_axis, dtype=np.float64).reshape(-1)
    if k.shape != (3,) or not np.isfinite(k).all() or np.linalg.norm(k) == 0:
        raise ParameterError("spin_axis", f"must be three finite numbers, not all zero; "
                             f"got {spin_axis!r}")
    return k / np.linalg.norm(k)


def _volume_centroid(v, f) -> np.ndarray:
    a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    vol = np.einsum("ij,ij->i", a, np.cross(b, c))
    return ((a + b + c) * vol[:, None]).sum(axis=0) / (4.0 * vol.sum())


def _coarse_magnitude(m: int, max_pairs: float) -> int:
    """Largest magnitude <= m whose vertices x facets fit the budget (at least 8)."""
    mc = m
    while mc > 8 and LatLongGrid(mc).n_vertices * 2.0 * LatLongGrid(mc).n_vertices > max_pairs:
        mc = max(8, int(mc * 0.9))
    return mc


def _body_field(body: Body, density, max_pairs, lod_magnitude):
    grid = body.grid
    mc = lod_magnitude if lod_magnitude is not None else _coarse_magnitude(body.magnitude,
                                                                           max_pairs)
    if mc >= body.magnitude:
        coarse, radii = grid, body.radii_m
    else:
        coarse = LatLongGrid(mc)
        colat = np.pi / 2 - coarse.latitudes()
        radii = grid.surface_radii(body.radii_m, colat, coarse.longitudes())
    verts = coarse.unit_vectors() * (radii[:, None] * body.stretch)
    faces = coarse.triangles()
    size = float(np.abs(verts).max())
    outward = verts / np.linalg.norm(verts, axis=1, keepdims=True)
    pot, acc = polyhedron_gravity(verts, faces, density, verts + _OFFSET * size * outward)
    centre = _volume_centroid(verts, faces)
    if coarse is grid:
        return pot, acc, centre, len(faces), len(verts)
    colat = np.pi / 2 - grid.latitudes()
    lon = grid.longitudes()
    pot_f = coarse.interpolate(pot, colat, lon)
    acc_f = np.stack([coarse.interpolate(np.ascontiguousarray(acc[:, k]), colat, lon)
                      for k in range(3)], axis=1)
    return pot_f, acc_f, centre, len(faces), len(verts)


def _mesh_field(v: np.ndarray, f: np.ndarray, density, max_pairs):
    size = float(np.abs(v - v.mean(axis=0)).max())
    normals = vertex_normals(v, f, "area", order="corners")
    centre = volume_centroid(v, f)
    if float(len(f)) * len(v) <= max_pairs:
        pot, acc = polyhedron_gravity(v, f, density, v + _OFFSET * size * normals)
        return pot, acc, centre, len(f), len(v)
    # the source's fidelity near the surface matters more than the points' density (the
    # field is smooth along the surface): keep every facet unless that leaves fewer than
    # _MIN_POINTS points, else decimate (measured on Eros: a half-decimated source tilts
    # the gravity ~1-2 deg, evaluating half the vertices of the full one ~0.1 deg)
    sv, sf = v, f
    min_points = min(_MIN_POINTS, len(v))
    if len(f) * min_points > max_pairs:
        import pyvista as pv

        mesh = pv.PolyData(v, np.hstack([np.full((len(f), 1), 3), f]).ravel())
        src = mesh.decimate(max(0.0, 1.0 - max_pairs / min_points / len(f)),
                            volume_preservation=True)
        sv = np.asarray(src.points, dtype=np.float64)
        sf = np.asarray(src.faces).reshape(-1, 4)[:, 1:]
    n_pts = max(min_points, int(max_pairs / len(sf)))
    pick = np.unique(np.linspace(0, len(v) - 1, min(n_pts, len(v))).astype(np.int64))
    pot_s, acc_s = polyhedron_gravity(sv, sf, density, v[pick] + _OFFSET * size * normals[pick])
    from scipy.spatial import cKDTree

    tree = cKDTree(v[pick])
    vals = np.concatenate([pot_s[:, None], acc_s], axis=1)
    out = np.empty((len(v), 4))
    step = 1 << 16
    for s in range(0, len(v), step):  # bounded memory
        _, nb = tree.query(v[s:s + step], k=min(_NEIGHBOURS, len(pick)))
        _local_linear_kernel(v[s:s + step], normals[s:s + step], v[pick], vals,
                             np.ascontiguousarray(nb, dtype=np.int64), out[s:s + step])
    return out[:, 0], out[:, 1:], centre, len(sf), len(pick)


def gravity(body_or_mesh, density_kg_m3: float, period_h: float = math.inf, *,
            spin_axis=(0.0, 0.0, 1.0), max_pairs: float = 3e7,
            lod_magnitude: int | None = None) -> GravityField:
    """Gravitational and effective (plus centrifugal) acceleration and potential at
    every vertex of a :class:`~latlong.Body` or :class:`~latlong.shapes.ShapeModel`.

    Parameters
    ----------
    body_or_mesh : Body, ShapeModel or another closed Surface
        Coordinates in metres; the mass is the enclosed volume times the density. A
        lat/long body is evaluated on a coarser grid of itself (module notes), any other
        surface on its mesh (:meth:`~latlong.geometry.surface.Surface.mesh`).
    density_kg_m3 : float
        Constant bulk density (Eros: 2670 kg/m^3, Yeomans et al. 2000).
    period_h : float
        Rotation period in hours; ``inf`` (default) for no rotation.
    spin_axis : (3,) floats
        Rotation axis (body frame), through the volume centroid; default +z.
    max_pairs : float
        Budget of facet x point evaluations of the polyhedron formula (~0.4 us each):
        sets the level of detail (bodies) or the decimation (meshes) when exceeded.
    lod_magnitude : int, optional
        Bodies: evaluate on this grid magnitude instead (>= the body's: exact).

    Examples
    --------
    >>> g = gravity(Body.sphere(LatLongGrid(16), 1000.0), 2000.0)
    >>> exact = 4 / 3 * math.pi * GRAVITATIONAL_CONSTANT * 2000.0 * 1000.0
    >>> bool(abs(np.linalg.norm(g.acceleration_m_s2, axis=1) / exact - 1).max() < 0.02)
    True
    """
    density_kg_m3 = check_positive("density_kg_m3", density_kg_m3)
    period_h = float(period_h)
    if not period_h > 0 or math.isnan(period_h):
        raise ParameterError("period_h", f"must be > 0 (inf: not rotating); got {period_h}")
    axis = _spin(spin_axis)
    max_pairs = check_positive("max_pairs", max_pairs)
    if isinstance(body_or_mesh, Body):
        if lod_magnitude is not None and (int(lod_magnitude) != lod_magnitude
                                          or lod_magnitude < 2):
            raise ParameterError("lod_magnitude", f"must be an integer >= 2; got "
                                 f"{lod_magnitude!r}")
        pot, acc, centre, n_f, n_p = _body_field(body_or_mesh, density_kg_m3, max_pairs,
                                                  lod_magnitude)
        pos = body_or_mesh.vertices()
    elif isinstance(body_or_mesh, Surface):
        pos, faces = body_or_mesh.mesh()
        pot, acc, centre, n_f, n_p = _mesh_field(pos, faces, density_kg_m3, max_pairs)
    else:
        raise TypeError("`body_or_mesh` must be a Body or ShapeModel (any closed Surface); "
                        f"got {type(body_or_mesh).__name__}")
    omega = 0.0 if math.isinf(period_h) else 2.0 * math.pi / (period_h * 3600.0)
    x = pos - centre
    # x . axis written out (a matrix-vector product goes to OpenBLAS: CPU-dependent bits)
    perp = x - np.outer(x[:, 0] * axis[0] + x[:, 1] * axis[1] + x[:, 2] * axis[2], axis)
    return GravityField(
        acceleration_m_s2=acc, potential_m2_s2=pot,
        effective_m_s2=acc + omega**2 * perp,
        effective_potential_m2_s2=pot + 0.5 * omega**2 * np.einsum("ij,ij->i", perp, perp),
        density_kg_m3=density_kg_m3, period_h=period_h,
        spin_axis=(float(axis[0]), float(axis[1]), float(axis[2])), source_facets=int(n_f),
        evaluated_points=int(n_p))
