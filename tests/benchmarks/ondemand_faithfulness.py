"""Terrain on demand against the sequential stamp (issue 37, "Faithful to the sequential
model"): the same base radii, the same counter-based catalogue, two surfaces compared.

For a scene (preset, seed, magnitude M) on the lat/long grid ``LatLongGrid(M)``
(resolution ``pi R / (2 M)``, craters >= 3 resolutions, as ``heights_at_units``):

* **on demand**: ``CraterField(scene).radii(units, d_min)`` at every vertex;
* **sequential**: ``latlong.stamp_craters`` of ``CraterField(scene).catalog(units,
  d_min)`` on ``Body(grid, base.radius(units))`` with the build's options
  (``latlong.build._build_latlong``: rim shapes and roughness seeds from
  ``rng=seed``, ``too_large="skip"``, slopes against self-gravity on shape bases);
* **sequential, matched draws**: the same, with each crater's rim perturbation and
  roughness seed taken from the on-demand field (``StampRequest.draws`` patched for the
  call), so that the per-vertex differences show the two models, not two random draws.

Craters the sequential stamp would skip as too large (``crater_extents_deg`` > 60 deg) are
left out of both sequential catalogues (counted: ``too_large``); the on-demand field
keeps them.

Reported per scene (``--json`` writes every number):

* **per-vertex height differences** on-demand minus sequential (both references):
  median, 95th percentile and max of |dh| in metres and as a share of the depth scale
  (the median *fresh* depth of the catalogue's craters: with ages up to 3.5 Gyr most
  craters of the small-body presets are diffused nearly flat, so the stamped depths are
  no scale);
* **slopes**: ``latlong.slopes.slopes_and_areas`` of both bodies, with the paper's 3 deg
  cap (``latlong slopes``'s default) and with none (each vertex's own normal, the
  stricter one); area-weighted histograms in 3 deg bins (``slope_summary``) and the
  two-sample Kolmogorov-Smirnov statistic of the area-weighted distributions;
* **per-crater base tilt**: the angle of each crater's base plane against "up" (the
  sequential stamp's ``slope_deg``; the on-demand base quadric's gradient at the centre,
  by the field kernel's formula): median and 95th percentile of the difference;
* **visible craters per size bin** [2^b, 2^(b+1)) m. A crater is *visible* when it was
  stamped (not erased by slope erosion: the sequential stamp's returned catalogue, the
  on-demand field's per-crater ``ACTIVE`` flag) and its centre is not within the nominal
  rim radius D/2 (great-circle distance at the base radius) of a younger stamped crater.
  The same rule on both surfaces, so the counts differ only where the two models erase
  different craters by slope;
* **depth/diameter measured on each surface** for its visible craters of at least 6
  resolutions across (fewer vertices do not resolve a floor): around the crater's
  centre point on the base (3-D, stretch included) the vertices within 1.3 radii are
  taken in the local tangent frame (normal of the stretched sphere); a plane fitted to
  those in the annulus 0.7-1.3 radii removes the regional tilt; rim crest = the median
  over 8 azimuth sectors of the sector's highest detrended height in the annulus (a
  neighbouring crater's rim raises one sector, not the median), floor = the lowest
  detrended height within 0.5 radii; d/D = (crest - floor) / D. Medians on each
  surface, and the median of the per-crater ratio on craters visible on both;
* **roughness spectra**: ``latlong.slopes.radius_spectrum`` (spherical-harmonic degree
  variance of the radius, the project's validated measure,
  ``measure_radius_spectrum.py``) up to degree 2M/3, summed in octave bands of degree
  (wavelength ``2 pi R / l``): on-demand / sequential power per band, and the share of
  each band's power that the difference field holds;
* **older crater visible inside a younger rim** (on-demand surface, 0 by construction):
  every vertex gets its *top* crater, the youngest stamped crater whose ejecta reach it
  (irregular rim); where the vertex lies inside that crater's rim the surface must equal
  that crater's interior (base quadric + slope-eroded profile + roughness overlay,
  recomputed here in numpy/numba from the field's per-crater record with
  ``craters.kernels``), whatever older craters lie under it. Counted: vertices checked,
  vertices off by more than 1e-6 m, and older stamped craters whose centre lies inside
  such a checked area (the opportunities) and how many of them show (a vertex of their
  rim disc off). The top crater also sorts the per-vertex differences by zone: inside
  its rim, rim to 1.5 radii (where the field blends the older terrain into the base),
  beyond to the ejecta edge, no crater.

Acceptance (issue 37): slope KS <= 0.05, visible craters per bin within 10 %, d/D median
within 5 %, no older crater visible inside a younger rim. One thread, per seed at M = 400:
fbm-cratered ~45 s, faulted-cratered ~20 s, eros ~19 s (at M = 200: 9, 4, 4 s).

Prints one table per scene and a summary over seeds; ``--png-dir`` saves a picture of
the worst region (largest |dh| against the matched-draws reference) of each scene's first
seed. Run by hand (one thread is enough; the timing column is per scene):

    NUMBA_NUM_THREADS=1 python tests/benchmarks/ondemand_faithfulness.py \
        --preset fbm-cratered --preset faulted-cratered --magnitude 200 --seeds 1-3 \
        --json /tmp/faith/m200.json --png-dir /tmp/faith
"""

from __future__ import annotations

import argparse
import json
import math
import time
from pathlib import Path
from types import SimpleNamespace
from unittest import mock

import numpy as np
from crater_depth import rim_minus_floor
from numba import njit
from scipy.spatial import cKDTree

