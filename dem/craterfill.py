r"""Crater gap filling and crater replacement (Martin, Parkes & Dunstan 2014, IV.C and IV.D).

Crater positions are metres in a local frame (:mod:`dem.frame`): by default the DEM's own
(origin at its centre pixel), or the stack's (origin at the site). Convert world
coordinates with ``frame.to_local(X, Y)``.

Crater gap filling (:func:`fill_crater_gaps`)
---------------------------------------------
Unknown pixels inside crater interiors (e.g. shadowed floors) are filled with a synthetic
crater warped to blend into the known terrain:

1. a copy of the DEM around the craters has all its gaps filled with fractal terrain
   (:func:`dem.fill_gaps`) and the craters stamped into it (``craters.stamp_many``: the
   plane fitted to the obliterated region, the Martin profile, roughness); this copy
   has craters of the right shape that do not meet the known terrain;
2. the *warp* ``c`` is the mismatch ``known - copy`` at the known pixels next to the
   filled region, continued into it as a harmonic function (the discrete Laplace
   equation, 4-neighbours: ``c`` at each filled pixel is the mean of its neighbours';
   known neighbours give the mismatch, unknown pixels outside the region are left out
   -- a natural boundary); the filled pixels get ``copy + c``.

A harmonic field is the smoothest continuation of the border mismatch (it minimises the
Dirichlet energy): an offset or tilt of the whole rim is carried into the floor
unchanged, pixel-scale disagreements fade within a few pixels of the border (a boundary
wave of wavelength ``l`` decays as ``exp(-2 pi d / l)`` inward). So the result meets
the known terrain without steps and keeps the synthetic crater's shape inside. (The
paper warps with an inverse-distance average of the nearest known mismatches along 8
directions, which is continuous too but leaves star-shaped ridges.) Regions without a
known neighbour get no warp. Known pixels are returned bit for bit; unknown pixels
outside the craters stay unknown.

Crater replacement (:func:`replace_crater`)
-------------------------------------------
A blurred crater (e.g. after several expansions) is replaced by a sharp synthetic one:
every pixel within the crater's reach (ejecta edge 1.5 D, times 1 + rim irregularity)
is erased and refilled with fractal terrain continued from the surroundings
(:func:`dem.fill_gaps`, without its gap craters), then the crater is stamped on it (plane fit,
profile, ejecta that ends on the terrain at the ejecta edge), so it blends into the
untouched terrain beyond the ejecta edge. In a :class:`dem.Stack` the crater goes into
the finest layer that contains its reach (plus one pixel), and the change is
propagated so the layers still match exactly: *up*, coarser footprints take the finer
layer's even pixels; *down*, each finer layer gets the change of its parent
interpolated bilinearly (its even pixels set exactly to the parent's), keeping its own
detail. The crater is added to that layer's catalog with kind ``replacement``.
"""

from __future__ import annotations

import math

import numpy as np
from rasterio.windows import Window

import craters
from craters._shared import check_range, normalize_rng

from .core import Dem
from .frame import LocalFrame, grid_affine, grid_pixel_size, pixel_affine, resolve_frame
from .gaps import fill_gaps
from .stack import Stack, propagate_up

__all__ = ["fill_crater_gaps", "replace_crater"]

#: Screening of the warp equation (relative to the Laplacian's diagonal): makes regions
#: with no known neighbour well posed (warp 0) and changes the others by < 1e-6.
_SCREEN = 1e-9
_IRREGULARITY = 0.02  # craters.stamp_many's default rim irregularity


