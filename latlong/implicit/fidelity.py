"""How closely an implicit body's coarse surface follows its constraint
(:func:`shape_fidelity`): distances between the two surfaces, and the distribution of
*slope against a smoothed copy* on each.

Distances: ``n_points`` points uniform on each surface, the unsigned distance of each to
the other surface (VTK's implicit distance to the triangles); the mean and the 99th
percentile of both directions together.

Slope against a smoothed copy (a scale-selective roughness that shows bumps between the
two scales and nothing else): both surfaces are covered by ``8 n_points`` area-uniform
points carrying their face's normal; at ``n_points`` area-uniform query points the normal
averaged over the points closer than ``fine`` (x longest axis) is compared with the one
averaged closer than ``smooth`` (default 5 % of the axis); the angle between them is the
slope. Per-sphere domes of a metaball surface tilt their flanks against the smoothed
copy and widen this distribution; the constraint's own hills do so too, equally on both
surfaces. ``slope_ks`` is the two-sample Kolmogorov-Smirnov distance between the two
area-weighted distributions (the query points are area-uniform, so equal weights).
"""

from __future__ import annotations

import dataclasses

import numpy as np

from craters._shared import check_int, check_range, normalize_rng

from ..geometry.surface import Surface

__all__ = ["ShapeFidelity", "shape_fidelity"]


@dataclasses.dataclass(frozen=True, slots=True)
class ShapeFidelity:
    """Distances and slope-distribution distance of a surface to its constraint."""

    axis_m: float
    """Longest bounding-box side of the constraint, metres."""
    mean_m: float
    """Mean unsigned distance between the surfaces (both directions), metres."""
    p99_m: float
    """99th percentile of those distances, metres."""
    slope_ks: float
    """KS distance between the area-weighted distributions of slope against a smoothed
    copy on the surface and on the constraint."""
    slope_median_deg: tuple[float, float]
    """Median slope against the smoothed copy: (surface, constraint), degrees."""
    fine_m: float
    """Averaging radius of the local normal, metres."""
    smooth_m: float
    """Averaging radius of the smoothed copy's normal, metres."""

    @property
    def mean_fraction(self) -> float:
        """``mean_m`` / ``axis_m``."""
        return self.mean_m / self.axis_m

    @property
    def p99_fraction(self) -> float:
        """``p99_m`` / ``axis_m``."""
        return self.p99_m / self.axis_m


def _faces(mesh):
    verts, faces = mesh.mesh() if isinstance(mesh, Surface) else mesh
    return np.asarray(verts, np.float64), np.asarray(faces, np.int64)


def _sample(verts, faces, n, rng):
    """n area-uniform points and their faces' unit normals."""
    a, b, c = (verts[faces[:, k]] for k in range(3))
    cross = np.cross(b - a, c - a)
    area = np.linalg.norm(cross, axis=1)
    k = rng.choice(len(faces), n, p=area / area.sum())
    u, v = rng.random(n), rng.random(n)
    flip = u + v > 1
    u[flip], v[flip] = 1 - u[flip], 1 - v[flip]
    pts = a[k] + u[:, None] * (b[k] - a[k]) + v[:, None] * (c[k] - a[k])
    return pts, cross[k] / np.maximum(area[k], 1e-300)[:, None]


def _distances(points, verts, faces):
    import pyvista as pv

    flat = np.column_stack([np.full(len(faces), 3), faces]).ravel()
    target = pv.PolyData(verts, flat)
    return np.abs(pv.PolyData(points).compute_implicit_distance(target)["implicit_distance"])


def _slopes(verts, faces, n, fine, smooth, rng):
    """Angle (degrees) between the normal averaged within ``fine`` and within ``smooth``
    at n area-uniform query points."""
    from scipy.sparse import csr_matrix
    from scipy.spatial import cKDTree

    cloud, normal = _sample(verts, faces, 8 * n, rng)
    query, _ = _sample(verts, faces, n, rng)
    near = cKDTree(query).sparse_distance_matrix(cKDTree(cloud), smooth, output_type="coo_matrix")
    rows, cols, dist = near.row, near.col, near.data
    out = []
    for keep in (dist <= fine, np.ones(len(dist), bool)):
        m = csr_matrix((np.ones(int(keep.sum())), (rows[keep], cols[keep])),
                       shape=(n, len(cloud)))
        s = m @ normal
        out.append(s / np.maximum(np.linalg.norm(s, axis=1, keepdims=True), 1e-300))
    cos = np.clip(np.einsum("ij,ij->i", out[0], out[1]), -1.0, 1.0)
    return np.degrees(np.arccos(cos))


def shape_fidelity(surface, constraint, *, n_points: int = 20000, fine: float = 0.01,
                   smooth: float = 0.05, rng=0) -> ShapeFidelity:
    """Distances and slope-distribution distance between ``surface`` and ``constraint``
    (module notes).

    ``surface`` and ``constraint`` are surfaces (ShapeModel ...) or ``(vertices, faces)`` in the
    same frame (:attr:`ImplicitSurface.base_vertices` are in the frame of the constraint
    moved to its volume centroid). ``fine`` and ``smooth`` are fractions of the
    constraint's longest axis.
    """
    from scipy.stats import ks_2samp

    n_points = check_int("n_points", n_points, 100, 10**7)
    fine = check_range("fine", fine, 1e-4, 0.5)
    smooth = check_range("smooth", smooth, fine, 1.0)
    rng = normalize_rng(rng)
    sv, sf = _faces(surface)
    cv, cf = _faces(constraint)
    axis = float(np.ptp(cv, axis=0).max())
    d = np.concatenate([_distances(_sample(sv, sf, n_points, rng)[0], cv, cf),
                        _distances(_sample(cv, cf, n_points, rng)[0], sv, sf)])
    s_surf = _slopes(sv, sf, n_points, fine * axis, smooth * axis, rng)
    s_con = _slopes(cv, cf, n_points, fine * axis, smooth * axis, rng)
    return ShapeFidelity(axis, float(d.mean()), float(np.percentile(d, 99)),
                         float(ks_2samp(s_surf, s_con).statistic),
                         (float(np.median(s_surf)), float(np.median(s_con))),
                         fine * axis, smooth * axis)