from craters.kernels import fbm2, roughness_amp, table, table_value, tilted_root
from craters.stamp import StampRequest, rim_perturbations_from_phases, stamping_profiles
from latlong import Body, LatLongGrid, Scene, stamp_craters
from latlong.cratering import crater_extents_deg
from latlong.ondemand import _field_kernels as K  # the field's per-crater record columns
from latlong.ondemand.base import grid_catalog, grid_directions
from latlong.ondemand.field import BLEND_EDGE, ROUGHNESS_OCTAVES, CraterField
from latlong.settings import ShapeBase
from latlong.slopes import radius_spectrum, slope_summary, slopes_and_areas
from latlong.surface import band_areas

MAX_EXTENT_DEG = 60.0  # stamp_craters' default, as the build uses it
DD_MIN_RES = 6.0  # d/D only for craters at least this many resolutions across
FRESH_DD = 0.05  # d/D also on the craters whose profile keeps at least this depth/D
TOL_M = 1e-6  # "older crater visible": a vertex off its top crater's interior by more


# ----------------------------------------------------------------------------- helpers
def weighted_ks(a, wa, b, wb) -> float:
    """Two-sample KS statistic of the weighted distributions of ``a`` and ``b``."""
    va = np.concatenate([a, b])
    order = np.argsort(va, kind="stable")
    wa_all = np.concatenate([wa / wa.sum(), np.zeros(len(b))])[order]
    wb_all = np.concatenate([np.zeros(len(a)), wb / wb.sum()])[order]
    ca, cb = np.cumsum(wa_all), np.cumsum(wb_all)
    # compare only after the last of equal values
    last = np.r_[va[order][1:] != va[order][:-1], True]
    return float(np.abs(ca - cb)[last].max())


def _frame(u):
    """East, north at unit vectors (the field's and the stamp's formula)."""
    e = np.stack([-u[:, 1], u[:, 0], np.zeros(len(u))], axis=1)
    en = np.hypot(e[:, 0], e[:, 1])
    pole = en < 1e-12
    e[pole] = (1.0, 0.0, 0.0)
    en[pole] = 1.0
    e /= en[:, None]
    return e, np.cross(u, e)


def _table_np(rims, theta):
    """``craters.kernels.table`` over arrays: rows ``rims`` at azimuths ``theta``."""
    n = rims.shape[1]
    t = (theta + np.pi) * (n / (2.0 * np.pi))
    k0 = np.floor(t).astype(np.int64)
    w = t - k0
    k0 %= n
    k1 = (k0 + 1) % n
    rows = np.arange(len(rims))
    return rims[rows, k0] + w * (rims[rows, k1] - rims[rows, k0])


def visible_mask(units, diam, rho, age, stamped):
    """Stamped craters whose centre is not within D/2 of a younger stamped crater's
    centre (great-circle distance at the base radius ``rho``)."""
    vis = stamped.copy()
    idx = np.flatnonzero(stamped)
    tree = cKDTree(units[idx])
    half = 0.5 * diam[idx] / rho[idx]
    chord = 2.0 * np.sin(np.minimum(half, np.pi) / 2.0)
    for j, near in zip(idx, tree.query_ball_point(units[idx], chord), strict=True):
        if len(near):
            near = idx[np.asarray(near)]
            older = near[age[near] > age[j]]
            vis[older] = False
    return vis


def size_bins(diam, mask, b_lo, b_hi):
    b = np.floor(np.log2(diam[mask])).astype(int)
    return {int(k): int((b == k).sum()) for k in range(b_lo, b_hi + 1)}


def depth_ratios(body: Body, tree, centres_u, base_rho, diam, stretch):
    """d/D of each crater measured on ``body`` (module notes); NaN where not measurable.
    ``tree``: a k-d tree of the grid's unit vectors (the vertices are gathered by
    direction, whatever height the surface has moved to; stretching only lengthens)."""
    v = body.vertices()
    s = np.asarray(stretch, dtype=np.float64)
    p = centres_u * s * base_rho[:, None]
    nrm = p / (s * s)
    nrm /= np.linalg.norm(nrm, axis=1, keepdims=True)
    e, n = _frame(nrm)
    out = np.full(len(diam), np.nan)
    rad = 0.5 * diam
    ang = np.minimum(1.3 * rad / base_rho, np.pi)
    for c, near in enumerate(tree.query_ball_point(centres_u, 2.0 * np.sin(ang / 2.0))):
        near = np.asarray(near, dtype=np.int64)
        d = v[near] - p[c]
        h = d @ nrm[c]
        x, y = d @ e[c], d @ n[c]
        xr = np.hypot(x, y) / rad[c]
        keep = xr <= 1.3
        if keep.sum() < 12:
            continue
        h, x, y, xr = h[keep], x[keep], y[keep], xr[keep]
        ann = (xr >= 0.7) & (xr <= 1.3)
        floor = xr <= 0.5
        if ann.sum() < 8 or not floor.any():
            continue
        a = np.stack([np.ones(ann.sum()), x[ann], y[ann]], axis=1)
        coef, *_ = np.linalg.lstsq(a, h[ann], rcond=None)
        hd = h - (coef[0] + coef[1] * x + coef[2] * y)
        depth = rim_minus_floor(hd, xr, np.arctan2(y, x), annulus=(0.7, 1.3), floor_r=0.5,
                                min_sectors=6)
        if depth is not None:
            out[c] = depth / diam[c]
    return out


def spectrum_bands(body: Body, l_max: int):
    deg, s = radius_spectrum(body, l_max)
    bands = {}
    k = 1
    while 2 ** k <= l_max:
        lo, hi = 2 ** k, min(2 ** (k + 1), l_max + 1)
        bands[f"{lo}-{hi - 1}"] = float(s[(deg >= lo) & (deg < hi)].sum())
        k += 1
    return bands