def _as_catalog(cat) -> np.ndarray:
    """A planar catalog from a structured array or a sequence of craters.Crater."""
    if isinstance(cat, craters.Crater):
        cat = [cat]
    if isinstance(cat, np.ndarray) and cat.dtype.names is not None:
        craters.validate_catalog(cat)
        if "x_m" not in cat.dtype.names:
            raise ValueError("`craters` needs local-frame positions x_m, y_m (metres)")
        return cat
    try:
        items = list(cat)
    except TypeError:
        raise TypeError("`craters` must be a catalog (structured array with x_m, y_m, "
                        "diameter_m) or a sequence of craters.Crater") from None
    if not items or not all(isinstance(c, craters.Crater) for c in items):
        raise TypeError("`craters` must be a catalog or a non-empty sequence of craters.Crater")
    return craters.make_catalog(x_m=[c.x_m for c in items], y_m=[c.y_m for c in items],
                                diameter_m=[c.diameter_m for c in items],
                                degradation=[c.degradation for c in items])


def _grid_positions(dem: Dem, frame: LocalFrame, x_m, y_m):
    """Pixel size and grid-frame positions (metres) of local-frame points on ``dem``."""
    a = pixel_affine(dem, frame)
    p = grid_pixel_size(a)
    g = grid_affine(a, p)
    x_m = np.asarray(x_m, dtype=np.float64)
    y_m = np.asarray(y_m, dtype=np.float64)
    return p, g.a * x_m + g.b * y_m + g.c, g.d * x_m + g.e * y_m + g.f


def _bbox(cx_px, cy_px, r_px, shape, margin: int) -> tuple[int, int, int, int]:
    """Clipped (r0, r1, c0, c1), end-exclusive, of discs around pixel positions."""
    rows, cols = shape
    r0 = max(int(math.floor(np.min(cy_px - r_px))) - margin, 0)
    r1 = min(int(math.ceil(np.max(cy_px + r_px))) + margin + 1, rows)
    c0 = max(int(math.floor(np.min(cx_px - r_px))) - margin, 0)
    c1 = min(int(math.ceil(np.max(cx_px + r_px))) + margin + 1, cols)
    return r0, r1, c0, c1


def _discs(shape, offset, cx_px, cy_px, r_px) -> np.ndarray:
    """Mask of the pixels (of a window at ``offset``) within ``r_px`` of any centre."""
    mask = np.zeros(shape, dtype=bool)
    for x, y, r in zip(cx_px, cy_px, r_px, strict=True):
        r0, r1, c0, c1 = _bbox(np.array([x - offset[1]]), np.array([y - offset[0]]),
                               np.array([r]), shape, 0)
        if r0 >= r1 or c0 >= c1:
            continue
        yy, xx = np.mgrid[r0:r1, c0:c1]
        mask[r0:r1, c0:c1] |= ((yy + offset[0] - y) ** 2 + (xx + offset[1] - x) ** 2
                               <= r * r)
    return mask


def harmonic_warp(z: np.ndarray, synth: np.ndarray, region: np.ndarray) -> np.ndarray:
    """The warp field of the module notes: harmonic on ``region``, ``z - synth`` at known
    4-neighbours (finite ``z``), natural boundary at unknown ones; 0 outside ``region``.

    Examples
    --------
    >>> z = np.zeros((3, 5)); z[:, 1:4] = np.nan
    >>> synth = np.zeros((3, 5)); synth[:, 4] = -4.0       # mismatch 0 left, 4 right
    >>> region = np.isnan(z)
    >>> harmonic_warp(z, synth, region)[1].round(6).tolist()  # linear in between
    [0.0, 1.0, 2.0, 3.0, 0.0]
    """
    import scipy.sparse  # scipy at import time would load argparse (through unittest)
    import scipy.sparse.linalg

    rows, cols = z.shape
    n = int(region.sum())
    out = np.zeros(z.shape)
    if n == 0:
        return out
    idx = np.full(z.shape, -1, dtype=np.int64)
    idx[region] = np.arange(n)
    known = np.isfinite(z)
    diag = np.zeros(n)
    rhs = np.zeros(n)
    i_parts: list[np.ndarray] = []
    j_parts: list[np.ndarray] = []
    pr, pc = np.nonzero(region)
    for dr, dc in ((-1, 0), (1, 0), (0, -1), (0, 1)):
        qr, qc = pr + dr, pc + dc
        ok = (qr >= 0) & (qr < rows) & (qc >= 0) & (qc < cols)
        p_i = idx[pr[ok], pc[ok]]
        qr, qc = qr[ok], qc[ok]
        inner = region[qr, qc]
        diag[p_i[inner]] += 1.0
        i_parts.append(p_i[inner])
        j_parts.append(idx[qr[inner], qc[inner]])
        border = ~inner & known[qr, qc]
        diag[p_i[border]] += 1.0
        np.add.at(rhs, p_i[border], z[qr[border], qc[border]] - synth[qr[border], qc[border]])
    i_off = np.concatenate(i_parts)
    j_off = np.concatenate(j_parts)
    rows_i = np.concatenate([np.arange(n), i_off])
    cols_j = np.concatenate([np.arange(n), j_off])
    vals = np.concatenate([diag + _SCREEN * np.maximum(diag, 1.0), -np.ones(i_off.size)])
    a = scipy.sparse.csc_matrix((vals, (rows_i, cols_j)), shape=(n, n))
    out[region] = scipy.sparse.linalg.spsolve(a, rhs)
    return out


