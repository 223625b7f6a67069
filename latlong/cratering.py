"""Crater-saturated bodies: stamping craters via local DEM mapping (Martin 2014, V.A).

For each crater (:func:`stamp_craters`): the vertices of its region are gathered through
the ring structure (no scan of the whole body); each gets its true distance from the
crater centre (arc length at the local radius, measured between the actual surface
directions, so stretched and irregular bodies work), its azimuth in the east/north
frame at the centre, and its height radially relative to the centre's radius. The base
of the obliterated region is a quadric fitted to those vertices (on a stretched or
curved body radial heights are curved even where the surface is smooth; on flat ground
it is the plane); the terrain relative to it is binned into a local height grid at the
local vertex spacing (holes filled by 8-direction inverse-distance averages), from which
the rim offsets are sampled. The slope used for slope erosion is the angle between the
base's normal and the normal of the reference body (the stretched sphere; the radial
direction when unstretched), so an elongated body's shape is not mistaken for steep
ground. Then the crater (:mod:`craters` profile, irregular rim, roughness) is evaluated
at every vertex with its true distance and azimuth, and the vertex's radial vector is
rescaled by its height change. Works across the 0/360 degree seam and over the poles.
The arguments every surface's stamping shares are checked once
(:func:`craters.stamp.stamp_request`).
"""

from __future__ import annotations

import dataclasses
import logging

import numba
import numpy as np

import craters as _craters
from craters._shared import check_choice, check_range, normalize_rng, progress_bar
from craters.profile import DEFAULT_EJECTA_EDGE
from craters.stamp import (
    StampRequest,
    as_stamped,
    stamp_request,
    stamped_after,
    stamping_profiles,
)
from craters.targets import Target

from ._crater_kernels import _stamp_body_kernel
from ._wave_kernels import _balance_waves_kernel, _stamp_waves_kernel, _wave_schedule_kernel
from .body import Body
from .surface import band_areas, sample_surface_points

__all__ = ["WaveScheduleOutgrown", "body_population", "crater_extents_deg", "stamp_craters"]

logger = logging.getLogger(__name__)
_BATCH = 256  # craters per kernel call when a progress bar is shown
#: The wave schedule allows each crater's local radius to fall to this share of its
#: value before stamping (checked: beyond it the craters are stamped serially).
WAVE_RADIUS_SHARE = 0.8
WAVE_FIXED_COST = 200.0  # a crater's fixed work (local grid, fits), in gathered vertices
_CHUNK = 1 << 20  # vertices per block of the whole-body checks (bounded temporaries)


class WaveScheduleOutgrown(RuntimeError):
    """:func:`stamp_craters` with ``overwrite_body=True`` found its parallel wave schedule
    outgrown (a crater's cap grew past the bound it was scheduled with): the body's radii
    are spent; stamp again from a fresh body without ``overwrite_body`` (that stamp then
    falls back to the serial one)."""