@njit(cache=False)
def _interior_residual(units, radii, top, fc, tabs, rims, seeds, rough, gain, octaves, xe,
                       out):
    """Surface minus the top crater's interior at vertices inside the top crater's rim
    (NaN elsewhere): the field kernel's formulas, from public ``craters.kernels``."""
    n_rim = rims.shape[1]
    for i in range(units.shape[0]):
        k = top[i]
        out[i] = np.nan
        if k < 0:
            continue
        p0, p1, p2 = units[i, 0], units[i, 1], units[i, 2]
        c = fc[k, K.C0] * p0 + fc[k, K.C1] * p1 + fc[k, K.C2] * p2
        xe_ = fc[k, K.E0] * p0 + fc[k, K.E1] * p1 + fc[k, K.E2] * p2
        xn = fc[k, K.N0] * p0 + fc[k, K.N1] * p1 + fc[k, K.N2] * p2
        s = np.sqrt(xe_ * xe_ + xn * xn)
        dist = np.arctan2(s, c) * fc[k, K.RHO]
        x, y, az = 0.0, 0.0, 0.0
        if s > 0.0:
            x = dist * xe_ / s
            y = dist * xn / s
            az = np.arctan2(xn, xe_)
        t = (az + np.pi) * (n_rim / (2.0 * np.pi))
        k0 = int(np.floor(t))
        w = t - k0
        k0 = k0 % n_rim
        k1 = (k0 + 1) % n_rim
        rim = rims[k, k0] + w * (rims[k, k1] - rims[k, k0])
        radius = fc[k, K.RAD]
        xr = dist / (radius * (1.0 + rim))
        if fc[k, K.TILT_CZ] > 0.0:  # made in its tilted base's frame
            out[i] = _tilted_interior(fc, k, x, y, tabs, rims, seeds, rough, gain, octaves, xe,
                                      radii[i])
            continue
        if xr > 1.0:
            continue
        scale = fc[k, K.SCALE]
        prof = scale * table_value(tabs[k], xr, xe)
        if rough[0] > 0.0 or rough[1] > 0.0 or rough[2] > 0.0:
            amp = roughness_amp(xr, xe, rough[0], rough[1], rough[2]) * fc[k, K.DEPTH] * scale
            if amp > 1e-6 * radius:  # the field's rule: no overlay on a crater diffused flat
                prof += amp * fbm2(seeds[k], x, y, radius, octaves, gain)
        q = (fc[k, K.P0] + fc[k, K.GX] * x + fc[k, K.GY] * y + fc[k, K.QA] * x * x
             + fc[k, K.QB] * x * y + fc[k, K.QC] * y * y)
        out[i] = radii[i] - (fc[k, K.RHO] + q + prof)


@njit(cache=False)
def _tilted_interior(fc, k, x, y, tabs, rims, seeds, rough, gain, octaves, xe, radius_now):
    """Surface minus crater k's interior for a crater made in its tilted base's frame
    (NaN outside its rim): the point's foot on the base plane in the frame's coordinates,
    and the radial line's meeting with the crater's surface over the base plane (the
    sequential stamp's root finder, ``craters.kernels.tilted_root``) plus the
    quadric's curvature radially."""
    fr = fc[k, K.TILT:K.TILT + 10]
    r2 = fc[k, K.GX] * x + fc[k, K.GY] * y
    u1 = x * fr[0] + y * fr[1] + r2 * fr[2]
    u2 = x * fr[3] + y * fr[4] + r2 * fr[5]
    w0 = x * fr[6] + y * fr[7] + r2 * fr[8]
    radius = fc[k, K.RAD]
    xr = np.sqrt(u1 * u1 + u2 * u2) / (radius * (1.0 + table(rims[k], np.arctan2(u2, u1))))
    if xr > 1.0:
        return np.nan
    scale = fc[k, K.SCALE]
    has_rough = octaves > 0 and (max(rough[0], max(rough[1], rough[2])) * fc[k, K.DEPTH]
                                 * scale > 1e-6 * radius)
    t = tilted_root(u1, u2, w0, radius, tabs[k], scale, fc[k, K.DEPTH], xe, rims[k], rough,
                    fc[k, K.WARP], has_rough, seeds[k], radius, octaves, gain, fr)
    q = (fc[k, K.P0] + fc[k, K.GX] * x + fc[k, K.GY] * y + fc[k, K.QA] * x * x
         + fc[k, K.QB] * x * y + fc[k, K.QC] * y * y)
    return radius_now - ((fc[k, K.RHO] + q) + t)


