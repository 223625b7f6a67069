"""``dem enhance`` layer by layer: stacks whose layers together do not fit in memory.

:func:`dem.enhance` keeps every layer of the stack in memory until the end, because the
craters of a finer layer change the coarser ones (:func:`dem.stack.propagate_up`). But
that change is only "the coarser layer's footprint takes the finer layer's even
pixels", and a layer is made from its parent *before* the finer layers touch the
parent. So :func:`enhance_to_folder` makes the layers one after the other
(:func:`dem.enhance.layers_of`: each the expansion of the previous one plus its own
craters and boulders), writes each into its GeoTIFF window by window as soon as it is
made (:class:`dem.io.WindowWriter`) and drops it, and at the end, finest first, writes
each finer layer's even pixels (read back from its file, strip by strip) into the
coarser layer's footprint. The files are the bytes :func:`dem.enhance` +
:meth:`dem.Stack.write` make; the memory holds the previous and the current layer with
their expansion and stamping (about :data:`LAYERS_HELD` layer-sized float64 arrays)
whatever the number of layers.

Within a layer the work is not cut into tiles: a crater is stamped on a plane fitted to
the terrain it obliterates (and erased on steep ground), so its pixels depend on every
older crater that overlapped it, and those on theirs; a tile would need the chain of
overlapping older craters around it, not a halo of one crater reach.
"""

from __future__ import annotations

import contextlib
import shutil
from pathlib import Path

import numpy as np

from craters._shared import temp_folder
from latlong.meshio.sizes import GEOTIFF_BYTES_PER_PIXEL, check_free_space

from .enhance import finish, layer_step, layers_of, prepare, stack_info
from .io import WindowWriter, read
from .stack import Stack, write_stack

__all__ = ["LAYERS_HELD", "enhance_to_folder"]

#: Layer-sized float64 arrays :func:`enhance_to_folder` holds at most (the previous
#: layer, the expansion, the stamped copies), for the up-front memory check.
LAYERS_HELD = 6
# rows a layer is written and read back in
_STRIP = 512


def enhance_to_folder(config, folder, *, dem=None, progress: bool = False
                      ) -> tuple[Stack, Path]:
    """:func:`dem.enhance` written into the stack folder ``folder`` layer by layer.

    ``folder`` must have been checked (:func:`dem.stack.check_stack_folder`). Returns
    the stack without its heights (its layers are placeholders of zeros with the real
    georeferencing and tags: the manifest, catalogs and info are the real ones) and the
    manifest's path. See the module notes.

    Examples
    --------
    >>> import tempfile
    >>> from dem import Dem, enhance
    >>> base = Dem(np.random.default_rng(0).normal(0, 5, (33, 33)), pixel_size_m=100.0)
    >>> cfg = {"layers": 3, "size": 17, "seed": 1,
    ...        "craters": ["c=0.05,k=-2,d_min_m=20,d_max_m=800"]}
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     _, m = enhance_to_folder(cfg, f"{tmp}/a", dem=base)
    ...     _ = enhance(cfg, dem=base).write(f"{tmp}/b")
    ...     same = all((m.parent / f.name).read_bytes() == f.read_bytes()
    ...                for f in Path(f"{tmp}/b").iterdir())
    >>> same
    True
    """
    run = prepare(config, dem, layers_held=LAYERS_HELD)
    folder = Path(folder)
    # the layers' GeoTIFFs, before any work
    check_free_space([(folder, GEOTIFF_BYTES_PER_PIXEL * run.cfg.layers * run.cfg.size**2)],
                     hint=f"{run.cfg.layers} layers of {run.cfg.size} x {run.cfg.size} "
                     f"pixels: give fewer layers, a smaller size or another folder")
    work = temp_folder(folder)
    writers: list[WindowWriter] = []
    try:
        shells, stamped, rocks = [], [], []
        for k, meta, z, cat, rock in layers_of(run, progress=progress):
            stamped.append(cat)
            rocks.append(rock)
            step = layer_step(run, k, stamped, rocks)
            # the layer's Dem without its heights (zeros: pages never touched)
            shells.append(meta.with_step(np.zeros(meta.shape), "dem.enhance", run.seed, step))
            out = WindowWriter(work / f"layer_{k:02d}.tif", meta.shape,
                               transform=meta.transform, crs=meta.crs,
                               tags=shells[-1].tags,
                               body_radius_m=meta.body_radius_m,
                               pixel_size_m=meta.pixel_size_m)
            writers.append(out)
            for a in range(0, z.shape[0], _STRIP):
                out.write(z[a:a + _STRIP], a, 0)
            del meta, z
        # synchronise, finest first: layer k's footprint takes layer k+1's even pixels
        writers[-1].close()
        for k in range(len(writers) - 2, -1, -1):
            r0, c0, w = run.windows[k]
            fine = writers[k + 1].path
            for a in range(0, 2 * w - 1, _STRIP):  # _STRIP is even: a stays even
                rows = min(_STRIP, 2 * w - 1 - a)
                part = read(fine, window=(a, 0, rows, 2 * w - 1)).heights[::2, ::2]
                writers[k].write(part, r0 + a // 2, c0)
            writers[k].close()
        stack = finish(run, shells, stamped, rocks, stack_info(run, stamped, rocks))
        manifest = write_stack(stack, folder, progress=progress,
                               layer_files=[w.path for w in writers])
    finally:
        for out in writers:
            with contextlib.suppress(Exception):
                out.__exit__(RuntimeError, None, None)
        shutil.rmtree(work, ignore_errors=True)
    return stack, manifest