def fill_crater_gaps(dem: Dem, craters_, *, frame: LocalFrame | None = None,
                     extent: float = 1.0, roughness: float | None = None,
                     smooth_craters: bool = False, rng=None, return_catalog: bool = False):
    """Fill the unknown pixels inside crater interiors with warped synthetic craters.

    See the module notes. Known pixels are unchanged bit for bit; unknown pixels farther
    than ``extent`` radii from every crater centre stay unknown (fill them afterwards
    with :func:`dem.fill_gaps`).

    Parameters
    ----------
    dem : Dem
    craters_ : structured array or sequence of craters.Crater
        The craters (``x_m, y_m`` in ``frame``, ``diameter_m``, optional ``degradation``,
        ``age_gyr``), stamped oldest first.
    frame : LocalFrame, optional
        Frame of the positions; default ``dem.local_frame(dem)`` (origin at the centre
        pixel).
    extent : float
        Radius of the region filled around each crater, in crater radii (0.1..1.5).
    roughness : float, optional
        Noise of the fractal base fill (see :func:`dem.fill_gaps`); default from the
        known terrain.
    smooth_craters : bool
        Ideal craters (no fractal overlay, circular rims).
    rng : int, numpy.random.Generator or None
    return_catalog : bool
        Also return the catalog of the craters as stamped (positions in ``frame``).

    Returns
    -------
    Dem (and the stamped catalog if ``return_catalog``).

    Notes
    -----
    The craters are real ones the user identified, so they are stamped whatever the
    slope of the ground (no slope erosion).

    Examples
    --------
    >>> import craters
    >>> crater = craters.Crater(200.0, 200.0, 200.0)      # grid frame of stamp()
    >>> truth = craters.stamp(np.zeros((41, 41)), 10.0, crater, roughness=False)
    >>> z = truth.copy(); z[15:26, 15:26] = np.nan          # the floor is unknown
    >>> d = Dem(z, pixel_size_m=10.0)                       # centre pixel (20, 20)
    >>> f = fill_crater_gaps(d, [craters.Crater(0.0, 0.0, 200.0)], smooth_craters=True,
    ...                      rng=1)
    >>> round(float(truth[20, 20]), 1), round(float(f.heights[20, 20]), 1)
    (-26.2, -26.2)
    """
    frame = resolve_frame(dem, frame)
    cat = craters.sort_oldest_first(_as_catalog(craters_))
    extent = check_range("extent", extent, 0.1, 1.5)
    gen = normalize_rng(rng)
    seed = _seed_of(rng)
    p, gx, gy = _grid_positions(dem, frame, cat["x_m"], cat["y_m"])
    fill = _discs(dem.shape, (0, 0), gx / p, gy / p, extent * cat["diameter_m"] / 2.0 / p)
    fill &= ~dem.known
    params = {"craters": len(cat), "extent": extent, "smooth_craters": smooth_craters,
              "filled_pixels": int(fill.sum())}
    if not fill.any():
        out = dem.with_step(np.array(dem.heights), "dem.fill_crater_gaps", seed, params)
        return (out, cat[:0]) if return_catalog else out
    r0, r1, c0, c1 = _work_window(fill, gx / p, gy / p, cat["diameter_m"], p, smooth_craters)
    crop = dem.crop(Window(c0, r0, c1 - c0, r1 - r0))
    names = cat.dtype.names
    assert names is not None  # a catalog: a structured array
    local = {name: cat[name] for name in names}
    local.update(x_m=gx - c0 * p, y_m=gy - r0 * p)
    synth, stamped = _synthetic_copy(crop, p, craters.make_catalog(**local), roughness,
                                     smooth_craters, _IRREGULARITY, gen)
    z, params["warp_max_abs_m"] = _blend(dem, synth, fill, (r0, r1, c0, c1))
    out = dem.with_step(z, "dem.fill_crater_gaps", seed, params)
    if not return_catalog:
        return out
    stamped["x_m"] = cat["x_m"]  # every crater is stamped, in this order (no erosion)
    stamped["y_m"] = cat["y_m"]
    return out, stamped


