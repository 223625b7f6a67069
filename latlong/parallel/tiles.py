"""Independent pieces of one result (the tiles of a DEM) as dask.distributed tasks.

:func:`map_tiles` runs ``fn(shared, item)`` for every item, in this process or on dask
(a local cluster of ``workers`` processes on 127.0.0.1, or the scheduler at an address),
and yields ``(index, result)`` as results arrive, so the caller writes each piece into
its place in the output at once. The pieces must not depend on each other (counter-based
randomness keyed by global index makes a tile's values independent of which process or
in which order it is computed): the caller then writes the same bytes whatever the order.

``shared`` (the input DEM) is sent to every worker once; at most ``window`` tasks are in
flight (default two per worker), which bounds both the workers' memory and the results
waiting for the caller. Tasks are pure and retried (``retries``) when a worker dies or a
task raises something other than a bad input, as in batches; on a local cluster each task
runs with one numba thread (the processes share the cores).
"""

from __future__ import annotations

import itertools
import uuid
from collections.abc import Callable, Iterator, Sequence
from typing import Any

from .batch import check_dask_address, dask_client
from .batch_tasks import limit_numba_threads

__all__ = ["map_tiles"]


def _one_tile(fn, shared, item, threads):
    if threads is not None:
        limit_numba_threads(threads)
    return fn(shared, item)


def map_tiles(fn: Callable[[Any, Any], Any], shared: Any, items: Sequence, *,
              scheduler: str | None = None, workers: int | None = None,
              window: int | None = None, retries: int = 2) -> Iterator[tuple[int, Any]]:
    """Yield ``(i, fn(shared, items[i]))`` for every item: in this process, in order, when
    neither ``scheduler`` nor ``workers`` is given, else on dask in the order they finish.

    Examples
    --------
    >>> sorted(map_tiles(lambda s, x: s * x, 10, [1, 2, 3]))
    [(0, 10), (1, 20), (2, 30)]
    """
    if scheduler is None and workers is None:
        for i, item in enumerate(items):
            yield i, fn(shared, item)
        return
    check_dask_address(scheduler, workers)
    from distributed import as_completed

    threads = 1 if scheduler is None else None
    with dask_client(scheduler, workers) as client:
        n_workers = max(1, len(client.scheduler_info().get("workers", {})))
        window = max(1, window or 2 * n_workers)
        token = uuid.uuid4().hex[:8]
        [big] = client.scatter([shared], broadcast=True, hash=False)
        todo = iter(enumerate(items))
        running: dict = {}
        done = as_completed()

        def submit(batch):
            for i, item in batch:
                fut = client.submit(_one_tile, fn, big, item, threads, retries=retries,
                                    key=f"craterform-tile-{token}-{i}", pure=False)
                running[fut] = i
                done.add(fut)

        try:
            submit(itertools.islice(todo, window))
            for fut in done:
                i = running.pop(fut)
                result = fut.result()
                fut.release()
                submit(itertools.islice(todo, 1))
                yield i, result
        except BaseException:
            client.cancel(list(running))
            raise
