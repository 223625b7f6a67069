"""Where independent tasks run: the one seam between craterform and dask.

A backend has one method, :meth:`Backend.map`: run ``fn(shared, item)`` for every item
and yield ``(index, result)`` as results arrive. Two implement it:

- :class:`Serial`: in this process, one item after the other, in order (numba keeps
  all its threads; no retries).
- :class:`Dask`: one dask.distributed task per item, on a local cluster on 127.0.0.1
  (one single-threaded worker process per core, or ``workers``; each task limited to
  one numba thread, so the processes do not oversubscribe the cores; no dashboard) or
  on the scheduler at an address (its workers keep their own numba setting: start them
  with ``NUMBA_NUM_THREADS=1`` and ``--nthreads 1``). ``shared`` is sent to every
  worker once; at most ``window`` tasks are in flight; a task that raises something
  other than a bad input is tried again (``retries``) and a worker that dies has its
  tasks rescheduled.

:func:`choose_backend` is the one place the choice is made: the backend named, else dask
when a scheduler address or a worker count is given, else the caller's default (tiles:
serial; batches: a local cluster). :func:`open_backend` opens the chosen one for a
``with`` block. Callers write the same bytes on either: a task's result may depend only
on its item and ``shared`` (counter-based randomness keyed by global index, never by
process or order).

Examples
--------
>>> with open_backend("serial") as backend:
...     sorted(backend.map(lambda s, x: s * x, [1, 2, 3], shared=10))
[(0, 10), (1, 20), (2, 30)]
"""

from __future__ import annotations

import contextlib
import dataclasses
import itertools
import logging
import os
import re
import uuid
from collections.abc import Callable, Iterator, Sequence
from typing import Any, Protocol

from craters._shared.settings import Setting
from craters._shared.validation import ParameterError

__all__ = ["BACKENDS", "CONNECT_TIMEOUT", "PARALLEL_MIN_ITEMS", "Backend", "Dask", "Serial",
           "choose_backend", "limit_numba_threads", "open_backend", "run_task", "serial_below"]

#: The backends :func:`choose_backend` knows.
BACKENDS = ("serial", "dask")
_ADDRESS = re.compile(r"((tcp|tls|ws|wss|ucx)://)?[A-Za-z0-9.\-\[\]:]+:[0-9]{1,5}")
#: Seconds a scheduler at an address has to answer (``--connect-timeout-s``).
CONNECT_TIMEOUT = Setting(10.0, "how long the dask scheduler at --scheduler has to answer "
                          "(then the run stops with a one-line error)", unit="s",
                          range=(0.1, 3600.0), run=True, metavar="S")
_WORKERS_S = 60
#: A local cluster's workers at most: per core, and one per this much memory (a worker
#: process with numpy, numba and its task's arrays).
WORKERS_PER_CORE = 4
WORKER_MEMORY_GIB = 0.5


def max_workers() -> int:
    """The most worker processes a local cluster may start on this machine."""
    from craters._shared.system import physical_memory_bytes

    by_memory = int(physical_memory_bytes() / (WORKER_MEMORY_GIB * 2**30))
    return max(1, min(WORKERS_PER_CORE * (os.cpu_count() or 1), by_memory))


class Backend(Protocol):
    """What runs a batch's variants or a raster's tiles (module notes)."""

    def map(self, fn: Callable[[Any, Any], Any], items: Sequence, *, shared: Any = None,
            window: int | None = None, retries: int = 2, errors: str = "raise",
            label: str = "task") -> Iterator[tuple[int, Any]]:
        """Yield ``(i, fn(shared, items[i]))`` for every item, as results arrive.

        ``window``: most tasks in flight (default two per worker); ``retries``: how often
        a failed task is tried again (dask); ``errors``: ``"raise"`` the first failure,
        or ``"return"`` it (the exception in place of the result) and go on; ``label``
        names the tasks (``craterform-LABEL-...``).
        """
        ...  # pragma: no cover


@dataclasses.dataclass(frozen=True)
class Serial:
    """Every item in this process, in order."""

    def map(self, fn, items, *, shared=None, window=None, retries=2, errors="raise",
            label="task"):
        for i, item in enumerate(items):
            try:
                result = fn(shared, item)
            except Exception as exc:
                if errors == "raise":
                    raise
                result = exc
            yield i, result