def _blend(dem: Dem, synth: np.ndarray, fill: np.ndarray, window) -> tuple[np.ndarray, float]:
    """Step 2 of the module notes: the heights of ``dem`` with its pixels ``fill`` taken
    from ``synth`` (the synthetic copy of the ``window`` (r0, r1, c0, c1)) plus the
    harmonic warp; and the warp's largest magnitude (m)."""
    r0, r1, c0, c1 = window
    region = fill[r0:r1, c0:c1]
    warp = harmonic_warp(dem.heights[r0:r1, c0:c1], synth, region)
    z = np.array(dem.heights)
    block = z[r0:r1, c0:c1]
    block[region] = synth[region] + warp[region]
    return z, float(np.abs(warp[region]).max())


def _seed_of(rng) -> int | None:
    """The seed a step records: ``rng`` when it is an int, else None."""
    return int(rng) if rng is not None and not isinstance(rng, np.random.Generator) else None


def _work_window(fill: np.ndarray, cx_px, cy_px, diameter_m, pixel_size_m: float,
                 smooth: bool):
    """(r0, r1, c0, c1) of the pixels ``fill`` and the reach of the craters (centres in
    pixels; the ejecta edge times 1 + rim irregularity), plus 2 pixels."""
    irr = 0.0 if smooth else _IRREGULARITY
    reach = craters.DEFAULT_EJECTA_EDGE * (1.0 + irr) * diameter_m / 2.0 / pixel_size_m
    r0, r1, c0, c1 = _bbox(cx_px, cy_px, reach, fill.shape, 2)
    fr, fc = np.nonzero(fill)
    return (min(r0, fr.min()), max(r1, fr.max() + 1), min(c0, fc.min()),
            max(c1, fc.max() + 1))


def _synthetic_copy(crop: Dem, pixel_size_m: float, cat, roughness, smooth: bool,
                    irregularity: float, gen):
    """``crop`` with its gaps filled by fractal terrain and the craters of ``cat`` (grid
    frame) stamped on it, whatever the slope; the heights and the stamped catalog."""
    base = fill_gaps(crop, roughness, craters=None, rng=gen)
    return craters.stamp_many(base.heights, pixel_size_m, cat, roughness=not smooth,
                              irregularity=irregularity, slope_erosion=False, rng=gen,
                              return_catalog=True)


