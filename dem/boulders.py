"""Boulders on DEMs: populations over a raster, placement, heightfield stamping.

The boulder shapes and size laws are :mod:`craters.boulders` (Martin 2014, V.C). On a
DEM a boulder's up axis is the ground's normal averaged over its footprint (the mean
height gradient over the pixels within half its size), turned by its azimuth; it sinks
until its deepest vertex is ``burial_frac`` x its height below the ground (bilinear
between pixel centres; depth measured along the normal, as on a body), and it is
stamped into the heights as a **heightfield maximum**: each pixel whose centre lies
under the boulder (seen from above) keeps the higher of the ground and the boulder's top
there. Boulders smaller than ``min_px`` pixels are not resolved by the raster and are
left out (counted), as are boulders whose footprint leaves the raster or touches an
unknown (NaN) pixel.

Frames: positions ``x_m, y_m`` are in a :class:`dem.LocalFrame` (default: origin at the
DEM's centre pixel); the placement (``centre_*_m``, ``normal_*``, ``quat_*``) is in the
same frame with z = height (same datum as the DEM), so
:func:`craters.boulders.boulder_world_meshes` gives the boulders as meshes in the frame
:func:`dem.to_mesh` uses.
"""

from __future__ import annotations

import numpy as np

import craters
from craters._shared import check_range, normalize_rng
from craters.boulders import (
    BoulderLayer,
    BoulderShape,
    boulder_meshes,
    draw_boulder_layer,
    mesh_chunk,
    orientations,
    placed_columns,
    rest_on_ground,
)

from ._boulder_kernels import (
    _bilinear_kernel,
    _bilinear_serial_kernel,
    _raster_max_kernel,
    _window_gradient_kernel,
)
from .core import Dem
from .frame import LocalFrame, grid_pixel_size, pixel_affine, resolve_frame

__all__ = ["BOULDER_REACH", "boulder_population", "draw_boulders", "place_boulders",
           "stamp_boulders"]

#: Largest horizontal reach of a boulder from its centre, in diameters (unit longest
#: extent, centred on its bounding box: at most half the box diagonal).
BOULDER_REACH = 0.87


def _layers(layers) -> list[BoulderLayer]:
    if isinstance(layers, BoulderLayer | str):
        layers = [layers]
    out = [got for la in layers
           for got in (craters.parse_boulder_specs(la) if isinstance(la, str) else (la,))]
    if not out or not all(isinstance(la, BoulderLayer) for la in out):
        raise TypeError("`layers` must be BoulderLayer(s) or specs like "
                        "'c=0.01,k=-3,d_min_m=0.5,d_max_m=5'")
    return out


def draw_boulders(layers, x_range_m, y_range_m, *, rng=None) -> np.ndarray:
    """Boulders of power-law layers over a rectangle (planar positions ``x_m, y_m``).

    Counts are Poisson with mean area x c (d_min^k - d_max^k); columns ``x_m, y_m,
    diameter_m, burial_frac, azimuth_deg, seed, layer`` and ``kind = "boulder"``.
    """
    rng = normalize_rng(rng)
    (x0, x1), (y0, y1) = x_range_m, y_range_m
    area = (x1 - x0) * (y1 - y0)
    parts = []
    for idx, la in enumerate(_layers(layers)):
        cols = draw_boulder_layer(la, area, idx, rng)
        n = len(cols["diameter_m"])
        parts.append(craters.make_catalog(x_m=rng.uniform(x0, x1, n),
                                          y_m=rng.uniform(y0, y1, n), **cols))
    return np.concatenate(parts)


def boulder_population(dem: Dem, layers, *, frame: LocalFrame | None = None,
                       rng=None) -> np.ndarray:
    """A boulder catalog over the area of ``dem`` (positions in ``frame``, metres).

    Parameters
    ----------
    dem : Dem
    layers : BoulderLayer, spec string or a list of them
        ``N_cum = c D^k`` per m^2 (D in metres), see :class:`craters.BoulderLayer`.
    frame : LocalFrame, optional
        Default ``dem.local_frame(dem)``.
    rng
        Seed or Generator.
    """
    frame = resolve_frame(dem, frame)
    a = pixel_affine(dem, frame)
    p = grid_pixel_size(a, "the DEM")
    rows, cols = dem.shape
    cat = draw_boulders(layers, (0.0, (cols - 1) * p), (0.0, (rows - 1) * p), rng=rng)
    # grid frame -> local frame
    u, v = cat["x_m"] / p, cat["y_m"] / p
    cat["x_m"], cat["y_m"] = a.a * u + a.b * v + a.c, a.d * u + a.e * v + a.f
    return cat


