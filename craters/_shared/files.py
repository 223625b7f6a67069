"""Files: output checks before any work, atomic writes, overlapped writes, TOML scene
files."""

from __future__ import annotations

import collections
import contextlib
import os
import queue
import stat
import tomllib
from collections.abc import Callable, Iterable, Iterator, Sequence
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

from .outputs import replace_output, sweep_temporaries, temp_file

__all__ = ["BackgroundWriter", "atomic_path", "check_output_path", "check_parent_folder",
           "check_regular_file", "check_suffix", "load_toml", "ordered_chunks"]


def check_parent_folder(path) -> None:
    """The folder an output goes into exists and is writable (one-line ValueError)."""
    path = Path(path)
    folder = path.parent if str(path.parent) else Path(".")
    if not folder.is_dir():
        raise ValueError(f"output {str(path)!r}: folder {str(folder)!r} does not exist")
    if not os.access(folder, os.W_OK | os.X_OK):
        raise ValueError(f"output {str(path)!r}: folder {str(folder)!r} is not writable")


def check_suffix(path, suffixes: Sequence[str]) -> Path:
    """The output's suffix is one of ``suffixes`` (one-line ValueError)."""
    path = Path(path)
    if path.suffix.lower() not in suffixes:
        raise ValueError(
            f"output {str(path)!r}: unknown format {path.suffix or '(no suffix)'!r}; "
            f"allowed: {' '.join(suffixes)}"
        )
    return path


def check_output_path(path, *, force: bool, suffixes: Sequence[str] | None = None) -> Path:
    """Validate an output path before any work is done.

    Raises ValueError for an unknown suffix, an existing file without ``force``, or a
    folder that does not exist or is not writable.
    """
    path = Path(path) if suffixes is None else check_suffix(path, suffixes)
    check_parent_folder(path)
    if path.is_dir():
        raise ValueError(f"output {str(path)!r} is a folder")
    if os.path.lexists(path) and not force:  # a dangling symlink too
        raise ValueError(f"output {str(path)!r} exists; use --force to overwrite")
    sweep_temporaries(path.parent if str(path.parent) else Path("."))
    return path


@contextlib.contextmanager
def atomic_path(path) -> Iterator[Path]:
    """Yield a temporary path in the target folder; move it onto ``path`` on success.

    On any exception the temporary file is removed and ``path`` is left untouched. Inside
    an output group (:func:`~craters._shared.outputs.output_group`) the move can be taken
    back if a later output of the group fails.
    """
    path = Path(path)
    tmp = temp_file(path, path.suffix)
    try:
        yield tmp
        os.chmod(tmp, 0o644)
        replace_output(tmp, path)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            tmp.unlink()
        raise


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


def check_regular_file(path, what: str, max_bytes: int | None = None) -> Path:
    """``path`` names an existing regular file (not a FIFO, device or folder) of at
    most ``max_bytes``; returns it as a Path, else a one-line ``FileNotFoundError`` (no
    such file) or ``ValueError``.

    Examples
    --------
    >>> check_regular_file("/dev/null", "config file")
    Traceback (most recent call last):
    ...
    ValueError: config file '/dev/null' is not a regular file (a device, FIFO or folder)
    """
    path = Path(path)
    try:
        st = os.stat(path)
    except FileNotFoundError:
        raise FileNotFoundError(f"{what} {str(path)!r} does not exist") from None
    except OSError as exc:
        raise ValueError(f"cannot read {what} {str(path)!r}: {exc.strerror or exc}") from None
    if not stat.S_ISREG(st.st_mode):
        raise ValueError(f"{what} {str(path)!r} is not a regular file (a device, FIFO or "
                         f"folder)")
    if max_bytes is not None and st.st_size > max_bytes:
        raise ValueError(f"{what} {str(path)!r} has {st.st_size} bytes; at most {max_bytes} "
                         f"are read")
    return path


#: Largest TOML scene or config file read, bytes (a scene is a few kilobytes).
MAX_TOML_BYTES = 16 << 20


def load_toml(path) -> dict:
    """Read a TOML scene file; errors become ValueError naming the file."""
    path = check_regular_file(path, "config file", MAX_TOML_BYTES)
    try:
        with open(path, "rb") as fh:
            return tomllib.load(fh)
    except FileNotFoundError:  # removed since the check
        raise FileNotFoundError(f"config file {str(path)!r} does not exist") from None
    except tomllib.TOMLDecodeError as exc:
        raise ValueError(f"config file {str(path)!r} is not valid TOML: {exc}") from None
    except RecursionError:
        raise ValueError(f"config file {str(path)!r} nests arrays or tables too deeply") from None