def _stamp_in_waves(body: Body, cat, rim_tabs, ejecta_edge: float, args, progress) -> bool:
    """Stamp ``cat`` in parallel waves (:mod:`latlong._wave_kernels`): the same radii as
    the serial kernel, bit for bit. ``args``: the serial kernel's arguments (full
    arrays). False if a crater's cap outgrew its scheduled bound (then nothing is valid)."""
    m = body.grid.magnitude
    n = len(cat)
    stretch = np.asarray(body.stretch, dtype=np.float64)
    lat = np.radians(np.asarray(cat["lat_deg"], dtype=np.float64))
    lon = np.mod(np.radians(np.asarray(cat["lon_deg"], dtype=np.float64)), 2.0 * np.pi)
    reach = ejecta_edge * 0.5 * np.asarray(cat["diameter_m"], dtype=np.float64) \
        * (1.0 + rim_tabs.max(axis=1))
    # the cap each crater will gather, for a local radius down to WAVE_RADIUS_SHARE of
    # today's: earlier craters would have to move the surface by more than that
    rnow = _local_radii(body, cat["lat_deg"], cat["lon_deg"])
    rloc = WAVE_RADIUS_SHARE * rnow
    bound = np.minimum(np.pi, (reach / rloc + np.pi / m) * stretch.max() / stretch.min())
    bound = np.ascontiguousarray(bound * (1.0 + 1e-9))
    # work per crater: the vertices of its gather cap today, plus a fixed share
    cap = np.minimum(np.pi, (reach / rnow + np.pi / m) * stretch.max() / stretch.min())
    cost = 0.5 * (1.0 - np.cos(cap)) * body.grid.n_vertices + WAVE_FIXED_COST
    n_theta = int(np.clip(np.pi / (2.0 * np.median(bound)), 4, 4096))
    wave = np.empty(n, dtype=np.int64)
    n_waves = _wave_schedule_kernel(np.pi / 2 - lat, lon, bound, n_theta, wave)
    order = np.lexsort((-cost, wave))  # by wave, the costliest first
    starts = np.searchsorted(wave[order], np.arange(n_waves + 1))
    n_threads = numba.get_num_threads()
    bounds = np.empty((n_waves, n_threads + 1), dtype=np.int64)
    _balance_waves_kernel(order.copy(), starts, cost, n_threads, order, bounds)
    ok = np.ones(n, dtype=np.bool_)
    chunks = np.linspace(0, n_waves, min(n_waves, 100 if progress else 1) + 1).astype(int)
    bar = progress_bar(total=n, enabled=progress, desc="craters")
    try:
        for w0, w1 in zip(chunks[:-1], chunks[1:], strict=True):
            # `args`: the kernel's middle arguments (a tuple mypy cannot count)
            _stamp_waves_kernel(order, bounds[w0:w1], *args, bound, ok)  # type: ignore[call-arg]
            bar.update(int(starts[w1] - starts[w0]))
    finally:
        bar.close()
    logger.debug("%d craters in %d waves (%d alone)", n, n_waves,
                 int((np.diff(starts) == 1).sum()))
    return bool(ok.all())


def body_population(body: Body, layers, *, rng=None) -> np.ndarray:
    """A crater catalog for ``body``: counts from its actual surface area, positions
    uniform on its actual surface (:func:`latlong.surface_positions`), oldest first.

    ``layers``: :class:`craters.CraterLayer` s.
    """
    if not isinstance(body, Body):
        raise TypeError(f"`body` must be a Body; got {type(body).__name__}")
    rng = normalize_rng(rng)
    totals = band_areas(body)
    cat = _craters.population(layers, area_m2=float(totals.sum()), rng=rng)
    lat, lon, _ = sample_surface_points(body, totals, len(cat), rng)
    cat["lat_deg"], cat["lon_deg"] = lat, lon
    return cat


def _local_radii(body: Body, lat_deg, lon_deg) -> np.ndarray:
    """|position| of the body surface in the directions (lat, lon) of the grid."""
    lat = np.radians(lat_deg)
    lon = np.radians(lon_deg)
    r = body.grid.interpolate(body.radii_m, np.pi / 2 - lat, lon)
    u = np.stack([np.cos(lat) * np.cos(lon), np.cos(lat) * np.sin(lon), np.sin(lat)], axis=-1)
    return r * np.linalg.norm(u * body.stretch, axis=-1)


def _gravity_up(body: Body, lat_deg, lon_deg) -> np.ndarray:
    """Unit "up" (against the constant-density self-gravity of the body as it is) at
    the surface points in the directions (lat, lon)."""
    lat = np.radians(lat_deg)
    lon = np.radians(lon_deg)
    u = np.stack([np.cos(lat) * np.cos(lon), np.cos(lat) * np.sin(lon), np.sin(lat)], axis=-1)
    points = u * body.stretch * body.grid.interpolate(body.radii_m, np.pi / 2 - lat, lon)[:, None]
    # lumps of 512 faces: ~ 20 000 point masses on a 6 M-vertex body; directions to a few
    # degrees, which is what telling a wall from a floor needs
    from .mesh.cratering import down_directions  # (latlong.mesh loads on this use only)

    return -down_directions(body.vertices(), body.grid.triangles(), points, block=512)