def older_inside_check(field, units, radii, tree):
    """The "older crater visible inside a younger rim" check (module notes)."""
    cr, fc = field.last["craters"], field.last["fc"]
    n = len(cr)
    rims = np.ascontiguousarray(rim_perturbations_from_phases(cr.rim_phases, field.irregularity))
    cat = np.zeros(n, dtype=[("lat_deg", "f8"), ("lon_deg", "f8"), ("diameter_m", "f8"),
                             ("age_gyr", "f8"), ("degradation", "f8")])
    cat["diameter_m"], cat["age_gyr"], cat["degradation"] = cr.diameter_m, cr.age_gyr, np.nan
    from craters.catalog import make_catalog
    prof = stamping_profiles(make_catalog(**{k: cat[k] for k in cat.dtype.names}),
                             field.target, ejecta_edge=field.xe)
    tabs = np.ascontiguousarray(prof.tables)
    active = fc[:, K.ACTIVE] > 0
    order = np.lexsort((cr.id, cr.age_gyr))[::-1]  # oldest first; the last write wins
    top = np.full(len(units), -1, dtype=np.int64)
    top_x = np.full(len(units), np.inf)  # radii (irregular rim) from the top crater
    cu = fc[:, K.C0:K.C2 + 1]
    for k in order:
        if not active[k]:
            continue
        near = np.asarray(tree.query_ball_point(cu[k], 2.0 * np.sin(fc[k, K.FAR] / 2.0)),
                          dtype=np.int64)
        if not len(near):
            continue
        pu = units[near]
        c = pu @ cu[k]
        xe_ = pu @ fc[k, K.E0:K.E2 + 1]
        xn = pu @ fc[k, K.N0:K.N2 + 1]
        dist = np.arctan2(np.hypot(xe_, xn), c) * fc[k, K.RHO]
        az = np.arctan2(xn, xe_)
        if fc[k, K.TILT_CZ] > 0.0:  # the reach in the tilted base's frame, as the kernel
            s_ = np.maximum(np.hypot(xe_, xn), 1e-300)
            x, y = dist * xe_ / s_, dist * xn / s_
            fr = fc[k, K.TILT:K.TILT + 10]
            foot = np.stack([x, y, fc[k, K.GX] * x + fc[k, K.GY] * y], axis=1)
            u1, u2 = foot @ fr[0:3], foot @ fr[3:6]
            dist, az = np.hypot(u1, u2), np.arctan2(u2, u1)
        rim = _table_np(np.broadcast_to(rims[k], (len(near), rims.shape[1])), az)
        xr = dist / (fc[k, K.RAD] * (1.0 + rim))
        # reach by the chord, as the kernel tests it (a cosine test misses the last
        # micrometres of a younger crater's ejecta tail: residuals of ~1e-6 m)
        hit = (xr < field.xe) & (np.sum((pu - cu[k]) ** 2, axis=1) <= fc[k, K.CHORD2])
        top[near[hit]] = k
        top_x[near[hit]] = xr[hit]
    res = np.empty(len(units))
    _interior_residual(units, radii, top, fc, tabs, rims, np.ascontiguousarray(cr.seed),
                       field.rough, field.gain, ROUGHNESS_OCTAVES, field.xe, res)
    checked = np.isfinite(res)
    off = checked & (np.abs(np.nan_to_num(res)) > TOL_M)
    # older stamped craters whose centre lies in a checked area: the opportunities
    opp = shown = 0
    v_of_centre = tree.query(cu)[1]
    rank = np.empty(n, dtype=np.int64)
    rank[np.lexsort((cr.id, cr.age_gyr))] = np.arange(n)  # 0 youngest
    for j in np.flatnonzero(active):
        t = top[v_of_centre[j]]
        if t < 0 or t == j or not checked[v_of_centre[j]] or rank[t] > rank[j]:
            continue
        opp += 1
        near = tree.query_ball_point(cu[j], 2.0 * np.sin(0.5 * fc[j, K.RAD] / fc[j, K.RHO]))
        if off[np.asarray(near, dtype=np.int64)].any():
            shown += 1
    return top_x, {"vertices_checked": int(checked.sum()), "vertices_off": int(off.sum()),
            "max_abs_residual_m": float(np.nanmax(np.abs(res))) if checked.any() else 0.0,
            "older_inside_younger_rim": opp, "older_visible_inside_younger_rim": shown}


def ondemand_tilt_deg(field):
    """Each crater's base-plane tilt against "up" (the field kernel's formula)."""
    fc = field.last["fc"]
    c, e, n = fc[:, K.C0:K.C2 + 1], fc[:, K.E0:K.E2 + 1], fc[:, K.N0:K.N2 + 1]
    normal = c - fc[:, K.GX:K.GX + 1] * e - fc[:, K.GY:K.GY + 1] * n
    up = field.base.up(c)
    cross = np.linalg.norm(np.cross(normal, up), axis=1)
    return np.degrees(np.arctan2(cross, np.einsum("ij,ij->i", normal, up)))


def stamp_reference(body, cat, scene, seed, draws=None):
    kw = dict(roughness=scene.craters.roughness, rng=seed, target=scene.target(),
              too_large="skip", max_extent_deg=MAX_EXTENT_DEG,
              slope_reference="gravity" if isinstance(scene.base, ShapeBase) else "body")
    if draws is None:
        return stamp_craters(body, cat, **kw)
    rims, seeds = draws

    def matched(self, n, rng):
        assert n == len(rims) and (self.catalog["id"] == cat["id"]).all()
        return rims.copy(), seeds.copy()

    with mock.patch.object(StampRequest, "draws", matched):
        return stamp_craters(body, cat, **kw)


def dh_stats(dh, depth_scale):
    a = np.abs(dh)
    q = [float(np.median(a)), float(np.percentile(a, 95)), float(a.max())]
    return {"median_m": q[0], "p95_m": q[1], "max_m": q[2],
            "median_rel": q[0] / depth_scale, "p95_rel": q[1] / depth_scale,
            "max_rel": q[2] / depth_scale}