@dataclasses.dataclass(frozen=True)
class Dask:
    """Every item as a task of a dask.distributed ``client``; ``threads``: numba threads
    of each task (None: the workers' own setting)."""

    client: Any
    threads: int | None = None

    def map(self, fn, items, *, shared=None, window=None, retries=2, errors="raise",
            label="task"):
        from distributed import as_completed

        client = self.client
        n_workers = max(1, len(client.scheduler_info().get("workers", {})))
        window = max(1, window or 2 * n_workers)
        token = uuid.uuid4().hex[:8]
        [big] = client.scatter([shared], broadcast=True, hash=False)
        todo = iter(enumerate(items))
        running: dict = {}
        done = as_completed()

        def submit(batch):
            for i, item in batch:
                fut = client.submit(run_task, fn, big, item, self.threads, retries=retries,
                                    key=f"craterform-{label}-{token}-{i}", pure=False)
                running[fut] = i
                done.add(fut)

        try:
            submit(itertools.islice(todo, window))
            for fut in done:
                i = running.pop(fut)
                try:
                    result = fut.result()
                except Exception as exc:  # retries spent, worker lost too often, ...
                    if errors == "raise":
                        raise
                    result = exc
                fut.release()
                submit(itertools.islice(todo, 1))
                yield i, result
        except BaseException:
            client.cancel(list(running))
            raise


def run_task(fn, shared, item, threads: int | None):
    """A task of :class:`Dask`: ``fn(shared, item)`` with at most ``threads`` numba
    threads (None: as the worker is set)."""
    if threads is not None:
        limit_numba_threads(threads)
    return fn(shared, item)


def limit_numba_threads(threads: int) -> None:
    """At most ``threads`` numba threads in this (the task's) thread. ``set_num_threads``
    and not ``NUMBA_NUM_THREADS``: a spawned worker whose parent's main module imports
    numba (``python -m latlong``) has numba's pool sized before dask sets the worker's
    environment, and a later compilation would then fail on the mismatch."""
    with contextlib.suppress(ImportError):
        import numba

        # numba.config sets its names at import, from the environment
        limit = numba.config.NUMBA_NUM_THREADS  # type: ignore[attr-defined]
        numba.set_num_threads(max(1, min(threads, limit)))


#: Items below which :func:`serial_below` keeps a numba kernel on the calling thread.
PARALLEL_MIN_ITEMS = 32_768


@contextlib.contextmanager
def serial_below(n_items: int, minimum: int | None = None) -> Iterator[None]:
    """Run the numba kernels called inside on the calling thread alone when ``n_items`` <
    ``minimum`` (default :data:`PARALLEL_MIN_ITEMS`), for kernels whose results do not
    depend on the thread count (the same bytes either way). A parallel region costs tens of
    microseconds on a quiet machine but waits for every pool thread the OS has descheduled
    on a busy one. Measured on the crater lookup behind a 1 cm on-demand tile (~60 small
    cell-set calls; 2 cores): 0.14-0.21 s quiet either way; beside a CPU hog on both cores
    1.48-1.86 s in parallel, 0.25-0.34 s this way."""
    if n_items >= (PARALLEL_MIN_ITEMS if minimum is None else minimum):
        yield
        return
    import numba

    before = numba.get_num_threads()
    numba.set_num_threads(1)
    try:
        yield
    finally:
        numba.set_num_threads(before)


def choose_backend(backend: str | None = None, scheduler: str | None = None,
                   workers: int | None = None, *, default: str = "serial",
                   connect_timeout_s: float | None = None) -> str:
    """The backend that runs: ``backend`` if given, else ``"dask"`` when ``scheduler``
    (a dask scheduler address) or ``workers`` (a local cluster's processes) is given,
    else ``default``. Checks them (one-line errors naming the parameter).

    Examples
    --------
    >>> choose_backend(), choose_backend(workers=2), choose_backend(default="dask")
    ('serial', 'dask', 'dask')
    >>> choose_backend("serial", workers=2)
    Traceback (most recent call last):
    ...
    craters._shared.validation.ParameterError: `workers` applies to the dask backend
    """
    if connect_timeout_s is not None:
        CONNECT_TIMEOUT.check("connect_timeout_s", connect_timeout_s)
    if backend is not None and backend not in BACKENDS:
        raise ParameterError("backend", f"must be one of {', '.join(BACKENDS)}; got "
                             f"{backend!r}")
    if scheduler is None:
        if workers is not None and (isinstance(workers, bool) or not isinstance(workers, int)
                                    or not 1 <= workers <= max_workers()):
            raise ParameterError("workers", f"must be an integer in [1, {max_workers()}] on "
                                 f"this machine ({WORKERS_PER_CORE} per core, one per "
                                 f"{WORKER_MEMORY_GIB} GiB of memory); got {workers!r}")
    else:
        if not isinstance(scheduler, str) or not _ADDRESS.fullmatch(scheduler):
            raise ParameterError("scheduler", f"must be a dask scheduler address like "
                                 f"tcp://127.0.0.1:8786; got {scheduler!r}")
        if workers is not None:
            raise ParameterError("workers", "applies to the local cluster (no {})",
                                 see=("scheduler",))
    dask = scheduler is not None or workers is not None
    if backend == "serial" and dask:
        raise ParameterError("scheduler" if scheduler is not None else "workers",
                             "applies to the dask backend")
    return backend or ("dask" if dask else default)


