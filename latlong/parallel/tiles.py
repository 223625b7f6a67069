"""Independent pieces of one result (the tiles of a DEM) on a backend (:mod:`.backends`).

:func:`map_tiles` runs ``fn(shared, item)`` for every item, in this process or on dask
(a local cluster of ``workers`` processes on 127.0.0.1, or the scheduler at an address),
and yields ``(index, result)`` as results arrive, so the caller writes each piece into
its place in the output at once. The pieces must not depend on each other (counter-based
randomness keyed by global index makes a tile's values independent of which process or
in which order it is computed): the caller then writes the same bytes whatever the order.

On dask ``shared`` (the input DEM) is sent to every worker once and at most ``window``
tasks are in flight (default two per worker), which bounds both the workers' memory and
the results waiting for the caller; tasks are pure and retried (``retries``) when a
worker dies or a task raises something other than a bad input, as in batches.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Sequence
from typing import Any

from .backends import open_backend

__all__ = ["map_tiles"]


def map_tiles(fn: Callable[[Any, Any], Any], shared: Any, items: Sequence, *,
              backend: str | None = None, scheduler: str | None = None,
              workers: int | None = None, window: int | None = None,
              retries: int = 2, connect_timeout_s: float | None = None,
              ) -> Iterator[tuple[int, Any]]:
    """Yield ``(i, fn(shared, items[i]))`` for every item: in this process, in order,
    unless ``backend`` is ``"dask"`` or a ``scheduler`` or ``workers`` is given (then on
    dask, in the order they finish; :func:`.backends.choose_backend`; a scheduler must
    answer within ``connect_timeout_s``).

    Examples
    --------
    >>> sorted(map_tiles(lambda s, x: s * x, 10, [1, 2, 3]))
    [(0, 10), (1, 20), (2, 30)]
    """
    with open_backend(backend, scheduler=scheduler, workers=workers,
                      connect_timeout_s=connect_timeout_s) as runner:
        yield from runner.map(fn, items, shared=shared, window=window, retries=retries,
                              label="tile")