# ----------------------------------------------------------------------------- a scene
def build_surfaces(preset: str, seed: int, magnitude: int, roughness: bool) -> SimpleNamespace:
    """The on-demand body and the two sequential references (module notes)."""
    t0 = time.perf_counter()
    # no boulders: the sequential stamp places them as meshes, the field as relief; the
    # comparison is of the crater models
    # "NAME:unstretched": the preset without its axis stretch. On a stretched body the
    # field works in the surface's directions w = S u / |S u| (latlong.ondemand.base):
    # the on-demand radii are R(w) / |S u| (where the Body puts vertex u), the catalogue
    # the sequential stamp takes names grid directions (grid_catalog)
    name, _, variant = preset.partition(":")
    extra = {"stretch": [1.0, 1.0, 1.0]} if variant == "unstretched" else {}
    scene = Scene.from_settings({"preset": name, "seed": seed, "magnitude": magnitude,
                                 "crater_roughness": roughness, "boulders": [], **extra})
    grid = LatLongGrid(magnitude)
    units = grid.unit_vectors()
    field = CraterField(scene)  # not crater_field: its lru_cache cannot hash shape scenes
    w, scale = grid_directions(field.base, units)
    radius_m = float(field.base.radius_m)
    res = math.pi * radius_m / (2 * magnitude)
    base = field.base.radius(w) / scale
    cat = grid_catalog(field.base, field.catalog(w, 3.0 * res))
    # the catalogue as drawn: its degradation reports what the field made (diffusion and
    # slope erosion); the sequential stamp takes a number there as an override, so it gets
    # NaN (degradation from the age), as the build's catalogue has
    cat["degradation"] = np.nan
    t1 = time.perf_counter()
    radii = field.radii(w, 3.0 * res) / scale
    t_od = time.perf_counter() - t1
    cr = field.last["craters"]
    assert len(np.unique(cr.id)) == len(cr) and set(cr.id.tolist()) == set(cat["id"].tolist())
    row = {k: i for i, k in enumerate(cr.id.tolist())}
    ci = np.array([row[k] for k in cat["id"].tolist()], dtype=np.int64)  # catalog -> field
    body0 = Body(grid, base, radius_m=radius_m, stretch=scene.body.stretch)
    ok = crater_extents_deg(body0, cat, irregularity=field.irregularity) <= MAX_EXTENT_DEG
    t1 = time.perf_counter()
    seq = stamp_reference(body0, cat[ok], scene, seed)
    t_seq = time.perf_counter() - t1
    rims = rim_perturbations_from_phases(cr.rim_phases[ci[ok]], field.irregularity)
    seqm = stamp_reference(body0, cat[ok], scene, seed, draws=(
        np.ascontiguousarray(rims), np.ascontiguousarray(cr.seed[ci[ok]])))
    return SimpleNamespace(
        scene=scene, grid=grid, units=units, tree=cKDTree(units), field=field, res=res,
        w=w, scale=scale, wtree=cKDTree(w),
        radius_m=radius_m, base=base, body0=body0, cat=cat, ok=ok, ci=ci, cr=cr,
        fc=field.last["fc"], od=Body(grid, radii, radius_m=radius_m, stretch=scene.body.stretch),
        seq=seq, seqm=seqm, t0=t0, t_od=t_od, t_seq=t_seq)


def height_stats(s: SimpleNamespace) -> dict:
    """Catalogue facts and the per-vertex differences."""
    fc, d_min = s.fc, 3.0 * s.res
    # the fresh depth: on old small bodies most craters are diffused nearly flat
    depth_scale = float(np.median(stamping_profiles(s.cat[s.ok],
                                                    s.scene.target()).fresh_depth_m))
    # vertices the too-large craters (on demand only) reach are left out of dh
    far = np.zeros(len(s.units), bool)
    for k in s.ci[~s.ok]:
        far[s.wtree.query_ball_point(fc[k, K.C0:K.C2 + 1],
                                    2.0 * np.sin(min(fc[k, K.FAR], np.pi) / 2.0))] = True
    area = float(band_areas(s.body0).sum())  # what the build draws its population on
    expected = sum(la.c * (max(d_min, la.d_min_m) ** la.k - la.d_max_m ** la.k)
                   for la in s.field.layers if la.d_max_m > d_min) * area
    return {"resolution_m": s.res, "d_min_m": d_min, "n_catalog": len(s.cat),
            "too_large": int((~s.ok).sum()), "catalog_over_expected": len(s.cat) / expected,
            "body_area_m2": area, "vertices_left_out": int(far.sum()),
            "depth_scale_m": depth_scale, "stretch": list(s.scene.body.stretch),
            "dh_seq": dh_stats((s.od.radii_m - s.seq.radii_m)[~far], depth_scale),
            "dh_matched": dh_stats((s.od.radii_m - s.seqm.radii_m)[~far], depth_scale)}


def slope_stats(s: SimpleNamespace) -> dict:
    sl = {}
    for cap in (3.0, 0.0):
        s_od, a_od = slopes_and_areas(s.od, cap)
        s_sq, a_sq = slopes_and_areas(s.seq, cap)
        s_m, a_m = slopes_and_areas(s.seqm, cap)
        h_od, h_sq = slope_summary(s_od, a_od), slope_summary(s_sq, a_sq)
        nb = min(len(h_od["area_fraction"]), len(h_sq["area_fraction"]))
        sl[f"cap{cap:g}"] = {
            "ks": weighted_ks(s_od, a_od, s_sq, a_sq),
            "ks_matched": weighted_ks(s_od, a_od, s_m, a_m),
            "median_deg": [h_od["median_deg"], h_sq["median_deg"]],
            "hist_edges_deg": h_od["edges_deg"][:nb + 1].tolist(),
            "hist_ondemand": h_od["area_fraction"][:nb].tolist(),
            "hist_seq": h_sq["area_fraction"][:nb].tolist()}
    return sl