@contextlib.contextmanager
def open_backend(backend: str | None = None, *, scheduler: str | None = None,
                 workers: int | None = None, default: str = "serial",
                 connect_timeout_s: float | None = None) -> Iterator[Backend]:
    """The backend :func:`choose_backend` picks, open for a ``with`` block: dask connects
    to the scheduler (which must answer within ``connect_timeout_s`` and have workers) or
    starts a local cluster, and closes the client and the local cluster at the end
    (``connect_timeout_s``: default ``CONNECT_TIMEOUT.default``, 10 s)."""
    if choose_backend(backend, scheduler, workers, default=default,
                      connect_timeout_s=connect_timeout_s) == "serial":
        yield Serial()
        return
    import distributed  # noqa: F401 - its import sets the level of its loggers

    quiet = logging.getLogger("distributed")
    level = quiet.level
    # the callers report what happened to each task; dask's own messages (a heartbeat
    # cut short when the local cluster closes, a lost worker) would only be noise
    quiet.setLevel(logging.CRITICAL)
    try:
        timeout_s = CONNECT_TIMEOUT.default if connect_timeout_s is None else connect_timeout_s
        with _connected(scheduler, workers, float(timeout_s)) as client:
            yield Dask(client, threads=1 if scheduler is None else None)
    finally:
        quiet.setLevel(level)


def _probe(scheduler: str, timeout_s: float) -> None:
    """A dask scheduler sends its handshake as soon as it accepts a connection: refuse
    within ``timeout_s`` an address that does not accept or accepts and stays silent
    (dask's own client would wait for ever)."""
    import socket

    m = re.fullmatch(r"(?:tcp://)?\[?([^\]]+?)\]?:([0-9]+)", scheduler)
    if m is None:
        return  # tls:// and others: dask's own timeout
    try:
        with socket.create_connection((m[1], int(m[2])), timeout=timeout_s) as sock:
            sock.settimeout(timeout_s)
            if not sock.recv(1):
                raise ConnectionResetError
    except (OSError, ValueError) as exc:
        why = "no answer" if isinstance(exc, TimeoutError) else type(exc).__name__
        raise ParameterError("scheduler", f"{scheduler}: no dask scheduler answered within "
                             f"{timeout_s:g} s ({why})") from None


@contextlib.contextmanager
def _connected(scheduler: str | None, workers: int | None, timeout_s: float):
    from distributed import Client, LocalCluster

    if scheduler is None:
        n = workers or os.cpu_count() or 1
        with LocalCluster(n_workers=n, threads_per_worker=1, processes=True, host="127.0.0.1",
                          dashboard_address=None, silence_logs=logging.CRITICAL,
                          # no dashboard; the scheduler's HTTP endpoints on a free port
                          scheduler_kwargs={"dashboard_address": "127.0.0.1:0"}) as cluster, \
                Client(cluster) as client:
            yield client
        return
    _probe(scheduler, timeout_s)
    try:
        client = Client(scheduler, timeout=timeout_s)
    except (OSError, TimeoutError) as exc:
        raise ParameterError("scheduler", f"{scheduler}: cannot connect within {timeout_s:g} "
                             f"s ({type(exc).__name__})") from None
    with client:
        try:
            client.wait_for_workers(1, timeout=_WORKERS_S)
        except (OSError, TimeoutError):
            raise ParameterError("scheduler", f"{scheduler} has no workers (waited "
                                 f"{_WORKERS_S} s)") from None
        _check_numpy_cap(client, scheduler)
        yield client


def _numpy_cap() -> str | None:
    return os.environ.get("NPY_DISABLE_CPU_FEATURES")


def _check_numpy_cap(client, scheduler: str) -> None:
    """Warn when the workers of an existing cluster do not cap numpy's SIMD loops as this
    process does (:func:`craters.cli.start.cap_numpy_simd`: a worker started by hand with
    numpy's own choice may write other last bits on an AVX-512 CPU)."""
    here = _numpy_cap()
    differ = sorted(w for w, v in client.run(_numpy_cap).items() if v != here)
    if differ:
        logging.getLogger(__name__).warning(
            "%d of the workers of %s run numpy with NPY_DISABLE_CPU_FEATURES other than "
            "this process's %r (e.g. %s): on a CPU with AVX-512 their results may differ in "
            "the last bits; start them with the same NPY_DISABLE_CPU_FEATURES",
            len(differ), scheduler, here, differ[0])
