"""Rocks on demand: the scene's boulder layers as part of the height field, drawn cell by
cell like the craters (:func:`craters.local.draw_rock_cells`), so any window gets the
rocks the whole body has there.

Each rock is an ellipsoid (footprint semi-axes ``D/2 sqrt(e)`` and ``D/2 / sqrt(e)``,
height ``flatten D`` x a factor in [0.7, 1.3], the scene's boulder shape) buried by its
burial fraction, cut by six facet planes into an angular block and roughened by its own
fBm (3 octaves from half its long semi-axis, 0.12 of its half-height). It stands on the
terrain made by the base shape and the craters; where rocks overlap the tallest counts (a
maximum, so no order enters). Rocks smaller than the requested minimum size (3 pixels)
are left out: that only filters, so a finer request changes heights only inside the added
rocks' footprints. A layer's ``near`` share (rocks around crater rims) is not drawn
apart on demand: its rocks are placed uniformly with the others.

For whole-body builds the sequential path places boulders as separate meshes
(:func:`latlong.place_boulders`); here they are relief, which is what a camera, a LIDAR
or a slope map of a window sees.
"""

from __future__ import annotations

import logging

import numpy as np

from craters.catalog import add_columns, make_catalog
from craters.local import ROCK_FACETS, bin_bounds, bin_level, bins, draw_rock_cells

from ..scene import Scene
from . import _rock_kernels as R
from .base import BaseField, lat_lon_of, tangent_frame
from .cellsets import block_pairs, cell_areas, cells_of, coarser, neighbour_set, unique_sorted

__all__ = ["RockField"]

logger = logging.getLogger(__name__)

_BIN_MARGIN = 1.05
assert ROCK_FACETS == R.N_FACETS


