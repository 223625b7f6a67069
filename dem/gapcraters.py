r"""Craters in filled gaps, at the crater density around each gap.

:func:`dem.fill_gaps` fills a gap with fractal terrain; a gap much larger than the
smallest crater the DEM resolves would then be a smooth, craterless patch in a cratered
landscape. So each gap that can hold a crater of :data:`dem.craterdensity.
RESOLVED_CRATER_PX` (4) pixels with its ejecta gets craters (``craters.stamp_many``) at
one of these densities (the ``craters`` argument of :func:`dem.fill_gaps`):

``"auto"`` (default)
    *Measured around the gap*: :func:`dem.crater_density` (the rim-over-floor crater
    detector, craters of 6 px and up, where it finds nearly all but the most degraded)
    on the known terrain of a window reaching one gap size beyond the gap on every side
    (clipped to the DEM). What that means, honestly: the number of crater-like bowls the
    detector finds per unit of known area near the gap, as a power law ``N(>D) = c D^k``
    with the equilibrium slope ``k = -2``, continued down to the resolved size.
    It counts craters deeper than 1 % of their diameter and clearly deeper than the
    terrain's own bowls, so it is a lower bound of the real population (and crater-free
    fBm terrain yields a few false ones: a low density); it is one number for the whole
    window (a gap on a mare/highland boundary gets the mix); fewer than 5 craters found:
    no craters (no density can be claimed).
a crater layer (``c=..,k=..,d_min_m=..,d_max_m=..`` or :class:`craters.CraterLayer`)
    The caller's population, e.g. a production function's law at the surface's age.
``None``
    No craters.

Each crater gets a diameter from the law between the resolved size (4 px, or the
layer's ``d_min_m`` if larger) and the largest crater whose ejecta (1.5 diameters from
the centre) fits in the gap; centres fall uniformly in the gap and a crater is kept only
where all of it fits inside (the known pixels are never changed), so the density holds
on the part of the gap a crater of that size fits in and is lower near the gap's edge.
Ages are uniform in 0..3.5 Gyr with the craters package's degradation for their age.
The craters are drawn from a generator keyed by (seed, level, the gap's global
position), so a crop that holds the gap stamps the same ones. Their shape is
``craters.stamp_many``'s, on the body the DEM's CRS names (``dem.frame.crater_target``;
the Moon without one) or the ``target`` given.

Measured (``tests/benchmarks/bench_craterdensity.py``): a 160-px disc cut from the LOLA
crop gets 34-42 craters (c = 0.043 from 55 craters found around it); the detector
then finds 0.45-0.75 times as many craters of 6 px and up inside the disc as around
it: the stamped craters include degraded ones it misses, and large ones cannot sit near
the gap's edge. Stamped into a 200-px gap of synthetic cratered terrain the ratio is in
the tests.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any

import numpy as np

import craters
from craters._shared import about

from .craterdensity import RESOLVED_CRATER_PX, CraterDensity, crater_density

__all__ = ["gap_crater_layer", "stamp_gap_craters"]

# fewest craters around a gap for a measured density
_MIN_COUNT = 5
# the ejecta reach of a crater in radii, with the rim irregularity stamp_many adds
_REACH_RADII = craters.DEFAULT_EJECTA_EDGE * 1.02


def gap_crater_layer(spec):
    """``"auto"``, None or a crater layer record from the ``craters`` argument.

    A layer is any record :func:`craters.population` takes that has ``d_min_m`` and
    ``d_max_m`` (:class:`craters.CraterLayer`; a spec string is parsed by
    :func:`craters.parse_layer_spec`).
    """
    if spec is None or spec is False or (isinstance(spec, str) and spec.lower() == "none"):
        return None
    if isinstance(spec, str) and spec.lower() == "auto":
        return "auto"
    if isinstance(spec, str):
        with about("craters"):
            return craters.parse_layer_spec(spec)
    if dataclasses.is_dataclass(spec) and hasattr(spec, "d_min_m") and hasattr(spec, "d_max_m"):
        return spec
    raise TypeError(f"`craters` must be 'auto', None, a spec string or a craters.CraterLayer; "
                    f"got {type(spec).__name__}")


def stamp_gap_craters(z: np.ndarray, sl, hole: np.ndarray, layer, key: int, target, *,
                      pixel_size_m, level: int, origin, around, offset=(0, 0)):
    """Stamp craters into one filled gap of ``z`` in place; returns (catalog, note).

    ``z`` is the DEM or a window of it at pixel ``offset`` of the DEM, holding the gap
    and, with ``layer`` "auto", one gap size around it (or the DEM's edge); ``sl`` is
    the gap's bounding box in ``z``, ``hole`` its mask there, ``layer`` "auto" or a
    :class:`craters.CraterLayer`, ``target`` the craters' body; ``pixel_size_m`` the
    DEM's (x, y), ``level`` and ``origin`` its lattice place (:attr:`Dem.origin`),
    ``around(w0, w1, v0, v1)`` the DEM (original known pixels) of rows ``w0:w1`` and
    columns ``v0:v1`` of ``z`` (what the density is measured on). The catalog has
    ``x_m, y_m`` from the centre of the DEM's pixel (0, 0) (columns and rows times the
    pixel sizes) and the stamped columns of ``craters.stamp_many``; the note records
    the density used (None when the gap holds no crater).
    """
    from scipy import ndimage

    r0, r1, c0, c1 = sl[0].start, sl[0].stop, sl[1].start, sl[1].stop
    g0, h0 = origin[0] + offset[0] + r0, origin[1] + offset[1] + c0  # lattice index
    dx, dy = pixel_size_m
    pixel = math.sqrt(dx * dy)
    # distance (pixels) from each gap pixel to the nearest pixel outside the gap
    inside = ndimage.distance_transform_edt(np.pad(hole, 1))[1:-1, 1:-1]
    d_lo = RESOLVED_CRATER_PX * pixel
    d_fit = 2.0 * (float(inside.max()) - 1.0) / _REACH_RADII * pixel
    if layer != "auto":
        d_lo = max(d_lo, layer.d_min_m)
        d_fit = min(d_fit, layer.d_max_m)
    if d_fit <= d_lo:
        return None, None
    note: dict[str, Any] = {"gap": [int(g0), int(h0), int(r1 - r0), int(c1 - c0)]}
    if layer == "auto":
        density = _density_around(z, sl, around)
        note.update(source="measured around the gap",
                    craters_found=0 if density is None else density.count)
        if density is None or density.count < _MIN_COUNT:
            return None, note
        law = density.layer(d_lo, d_fit, kind="gap")
        note.update(c=density.c, k=density.k, area_km2=density.area_m2 / 1e6,
                    counted_m=[density.d_lo_m, density.d_hi_m])
    else:
        law = dataclasses.replace(layer, d_min_m=d_lo, d_max_m=d_fit)
        note.update(source="given", layer=repr(layer))
    note.update(d_min_m=d_lo, d_max_m=d_fit)
    gen = np.random.default_rng([key, 21, level, g0 + 2**40, h0 + 2**40])
    cat = craters.population([law],
                             x_range_m=(-0.5 * dx, (c1 - c0 - 0.5) * dx),
                             y_range_m=(-0.5 * dy, (r1 - r0 - 0.5) * dy), rng=gen)
    col = np.clip(np.rint(cat["x_m"] / dx).astype(int), 0, c1 - c0 - 1)
    row = np.clip(np.rint(cat["y_m"] / dy).astype(int), 0, r1 - r0 - 1)
    fits = hole[row, col] & (inside[row, col] - 1.0 >= 0.5 * _REACH_RADII
                             * cat["diameter_m"] / pixel)
    cat = cat[fits]
    note["stamped"] = 0
    if len(cat) == 0:
        return None, note
    # stamp on the gap's box (pixel-unit positions: one pixel size for both axes)
    local = {name: cat[name] for name in cat.dtype.names}
    local.update(x_m=cat["x_m"] / dx * pixel, y_m=cat["y_m"] / dy * pixel)
    block = z[r0:r1, c0:c1]
    # other gaps in the box that are not filled yet (a gap around an island holding one)
    # are NaN; the craters lie inside this gap and never reach them, so any number does
    ground = np.where(np.isnan(block), 0.0, block) if np.isnan(block).any() else block
    out, stamped = craters.stamp_many(ground, pixel, craters.make_catalog(**local), rng=gen,
                                      target=target, return_catalog=True)
    block[hole] = out[hole]
    stamped["x_m"] = (stamped["x_m"] / pixel + (c0 + offset[1])) * dx
    stamped["y_m"] = (stamped["y_m"] / pixel + (r0 + offset[0])) * dy
    note["stamped"] = len(stamped)
    return stamped, note


def _density_around(z: np.ndarray, sl, around) -> CraterDensity | None:
    """:func:`dem.crater_density` of the known terrain within one gap size of the gap."""
    rows, cols = z.shape
    r0, r1, c0, c1 = sl[0].start, sl[0].stop, sl[1].start, sl[1].stop
    reach = max(r1 - r0, c1 - c0)
    w0, w1 = max(r0 - reach, 0), min(r1 + reach, rows)
    v0, v1 = max(c0 - reach, 0), min(c1 + reach, cols)
    return crater_density(around(w0, w1, v0, v1))
