"""The build: a :class:`~latlong.Scene` in, a body out, nothing written.

Lat/long backend: the base radii (sphere, two-phase faulting, Perlin fBm or a shape
model ray-cast onto the grid, with fBm detail), then the crater catalog drawn on the
body's actual surface and stamped oldest first, then boulders drawn and placed on the
cratered surface; the body's metadata records the scene (seed, base parameters, layers).
Implicit backend: :func:`latlong.implicit_surface` of the scene's constraint and layers.
Both draw every random number from one generator seeded with the scene's seed, in a
fixed order, so the same scene gives the same bytes whatever the thread count.
"""

from __future__ import annotations

import dataclasses
import logging
from typing import Any, cast

import numba
import numpy as np

from craters._shared import ParameterError, ParameterTypeError, package_version

from .body import Body
from .boulders import boulder_population, place_boulders
from .cratering import WaveScheduleOutgrown, body_population, stamp_craters
from .faulting import FaultingParams, two_phase_faulting
from .grid import LatLongGrid
from .perlin import FbmParams, perlin_fbm
from .scene import Scene
from .scratch import disk_radii
from .settings import ShapeBase, SphereBase
from .shapes import from_shape_model

__all__ = ["build", "mesh_spacing_m"]

#: Vertices per block of the whole-body numpy steps (8 MB of radii).
_BLOCK = 1 << 20
logger = logging.getLogger(__name__)


def _base_heights(scene: Scene, grid: LatLongGrid, rng, progress: bool, out=None):
    """(heights above the reference radius in metres, reference radius, parameters for
    the metadata) of the scene's base shape; the heights are a new float64 array of the
    caller's (:func:`build` turns it into the radii in place), or ``out`` (sphere and fbm
    bases) filled."""
    base, body = scene.base, scene.body
    if isinstance(base, SphereBase):
        if out is None:
            return np.zeros(grid.n_vertices), body.radius_m, {}
        for b0 in range(0, len(out), _BLOCK):
            out[b0:b0 + _BLOCK] = 0.0
        return out, body.radius_m, {}
    if isinstance(base, FaultingParams):  # its stretch is the body's (the scene made it so)
        assert body.radius_m is not None  # Scene.__post_init__ sets it
        heights = two_phase_faulting(grid, body.radius_m, base, rng=rng, progress=progress)
        return heights, body.radius_m, dataclasses.asdict(base)
    if isinstance(base, FbmParams):
        params: dict[str, Any] = {"frequency": base.frequency, "octaves": base.octaves,
                  "persistence": base.persistence, "lacunarity": base.lacunarity,
                  "amplitude_m": base.amplitude_m}
        return (perlin_fbm(grid, *params.values(), rng=rng, out=out, progress=progress),
                body.radius_m, params)
    assert isinstance(base, ShapeBase)
    try:
        shaped = from_shape_model(base.model, grid.magnitude, center=base.center,
                                  crossings=base.crossings, smooth=base.smooth)
    except ParameterError as exc:  # the scene's names (settings)
        raise exc.renamed(f"shape_{exc.name}" if exc.name in ("crossings", "center")
                          else exc.name) from None
    params = {"frequency": base.detail_frequency, "octaves": base.detail_octaves,
              "persistence": base.detail_persistence, "lacunarity": base.detail_lacunarity,
              "amplitude_m": base.detail_amplitude_m}
    detail = perlin_fbm(grid, *params.values(), rng=rng) if base.detail_amplitude_m else 0.0
    params["shape"] = shaped.metadata
    heights = shaped.radii_m - shaped.radius_m
    heights += detail
    return heights, shaped.radius_m, params