def _replace_in_layer(d: Dem, frame: LocalFrame, crater, *, roughness, smooth, gen):
    """New heights of ``d`` with ``crater`` replaced; the stamped catalog row."""
    p, gx, gy = _grid_positions(d, frame, [crater.x_m], [crater.y_m])
    irr = 0.0 if smooth else crater.irregularity
    reach = craters.DEFAULT_EJECTA_EDGE * (1.0 + irr) * crater.diameter_m / 2.0 / p
    cx, cy = float(gx[0] / p), float(gy[0] / p)
    margin = max(4, int(math.ceil(0.1 * reach)))
    r0, r1, c0, c1 = _bbox(np.array([cx]), np.array([cy]), np.array([reach]), d.shape, margin)
    crop = d.crop(Window(c0, r0, c1 - c0, r1 - r0))
    disc = _discs(crop.shape, (r0, c0), [cx], [cy], [reach])
    erased = crop.replace(heights=np.where(disc, np.nan, crop.heights))
    cat = craters.make_catalog(x_m=[gx[0] - c0 * p], y_m=[gy[0] - r0 * p],
                               diameter_m=[crater.diameter_m],
                               degradation=[crater.degradation], kind=["replacement"],
                               layer=[-1], index=[0])
    synth, stamped = _synthetic_copy(erased, p, cat, roughness, smooth, irr, gen)
    z = np.array(d.heights)
    block = z[r0:r1, c0:c1]
    block[disc] = synth[disc]
    stamped["x_m"] = crater.x_m
    stamped["y_m"] = crater.y_m
    return z, stamped


def _contains(d: Dem, frame: LocalFrame, crater, smooth: bool) -> bool:
    """The crater's reach plus one pixel is clear of ``d``'s border pixels."""
    p, gx, gy = _grid_positions(d, frame, [crater.x_m], [crater.y_m])
    irr = 0.0 if smooth else crater.irregularity
    reach = craters.DEFAULT_EJECTA_EDGE * (1.0 + irr) * crater.diameter_m / 2.0 + p
    rows, cols = d.shape
    x, y = float(gx[0]), float(gy[0])
    return reach <= x <= (cols - 1) * p - reach and reach <= y <= (rows - 1) * p - reach


def _upsample(delta: np.ndarray) -> np.ndarray:
    """Bilinear 2x upsampling onto the (2n - 1) grid whose even pixels are ``delta``."""
    n_r, n_c = delta.shape
    up = np.empty((2 * n_r - 1, 2 * n_c - 1))
    up[::2, ::2] = delta
    up[1::2, ::2] = 0.5 * (delta[:-1] + delta[1:])
    up[::2, 1::2] = 0.5 * (delta[:, :-1] + delta[:, 1:])
    up[1::2, 1::2] = 0.25 * (delta[:-1, :-1] + delta[1:, :-1] + delta[:-1, 1:] + delta[1:, 1:])
    return up


def _append(cat, row: np.ndarray) -> np.ndarray:
    if cat is None:
        return row
    out = np.zeros(len(cat) + 1, dtype=cat.dtype)
    out[:-1] = cat
    names, row_names = cat.dtype.names, row.dtype.names
    assert names is not None and row_names is not None  # catalog rows: structured arrays
    for name in names:
        if name in row_names:
            out[name][-1] = row[name][0]
    return out