def crater_stats(s: SimpleNamespace) -> dict:
    """Base tilts, visible craters per bin, d/D measured on each surface."""
    cr, fc = s.cr, s.fc
    # the stamped catalogue holds ``id`` as float64 (make_catalog's column type): match
    # on the float rendering of the field's uint64 ids (unique, checked)
    fid = {float(np.float64(k)): i for i, k in enumerate(cr.id.tolist())}
    assert len(fid) == len(cr)
    stamped_seq = np.zeros(len(cr), bool)
    tilt_seq = np.full(len(cr), np.nan)
    for k, s_deg in zip(s.seq.craters["id"].tolist(), s.seq.craters["slope_deg"], strict=True):
        stamped_seq[fid[k]] = True
        tilt_seq[fid[k]] = s_deg
    dt = np.abs(ondemand_tilt_deg(s.field) - tilt_seq)[stamped_seq]
    cu = fc[:, K.C0:K.C2 + 1]
    stamped_od = fc[:, K.ACTIVE] > 0
    vis_od = visible_mask(cu, cr.diameter_m, fc[:, K.RHO], cr.age_gyr, stamped_od)
    vis_sq = visible_mask(cu, cr.diameter_m, fc[:, K.RHO], cr.age_gyr, stamped_seq)
    b_lo = int(np.floor(np.log2(3.0 * s.res)))
    b_hi = int(np.floor(np.log2(cr.diameter_m.max())))
    big = cr.diameter_m >= DD_MIN_RES * s.res
    fresh = fc[:, K.DEPTH] >= FRESH_DD * cr.diameter_m  # the profile's depth (catalogue)
    # depth_ratios takes grid directions and the unstretched base radius (u = S^-1 w / n,
    # R(w) n with n = |S^-1 w|: the same point)
    v = cu / np.asarray(s.scene.body.stretch)
    nv = np.linalg.norm(v, axis=1)
    base_c = s.field.base.radius(cu) * nv
    cu_grid = v / nv[:, None]
    dd = {}
    for name, body, vis in (("ondemand", s.od, vis_od), ("seq", s.seq, vis_sq)):
        sel = np.flatnonzero(vis & big)
        dd[name] = np.full(len(cr), np.nan)
        dd[name][sel] = depth_ratios(body, s.tree, cu_grid[sel], base_c[sel],
                                     cr.diameter_m[sel],
                                     s.scene.body.stretch)
    both = np.isfinite(dd["ondemand"]) & np.isfinite(dd["seq"])

    def finite(v):
        return v[np.isfinite(v)].tolist()

    return {"tilt_diff_deg": {"median": float(np.median(dt)),
                              "p95": float(np.percentile(dt, 95))},
            "stamped": [int(stamped_od.sum()), int(stamped_seq.sum())],
            "visible_bins": {"ondemand": size_bins(cr.diameter_m, vis_od, b_lo, b_hi),
                             "seq": size_bins(cr.diameter_m, vis_sq, b_lo, b_hi)},
            "dD": {"median_ondemand": _med(finite(dd["ondemand"])),
                   "median_seq": _med(finite(dd["seq"])),
                   "n": [len(finite(dd["ondemand"])), len(finite(dd["seq"]))],
                   "median_ratio_paired": _med(dd["ondemand"][both] / dd["seq"][both]),
                   "values_ondemand": finite(dd["ondemand"]), "values_seq": finite(dd["seq"]),
                   "fresh_values_ondemand": finite(dd["ondemand"][fresh]),
                   "fresh_values_seq": finite(dd["seq"][fresh])}}


def run_scene(preset: str, seed: int, magnitude: int, png_dir: Path | None,
              roughness: bool = True) -> dict:
    s = build_surfaces(preset, seed, magnitude, roughness)
    out = {"preset": preset if roughness else f"{preset} (no roughness)", "seed": seed,
           "magnitude": magnitude, **height_stats(s), "slopes": slope_stats(s),
           **crater_stats(s)}
    l_max = (2 * magnitude) // 3
    sp_od, sp_sq = spectrum_bands(s.od, l_max), spectrum_bands(s.seq, l_max)
    diff = Body(s.grid, s.radius_m + (s.od.radii_m - s.seqm.radii_m),
                radius_m=s.radius_m)  # unstretched: the difference alone
    out["spectrum"] = {"bands": list(sp_od), "ondemand": list(sp_od.values()),
                       "seq": list(sp_sq.values()),
                       "diff_matched": list(spectrum_bands(diff, l_max).values())}
    top_x, out["older_inside"] = older_inside_check(s.field, s.w, s.od.radii_m * s.scale,
                                                    s.wtree)
    # where the differences are: by the youngest stamped crater reaching each vertex
    adh = np.abs(s.od.radii_m - s.seqm.radii_m)
    zones = {"inside rim": top_x <= 1.0, "rim to 1.5 radii (blend)": (top_x > 1.0)
             & (top_x < BLEND_EDGE), "1.5 radii to ejecta edge": (top_x >= BLEND_EDGE)
             & np.isfinite(top_x), "no crater": ~np.isfinite(top_x)}
    out["dh_matched_by_zone"] = {
        k: {"share_of_vertices": float(z.mean()), "median_m": _med(adh[z]),
            "p95_m": float(np.percentile(adh[z], 95)) if z.any() else float("nan"),
            "share_of_sum_sq": float((adh[z] ** 2).sum() / (adh ** 2).sum())}
        for k, z in zones.items()}
    out["seconds"] = {"ondemand_radii": s.t_od, "seq_stamp": s.t_seq,
                      "total": time.perf_counter() - s.t0}
    if png_dir is not None:
        out["png"] = worst_region_png(png_dir, f"{out['preset']} seed {seed} M={magnitude}",
                                      s.grid, s.base, s.od, s.seqm, s.seq, s.radius_m)
    return out


