"""Chunked writing for the mesh writers and exporters: buffers written on a background
thread (:class:`BackgroundWriter`) while the next is made, and chunks made in order on
worker threads (:func:`ordered_chunks`)."""

from __future__ import annotations

import collections
import queue
from collections.abc import Callable, Iterable, Iterator
from concurrent.futures import ThreadPoolExecutor

__all__ = ["BackgroundWriter", "ordered_chunks"]


class BackgroundWriter:
    """Write buffers to a binary file on one background thread, in order, at most one
    write pending, so that the caller computes the next buffer while the last one is
    written (the write call releases the GIL, numba kernels with ``nogil`` too).

    A buffer handed to :meth:`write` must stay unchanged until the next-but-one
    :meth:`write` (or :meth:`close`) returns: producers alternate two buffers. An error
    of a write is raised by the next call. Use as a context manager.

    Examples
    --------
    >>> import io
    >>> sink = io.BytesIO()
    >>> with BackgroundWriter(sink) as out:
    ...     out.write(b"ab")
    ...     out.write(b"cd")
    >>> sink.getvalue()
    b'abcd'
    """

    def __init__(self, fh):
        self._fh = fh
        self._pool = ThreadPoolExecutor(max_workers=1, thread_name_prefix="craterform-write")
        self._pending = None

    def write(self, data) -> None:
        """Queue ``data`` (bytes-like) after the writes before it."""
        self.wait()
        self._pending = self._pool.submit(self._fh.write, data)

    def wait(self) -> None:
        """Return when every queued write is done (raising its error, if any)."""
        pending, self._pending = self._pending, None
        if pending is not None:
            pending.result()

    def close(self) -> None:
        """Finish the queued writes and stop the thread."""
        try:
            self.wait()
        finally:
            self._pool.shutdown(wait=True)

    def __enter__(self) -> BackgroundWriter:
        return self

    def __exit__(self, *exc) -> None:
        self.close()


def ordered_chunks(make: Callable, items: Iterable, buffer: Callable[[], object], *,
                   threads: int | None = None) -> Iterator:
    """Yield ``make(item, buf)`` for each item, in order, made on worker threads.

    ``make`` fills a buffer of the pool (``buffer()`` makes one) and returns what to yield
    (the buffer or a view of it); it should spend its time in ``nogil`` numba kernels, so
    the threads run in parallel. Up to ``2 threads`` items are made ahead. A yielded
    value's buffer goes back to the pool two yields later (:class:`BackgroundWriter`'s
    contract: a buffer is written before the next-but-one write returns), so at most
    ``2 threads + 2`` buffers exist. Independent chunks on threads need no parallel
    region per chunk: unlike ``prange`` loops they do not stall at a barrier when the
    machine is busy. ``threads`` defaults to numba's thread count (``NUMBA_NUM_THREADS``);
    the order and values never depend on it.

    Examples
    --------
    >>> def square(i, buf):
    ...     buf[0] = i * i
    ...     return buf[0]
    >>> list(ordered_chunks(square, range(5), lambda: [0], threads=2))
    [0, 1, 4, 9, 16]
    """
    if threads is None:
        import numba

        threads = numba.get_num_threads()
    threads = max(1, int(threads))
    ahead = 2 * threads
    free: queue.SimpleQueue = queue.SimpleQueue()
    for _ in range(ahead + 2):
        free.put(None)  # a slot: the buffer is made on first use

    def run(item):
        buf = free.get()
        buf = buffer() if buf is None else buf
        return buf, make(item, buf)

    items = iter(items)
    pending: collections.deque = collections.deque()
    held: collections.deque = collections.deque()
    with ThreadPoolExecutor(max_workers=threads,
                            thread_name_prefix="craterform-chunk") as pool:
        try:
            for item in items:
                pending.append(pool.submit(run, item))
                if len(pending) >= ahead:
                    break
            while pending:
                buf, value = pending.popleft().result()
                nxt = next(items, _END)
                if nxt is not _END:
                    pending.append(pool.submit(run, nxt))
                yield value
                held.append(buf)
                if len(held) > 1:  # the one yielded before the last: written by now
                    free.put(held.popleft())
        finally:
            for fut in pending:
                fut.cancel()


_END = object()
