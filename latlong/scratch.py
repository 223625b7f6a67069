"""Radii kept on disk: lat/long bodies bigger than memory (issue 18).

A body's radii (8 B a vertex, 8.1 GB at magnitude 13 000) are the one array of a build
that grows with the grid; everything else is bounded buffers. :func:`disk_radii` makes
that array a memory-mapped scratch file instead: the base is written into it in chunks,
the craters are stamped into it by the very kernels of the in-memory build (the same
operations in the same order, so the same bytes), and the exports stream it out window
by window. The kernel's page cache holds what fits and writes the rest back to the file,
so the body may be larger than the machine's memory.

The file is unlinked as soon as it is mapped: it disappears when the body does, or when
the process ends however it ends (a kill leaves nothing behind). A background thread
drops the mapping's resident pages every :data:`TRIM_INTERVAL_S` seconds
(``madvise(MADV_DONTNEED)``; for a shared file mapping the data stays in the page cache
and the file, and the next access maps it back), so the process's resident memory stays
bounded by the pages touched between two trims plus the build's buffers, not by the
body's size.

Why not patches with halos. A crater's stamp reads its whole region (the quadric base
fitted to it, the local height grid its rim samples), so the bytes of a patch depend on
every older crater overlapping that region, and on the older craters overlapping those:
on a crater-saturated body that chain reaches the whole body, and no halo narrower than
the body gives the in-memory bytes. Keeping the global age order over a disk-backed array
does.
"""

from __future__ import annotations

import mmap
import os
import tempfile
import threading
import weakref
from pathlib import Path

import numpy as np

from craters._shared import ParameterError

__all__ = ["TRIM_INTERVAL_S", "disk_radii", "drop_pages", "is_on_disk"]

#: Seconds between two drops of the scratch mapping's resident pages.
TRIM_INTERVAL_S = 0.5


def disk_radii(n_vertices: int, folder=None, *,
               trim_interval_s: float = TRIM_INTERVAL_S) -> np.ndarray:
    """A new writeable float64 array of ``n_vertices`` values backed by an unlinked
    scratch file in ``folder`` (default: the system's temporary folder; choose a disk with
    room for 8 B a vertex, not a RAM-backed tmpfs). Its resident pages are dropped every
    ``trim_interval_s`` seconds while it lives.

    Examples
    --------
    >>> a = disk_radii(1000)
    >>> a[:] = 1.5
    >>> float(a.sum()), is_on_disk(a)
    (1500.0, True)
    """
    n = int(n_vertices)
    if n < 1:
        raise ParameterError("n_vertices", f"must be >= 1; got {n}")
    folder = Path(tempfile.gettempdir() if folder is None else folder)
    if not folder.is_dir():
        raise ParameterError("scratch_dir", f"{str(folder)!r} is not a folder")
    fd, name = tempfile.mkstemp(prefix=".craterform-radii.", suffix=".tmp", dir=folder)
    try:
        os.unlink(name)
        try:
            os.posix_fallocate(fd, 0, 8 * n)  # room on the disk now, not a SIGBUS later
        except OSError as exc:
            raise OSError(exc.errno, f"no room for the body's radii ({8 * n / 1e9:.3g} GB) "
                          f"in the scratch folder {str(folder)!r}: {exc.strerror}") from None
        mm = mmap.mmap(fd, 8 * n, flags=mmap.MAP_SHARED, prot=mmap.PROT_READ | mmap.PROT_WRITE)
    finally:
        os.close(fd)
    radii = np.frombuffer(mm, dtype=np.float64, count=n)
    stop = threading.Event()
    thread = threading.Thread(target=_trim, args=(mm, stop, float(trim_interval_s)),
                              name="craterform-radii-trim", daemon=True)
    thread.start()
    weakref.finalize(radii, stop.set)
    return radii


def _mapping(a: np.ndarray) -> mmap.mmap | None:
    base: object = a
    while isinstance(base, np.ndarray):
        base = base.base
    if isinstance(base, memoryview):
        base = base.obj
    return base if isinstance(base, mmap.mmap) else None


def is_on_disk(a: np.ndarray) -> bool:
    """Whether ``a`` is (a view of) an array made by :func:`disk_radii`."""
    return _mapping(a) is not None


def drop_pages(a: np.ndarray, start: int, stop: int) -> None:
    """Drop the resident pages of elements ``start:stop`` of ``a`` now, when ``a`` is an
    array of :func:`disk_radii` (else nothing): a pass over the whole array reads faster
    than the trimming thread drops pages (8 GB in well under its interval), so passes
    drop what they have read as they go."""
    mm = _mapping(a)
    if mm is None or stop <= start:
        return
    itemsize = a.itemsize
    first = (start * itemsize) // mmap.PAGESIZE * mmap.PAGESIZE
    last = -(-(stop * itemsize) // mmap.PAGESIZE) * mmap.PAGESIZE
    last = min(last, len(mm))
    try:
        mm.madvise(mmap.MADV_DONTNEED, first, last - first)
    except (ValueError, OSError):  # closed, or not supported here
        pass


def _trim(mm: mmap.mmap, stop: threading.Event, interval: float) -> None:
    """Drop the mapping's resident pages until ``stop`` is set."""
    while not stop.wait(interval):
        try:
            mm.madvise(mmap.MADV_DONTNEED)
        except (ValueError, OSError):  # closed, or not supported here
            return