def crater_extents_deg(body: Body, catalog, *, ejecta_edge: float = DEFAULT_EJECTA_EDGE,
                       irregularity: float = 0.02) -> np.ndarray:
    """Angular diameter (degrees of arc) of each crater's affected region on ``body``:
    ejecta edge to ejecta edge, seen from the body centre at the local radius."""
    reach = ejecta_edge * 0.5 * catalog["diameter_m"] * (1.0 + irregularity)
    rloc = _local_radii(body, catalog["lat_deg"], catalog["lon_deg"])
    return np.degrees(2.0 * np.minimum(reach / rloc, np.pi / 2))


def stamp_craters(body: Body, catalog, *, roughness=True, rng=None, progress: bool = False,
                  max_extent_deg: float = 60.0, irregularity: float = 0.02,
                  slope_erosion: bool = True, onset_deg: float = 20.0, full_deg: float = 45.0,
                  target: str | Target = "moon", ejecta_edge: float = DEFAULT_EJECTA_EDGE,
                  too_large: str = "error", slope_reference: str = "body",
                  overwrite_body: bool = False) -> Body:
    """Stamp a crater catalog on a body, oldest first (the method: module notes); returns
    a new :class:`Body`.

    Parameters
    ----------
    body : Body
    catalog : structured array
        Columns ``lat_deg, lon_deg`` (the grid's latitude/longitude: planetocentric on
        an unstretched body), ``diameter_m``, optionally ``degradation``, ``age_gyr``
        (stamping order, oldest first) and ``kind``.
    roughness : bool or craters.Roughness
        Fractal overlay and irregular rims (False: ideal, deterministic craters).
    rng
        Seed or Generator for rim shapes and overlay seeds.
    max_extent_deg : float
        Largest allowed angular diameter of a crater's affected region (ejecta edge to
        ejecta edge), measured at the crater's location; larger craters would be
        distorted by the local mapping.
    too_large : {"error", "skip"}
        What to do with craters above ``max_extent_deg``: raise ValueError, or leave
        them out (logged; the returned catalog lists only stamped craters).
    slope_reference : {"body", "gravity"}
        What slope erosion measures slopes against: the reference body's normal (the
        stretched sphere; radial when unstretched), or the direction of the body's own
        self-gravity at each crater (constant density, :func:`latlong.mesh.down_directions`;
        for real shape models, whose ends and necks are not steep although they are far
        from radial: on Eros 7790 at magnitude 120 the radial reference erased 47 % of
        0.1-1.2 km craters).
    irregularity, slope_erosion, onset_deg, full_deg, target, ejecta_edge
        As in :func:`craters.stamp_many` (``target``: the body whose crater morphology
        and diffusivity apply, e.g. :func:`craters.small_body` of this body's size).
    overwrite_body : bool
        Stamp into ``body``'s own radii array instead of a copy (8 B a vertex less, for
        very large bodies): ``body`` (and any body sharing its radii, see
        :meth:`Body.replace`) is consumed and must not be used afterwards. In the rare
        case that the parallel wave schedule is outgrown (a crater moving the surface by
        a fifth of the local radius) the radii cannot be restored: raises
        :class:`WaveScheduleOutgrown`.

    Returns
    -------
    Body with the new radii and ``craters`` = the catalog as stamped (stamping order;
    craters on ground at or above ``full_deg`` are erased by mass wasting, not stamped,
    and left out), with the degradation actually used, ``rim_radius_m``, ``depth_m``,
    ``rim_height_m``, ``slope_deg``, the 3-D centre ``centre_x_m, centre_y_m,
    centre_z_m``, ``seed``, ``max_change_m`` (largest radial change) and ``n_vertices``
    touched.
    """
    if not isinstance(body, Body):
        raise TypeError(f"`body` must be a Body; got {type(body).__name__}")
    req = stamp_request(catalog, columns=("lat_deg", "lon_deg"), onto="a body",
                        roughness=roughness, irregularity=irregularity,
                        ejecta_edge=ejecta_edge, slope_erosion=slope_erosion,
                        onset_deg=onset_deg, full_deg=full_deg)
    max_extent_deg = check_range("max_extent_deg", max_extent_deg, 1.0, 180.0)
    check_choice("too_large", too_large, ("error", "skip"))
    check_choice("slope_reference", slope_reference, ("body", "gravity"))
    cat = _within_extent(body, req, max_extent_deg, too_large)
    rim_tabs, seeds = req.draws(len(cat), normalize_rng(rng))
    radii, overwritten = _radii_to_stamp(body, overwrite_body)
    prof = stamping_profiles(cat, target, ejecta_edge=req.ejecta_edge)
    gravity_up = slope_reference == "gravity" and len(cat) > 0 and req.slope_erosion
    run = _BodyStamp.of(body, radii, cat, prof, rim_tabs, seeds, req, gravity_up)
    _stamp(run, body, cat, overwritten, progress)
    if len(cat) and any((radii[s:s + _CHUNK] <= 0).any() for s in range(0, len(radii), _CHUNK)):
        raise ValueError("craters pushed the surface through the body centre; lower the "
                         "largest diameter or max_extent_deg")
    stamped = run.catalog(cat, prof, seeds)
    return body.replace(radii_m=radii, craters=stamped_after(body.craters, stamped),
                        copy=False)