class RockField:
    """The boulder layers of a scene as rocks in the height field (module notes)."""

    def __init__(self, scene: Scene, base: BaseField):
        self.base = base
        self.layers = tuple(scene.boulders.layers)
        self.shape = scene.boulders.shape
        if any(la.near > 0 for la in self.layers):
            logger.warning("terrain on demand places every rock uniformly: the boulder "
                           "layers' `near` share is not drawn around crater rims")
        self.levels: dict[int, int] = {}
        stretch = np.sqrt(self.shape.elongation)
        for la in self.layers:
            for b in bins(la):
                reach = 0.5 * bin_bounds(la, b)[1] * stretch
                self.levels[int(b)] = min(self.levels.get(int(b), 99),
                                          bin_level(_BIN_MARGIN * reach / base.min_radius_m))
        self.last = self.rocks(np.zeros((0, 3)), np.inf)
        self.last_which = np.zeros(0, dtype=np.int64)  # each point's rock row, -1: none

    def __bool__(self) -> bool:
        return bool(self.layers)

    def rocks(self, units: np.ndarray, d_min: float) -> dict:
        """The rocks at least ``d_min`` across that may stand over ``units``: the
        records (:mod:`._rock_kernels` columns, ``"rc"``) and the catalogue columns."""
        parts = []
        fine: tuple[int, np.ndarray] | None = None
        for b, level in sorted(self.levels.items()):  # finest cells first
            drawn = [idx for idx, la in enumerate(self.layers)
                     if b in set(bins(la).tolist()) and bin_bounds(la, b)[1] > d_min]
            if not drawn or not len(units):
                continue
            # the points' cells once, at the finest level drawn; coarser ones by shifts
            fine = (level, unique_sorted(cells_of(units, level))) if fine is None else fine
            cells = neighbour_set(coarser(fine[1], fine[0], level))
            area = cell_areas(self.base, level, cells)
            for idx in drawn:
                la = self.layers[idx]
                got = draw_rock_cells(la, idx, seed=self.base.seed, b=b, level=level,
                                      cell_ids=cells, area_m2=area,
                                      elongation=self.shape.elongation,
                                      flatten=self.shape.flatten)
                keep = got["diameter_m"] >= d_min
                got = {k: v[keep] for k, v in got.items()}
                got["layer"] = np.full(int(keep.sum()), idx, dtype=np.int64)
                parts.append(got)
        if not parts:
            return {"rc": np.zeros((0, R.N_ROCK_COLS)), "diameter_m": np.zeros(0),
                    "seed": np.zeros(0, np.uint64),
                    "id": np.zeros(0, np.uint64), "layer": np.zeros(0, np.int64),
                    "height_m": np.zeros(0), "burial_frac": np.zeros(0),
                    "unit": np.zeros((0, 3)), "reach_rad": np.zeros(0)}
        got = {k: np.concatenate([p[k] for p in parts]) for k in parts[0]}
        got["rc"], got["reach_rad"] = self._records(got)
        return got

    def _records(self, got: dict) -> tuple[np.ndarray, np.ndarray]:
        """(the rocks' kernel records, each rock's reach in radians)."""
        u = got["unit"]
        rc = np.zeros((len(u), R.N_ROCK_COLS))
        rc[:, 0:3] = u
        e, nn = tangent_frame(u)
        rc[:, 3:6] = e
        rc[:, 6:9] = nn
        rc[:, 9] = self.base.radius(u)
        s = np.sqrt(got["elongation"])
        a = 0.5 * got["diameter_m"] * s
        rc[:, R.A] = a
        rc[:, R.B] = 0.5 * got["diameter_m"] / s
        rc[:, 10] = a
        angle = np.minimum(a * (1.0 + 1e-9) / rc[:, 9], np.pi)
        rc[:, 11] = np.cos(angle)
        rc[:, R.CHORD2] = (2.0 * np.sin(0.5 * angle)) ** 2
        rc[:, R.CA] = np.cos(got["azimuth_rad"])
        rc[:, R.SA] = np.sin(got["azimuth_rad"])
        h = got["height_m"]
        rc[:, R.CZ] = 0.5 * h
        rc[:, R.Z0] = 0.5 * h - got["burial_frac"] * h
        f = got["facets"]
        rc[:, R.F0::4][:, :R.N_FACETS] = np.cos(f[:, :, 0])
        rc[:, R.F0 + 1::4][:, :R.N_FACETS] = np.sin(f[:, :, 0])
        rc[:, R.F0 + 2::4][:, :R.N_FACETS] = f[:, :, 1]
        rc[:, R.F0 + 3::4][:, :R.N_FACETS] = f[:, :, 2]
        return rc, angle

    def add(self, units: np.ndarray, out: np.ndarray, d_min: float, level: int,
            occ: np.ndarray, block_of: np.ndarray) -> int:
        """Adds the rocks at least ``d_min`` across to the radii ``out`` at ``units``,
        through the blocks of the crater field (``level``, the occupied block cells
        ``occ``, each point's block). Returns the number of rocks."""
        got = self.rocks(units, d_min)
        rc = np.ascontiguousarray(got["rc"])
        self.last = got
        self.last_which = np.full(len(units), -1, dtype=np.int64)
        if not len(rc):
            return 0
        active = np.arange(len(rc), dtype=np.int64)
        start, lst = block_pairs(rc, got["reach_rad"], active, level, occ, active)
        R._rocks_kernel(units, block_of, start, lst, rc, np.ascontiguousarray(got["seed"]),
                        out, self.last_which)
        return len(rc)

    def last_catalog(self, rows: np.ndarray | None = None) -> np.ndarray:
        """The boulder catalog (:func:`craters.catalog.write_catalog`'s boulder columns)
        of the rocks of the last :meth:`add` call, or of its ``rows``: centre (the
        rock's foot direction), ``diameter_m``, ``height_m``, ``burial_frac``, ``id``."""
        got = self.last
        rows = np.arange(len(got["diameter_m"])) if rows is None else np.asarray(rows)
        lat, lon = lat_lon_of(got["unit"][rows])
        cat = make_catalog(lat_deg=lat, lon_deg=lon, diameter_m=got["diameter_m"][rows],
                           kind=np.full(len(rows), "boulder"),
                           burial_frac=got["burial_frac"][rows],
                           height_m=got["height_m"][rows], layer=got["layer"][rows])
        return add_columns(cat, "id", got["id"][rows])
