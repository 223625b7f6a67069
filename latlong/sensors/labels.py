"""Ground-truth labels of surface points: crater ids, boulder ids, projected rim ellipses.

Crater id of a surface point ``p`` (body frame): the catalog row of the crater whose rim
contains it. A crater with centre ``c`` (``centre_x_m, centre_y_m, centre_z_m``, on the
surface where it was stamped) and rim radius ``R`` (``rim_radius_m``, else
``diameter_m / 2``) contains ``p`` when

* the catalog has the crater's up axis ``normal_x, normal_y, normal_z`` (craters stamped
  on a mesh surface, LCSN craters): the distance from ``c`` measured in the crater's
  tangent plane, ``|(p - c) - ((p - c).n) n|``, is at most ``R`` and the height
  ``|(p - c).n|`` is at most ``R`` (a slab that keeps the far side of a small body out);
* otherwise (craters on a lat/long body, stamped around the body's origin): the arc
  ``|c| angle(p, c)`` is at most ``R`` (the distance the stamping kernel uses) and
  ``| |p| - |c| |`` is at most ``R``.

Where craters overlap the youngest wins, i.e. the **last row** of the catalog that
contains the point: catalogs are in stamping order (oldest first), and the youngest
crater is the one whose rim the surface shows. Irregular rims (the stamping's random
rim perturbation, a few per cent of ``R``) are not in the catalog: the label follows the
nominal circular rim. Ids are catalog rows (0-based), -1 for no crater; boulder ids are
boulder catalog rows from the mesh's per-triangle ``boulder_id`` (-1 on the surface).
The two are independent: a boulder inside a rim carries the crater's id as well.

Rim ellipses: the rim crest of each crater is the circle of radius ``R`` around ``c`` in
the crater's tangent plane (normal: the catalog's up axis, else the radial direction of
``c``), lifted by ``rim_height_m`` along the up axis when the catalog has it: the
stamping replaces the terrain inside the rim by a fitted plane plus the bowl, so the crest
stands ``rim_height_m`` above the tangent plane, not above the curved ground (on a 500 m
body a 40 m rim is 1.6 m above the sphere there; the arc of the label rule and the plane
radius differ by ``R^3 / (6 |c|^2)``, 4 cm). Its image through a pinhole camera is an
exact conic (the circle's plane maps to the image by a homography ``H = K [r e1, r e2,
centre]``; the unit circle ``diag(1, 1, -1)`` maps to ``H^-T diag(1, 1, -1) H^-1``),
an ellipse whenever the whole circle is in front of the camera. :func:`rim_curves` can
instead fit each rim's height and tilt to the stamped surface (the same homography
with the fitted axes), which follows worn, tilted and overprinted rims. Pixel coordinates are
OpenCV's with pixel centres at integer + 0.5: pixel (col i, row j) covers
``[i, i + 1) x [j, j + 1)`` and ``u = fx X / Z + cx``, ``v = fy Y / Z + cy``.
"""

from __future__ import annotations

import numpy as np

from craters._shared import ParameterError
from craters.exact import dot, matmul

from ..geometry.surface import Surface
from .camera import quaternion_to_matrix

__all__ = ["ELLIPSE_DTYPE", "FittedRims", "boulder_labels", "crater_labels", "rim_curves",
           "rim_ellipses", "surface_tree"]

#: Fields of :func:`rim_ellipses` (pixels; the angle of the major axis from +x towards
#: +y, i.e. clockwise on the picture, degrees in [0, 180)).
_GRID_CELLS = 128  # cells along the longest side of the points' box

ELLIPSE_DTYPE = np.dtype([("crater_id", "<i8"), ("centre_x_px", "<f8"), ("centre_y_px", "<f8"),
                          ("semi_major_px", "<f8"), ("semi_minor_px", "<f8"),
                          ("angle_deg", "<f8")])


def _centres_radii(catalog):
    names = catalog.dtype.names or ()
    if not all(k in names for k in ("centre_x_m", "centre_y_m", "centre_z_m")):
        raise ParameterError("catalog", "needs centre_x_m, centre_y_m, centre_z_m columns (a "
                             "catalog as stamped)")
    c = np.stack([catalog["centre_x_m"], catalog["centre_y_m"], catalog["centre_z_m"]],
                 1).astype(np.float64)
    if "rim_radius_m" in names:
        r = np.asarray(catalog["rim_radius_m"], dtype=np.float64)
    elif "diameter_m" in names:
        r = 0.5 * np.asarray(catalog["diameter_m"], dtype=np.float64)
    else:
        raise ParameterError("catalog", "needs rim_radius_m or diameter_m")
    normals = None
    if all(k in names for k in ("normal_x", "normal_y", "normal_z")):
        normals = np.stack([catalog["normal_x"], catalog["normal_y"], catalog["normal_z"]],
                           1).astype(np.float64)
        normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    return c, r, normals


