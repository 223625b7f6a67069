"""RMD expansion written tile by tile into a GeoTIFF (:func:`expand_to_file`): results
bigger than memory, the same bytes as expanding the whole region (:mod:`dem.expansion`).
"""

from __future__ import annotations

from pathlib import Path
from typing import NamedTuple

import numpy as np

from craters._shared import about, check_int, progress_bar
from latlong.meshio.sizes import check_free_space

from .budget import check_memory_need
from .core import Dem
from .expansion import (
    BYTES_PER_PIXEL,
    HALO_PX,
    ExpansionPlan,
    expand_tile,
    expansion_extent,
    plan_expansion,
)

__all__ = ["TILE_PX", "ExpandedFile", "expand_to_file"]


class ExpandedFile(NamedTuple):
    """What :func:`expand_to_file` wrote."""

    path: Path
    """The cloud-optimised GeoTIFF."""
    shape: tuple[int, int]
    """Its rows and columns."""
    seed: int | None
    """The seed recorded (``rng`` when it is an int)."""
    parameters: dict
    """The step's parameters (``CRATERFORM_PARAMETERS``), as ``expand`` records them."""
    tiles: int
    """How many tiles were expanded."""


#: Default largest output tile side of :func:`expand_to_file`, pixels (about 80 MB).
TILE_PX = 2049


def expand_to_file(dem: Dem, path, levels: int = 1, fractal_dimension: float | None = None,
                   roughness: float | None = None, region=None, rng=None, *,
                   tile_px: int | None = None, backend: str | None = None,
                   scheduler: str | None = None, workers: int | None = None,
                   progress: bool = False, connect_timeout_s: float | None = None,
                   ) -> ExpandedFile:
    """:func:`expand` written tile by tile into a GeoTIFF: results bigger than memory.

    The region is expanded as square tiles of ``2^k + 1`` input pixels sharing their
    edge pixels, each at most ``tile_px`` pixels a side once expanded (a tile of 3 input
    pixels when even that is larger), each with its context halo at every level; the
    counter-based randomness is keyed by global pixel index and every estimate (the
    fractal dimension, the fallback roughness) is made once on the whole input DEM, so
    every tile holds exactly the pixels of the whole expansion. Each tile goes into its
    window of the output (:class:`dem.io.WindowWriter`): the file has the same bytes as
    ``dem.write(expand(...), path)`` while the memory holds one tile (about 18 bytes an
    output pixel of a tile) plus GDAL's block cache.

    Parameters are those of :func:`expand`, plus:

    path : str or Path
        The ``.tif`` to write (atomically; an existing file is replaced).
    tile_px : int, optional
        Largest output tile side in pixels (>= 3); default :data:`TILE_PX` (2049, about
        80 MB a tile).
    backend, scheduler, workers, connect_timeout_s : optional
        Expand the tiles as dask.distributed tasks (:mod:`latlong.parallel.backends`): on
        the scheduler at an address such as ``tcp://127.0.0.1:8786`` (answering within
        ``connect_timeout_s``, default 10 s), or on a local
        cluster of ``workers`` processes (``backend="dask"`` alone: one per core); each
        tile is written as it arrives (the same bytes; the input DEM is sent to each
        worker once). None of them (or ``backend="serial"``): tile after tile in this
        process.

    Returns
    -------
    ExpandedFile

    Examples
    --------
    >>> import tempfile
    >>> from dem.io import write
    >>> from dem.expansion import expand
    >>> d = Dem(np.random.default_rng(0).normal(0, 5, (17, 17)), pixel_size_m=8.0)
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     info = expand_to_file(d, f"{tmp}/t.tif", 2, 2.3, rng=1, tile_px=17)
    ...     whole = write(expand(d, 2, 2.3, rng=1), f"{tmp}/w.tif")
    ...     same = info.path.read_bytes() == whole.read_bytes()
    >>> info.shape, info.tiles, same
    ((65, 65), 16, True)
    """
    from latlong.parallel.backends import choose_backend
    from latlong.parallel.tiles import map_tiles

    from .io import WindowWriter

    with about("tile_px"):
        tile_px = check_int("tile_px", TILE_PX if tile_px is None else tile_px, 3)
    _check_disk(path, expansion_extent(dem, levels, region)[2])  # before any estimate
    choose_backend(backend, scheduler, workers, connect_timeout_s=connect_timeout_s)
    plan = plan_expansion(dem, levels, fractal_dimension, roughness, region, rng)
    t_in, t_out = _tile_sides(plan, tile_px)
    n = (plan.width - 1) // (t_in - 1)
    tags = dem.step_tags("dem.expand", plan.seed, plan.params, level=dem.level + plan.levels,
                         origin=plan.origin)
    with WindowWriter(path, (plan.side, plan.side), transform=plan.transform, crs=dem.crs,
                      tags=tags, body_radius_m=dem.body_radius_m,
                      pixel_size_m=plan.pixel_size_m) as out:
        tiles = [(i, j) for i in range(n) for j in range(n)]
        corners = [(plan.r0 + i * (t_in - 1), plan.c0 + j * (t_in - 1), t_in) for i, j in tiles]
        made = map_tiles(_tile_task, (dem, plan), corners, backend=backend, scheduler=scheduler,
                         workers=workers, connect_timeout_s=connect_timeout_s)
        for k, z in progress_bar(made, enabled=progress, total=len(tiles), desc="expand tiles"):
            i, j = tiles[k]
            # tiles share their edge pixels: each writes all but its last row / column,
            # the last ones all (windows aligned to the output's blocks when large)
            rows = t_out if i == n - 1 else t_out - 1
            cols = t_out if j == n - 1 else t_out - 1
            out.write(z[:rows, :cols], i * (t_out - 1), j * (t_out - 1))
    return ExpandedFile(out.path, (plan.side, plan.side), plan.seed, plan.params, len(tiles))


def _check_disk(path, side: int) -> None:
    """The free space for a ``side``-square output, before any work (a float32 pixel
    each): refused up front (one-line ValueError) when the folder has no room for it."""
    check_free_space([(path, 4.0 * side**2)],
                     hint=f"a float32 DEM of {side} x {side} pixels (deflate saves ~1 % of "
                     f"fractal terrain): give fewer levels or a smaller region")


def _tile_sides(plan: ExpansionPlan, tile_px: int) -> tuple[int, int]:
    """Input and output side of :func:`expand_to_file`'s tiles: ``2^k + 1`` input pixels,
    the largest whose expansion fits ``tile_px`` (at least 3); a tile too large for this
    machine's memory is refused."""
    step = 2**plan.levels
    k = max(1, min((plan.width - 1).bit_length() - 1,
                   ((tile_px - 1) // step).bit_length() - 1))
    t_in = 2**k + 1
    t_out = (t_in - 1) * step + 1
    check_memory_need((t_out + 4 * HALO_PX) ** 2 * BYTES_PER_PIXEL,
                      f"one tile of {t_in} x {t_in} pixels expanded {plan.levels} levels "
                      f"({t_out} x {t_out} pixels)", share=0.85)
    return t_in, t_out


def _tile_task(shared: tuple[Dem, ExpansionPlan], corner: tuple[int, int, int]) -> np.ndarray:
    """One tile of :func:`expand_to_file` (a task: ``shared`` is sent once a worker)."""
    return expand_tile(*shared, *corner)