def _within_extent(body: Body, req: StampRequest, max_extent_deg: float,
                   too_large: str) -> np.ndarray:
    """The catalog's craters whose region spans at most ``max_extent_deg`` where they
    fall (``too_large="skip"``: the others left out, logged); else ValueError."""
    cat = req.catalog
    if not len(cat):
        return cat
    ext = crater_extents_deg(body, cat, ejecta_edge=req.ejecta_edge,
                             irregularity=req.irregularity)
    over = ext > max_extent_deg
    if over.any() and too_large == "skip":
        logger.warning("skipped %d of %d craters whose ejecta would span more than %g "
                       "degrees of arc where they fall", int(over.sum()), len(cat),
                       max_extent_deg)
        cat, ext = cat[~over], ext[~over]
    worst = int(np.argmax(ext)) if len(cat) else 0
    if len(cat) and ext[worst] > max_extent_deg:
        raise ValueError(
            f"crater of diameter {cat['diameter_m'][worst]:.6g} m at lat "
            f"{cat['lat_deg'][worst]:.3f}, lon {cat['lon_deg'][worst]:.3f} deg spans "
            f"{ext[worst]:.1f} deg of arc (limit max_extent_deg = {max_extent_deg:g}): "
            "too large for this body; lower the largest diameter"
        )
    return cat