def crater_labels(points, catalog) -> np.ndarray:
    """(k,) int64 crater id (catalog row) of each surface point, -1 outside every rim.

    Parameters
    ----------
    points : (k, 3) array_like
        Surface points in the body frame, metres (rows of NaN/inf give -1).
    catalog : structured array
        Craters as stamped (module notes for the columns and the overlap rule).

    Examples
    --------
    >>> import craters
    >>> cat = craters.make_catalog(x_m=[0.0, 0.0], y_m=[0.0, 0.0], diameter_m=[20.0, 4.0],
    ...                            centre_x_m=[100.0, 100.0], centre_y_m=[0.0, 4.0],
    ...                            centre_z_m=[0.0, 0.0])
    >>> crater_labels([[100.0, 0, 0], [99.0, 4.5, 0], [100.0, 30, 0]], cat).tolist()
    [0, 1, -1]
    """
    import numba

    from ._label_kernels import (  # numba loads here
        _bin_points_kernel,
        _finite_box_kernel,
        _label_kernel,
    )
    p = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    out = np.full(len(p), -1, dtype=np.int64)
    if catalog is None or not len(catalog) or not len(p):
        return out
    c, r, normals = _centres_radii(catalog)
    p = np.ascontiguousarray(p)
    finite = np.empty(len(p), dtype=np.bool_)
    lo, hi = np.zeros(3), np.zeros(3)
    n_ok = _finite_box_kernel(p, finite, lo, hi)
    if not n_ok:
        return out
    ok = slice(None) if n_ok == len(p) else np.flatnonzero(finite)
    q = p if n_ok == len(p) else np.ascontiguousarray(p[ok])
    reach = 2.0 * r[:, None]  # every point either rule accepts is within 2 R of the centre
    rows = np.flatnonzero(((c + reach >= lo) & (c - reach <= hi)).all(axis=1) & (r > 0))
    if not len(rows):
        return out
    h = max(float(np.max(hi - lo)) / _GRID_CELLS,
            1e-9 * max(1.0, float(np.abs(lo).max()), float(np.abs(hi).max())))
    dims = (np.floor((hi - lo) / h).astype(np.int64) + 1)
    offsets = np.zeros(int(np.prod(dims)) + 1, dtype=np.int64)
    order = np.empty(len(q), dtype=np.int64)
    _bin_points_kernel(q, lo, h, dims, offsets, order)
    sub = np.full(len(q), -1, dtype=np.int64)
    use = normals is not None
    _label_kernel(q, lo, h, dims, offsets, order, np.ascontiguousarray(c[rows]),
                  np.ascontiguousarray(r[rows]),
                  np.ascontiguousarray(normals[rows]) if use else np.zeros((len(rows), 3)),
                  use, numba.get_num_threads(), sub)
    out[ok] = np.where(sub >= 0, rows[np.maximum(sub, 0)], -1)
    return out


def boulder_labels(face, face_boulder_id) -> np.ndarray:
    """(k,) int64 boulder id of each hit (``face`` -1 = a miss) from the per-triangle
    ``face_boulder_id`` (-1 on the surface)."""
    face = np.asarray(face, dtype=np.int64)
    ids = np.asarray(face_boulder_id, dtype=np.int64)
    return np.where(face >= 0, ids[np.maximum(face, 0)], -1)