def build(scene: Scene, *, progress: bool = False, scratch_dir=None):
    """Make the body a scene describes; writes nothing.

    Parameters
    ----------
    scene : Scene
    progress : bool
        Progress bars on a terminal for the long steps.
    scratch_dir : path, optional
        Where the radii's scratch file goes when :meth:`Scene.radii_on_disk` (a body bigger
        than ``max_memory_gb``; :mod:`latlong.scratch`); default the system's temporary
        folder. The body's radii are then that file, mapped (same bytes as in memory).

    Returns
    -------
    Body
        For the lat/long backend: the base, then the craters (``body.craters``, the
        catalog as stamped), then the boulders (``body.boulders``, as placed).
    latlong.mesh.MeshSurface
        For a shape base with ``surface="mesh"``: the model refined to the spacing
        (:func:`mesh_spacing_m`), then fBm detail, craters and boulders on its own mesh.
    latlong.implicit.ImplicitSurface
        For the implicit backend (``.to_body(magnitude)`` casts it onto a grid).

    Examples
    --------
    >>> from latlong import BodySettings, FbmParams, Scene
    >>> body = build(Scene(BodySettings(magnitude=8), FbmParams(octaves=3), seed=1))
    >>> body.n_vertices, body.metadata["seed"]
    (386, 1)
    """
    if not isinstance(scene, Scene):
        raise TypeError(f"`scene` must be a latlong.Scene; got {type(scene).__name__}")
    if scene.implicit is not None:
        return _build_implicit(scene, progress)
    if isinstance(scene.base, ShapeBase) and scene.base.surface == "mesh":
        return _build_mesh(scene, progress)
    if scene.on_demand:
        return _build_on_demand(scene)
    on_disk = scene.radii_on_disk()
    radii = disk_radii(LatLongGrid(scene.body.magnitude).n_vertices, scratch_dir) \
        if on_disk else None
    try:
        return _build_latlong(scene, progress, overwrite=True, out=radii)
    except WaveScheduleOutgrown:
        pass  # (rare) its radii are spent: build again, the stamp copying the radii
    if on_disk:  # a copy would be a second body in memory: stamp serially into the file
        logger.info("crater wave schedule outgrown: building again, stamping serially")
        threads = numba.get_num_threads()
        numba.set_num_threads(1)
        try:
            return _build_latlong(scene, progress, overwrite=True, out=radii)
        finally:
            numba.set_num_threads(threads)
    logger.info("crater wave schedule outgrown: building again with a copy of the radii")
    return _build_latlong(scene, progress, overwrite=False)


def _build_latlong(scene: Scene, progress: bool, *, overwrite: bool, out=None) -> Body:
    """The lat/long body. Memory: one float64 radius per vertex plus bounded buffers
    (the base is made in place, the craters stamped into the body's own radii when
    ``overwrite``; the same bytes either way); none of it with ``out``, the radii's
    scratch file (:func:`latlong.scratch.disk_radii`)."""
    grid = LatLongGrid(scene.body.magnitude)
    rng = np.random.default_rng(scene.seed)
    heights, radius_m, params = _base_heights(scene, grid, rng, progress, out)
    # the radii, in place (`heights` is this function's own array), a block at a time so
    # a disk-backed array's pages can be dropped between blocks (latlong.scratch)
    for b0 in range(0, len(heights), _BLOCK):
        heights[b0:b0 + _BLOCK] += radius_m
    craters, boulders = scene.craters, scene.boulders
    target = scene.target()
    metadata = _metadata(scene, params)
    try:
        body = Body(grid, heights, radius_m=radius_m, stretch=scene.body.stretch,
                    metadata=metadata, copy=False)
    except ParameterError as exc:
        if exc.name != "radii_m":
            raise
        raise _too_rough(scene, radius_m, exc) from None
    del heights
    if craters.layers:
        cat = body_population(body, craters.layers, rng=rng)
        body = stamp_craters(body, cat, roughness=craters.roughness, rng=rng,
                             progress=progress, max_extent_deg=craters.max_extent_deg,
                             target=target, too_large="skip",
                             slope_reference="gravity" if isinstance(scene.base, ShapeBase)
                             else "body", overwrite_body=overwrite)
        assert body.craters is not None  # stamp_craters records the catalog it stamped
        body = body.replace(metadata={**body.metadata,
                                      "craters_skipped_too_large": len(cat) - len(body.craters)})
    if boulders.layers:
        found = boulder_population(body, boulders.layers, rng=rng)
        body = body.replace(boulders=place_boulders(body, found, shape=boulders.shape))
    return body


def _build_on_demand(scene: Scene) -> Body:
    """The lat/long body as terrain on demand (:mod:`latlong.ondemand`): every vertex of
    the grid at the grid's ring spacing (craters at least 3 spacings across), each value
    the same as :func:`latlong.heights_at` gives it alone; in one patch here
    (:func:`latlong.ondemand.patches.build_patches` for more, on dask)."""
    from .ondemand.patches import build_patches  # the on-demand engine loads when asked

    return build_patches(scene)