@dataclasses.dataclass(frozen=True)
class _BodyStamp:
    """The arrays of one stamping run on a body, in the kernels' argument order: the grid
    and radii (written), then per crater (catalog order) the inputs, the options and the
    outputs (:func:`~latlong._crater_kernels._stamp_body_kernel`)."""

    grid: tuple
    """(magnitude, ring offsets, radii, stretch)."""
    inputs: tuple
    """(lat, lon, diameter, profile tables, depths, rim perturbations, seeds)."""
    options: tuple
    """(ejecta edge, slope erosion, onset, full, roughness amplitudes, gain)."""
    outputs: tuple
    """(scale, slope, centre, max change, vertices touched, spacing, erased)."""
    up: np.ndarray
    """(n, 3) the "up" each crater's slope is measured against, or (0, 3): the body's."""

    @classmethod
    def of(cls, body: Body, radii, cat, prof, rim_tabs, seeds, req: StampRequest,
           gravity_up: bool) -> _BodyStamp:
        n = len(cat)
        lat = np.ascontiguousarray(cat["lat_deg"], dtype=np.float64)
        lon = np.ascontiguousarray(cat["lon_deg"], dtype=np.float64)
        # writeable copies: numba compiles read-only arrays as another type, and that
        # specialisation of the parallel wave kernel ran ~50 % slower (issue 20)
        stretch = np.array(body.stretch, dtype=np.float64)
        grid = (body.grid.magnitude, np.array(body.grid.ring_offsets()), radii, stretch)
        inputs = (lat, lon, np.ascontiguousarray(cat["diameter_m"], dtype=np.float64),
                  prof.tables, prof.depth_m, req.warps(prof), rim_tabs, seeds)
        options = (req.ejecta_edge, req.slope_erosion, req.onset_deg, req.full_deg,
                   req.rough_array, req.gain)
        outputs = (np.ones(n), np.zeros(n), np.zeros((n, 3)), np.zeros(n), np.zeros(n),
                   np.zeros(n), np.zeros(n, dtype=np.bool_))
        up = _gravity_up(body, lat, lon) if gravity_up else np.empty((0, 3))
        return cls(grid, inputs, options, outputs, up)

    def args(self, s: int = 0, e: int | None = None) -> tuple:
        """The kernels' arguments after the grid for craters s..e-1."""
        return (*(a[s:e] for a in self.inputs), *self.options,
                *(a[s:e] for a in self.outputs), self.up[s:e])

    def catalog(self, cat, prof, seeds) -> np.ndarray:
        """The catalog as stamped (erased craters left out, logged)."""
        scale, slope, centre, maxdh, nvert, spacing, erased = self.outputs
        cols = {k: cat[k] for k in cat.dtype.names}
        cols.update(as_stamped(prof, scale, self.inputs[2]), slope_deg=slope,
                    centre_x_m=centre[:, 0], centre_y_m=centre[:, 1], centre_z_m=centre[:, 2],
                    seed=seeds, max_change_m=maxdh, n_vertices=nvert.astype(np.int64),
                    spacing_m=spacing)
        if erased.any():
            logger.info("%d of %d craters fell on ground steeper than %g deg and were erased",
                        int(erased.sum()), len(cat), self.options[3])
        return _craters.make_catalog(**cols)[~erased]


def _stamp(run: _BodyStamp, body: Body, cat, overwritten: bool, progress: bool) -> None:
    """Stamp in parallel waves (more than one thread and crater), else (or when the wave
    schedule is outgrown) serially, into ``run``'s radii."""
    n = len(cat)
    radii = run.grid[2]
    if numba.get_num_threads() > 1 and n > 1:
        if _stamp_in_waves(body, cat, run.inputs[6], run.options[0], (*run.grid, *run.args()),
                           progress):
            return
        if overwritten:
            raise WaveScheduleOutgrown(f"the parallel wave schedule of {n} craters was "
                                       "outgrown and the body's radii were overwritten")
        logger.info("wave schedule outgrown; stamping %d craters serially", n)
        radii[:] = body.radii_m  # a surface moved more than the schedule allowed: redo
    unit = np.empty((0, 3))  # only the benchmark's naive gather uses it
    m, offs, _, stretch = run.grid
    step = _BATCH if progress else max(n, 1)
    for s in progress_bar(range(0, n, step), enabled=progress, desc="craters"):
        _stamp_body_kernel(m, offs, unit, radii, stretch, *run.args(s, s + step))


def _radii_to_stamp(body: Body, overwrite: bool) -> tuple[np.ndarray, bool]:
    """(writeable radii to stamp into, whether they are the body's own array)."""
    if overwrite:
        radii = body.radii_m
        try:
            radii.setflags(write=True)  # its own memory (not a read-only buffer's view)
        except ValueError:
            pass
        else:
            return radii, True
    return np.array(body.radii_m, dtype=np.float64, copy=True), False