def rim_curves(catalog, surface=None, *, ids=None):
    """The rim crest of each crater as a planar curve in 3-D: ``(centres (n, 3), axis1
    (n, 3), axis2 (n, 3))`` in the body frame, metres; the rim's points are ``centre +
    cos(theta) axis1 + sin(theta) axis2``.

    Without ``surface``: the circle of radius ``R`` in the tangent plane lifted by
    ``rim_height_m`` (module notes). With ``surface`` (a :class:`SceneGeometry`, whose
    boulders are left out, or an (n, 3) array of surface vertices): fitted to the surface
    as stamped - the plane ``h = a + b x + c y`` (heights along the up axis, x and y in
    the tangent plane) of the vertices whose in-plane distance from the centre is within
    5 % of ``R`` (15 % when fewer than 8 are), i.e. the crest's actual height and tilt
    (craters on slopes or inside older craters, worn or overprinted rims); the rim is that
    plane cut by the cylinder of radius ``R`` about the up axis. Craters with too few
    vertices keep the catalog rule. ``ids`` (catalog rows) limits the fit to those craters
    (the others keep the catalog rule): a frame's visible craters, not a whole catalog.
    """
    c, r, normals = _centres_radii(catalog)
    up = normals if normals is not None else c / np.linalg.norm(c, axis=1, keepdims=True)
    e1, e2 = _basis(up)
    a = np.asarray(catalog["rim_height_m"], dtype=np.float64).copy() \
        if "rim_height_m" in catalog.dtype.names else np.zeros(len(c))
    tilt = np.zeros((len(c), 2))
    if surface is not None and len(c):
        tree = surface_tree(surface)
        verts = tree.data
        rows = np.arange(len(c)) if ids is None else np.unique(np.asarray(ids, np.int64))
        rows = rows[(rows >= 0) & (rows < len(c))]
        for i, near in zip(rows, tree.query_ball_point(c[rows], 1.6 * r[rows]), strict=True):
            d = verts[np.asarray(near, dtype=np.int64)] - c[i]
            h, x, y = matmul(d, np.stack([up[i], e1[i], e2[i]], axis=1)).T
            rho = np.hypot(x, y)
            for width in (0.05, 0.15):
                ring = (np.abs(rho - r[i]) <= width * r[i]) & (np.abs(h) <= r[i])
                if ring.sum() >= 8:
                    ok, a_i, b_i, c_i = _plane_of(x[ring], y[ring], h[ring], r[i])
                    if ok:
                        a[i], tilt[i, 0], tilt[i, 1] = a_i, b_i, c_i
                        break
    return (c + a[:, None] * up, r[:, None] * (e1 + tilt[:, :1] * up),
            r[:, None] * (e2 + tilt[:, 1:] * up))


def _plane_of(x, y, h, scale_m: float) -> tuple[bool, float, float, float]:
    """(ok, a, b, c): the least-squares plane ``h = a + b x + c y`` of the points from their
    sums in order and cofactors (``craters.kernels.plane_solve``): the same bits on every
    CPU, where LAPACK's ``lstsq`` varies with the kernels OpenBLAS picks. x and y are
    divided by ``scale_m`` (the rim radius) first, so the degeneracy test does not depend
    on the crater's size (a 1 mm ring in metres would fail it)."""
    u, v = x / scale_m, y / scale_m
    one = np.ones(len(u))
    s = (float(len(u)), dot(u, one), dot(v, one), dot(u, u), dot(v, v), dot(u, v),
         dot(h, one), dot(h, u), dot(h, v))
    big = max(s[3], s[4], 1.0)
    from craters.kernels import plane_solve  # numba loads here

    ok, a, b, c = plane_solve(s, s[0] * big * big)
    return bool(ok), float(a), float(b) / scale_m, float(c) / scale_m


class FittedRims:
    """:func:`rim_curves` of a catalog fitted to a surface on demand and kept: each
    crater is fitted once, the first time a frame sees it (a fit depends on the crater
    alone, so the arrays equal ``rim_curves(catalog, surface, ids=...)`` on those ids)."""

    def __init__(self, catalog, surface):
        self._catalog = catalog
        self._tree = surface_tree(surface)
        self._rims = tuple(np.array(a) for a in rim_curves(catalog))  # the catalog rule
        self._fitted = np.zeros(len(catalog), dtype=np.bool_)

    def __call__(self, ids):
        """The rims (centres, axis1, axis2), with the craters ``ids`` fitted."""
        ids = np.unique(np.asarray(ids, dtype=np.int64))
        new = ids[~self._fitted[ids]]
        if len(new):
            fresh = rim_curves(self._catalog, self._tree, ids=new)
            for mine, theirs in zip(self._rims, fresh, strict=True):
                mine[new] = theirs[new]
            self._fitted[new] = True
        return self._rims


def surface_tree(surface):
    """A ``scipy.spatial.cKDTree`` of a surface's vertices (a :class:`SceneGeometry` without
    its boulders, or (n, 3) vertices), to share between :func:`rim_curves` calls (a tree
    given is returned as it is)."""
    from scipy.spatial import cKDTree  # scipy.spatial loads argparse: only when used

    if isinstance(surface, cKDTree):
        return surface
    return cKDTree(_surface_vertices(surface))