def _too_rough(scene: Scene, radius_m: float, exc: ParameterError) -> ParameterError:
    """A base whose heights make radii <= 0 (or not finite): the error of the settings
    that made them (the scene's names), not of the body's radii."""
    see: tuple[str, ...]
    if isinstance(scene.base, FaultingParams):
        name, see, what = "max_fault_1_m", ("max_fault_2_m",), "and {} are"
    else:  # fBm, or a shape model's fBm detail
        name, see, what = "amplitude_m", (), "is"
    if isinstance(scene.base, ShapeBase):
        return ParameterError(name, f"{what} too large for the shape model (mean radius "
                              f"{radius_m:.6g} m): the radii {exc.rule}", see=see)
    return ParameterError(name, f"{what} too large for {{}} = {radius_m:g} m: the "
                          f"radii {exc.rule}", see=(*see, "radius_m"))


def _metadata(scene: Scene, params: dict) -> dict:
    return scene.body_metadata(params)


def mesh_spacing_m(scene: Scene) -> float:
    """The refined mesh's mean edge of a ``surface="mesh"`` shape base: its
    ``spacing_m``, else the lat/long grid's spacing at the scene's magnitude,
    (pi / 2) R / M (R the model's volume-equivalent radius)."""
    base = cast(ShapeBase, scene.base)  # documented precondition: a shape base
    if base.spacing_m is not None:
        return base.spacing_m
    return 0.5 * np.pi * base.radius_m / scene.body.magnitude


def _build_mesh(scene: Scene, progress: bool):
    """A shape base cratered on its own refined mesh (:mod:`latlong.mesh`)."""
    from .mesh import (
        mesh_boulder_population,
        mesh_crater_population,
        mesh_surface,
        place_mesh_boulders,
        stamp_mesh_craters,
        with_detail,
    )

    base, rng = scene.base, np.random.default_rng(scene.seed)
    assert isinstance(base, ShapeBase)  # build() sends only shape bases here
    params: dict[str, Any] = {
        "frequency": base.detail_frequency, "octaves": base.detail_octaves,
        "persistence": base.detail_persistence, "lacunarity": base.detail_lacunarity,
        "amplitude_m": base.detail_amplitude_m}
    try:
        surf = mesh_surface(base.model, mesh_spacing_m(scene), center=base.center,
                            smooth=base.smooth)
    except ParameterError as exc:
        raise exc.renamed({"center": "shape_center", "smooth": "shape_smooth"}.get(
            exc.name, exc.name)) from None
    params["shape"] = dict(surf.metadata)
    surf = surf.replace(metadata={**surf.metadata, **_metadata(scene, params),
                                  "surface": "mesh"})
    if base.detail_amplitude_m:
        surf = with_detail(surf, *list(params.values())[:5], rng=rng)
    craters, boulders = scene.craters, scene.boulders
    if craters.layers:
        cat = mesh_crater_population(surf, craters.layers, rng=rng)
        surf = stamp_mesh_craters(surf, cat, roughness=craters.roughness, rng=rng,
                                  progress=progress, target=scene.target())
    if boulders.layers:
        found = mesh_boulder_population(surf, boulders.layers, rng=rng)
        surf = surf.replace(boulders=place_mesh_boulders(surf, found, shape=boulders.shape))
    return surf


def _build_implicit(scene: Scene, progress: bool):
    from .implicit import implicit_surface

    imp = scene.implicit
    assert imp is not None  # build() sends only implicit scenes here
    try:
        surf = implicit_surface(imp.shape, imp.layers, gabor=imp.gabor, voxel_m=imp.voxel_m,
                                target_polygons=imp.polygons, cell_m=imp.cell_m,
                                packing_voxels=imp.packing_voxels,
                                min_sphere_m=imp.min_sphere_m,
                                constraint_weight=imp.constraint_weight, rng=scene.seed,
                                progress=progress)
    except (ParameterError, ParameterTypeError) as exc:  # the scene's names (settings)
        raise exc.renamed({"target_polygons": "polygons"}.get(exc.name, exc.name)) from None
    meta = {**surf.metadata, "seed": scene.seed, "version": package_version(),
            "shape_units": imp.units}
    return dataclasses.replace(surf, metadata=meta)
