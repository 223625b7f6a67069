"""The local crater field: heights at any points, from the craters near them only.

Sequential stamping (:func:`latlong.stamp_craters`) fits each crater's base to whatever
every older crater left, so a value can depend on craters anywhere. Here (DESIGN notes
in the README, "Terrain on demand"):

1. **Catalogue.** Each crater layer's (power law or model age) size bin
   ``[2**b, 2**(b+1))`` is drawn per cell
   of one level of the cube-sphere hierarchy (:mod:`craters.local`), the level a function
   of the bin and the body (cells at least an ejecta reach plus a radius wide), never of
   the request.
   Craters smaller than the requested minimum diameter are left out; that only filters.
2. **A crater's base** is a quadric fitted (a fixed 61-point stencil over its rim disc:
   the centre and rings of 6, 12, 18 and 24 points at 1/4 .. 1 radius; a fixed
   least-squares operator) to the terrain made by the base shape and the *older, larger*
   craters at the stencil points (roughness overlay included: at a smaller crater's scale
   a larger crater's overlay is a smooth offset, not noise). Smaller craters barely move
   a plane fitted over a larger crater's floor, and leaving them out makes every
   crater's parameters independent of the requested resolution. The slope of that base
   against "up" (radial, or a shape model's self-gravity) sets the slope erosion
   (Martin's lunar paper III), as in the sequential stamp.
3. **Composition.** Each crater acts on the height before it as an affine map: inside its
   (irregular) rim it replaces the terrain by its base quadric plus its profile (so older
   craters there are erased); outside, its profile (ejecta, roughness) adds to the old
   terrain, which is blended into the base quadric between the rim and 1.5 radii (the
   rim stays continuous whatever lies under it). The height at a point is the
   composition over the craters that reach it, youngest first in the fixed (age, id)
   order, stopping at the first rim that holds the point; then the base shape.
   On ground tilted more than 10 deg from the radial a crater is made in its
   base plane's own frame, as the sequential stamp makes it (issue 36): a point's foot on
   the base plane gives its in-plane coordinates; inside the rim the height is where the
   radial line meets the crater's surface over the base plane (the stamp's root finder)
   plus the base quadric's curvature taken radially, as outside, where the profile is
   added along the base normal. Made radially instead, a crater on ground tilted 49 deg
   had its rim 1.50 radii out along the dip and 1.01 across.
   The sequential stamp shifts the older terrain outside the rim by its offset from the
   base at the rim (an azimuth table sampled from everything older), and fits its base to
   everything older; both would make a crater depend on every older crater around it.
   The blend and the fit to larger craters keep the point local, and leave the terrain
   around craters diffused flat somewhat smoother than sequential stamping makes it
   (on the faulted preset ~10 % less relief at their scale, which their rim-minus-floor
   depth, a small difference of two noise maxima, turns into -40 %); craters with relief
   agree (figures: ``tests/benchmarks/ondemand_faithfulness.py``).

Which craters are needed for a set of points is found bin by bin, smallest first: those
in the cells around the points, and then every larger crater that reaches a stencil
point of a needed crater, until nothing changes. The values do not depend on that set
(a superset gives the same bytes), nor on the point batch, nor on the thread count.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from craters import CraterLayer, ModelAgeLayer
from craters._shared import check_positive
from craters.catalog import add_columns, make_catalog
from craters.local import bin_bounds, bin_level, bins, draw_cells
from craters.morphology import EJECTA_EDGE
from craters.stamp import (
    resolve_roughness,
    rim_perturbations_from_phases,
    stamping_profiles,
)

from ..parallel.backends import serial_below
from ..scene import Scene
from . import _field_kernels as K
from .base import BaseField, base_field, lat_lon_of, per_scene, tangent_frame
from .cellsets import (
    GrowingRows,
    block_level,
    block_pairs,
    cell_areas,
    cells_of,
    coarser,
    in_sorted,
    neighbour_set,
    neighbours,
    reaching,
    unique_inverse,
    unique_sorted,
)
from .rocks import RockField

__all__ = ["BLEND_EDGE", "IRREGULARITY", "ROUGHNESS_OCTAVES", "CraterField", "crater_field",
           "heights_at_units"]


#: Radii (x = r / R) out to which the older terrain is blended into a crater's base.
BLEND_EDGE = 1.5
#: Largest rim-radius perturbation (the sequential stamp's default).
IRREGULARITY = 0.02
#: Octaves of a crater's roughness overlay (radius down to radius / 2): fixed per
#: crater, so the overlay never depends on the requested resolution (the smallest craters
#: drawn, 3 pixels across, get roughness down to 0.75 pixel, as the sequential stamp's
#: overlay stops at two grid spacings; smaller craters and rocks carry on below).
ROUGHNESS_OCTAVES = 2
_RINGS = ((0.0, 1), (0.25, 6), (0.5, 12), (0.75, 18), (1.0, 24))
_BIN_MARGIN = 1.05
#: Most craters whose parameters (base quadric, slope erosion) a field keeps between
#: calls (a descent's frames and a build's patches share most of their larger craters).
PARAMS_CACHE = 500_000


def _stencil_xy() -> np.ndarray:
    pts = []
    for ring, (r, n) in enumerate(_RINGS):
        for s in range(n):
            phi = 2.0 * np.pi * (s + 0.5 * (ring % 2)) / n
            pts.append((r * np.cos(phi), r * np.sin(phi)))
    return np.array(pts)


STENCIL_XY = _stencil_xy()
FIT = K._fit_operator(STENCIL_XY)


@dataclasses.dataclass
class _Craters:
    """Craters as columns (the kernel's record ``fc`` plus the catalogue's)."""

    fc: np.ndarray
    diameter_m: np.ndarray
    age_gyr: np.ndarray
    id: np.ndarray
    cell: np.ndarray
    rim_phases: np.ndarray
    seed: np.ndarray
    layer: np.ndarray

    @staticmethod
    def concat(parts: list) -> _Craters:
        return _Craters(*(np.concatenate([getattr(p, f.name) for p in parts])
                          for f in dataclasses.fields(_Craters)))

    def take(self, idx) -> _Craters:
        return _Craters(*(getattr(self, f.name)[idx] for f in dataclasses.fields(_Craters)))

    def __len__(self) -> int:
        return len(self.diameter_m)


class CraterField:
    """The crater layers of a scene as a local field (module notes)."""

    def __init__(self, scene: Scene, base: BaseField | None = None):
        self.scene = scene
        self.base = base if base is not None else base_field(scene)
        self.rocks = RockField(scene, self.base)
        self._params: dict[tuple[int, int], np.ndarray] = {}
        self.layers: tuple[CraterLayer | ModelAgeLayer, ...] = tuple(scene.craters.layers)
        self.target = scene.target()
        rough, irregular = resolve_roughness(scene.craters.roughness)
        self.rough = np.array([rough.bowl, rough.wall, rough.ejecta])
        self.terraces = rough.terraces
        self.gain = 2.0 ** (rough.fractal_dimension - 3.0)
        self.irregularity = IRREGULARITY if irregular else 0.0
        self.xe = float(EJECTA_EDGE)
        # the level of each size bin: cells at least an ejecta reach plus a radius wide
        self.levels: dict[int, int] = {}
        self._bins = [frozenset(int(b) for b in bins(la)) for la in self.layers]
        # the largest diameter of each bin over the layers that have it
        self._tops = {b: max(bin_bounds(la, b)[1] for la, bs in zip(self.layers, self._bins,
                                                                    strict=True) if b in bs)
                      for b in set().union(*self._bins)}
        for la in self.layers:
            for b in bins(la):
                # a crater's ejecta reach plus the radius of a smaller crater it shapes
                reach = (self.xe * (1.0 + self.irregularity) + 1.0) * 0.5 * bin_bounds(la, b)[1]
                self.levels[int(b)] = min(self.levels.get(int(b), 99),
                                          bin_level(_BIN_MARGIN * reach / self.base.min_radius_m))

    # ------------------------------------------------------------------ catalogue
    def _draw(self, b: int, cells: np.ndarray, d_min: float) -> _Craters:
        """Craters of bin ``b`` (all layers) in ``cells``, at least ``d_min`` across."""
        level = self.levels[b]
        area = cell_areas(self.base, level, cells)
        parts = []
        for idx, la in enumerate(self.layers):
            if b not in self._bins[idx] or bin_bounds(la, b)[1] <= d_min:
                continue
            got = draw_cells(la, idx, seed=self.base.seed, b=b, level=level, cell_ids=cells,
                             area_m2=area)
            keep = got["diameter_m"] >= d_min
            parts.append(self._records({k: v[keep] for k, v in got.items()}, idx))
        if not parts:
            return self._records(None, 0)
        return _Craters.concat(parts)

    def _records(self, got: dict | None, layer: int) -> _Craters:
        if got is None:
            z = np.zeros(0)
            return _Craters(np.zeros((0, K.N_COLS)), z, z, z.astype(np.uint64),
                            z.astype(np.uint64), np.zeros((0, 15)), z.astype(np.uint64),
                            z.astype(np.int64))
        u = got["unit"]
        n = len(u)
        fc = np.zeros((n, K.N_COLS))
        fc[:, K.C0:K.C2 + 1] = u
        e, nn = tangent_frame(u)
        fc[:, K.E0:K.E2 + 1] = e
        fc[:, K.N0:K.N2 + 1] = nn
        fc[:, K.RHO] = self.base.radius(u)
        radius = 0.5 * got["diameter_m"]
        fc[:, K.RAD] = radius
        far = self.xe * radius * (1.0 + self.irregularity) * (1.0 + 1e-9) / fc[:, K.RHO]
        fc[:, K.COS_FAR] = np.cos(np.minimum(far, np.pi))
        fc[:, K.FAR] = np.minimum(far, np.pi)
        fc[:, K.CHORD2] = (2.0 * np.sin(0.5 * fc[:, K.FAR])) ** 2
        return _Craters(fc, got["diameter_m"], got["age_gyr"], got["id"], got["cell"],
                        got["rim_phases"], got["seed"], np.full(n, layer, dtype=np.int64))

    def needed(self, units: np.ndarray, d_min: float, blocks: tuple[int, np.ndarray]):
        """The craters the heights at ``units`` need (module notes), and (owner, dep)
        index pairs: crater ``dep`` is larger than ``owner`` and its ejecta may reach
        the owner's rim disc (a superset of what the owner's base fit reads). The
        points' blocks (their level and sorted occupied cells) narrow the craters drawn
        around them to those that may reach a point of a block (the others reach no point:
        leaving them and their dependencies out changes no value)."""
        parts: list[_Craters] = []
        owners_all: list[np.ndarray] = []
        deps_all: list[np.ndarray] = []
        fc_rows, d_rows = GrowingRows(K.N_COLS), GrowingRows(0)  # the craters kept
        at_level = self._cells_by_level(units, d_min)
        for b in sorted(self.levels):
            if self._tops[b] <= d_min:
                continue
            level = self.levels[b]
            n_have = fc_rows.n
            first_pair = len(owners_all)
            # the query rule: every crater of the cells around the points' cells
            cand_cells = unique_sorted(neighbours(at_level[level]))
            q_cells = cand_cells
            # the cells around the centres of the needed smaller craters
            own_cells = cells_of(fc_rows.kept()[:, K.C0:K.C2 + 1], level)
            set9 = neighbour_set(own_cells)  # the cells around them, distinct
            cand_cells = unique_sorted(np.concatenate([cand_cells, set9]))
            cand = self._draw(b, cand_cells, d_min)
            needed_mask = in_sorted(cand.cell, q_cells)
            needed_mask[needed_mask] = reaching(cand.fc[needed_mask], *blocks)
            owners = np.arange(n_have, dtype=np.int64)
            owner_cells = own_cells
            # the query-rule craters are owners within this bin too
            first = np.flatnonzero(needed_mask)
            while True:
                owners = np.concatenate([owners, first + n_have])
                first_cells = cells_of(cand.fc[first, K.C0:K.C2 + 1], level)
                owner_cells = np.concatenate([owner_cells, first_cells])
                set9 = unique_sorted(np.concatenate([set9, neighbour_set(first_cells)]))
                extra = set9[~in_sorted(set9, cand_cells)]
                if len(extra):  # cells around same-bin owners not drawn yet
                    more = self._draw(b, extra, d_min)
                    cand = _Craters.concat([cand, more])
                    needed_mask = np.concatenate([needed_mask, np.zeros(len(more), bool)])
                    cand_cells = unique_sorted(np.concatenate([cand_cells, extra]))
                o, d = _dep_pairs(owners, owner_cells, cand, n_have, fc_rows.with_tail(cand.fc),
                                  d_rows.with_tail(cand.diameter_m))
                owners_all.append(o)
                deps_all.append(d)
                hit = np.zeros(len(cand), bool)
                hit[d - n_have] = True
                first = np.flatnonzero(hit & ~needed_mask)
                needed_mask |= hit
                if not len(first):
                    break
                owners = np.zeros(0, dtype=np.int64)
                owner_cells = np.zeros(0, dtype=np.uint64)
                set9 = np.zeros(0, dtype=np.uint64)
            keep = np.flatnonzero(needed_mask)
            # this bin's pairs point at its candidates: renumber them (earlier bins' pairs
            # hold kept indices below n_have already)
            for pairs in (owners_all, deps_all):
                pairs[first_pair:] = _renumbered(pairs[first_pair:], keep, len(cand), n_have)
            kept = cand.take(keep)
            parts.append(kept)
            fc_rows.keep(kept.fc)
            d_rows.keep(kept.diameter_m)
        craters = _Craters.concat(parts) if parts else self._records(None, 0)
        if owners_all:
            owner = np.concatenate(owners_all)
            dep = np.concatenate(deps_all)
            ok = (owner >= 0) & (dep >= 0)
            return craters, owner[ok], dep[ok]
        return craters, np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64)

    def _cells_by_level(self, units: np.ndarray, d_min: float) -> dict[int, np.ndarray]:
        """{level: the sorted distinct cells of the points} at every level a bin with
        craters >= ``d_min`` is drawn at: the finest once, the coarser ones by shifts."""
        at_level: dict[int, np.ndarray] = {}
        drawn = {lv for b, lv in self.levels.items() if self._tops[b] > d_min}
        level_now = max(drawn, default=0)
        cells_now = unique_sorted(cells_of(units, level_now))
        for lv in sorted(drawn, reverse=True):
            cells_now = coarser(cells_now, level_now, lv)
            level_now = lv
            at_level[lv] = cells_now
        return at_level

    def catalog(self, units: np.ndarray, d_min: float) -> np.ndarray:
        """The crater catalog (oldest first) of the craters that the heights at ``units``
        with craters >= ``d_min`` are made of (for every vertex of a body, the whole
        body's craters >= ``d_min``): ``craters.make_catalog`` columns (``degradation``:
        the share of the fresh depth gone, by diffusion and slope erosion) plus ``id``,
        ``layer``, and as made: ``rim_radius_m``, ``depth_m`` (after slope erosion),
        ``slope_factor`` (0: erased on ground steeper than the angle of repose),
        ``centre_x_m, centre_y_m, centre_z_m`` (the centre on its base, body frame: what
        :func:`latlong.sensors.labels.crater_labels` measures from)."""
        self.radii(units, d_min)
        return self.last_catalog()

    def last_catalog(self) -> np.ndarray:
        """:meth:`catalog` of the craters of the last :meth:`radii` call."""
        cr, fc = self.last["craters"], self.last["fc"]
        u = fc[:, K.C0:K.C2 + 1]
        lat, lon = lat_lon_of(u)
        kinds = np.array([la.kind for la in self.layers] or ["crater"])
        depth = fc[:, K.DEPTH] * fc[:, K.SCALE]
        with np.errstate(divide="ignore", invalid="ignore"):
            degradation = np.clip(1.0 - depth / self.last["fresh_depth_m"], 0.0, 1.0)
        cat = make_catalog(lat_deg=lat, lon_deg=lon, diameter_m=cr.diameter_m,
                           age_gyr=cr.age_gyr, degradation=degradation,
                           kind=kinds[cr.layer], layer=cr.layer)
        # the centre on the ground the crater was made in (its base at the centre): the
        # position the sensors' labels measure a crater from
        centre = u * (fc[:, K.RHO] + fc[:, K.P0])[:, None]
        cat = add_columns(cat, ("id", "rim_radius_m", "depth_m", "slope_factor",
                                "centre_x_m", "centre_y_m", "centre_z_m"),
                          (cr.id, fc[:, K.RAD], depth, fc[:, K.SCALE], centre[:, 0],
                           centre[:, 1], centre[:, 2]))
        # oldest first: the composition's (age, id) order reversed
        return cat[np.lexsort((cr.id, cr.age_gyr))[::-1]]

    # ------------------------------------------------------------------ parameters
    _PARAM_COLS = np.r_[K.P0:K.ACTIVE + 1, K.TILT:K.TILT + 10]

    def _recall(self, keys: list, fc: np.ndarray) -> np.ndarray:
        """Fill ``fc``'s parameter columns (base quadric, slope erosion, tilted frame) of
        the craters an earlier call computed; returns which those are."""
        known = np.array([k in self._params for k in keys], dtype=bool)
        if known.any():
            fc[np.ix_(known, self._PARAM_COLS)] = np.array(
                [self._params[k] for k, h in zip(keys, known, strict=True) if h])
        return known

    def _remember(self, keys: list, fc: np.ndarray) -> None:
        if len(self._params) + len(keys) > PARAMS_CACHE:
            self._params.clear()
        self._params.update(zip(keys, fc[:, self._PARAM_COLS], strict=True))

    # ------------------------------------------------------------------ heights
    def radii(self, units: np.ndarray, d_min: float) -> np.ndarray:
        """Radius (m) in each direction ``units`` (n, 3) with craters >= ``d_min``."""
        units = np.ascontiguousarray(units, dtype=np.float64)
        base = self.base.radius(units)
        # blocks of points, and the craters (rocks) that may reach each block
        level = block_level(len(units), units)
        occ, block_of = unique_inverse(cells_of(units, level))
        block_of = block_of.astype(np.int64).ravel()
        cr, owner, dep = self.needed(units, d_min, (level, occ))
        n = len(cr)
        if n == 0:
            self.last = {"craters": cr, "fc": cr.fc, "rank": np.zeros(0, np.int64), "n_pairs": 0,
                         "fresh_depth_m": np.zeros(0)}
            out = base.copy()
            self.rocks.add(units, out, d_min, level, occ, block_of)
            return out
        fc = cr.fc
        order = np.lexsort((cr.id, cr.age_gyr)).astype(np.int64)  # youngest first
        rank = np.empty(n, dtype=np.int64)
        rank[order] = np.arange(n)
        # a layer's fixed degradation overrides the one its ages give (as in a build)
        fixed = np.array([np.nan if la.degradation is None else la.degradation
                          for la in self.layers] or [np.nan])
        cat = make_catalog(lat_deg=np.zeros(n), lon_deg=np.zeros(n), diameter_m=cr.diameter_m,
                           age_gyr=cr.age_gyr, degradation=fixed[cr.layer])
        prof = stamping_profiles(cat, self.target, ejecta_edge=self.xe)
        tabs = np.ascontiguousarray(prof.tables)
        rims = np.ascontiguousarray(rim_perturbations_from_phases(cr.rim_phases,
                                                                  self.irregularity))
        fc[:, K.DEPTH] = prof.depth_m
        fc[:, K.WARP] = prof.warps(self.terraces)
        seeds = np.ascontiguousarray(cr.seed)
        up = np.ascontiguousarray(self.base.up(fc[:, K.C0:K.C2 + 1]))
        # dependencies per owner, youngest first
        key = unique_sorted(owner * n + dep)
        owner, dep = key // n, key % n
        # a base is fitted to older, larger craters: the younger left out (fewer generations)
        older = (rank[dep] > rank[owner]) & (cr.diameter_m[dep] > cr.diameter_m[owner])
        owner, dep = owner[older], dep[older]
        srt = np.lexsort((rank[dep], owner))
        dep_list = np.ascontiguousarray(dep[srt])
        dep_start = np.searchsorted(owner[srt], np.arange(n + 1)).astype(np.int64)
        # craters whose parameters an earlier call computed (a crater's parameters are a
        # function of the crater alone: the same bits whenever they are computed)
        keys = list(zip(cr.cell.tolist(), cr.id.tolist(), strict=True))
        known = self._recall(keys, fc)
        fc[known, K.DEPTH] = prof.depth_m[known]
        new = np.flatnonzero(~known)
        stencil = np.zeros((n, len(STENCIL_XY), 3))
        st_base = np.zeros((n, len(STENCIL_XY)))
        if len(new):
            stencil[new] = _stencil_points(fc[new])
            st_base[new] = self.base.radius(stencil[new].reshape(-1, 3)).reshape(len(new), -1)
        todo = np.lexsort((cr.id, -cr.diameter_m)).astype(np.int64)
        diam = np.ascontiguousarray(cr.diameter_m)
        rough = self.rough
        gen = np.zeros(n, dtype=np.int64)
        K._generations_kernel(todo, dep_start, dep_list, gen)
        todo = todo[np.argsort(gen[todo], kind="stable")]
        todo = todo[~known[todo]]
        gen_start = np.searchsorted(gen[todo], np.arange(gen.max() + 2)).astype(np.int64)
        K._params_kernel(todo, gen_start, dep_start, dep_list, stencil, st_base, FIT, fc, tabs,
                         rims, seeds, rough, self.gain, ROUGHNESS_OCTAVES, self.xe, BLEND_EDGE,
                         rank, diam, up, 20.0, 45.0, True)
        self._remember([keys[i] for i in new], fc[new])
        active = order[fc[order, K.ACTIVE] > 0]
        blk_start, blk_list = block_pairs(fc, fc[:, K.FAR], active, level, occ, rank)
        out = np.empty(len(units))
        K._points_kernel(units, block_of, blk_start, blk_list, base, fc, tabs, rims, seeds,
                         rough, self.gain, ROUGHNESS_OCTAVES, self.xe, BLEND_EDGE, rank, diam, out)
        self.rocks.add(units, out, d_min, level, occ, block_of)
        self.last = {"craters": cr, "fc": fc, "rank": rank, "n_pairs": len(key),
                     "fresh_depth_m": prof.fresh_depth_m}
        return out


def _renumbered(pairs: list[np.ndarray], keep: np.ndarray, n_cand: int,
                n_have: int) -> list[np.ndarray]:
    """Indices ``n_have + i`` of a bin's candidates become those of the kept ones
    (``n_have + position in keep``; -1 for a candidate left out); lower ones stay."""
    remap = np.full(n_cand, -1, dtype=np.int64)
    remap[keep] = np.arange(len(keep)) + n_have
    out = []
    for x in pairs:
        y = x.copy()
        hi = x >= n_have
        y[hi] = remap[x[hi] - n_have]
        out.append(y)
    return out


def _dep_pairs(owners, owner_cells, cand: _Craters, n_have: int, fc_all, d_all):
    """(owner, dep) pairs of ``owners`` (indices into ``fc_all``, their centres in
    ``owner_cells``) and the candidates of the bin (indices ``n_have + i``)
    (:func:`_field_kernels._dep_kernel`). Owners of one cell share the candidates of the
    cells around it, found once a cell."""
    if not len(owners) or not len(cand):
        return np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64)
    order = np.argsort(cand.cell, kind="stable")
    srt = cand.cell[order]
    first = np.concatenate([[True], srt[1:] != srt[:-1]])
    ucells, starts = srt[first], np.flatnonzero(first)
    ends = np.append(starts[1:], len(order))
    cells, owner_cell = unique_inverse(owner_cells)
    around = neighbours(cells, keep_shape=True)
    pos = np.minimum(np.searchsorted(ucells, around), len(ucells) - 1)
    found = ucells[pos] == around
    # each distinct neighbour once (the neighbourhood of a cube corner repeats cells)
    earlier = np.tril(np.ones((9, 9), dtype=bool), -1)
    found &= ~((around[:, :, None] == around[:, None, :]) & earlier).any(axis=2)
    lo = np.where(found, starts[pos], 0).astype(np.int64)
    hi = np.where(found, ends[pos], 0).astype(np.int64)
    cand_idx = (order + n_have).astype(np.int64)
    with serial_below(len(owners)):
        return K._dep_kernel(owners.astype(np.int64), owner_cell.astype(np.int64), lo, hi,
                             cand_idx, fc_all, d_all)


def _stencil_points(fc: np.ndarray) -> np.ndarray:
    """(n, 61, 3) directions of each crater's stencil: angle r R / rho from its centre."""
    out = np.empty((len(fc), len(STENCIL_XY), 3))
    if len(fc):
        K._stencil_kernel(np.ascontiguousarray(fc), STENCIL_XY, out)
    return out


_CRATER_FIELDS: list = []


def crater_field(scene: Scene) -> CraterField:
    """The scene's :class:`CraterField`, made once per scene."""
    return per_scene(_CRATER_FIELDS, scene, CraterField)


def heights_at_units(scene: Scene, units, *, resolution_m: float) -> np.ndarray:
    """Radii (m) of the scene's surface in directions ``units`` (n, 3) at
    ``resolution_m``: craters at least 3 resolutions across."""
    resolution_m = check_positive("resolution_m", resolution_m)
    return crater_field(scene).radii(np.asarray(units, dtype=np.float64).reshape(-1, 3),
                                     3.0 * resolution_m)