def _surface_vertices(surface) -> np.ndarray:
    if isinstance(surface, Surface):  # a SceneGeometry ...: the boulders' left out
        vertices, faces = surface.mesh()
        used = np.zeros(len(vertices), dtype=np.bool_)
        used[faces.ravel()] = True  # the rows np.unique(faces) gives, in its order
        return vertices[used]
    verts = np.asarray(surface, dtype=np.float64)
    if verts.ndim != 2 or verts.shape[1] != 3:
        raise ParameterError("surface", f"must be a SceneGeometry or (n, 3) vertices; got "
                             f"shape {verts.shape}")
    return verts


def _basis(n):
    a = np.where(np.abs(n[:, :1]) < 0.9, [[1.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]])
    e1 = np.cross(n, a)
    e1 /= np.linalg.norm(e1, axis=1, keepdims=True)
    return e1, np.cross(n, e1)


def _conic_ellipse(q):
    """(cx, cy, a, b, angle_deg) of the ellipse x^T q x = 0, or None if not an ellipse."""
    m = q[:2, :2]
    try:
        centre = np.linalg.solve(m, -q[:2, 2])
    except np.linalg.LinAlgError:
        return None
    k = -(q[2, 2] + q[:2, 2] @ centre)
    lam, vec = np.linalg.eigh(m / k)
    if not (lam > 0).all():
        return None
    a, b = 1.0 / np.sqrt(lam)  # eigh: ascending, so a (from the smaller lam) is major
    angle = np.degrees(np.arctan2(vec[1, 0], vec[0, 0])) % 180.0
    return centre[0], centre[1], a, b, angle


def rim_ellipses(catalog, intrinsics, position_m, quaternion_wxyz, *, ids=None,
                 width: int | None = None, height: int | None = None,
                 rims=None) -> np.ndarray:
    """The projected rim ellipse of each crater in front of a pinhole camera.

    Parameters
    ----------
    catalog : structured array
        Craters as stamped (module notes).
    intrinsics : (fx, fy, cx, cy)
        Pinhole intrinsics, pixels (pixel centres at integer + 0.5).
    position_m, quaternion_wxyz
        The camera pose: position in the body frame (metres) and the camera-to-body
        rotation (OpenCV camera frame: x right, y down, z forward).
    ids : array_like of int, optional
        Only these craters (e.g. the ids present in a label image: the visible ones).
    width, height : int, optional
        With both, only ellipses whose bounding box meets the picture are kept.
    rims : tuple, optional
        :func:`rim_curves` of the catalog, e.g. fitted to the model's surface once and
        shared by the frames (default: ``rim_curves(catalog)``, the catalog rule).

    Returns
    -------
    structured array of :data:`ELLIPSE_DTYPE`, one row per crater whose whole rim is in
    front of the camera, in catalog order.
    """
    fx, fy, cx, cy = (float(v) for v in intrinsics)
    k_mat = np.array([[fx, 0.0, cx], [0.0, fy, cy], [0.0, 0.0, 1.0]])
    rot = quaternion_to_matrix(quaternion_wxyz)
    t = np.asarray(position_m, dtype=np.float64).reshape(3)
    out = np.zeros(0, ELLIPSE_DTYPE)
    if catalog is None or not len(catalog):
        return out
    centres, axis1, axis2 = rim_curves(catalog) if rims is None else rims
    rows = np.arange(len(centres)) if ids is None else np.unique(np.asarray(ids, np.int64))
    rows = rows[(rows >= 0) & (rows < len(centres))]
    cc = (centres[rows] - t) @ rot  # camera frame: R^T (x - t)
    a1, a2 = axis1[rows] @ rot, axis2[rows] @ rot
    keep = []
    for i, row in enumerate(rows):
        if cc[i, 2] - np.hypot(a1[i, 2], a2[i, 2]) <= 0.0:
            continue  # part of the rim behind the camera: no ellipse
        h = k_mat @ np.stack([a1[i], a2[i], cc[i]], 1)
        hinv = np.linalg.inv(h)
        e = _conic_ellipse(hinv.T @ np.diag([1.0, 1.0, -1.0]) @ hinv)
        if e is None:
            continue
        if width is not None and height is not None:
            ext = e[2]  # the semi-major axis bounds the ellipse
            if e[0] + ext < 0 or e[0] - ext > width or e[1] + ext < 0 or e[1] - ext > height:
                continue
        keep.append((int(row), *e))
    return np.array(keep, dtype=ELLIPSE_DTYPE) if keep else out