def replace_crater(target, crater, *, frame: LocalFrame | None = None,
                   roughness: float | None = None, smooth_craters: bool = False, rng=None):
    """Replace a (blurred) crater by a sharp synthetic one; in a stack, keep layers matching.

    See the module notes.

    Parameters
    ----------
    target : Dem or Stack
    crater : craters.Crater
        Centre ``x_m, y_m`` in the frame (a Dem's own local frame, or the stack's),
        rim diameter, degradation and rim irregularity of the new crater.
    frame : LocalFrame, optional
        Only for a Dem: the frame of the position (default ``dem.local_frame(dem)``).
    roughness : float, optional
        Noise of the fractal refill (see :func:`dem.fill_gaps`).
    smooth_craters : bool
        An ideal crater (no fractal overlay, circular rim).
    rng : int, numpy.random.Generator or None

    Returns
    -------
    Dem or Stack
        A new object; a stack gets the crater in the catalog of the layer it went into.

    Examples
    --------
    >>> import craters
    >>> d = Dem(np.zeros((61, 61)), pixel_size_m=10.0)
    >>> r = replace_crater(d, craters.Crater(0.0, 0.0, 150.0), smooth_craters=True, rng=0)
    >>> round(float(r.heights[30, 30]), 1), float(r.heights[0, 0])
    (-18.6, 0.0)
    """
    if not isinstance(crater, craters.Crater):
        raise TypeError(f"`crater` must be a craters.Crater; got {type(crater).__name__}")
    gen = normalize_rng(rng)
    seed = _seed_of(rng)
    params = {"x_m": crater.x_m, "y_m": crater.y_m, "diameter_m": crater.diameter_m,
              "degradation": crater.degradation, "smooth_craters": smooth_craters}
    if isinstance(target, Dem):
        frame = resolve_frame(target, frame)
        if not _contains(target, frame, crater, smooth_craters):
            raise ValueError(f"the crater (diameter {crater.diameter_m:g} m at x_m "
                             f"{crater.x_m:g}, y_m {crater.y_m:g}) with its ejecta does not "
                             f"fit inside the DEM")
        z, _ = _replace_in_layer(target, frame, crater, roughness=roughness,
                                 smooth=smooth_craters, gen=gen)
        return target.with_step(z, "dem.replace_crater", seed, params)
    if not isinstance(target, Stack):
        raise TypeError(f"`target` must be a Dem or a Stack; got {type(target).__name__}")
    if frame is not None:
        raise ValueError("`frame` is only for a Dem; a stack's craters are in stack.frame")
    return _replace_in_stack(target, crater, roughness=roughness, smooth=smooth_craters,
                             gen=gen, seed=seed, params=params)


def _replace_in_stack(stack: Stack, crater, *, roughness, smooth: bool, gen, seed,
                      params: dict) -> Stack:
    """The stack with ``crater`` replaced in the finest layer that holds its reach, the
    change carried up and down so the layers still match, the crater in its catalog."""
    frame = stack.frame
    layers = stack.layers
    home = next((k for k in range(len(layers) - 1, -1, -1)
                 if _contains(layers[k], frame, crater, smooth)), None)
    if home is None:
        raise ValueError(f"the crater (diameter {crater.diameter_m:g} m at x_m {crater.x_m:g}, "
                         f"y_m {crater.y_m:g}) with its ejecta does not fit inside any layer")
    z, row = _replace_in_layer(layers[home], frame, crater, roughness=roughness,
                               smooth=smooth, gen=gen)
    arrays = [np.array(d.heights) for d in layers]
    arrays[home] = z
    propagate_up(arrays, stack.windows, home)
    _propagate_down(arrays, stack, home)
    params["layer"] = home
    new_layers = [d if np.array_equal(arrays[k], d.heights) else
                  d.with_step(arrays[k], "dem.replace_crater", seed, params)
                  for k, d in enumerate(layers)]
    catalogs = list(stack.catalogs)
    cat = catalogs[home]
    row["index"] = max((int(c["index"].max()) for c in catalogs
                        if c is not None and len(c) and "index" in c.dtype.names),
                       default=-1) + 1
    catalogs[home] = _append(cat, row)
    return stack.replace(layers=new_layers, catalogs=catalogs)


def _propagate_down(arrays: list, stack: Stack, home: int) -> None:
    """Give each layer finer than ``home`` its parent's change, interpolated bilinearly
    (its even pixels set to the parent's exactly), in place; stop at the first layer the
    change does not reach."""
    layers = stack.layers
    for j in range(home + 1, len(layers)):
        r0, c0, w = stack.windows[j - 1]
        parent_new = arrays[j - 1][r0:r0 + w, c0:c0 + w]
        delta = parent_new - layers[j - 1].heights[r0:r0 + w, c0:c0 + w]
        if not delta.any():
            break
        fine = layers[j].heights + _upsample(delta)
        fine[::2, ::2] = parent_new
        arrays[j] = fine