def worst_region_png(png_dir: Path, title, grid, base, od, seqm, seq, radius_m):
    """Heights over the base (m) of the three surfaces and their difference, within 25
    resolutions of the vertex of the largest |dh| (against the matched draws)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    dh = od.radii_m - seqm.radii_m
    w = int(np.argmax(np.abs(dh)))
    u = grid.unit_vectors()
    ang = np.arccos(np.clip(u @ u[w], -1, 1)) * radius_m
    win = ang <= 25.0 * math.pi * radius_m / (2 * grid.magnitude)
    e, n = _frame(u[w:w + 1])
    x, y = u[win] @ e[0] * radius_m, u[win] @ n[0] * radius_m
    panels = [("on demand", od.radii_m[win] - base[win]),
              ("sequential, matched draws", seqm.radii_m[win] - base[win]),
              ("sequential, rng=seed", seq.radii_m[win] - base[win]),
              ("on demand - matched", dh[win])]
    fig, axes = plt.subplots(1, 4, figsize=(18, 4.6))
    lo = min(p[1].min() for p in panels[:3])
    hi = max(p[1].max() for p in panels[:3])
    for ax, (name, val) in zip(axes, panels, strict=True):
        diff = name.startswith("on demand -")
        lim = np.abs(val).max() if diff else None
        sc = ax.tripcolor(x, y, val, cmap="RdBu_r" if diff else "gray",
                          vmin=-lim if diff else lo, vmax=lim if diff else hi,
                          shading="gouraud")
        ax.set_aspect("equal")
        ax.set_title(name)
        fig.colorbar(sc, ax=ax, shrink=0.8, label="m")
    fig.suptitle(f"{title}: heights over the base; worst |dh| {abs(dh[w]):.3f} m "
                 "(x, y in m, east/north)")
    path = png_dir / ("worst_" + "".join(c for c in title.replace(" ", "_") if c.isalnum()
                                         or c in "_-") + ".png")
    png_dir.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=90, bbox_inches="tight")
    plt.close(fig)
    return str(path)


# ----------------------------------------------------------------------------- reporting
def _med(v) -> float:
    return float(np.median(v)) if len(v) else float("nan")


def print_scene(r: dict) -> None:
    d, m, s3, s0 = r["dh_seq"], r["dh_matched"], r["slopes"]["cap3"], r["slopes"]["cap0"]
    print(f"\n== {r['preset']} seed {r['seed']} M={r['magnitude']} (res {r['resolution_m']:.3f} "
          f"m, D >= {r['d_min_m']:.2f} m, {r['n_catalog']} craters, {r['too_large']} too "
          f"large for the sequential stamp; stamped on demand / sequential "
          f"{r['stamped'][0]} / {r['stamped'][1]}; catalogue / N_cum x body area "
          f"{r['catalog_over_expected']:.3f}; {r['seconds']['total']:.1f} s: on-demand "
          f"radii {r['seconds']['ondemand_radii']:.1f} s, stamp {r['seconds']['seq_stamp']:.1f} s)")
    for name, x in (("|dh| vs seq (rng=seed)", d), ("|dh| vs seq (matched draws)", m)):
        print(f"  {name:28s} median {x['median_m']:.4f} m ({x['median_rel']:.3f} depth), p95 "
              f"{x['p95_m']:.4f} m ({x['p95_rel']:.3f}), max {x['max_m']:.3f} m "
              f"({x['max_rel']:.2f})  [depth scale {r['depth_scale_m']:.3f} m]")
    for name, x in (("slopes, 3 deg cap", s3), ("slopes, vertex normals", s0)):
        print(f"  {name:28s} KS {x['ks']:.4f} (matched {x['ks_matched']:.4f})  median "
              f"{x['median_deg'][0]:.2f} / {x['median_deg'][1]:.2f} deg")
    print(f"  {'base tilt |diff|':28s} median {r['tilt_diff_deg']['median']:.2f} deg, p95 "
          f"{r['tilt_diff_deg']['p95']:.2f} deg")
    vb = r["visible_bins"]
    print("  visible per bin (m): " + "  ".join(
        f"{2 ** int(b):g}-{2 ** (int(b) + 1):g}: {vb['ondemand'][b]}/{vb['seq'][b]}"
        for b in vb["ondemand"]))
    dd = r["dD"]
    print(f"  {'d/D median':28s} {dd['median_ondemand']:.4f} / {dd['median_seq']:.4f} "
          f"(n {dd['n'][0]}/{dd['n'][1]}; paired ratio {dd['median_ratio_paired']:.3f}); "
          f"profile d/D >= {FRESH_DD}: {_med(dd['fresh_values_ondemand']):.4f} / "
          f"{_med(dd['fresh_values_seq']):.4f} (n {len(dd['fresh_values_ondemand'])}/"
          f"{len(dd['fresh_values_seq'])})")
    sp = r["spectrum"]
    print("  spectrum on-demand/seq by degree band: " + "  ".join(
        f"{b}: {a / s:.3f}" for b, a, s in zip(sp["bands"], sp["ondemand"], sp["seq"],
                                                strict=True)))
    print("  difference (matched) / seq power:     " + "  ".join(
        f"{b}: {a / s:.3f}" for b, a, s in zip(sp["bands"], sp["diff_matched"], sp["seq"],
                                                strict=True)))
    print("  |dh| (matched) by the top crater's zone: " + "  ".join(
        f"{k}: {v['share_of_vertices']:.2f} of vertices, median {v['median_m']:.3f} m, "
        f"{v['share_of_sum_sq']:.2f} of sum dh^2" for k, v in r["dh_matched_by_zone"].items()))
    o = r["older_inside"]
    print(f"  older crater visible inside a younger rim: {o['older_visible_inside_younger_rim']} "
          f"of {o['older_inside_younger_rim']} (vertices checked {o['vertices_checked']}, off "
          f"{o['vertices_off']}, max residual {o['max_abs_residual_m']:.2e} m)")


def summary(results: list[dict]) -> dict:
    out = {}
    for preset in dict.fromkeys(r["preset"] for r in results):
        for mag in sorted({r["magnitude"] for r in results if r["preset"] == preset}):
            rs = [r for r in results if r["preset"] == preset and r["magnitude"] == mag]

            def ms(vals):
                v = np.asarray(vals, dtype=float)
                return [float(v.mean()), float(v.std()), float(v.min()), float(v.max())]

            bins = list(rs[0]["visible_bins"]["ondemand"])
            vo = {b: sum(r["visible_bins"]["ondemand"][b] for r in rs) for b in bins}
            vs = {b: sum(r["visible_bins"]["seq"][b] for r in rs) for b in bins}
            dd_o = np.concatenate([r["dD"]["values_ondemand"] for r in rs])
            dd_s = np.concatenate([r["dD"]["values_seq"] for r in rs])
            fr_o = np.concatenate([r["dD"]["fresh_values_ondemand"] for r in rs])
            fr_s = np.concatenate([r["dD"]["fresh_values_seq"] for r in rs])
            s = {"n_seeds": len(rs),
                 "dh_matched_median_m": ms([r["dh_matched"]["median_m"] for r in rs]),
                 "dh_matched_p95_m": ms([r["dh_matched"]["p95_m"] for r in rs]),
                 "dh_matched_max_m": ms([r["dh_matched"]["max_m"] for r in rs]),
                 "dh_seq_median_m": ms([r["dh_seq"]["median_m"] for r in rs]),
                 "dh_matched_median_rel": ms([r["dh_matched"]["median_rel"] for r in rs]),
                 "ks_cap3": ms([r["slopes"]["cap3"]["ks"] for r in rs]),
                 "ks_cap0": ms([r["slopes"]["cap0"]["ks"] for r in rs]),
                 "ks_cap3_matched": ms([r["slopes"]["cap3"]["ks_matched"] for r in rs]),
                 "ks_cap0_matched": ms([r["slopes"]["cap0"]["ks_matched"] for r in rs]),
                 "visible_pooled": {b: [vo[b], vs[b], (vo[b] - vs[b]) / vs[b] if vs[b] else None]
                                    for b in bins},
                 "dD_median_pooled": [float(np.median(dd_o)), float(np.median(dd_s)),
                                      float(np.median(dd_o) / np.median(dd_s) - 1)],
                 "dD_fresh_median_pooled": [_med(fr_o), _med(fr_s), _med(fr_o) / _med(fr_s) - 1,
                                            len(fr_o), len(fr_s)],
                 "spectrum_ratio_mean": [float(np.mean([r["spectrum"]["ondemand"][i]
                                                        / r["spectrum"]["seq"][i] for r in rs]))
                                         for i in range(len(rs[0]["spectrum"]["bands"]))],
                 "spectrum_bands": rs[0]["spectrum"]["bands"],
                 "older_visible": sum(r["older_inside"]["older_visible_inside_younger_rim"]
                                      for r in rs),
                 "older_opportunities": sum(r["older_inside"]["older_inside_younger_rim"]
                                            for r in rs),
                 "vertices_off": sum(r["older_inside"]["vertices_off"] for r in rs),
                 "seconds_per_seed": ms([r["seconds"]["total"] for r in rs])}
            out[f"{preset} M={mag}"] = s
            print(f"\n## summary {preset} M={mag} over {len(rs)} seeds (mean +- sd [min, max])")
            for k in ("dh_matched_median_m", "dh_matched_p95_m", "dh_matched_max_m",
                      "dh_seq_median_m", "dh_matched_median_rel", "ks_cap3", "ks_cap0",
                      "ks_cap3_matched", "ks_cap0_matched", "seconds_per_seed"):
                v = s[k]
                print(f"  {k:24s} {v[0]:.4f} +- {v[1]:.4f} [{v[2]:.4f}, {v[3]:.4f}]")
            print("  visible pooled on demand / seq (rel. diff): " + "  ".join(
                f"{2 ** int(b):g}-{2 ** (int(b) + 1):g}: {a}/{c} "
                f"({'' if d is None else f'{d:+.3f}'})"
                for b, (a, c, d) in s["visible_pooled"].items()))
            print(f"  d/D median pooled: {s['dD_median_pooled'][0]:.4f} / "
                  f"{s['dD_median_pooled'][1]:.4f} ({s['dD_median_pooled'][2]:+.3f}); profile "
                  f"d/D >= {FRESH_DD}: {s['dD_fresh_median_pooled'][0]:.4f} / "
                  f"{s['dD_fresh_median_pooled'][1]:.4f} ({s['dD_fresh_median_pooled'][2]:+.3f}, n "
                  f"{s['dD_fresh_median_pooled'][3]}/{s['dD_fresh_median_pooled'][4]})")
            print("  spectrum ratio (mean): " + "  ".join(
                f"{b}: {v:.3f}" for b, v in zip(s["spectrum_bands"], s["spectrum_ratio_mean"],
                                                strict=True)))
            print(f"  older crater visible inside a younger rim: {s['older_visible']} of "
                  f"{s['older_opportunities']} (vertices off {s['vertices_off']})")
    return out


def _seeds(text: str) -> list[int]:
    out: list[int] = []
    for part in text.split(","):
        a, _, b = part.partition("-")
        out.extend(range(int(a), int(b or a) + 1))
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--preset", action="append", help="(repeatable; default: fbm-cratered; "
                    "NAME:unstretched drops the preset's axis stretch)")
    ap.add_argument("--magnitude", type=int, default=200, help="(default: 200)")
    ap.add_argument("--seeds", default="1-3", help="e.g. 1-20 or 1,4,7 (default: 1-3)")
    ap.add_argument("--json", type=Path, help="write every number here")
    ap.add_argument("--png-dir", type=Path, help="worst-region pictures (first seed)")
    ap.add_argument("--no-roughness", action="store_true",
                    help="ideal craters (crater_roughness = false): no overlay, round rims")
    args = ap.parse_args()
    results = []
    for preset in args.preset or ["fbm-cratered"]:
        for i, seed in enumerate(_seeds(args.seeds)):
            r = run_scene(preset, seed, args.magnitude, args.png_dir if i == 0 else None,
                          roughness=not args.no_roughness)
            print_scene(r)
            results.append(r)
            if args.json:
                args.json.write_text(json.dumps({"scenes": results}, indent=1))
    summ = summary(results)
    if args.json:
        args.json.write_text(json.dumps({"scenes": results, "summary": summ}, indent=1))


if __name__ == "__main__":
    main()