def _bilinear(z, cols, rows):
    cols = np.ascontiguousarray(cols, dtype=np.float64).ravel()
    rows = np.ascontiguousarray(rows, dtype=np.float64).ravel()
    out = np.empty(len(cols))
    # a parallel region per small call stalls when the other core is busy
    (_bilinear_kernel if len(cols) >= 65536 else _bilinear_serial_kernel)(z, cols, rows, out)
    return out


def _ground_normals(z, nan, p: float, m: np.ndarray, xs, ys, ds) -> np.ndarray:
    """Unit ground normals (local frame, z up) at pixel positions ``xs, ys``: the mean
    height gradient (``numpy.gradient``, unknown pixels read as 0) over the pixels within
    half of each size ``ds``, summed window by window (no whole-raster arrays)."""
    rows, cols = z.shape
    half = np.maximum(np.rint(0.5 * ds / p), 1).astype(np.int64)
    ic, ir = np.rint(xs).astype(np.int64), np.rint(ys).astype(np.int64)
    r0, r1 = np.maximum(ir - half, 0), np.minimum(ir + half + 1, rows)
    c0, c1 = np.maximum(ic - half, 0), np.minimum(ic + half + 1, cols)
    mean = np.empty((len(ds), 2))
    _window_gradient_kernel(z, ~nan, float(p), r0, r1, c0, c1, mean)
    grad = mean @ m.T  # (dz/dx, dz/dy): m is orthogonal
    nrm = np.concatenate([-grad, np.ones((len(ds), 1))], axis=1)
    return nrm / np.linalg.norm(nrm, axis=1, keepdims=True)


def place_boulders(z, p: float, m: np.ndarray, t: np.ndarray, cat, *, shape: BoulderShape,
                   max_iterations: int = 12):
    """Place and stamp boulders on a height grid; positions ``x_m, y_m`` in a local frame
    where ``(x, y) = p m (col, row) + t`` (``m`` orthogonal 2 x 2, pixel side ``p``).

    Returns ``(heights, keep, placed)``: the new heights (a copy), which catalog rows
    were placed, and the placed rows with their placement in the local frame (x, y,
    z up; see :func:`stamp_boulders`).
    """
    z = np.ascontiguousarray(z, dtype=np.float64)
    rows, cols = z.shape
    minv = np.linalg.inv(m)

    def to_pixels(x, y):
        u = (np.stack([x, y], axis=-1) - t) @ minv.T / p
        return u[..., 0], u[..., 1]

    d = np.asarray(cat["diameter_m"], dtype=np.float64)
    cx, cy = to_pixels(np.asarray(cat["x_m"], float), np.asarray(cat["y_m"], float))
    reach = BOULDER_REACH * d / p + 1.0
    keep = (cx - reach >= 0) & (cx + reach <= cols - 1) & (cy - reach >= 0) & \
        (cy + reach <= rows - 1)
    # no unknown pixel under the footprint: integral image of the NaN mask
    nan = np.isnan(z)
    if nan.any():
        sat = np.zeros((rows + 1, cols + 1), dtype=np.int64)
        sat[1:, 1:] = nan.cumsum(0, dtype=np.int64).cumsum(1)
        idx = np.nonzero(keep)[0]
        r0 = np.floor(cy[idx] - reach[idx]).astype(int)
        r1 = np.ceil(cy[idx] + reach[idx]).astype(int) + 1
        c0 = np.floor(cx[idx] - reach[idx]).astype(int)
        c1 = np.ceil(cx[idx] + reach[idx]).astype(int) + 1
        bad = sat[r1, c1] - sat[r0, c1] - sat[r1, c0] + sat[r0, c0] > 0
        keep[idx[bad]] = False
    sel = np.nonzero(keep)[0]
    n = len(sel)
    out = z.copy()
    sub = cat[sel]
    ds, xs, ys = d[sel], cx[sel], cy[sel]
    nrm = _ground_normals(z, nan, p, m, xs, ys, ds) if n else np.zeros((0, 3))
    rot = orientations(nrm, np.radians(sub["azimuth_deg"]))
    ground = np.stack([sub["x_m"], sub["y_m"], _bilinear(z, xs, ys)], axis=1)

    def depths(points, normals):
        pc, pr = to_pixels(points[..., 0], points[..., 1])
        h = _bilinear(z, pc.ravel(), pr.ravel()).reshape(points.shape[:2])
        return (h - points[..., 2]) * normals[:, 2:3]

    centre = np.empty((n, 3))
    height, burial, achieved, top = np.empty(n), np.empty(n), np.empty(n), np.empty(n)
    settled = np.zeros(n, dtype=bool)
    chunk = mesh_chunk(shape)
    for s0 in range(0, n, chunk):
        sl = slice(s0, min(s0 + chunk, n))
        verts, faces_by_level = boulder_meshes(sub["seed"][sl], shape)
        world = np.einsum("kij,kvj->kvi", rot[sl], verts * ds[sl, None, None])
        centre[sl], achieved[sl], height[sl], burial[sl] = rest_on_ground(
            depths, world, ground[sl], nrm[sl], sub["burial_frac"][sl], ds[sl],
            max_iterations=max_iterations)
        # a boulder whose points left the raster while settling (extremely rough ground)
        # is left out like one off the grid: no floating or unmeasured boulders
        ok = np.abs(achieved[sl] - burial[sl]) <= 1e-6 * ds[sl]
        settled[sl] = ok
        # every boulder rests on the original ground; then the tops are stamped
        placed = world[ok] + centre[sl][ok, None, :]
        top[sl][ok] = placed[..., 2].max(axis=1)
        pc, pr = to_pixels(placed[..., 0], placed[..., 1])
        _raster_max_kernel(out, np.ascontiguousarray(np.stack([pc, pr, placed[..., 2]], -1)),
                           np.ascontiguousarray(faces_by_level[shape.levels[-1]],
                                                dtype=np.int64))
    keep[sel[~settled]] = False
    cols = placed_columns(sub[settled], centre[settled], nrm[settled], rot[settled],
                          height[settled], burial[settled], achieved[settled], shape)
    cols["top_m"] = top[settled]
    return out, keep, craters.make_catalog(**cols)


