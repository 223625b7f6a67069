"""A whole lat/long body as terrain on demand, patch by patch: every vertex of the
``M``-grid at the grid's resolution (craters at least 3 ring spacings across), in
independent patches of vertices on any backend (:mod:`latlong.parallel.backends`: this
process, a local dask cluster, or a running scheduler). A patch's radii depend only on
its vertices (:mod:`.field`), so any number of patches, in any order, on any worker,
gives the same bytes; memory is bounded by a patch (and the body's radii where they are
gathered). The crater catalog is gathered the same way: each crater from the patch that
holds the vertex nearest its centre.
"""

from __future__ import annotations

import numpy as np
import numpy.lib.recfunctions as rfn

from craters._shared import check_int

from ..body import Body
from ..grid import LatLongGrid
from ..scene import Scene
from ..scratch import drop_pages
from .base import grid_catalog, grid_directions

__all__ = ["PATCH_VERTICES", "build_patches", "patch_count", "patch_ranges"]

#: Most vertices in a patch when the number of patches is not given (about 0.5 GB of
#: working memory a patch).
PATCH_VERTICES = 1 << 22


def patch_count(n_vertices: int, patches: int | None = None) -> int:
    """``patches`` checked against ``n_vertices``, or by default enough patches of at
    most :data:`PATCH_VERTICES` vertices."""
    if patches is None:
        patches = -(-int(n_vertices) // PATCH_VERTICES)
    return check_int("patches", patches, 1, max(1, int(n_vertices)))


def patch_ranges(n_vertices: int, patches: int) -> list[tuple[int, int]]:
    """``patches`` contiguous vertex ranges of nearly equal size covering ``n_vertices``."""
    edges = np.linspace(0, n_vertices, patches + 1).round().astype(np.int64)
    return [(int(a), int(b)) for a, b in zip(edges[:-1], edges[1:], strict=True) if b > a]


def _patch(scene: Scene, item: tuple[int, int]) -> tuple[np.ndarray, np.ndarray]:
    """(radii, catalog rows owned) of the vertices ``item`` = (start, stop) of the scene's
    grid (a task: pure, any process)."""
    from .field import crater_field

    start, stop = item
    grid = LatLongGrid(scene.body.magnitude)
    field = crater_field(scene)
    d_min = 3.0 * grid.spacing(field.base.radius_m)
    w, scale = grid_directions(field.base, grid.unit_vectors_range(start, stop))
    radii = field.radii(w, d_min) / scale  # on a stretched body: where the Body puts it
    cat = grid_catalog(field.base, field.last_catalog())
    # the vertex nearest each crater's centre (its ring, its place on the ring) is the
    # owning patch's; the patch's craters hold every crater within reach of its vertices
    ring = np.clip(np.round((90.0 - cat["lat_deg"]) / 180.0 * 2 * grid.magnitude), 0,
                   2 * grid.magnitude).astype(np.int64)
    size = grid.ring_sizes()[ring]
    place = np.round(np.mod(cat["lon_deg"], 360.0) / 360.0 * size).astype(np.int64) % size
    vertex = grid.ring_offsets()[ring] + place
    return radii, cat[(vertex >= start) & (vertex < stop)]


def build_patches(scene: Scene, *, patches: int | None = None, backend: str | None = None,
                  scheduler: str | None = None, workers: int | None = None,
                  progress=None, out: np.ndarray | None = None,
                  connect_timeout_s: float | None = None) -> Body:
    """The scene's body on its ``M``-grid as terrain on demand, in ``patches`` patches
    (module notes; default: patches of at most :data:`PATCH_VERTICES`); ``backend``,
    ``scheduler``, ``workers``, ``connect_timeout_s`` as in
    :func:`latlong.parallel.tiles.map_tiles`;
    ``progress(done, total)`` is called as patches arrive; ``out``: the radii's array
    (e.g. a scratch file's map, :func:`latlong.scratch.disk_radii`), one float64 per
    vertex."""
    from ..parallel.tiles import map_tiles
    from .field import crater_field

    if not isinstance(scene, Scene):
        raise TypeError(f"`scene` must be a latlong.Scene; got {type(scene).__name__}")
    if not scene.on_demand:
        raise ValueError("`scene` must be an on-demand scene (on_demand=True)")
    grid = LatLongGrid(scene.body.magnitude)
    patches = patch_count(grid.n_vertices, patches)
    items = patch_ranges(grid.n_vertices, patches)
    radii = np.empty(grid.n_vertices) if out is None else out
    if radii.shape != (grid.n_vertices,) or radii.dtype != np.float64:
        raise ValueError(f"`out` must be a float64 array of {grid.n_vertices} radii")
    cats: list[np.ndarray] = [np.zeros(0)] * len(items)
    made = map_tiles(_patch, scene, items, backend=backend, scheduler=scheduler,
                     workers=workers, connect_timeout_s=connect_timeout_s)
    for done, (i, (r, cat)) in enumerate(made):
        start, stop = items[i]
        radii[start:stop] = r
        drop_pages(radii, start, stop)  # radii on disk: the patch leaves memory now
        cats[i] = cat
        if progress is not None:
            progress(done + 1, len(items))
    cat = np.concatenate(cats)
    order = np.lexsort((cat["id"], cat["age_gyr"]))[::-1]  # oldest first, as stamped
    cat = cat[order]
    field = crater_field(scene)
    d_min = 3.0 * grid.spacing(field.base.radius_m)
    return Body(grid, radii, radius_m=field.base.radius_m, stretch=scene.body.stretch,
                metadata={**scene.body_metadata({}), "on_demand": True,
                          "min_crater_diameter_m": d_min, "patches": len(items)},
                craters=rfn.repack_fields(cat), copy=False)