def stamp_boulders(dem: Dem, catalog, *, frame: LocalFrame | None = None,
                   shape: BoulderShape | None = None, min_px: float = 2.0,
                   return_catalog: bool = False):
    """Place boulders on a DEM and stamp them into its heights (heightfield maximum).

    Parameters
    ----------
    dem : Dem
        Square pixels (any CRS the DEM supports); not modified.
    catalog : structured array
        ``x_m, y_m`` (in ``frame``), ``diameter_m``, ``burial_frac``, ``azimuth_deg``,
        ``seed`` (e.g. :func:`boulder_population`).
    frame : LocalFrame, optional
        Default ``dem.local_frame(dem)``.
    shape : craters.BoulderShape, optional
    min_px : float
        Smallest diameter stamped, in pixels (the raster must resolve the boulder).
    return_catalog : bool
        Also return the placed boulders (``centre_*_m, normal_*, quat_*`` in ``frame``
        with z = height, ``height_m, burial_m, bottom_depth_m, top_m`` and the shape).

    Returns
    -------
    Dem, or (Dem, catalog)
        The stamped DEM (its history records how many boulders were given, stamped,
        too small for the pixels, off the raster or on unknown pixels) and, with
        ``return_catalog``, the catalog of the stamped boulders.
    """
    frame = resolve_frame(dem, frame)
    shape = BoulderShape() if shape is None else shape
    if not isinstance(shape, BoulderShape):
        raise TypeError(f"`shape` must be a BoulderShape; got {type(shape).__name__}")
    check_range("min_px", min_px, 0.0, 1e6)
    cat = np.asarray(catalog)
    for name in ("x_m", "y_m", "diameter_m", "burial_frac", "azimuth_deg", "seed"):
        if name not in (cat.dtype.names or ()):
            raise ValueError(f"boulder catalog needs a {name!r} column")
    a = pixel_affine(dem, frame)
    p = grid_pixel_size(a, "the DEM")
    m = np.array([[a.a, a.b], [a.d, a.e]]) / p
    resolved = np.nonzero(cat["diameter_m"] >= min_px * p)[0]
    z, keep, placed = place_boulders(dem.heights, p, m, np.array([a.c, a.f]), cat[resolved],
                                     shape=shape)
    rows_placed = resolved[keep]
    out = dem.with_step(z, "dem.stamp_boulders", None,
                        {"boulders": int(len(rows_placed)), "given": int(len(cat)),
                         "unresolved": int(len(cat) - len(resolved)),
                         "off_grid_or_unknown": int(len(resolved) - len(rows_placed)),
                         "min_px": float(min_px)})
    return (out, placed) if return_catalog else out
