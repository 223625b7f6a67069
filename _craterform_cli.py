"""The console scripts ``latlong``, ``dem`` and ``craters``: start-up without tracebacks.

A console script imports its ``main`` before calling it, and importing a package loads
numpy, numba, pyvista and rasterio (a second or more). Problems of that start-up would
show a traceback, so each script starts here, in a module that imports nothing heavy:
a Ctrl-C while the libraries load is ``error: interrupted`` and exit code 130 (as a
Ctrl-C later in a run, :func:`craters._shared.cli.run_cli`), and a ``NUMBA_NUM_THREADS``
numba would refuse at import is one ``error:`` line and exit code 2.
"""

from __future__ import annotations

import importlib
import os
import signal
import sys

__all__ = ["craters", "dem", "latlong"]


def _check_environment() -> str | None:
    """The problem with the environment, or None."""
    text = os.environ.get("NUMBA_NUM_THREADS")
    if text is not None and text.strip():
        try:
            ok = int(text) >= 1
        except ValueError:
            ok = False
        if not ok:
            return (f"the environment variable NUMBA_NUM_THREADS must be an integer >= 1 "
                    f"(the threads of the numba kernels) or unset; got {text!r}")
    return None


def _run(package: str, argv: list[str] | None) -> int:
    problem = _check_environment()
    if problem is not None:
        sys.stderr.write(f"error: {problem}\n")
        return 2
    # a Ctrl-C while the libraries load is noted, not raised: a KeyboardInterrupt inside
    # the import machinery can be swallowed ("Exception ignored in ...") and the run go on
    interrupted: list[int] = []
    previous = signal.signal(signal.SIGINT, lambda signum, frame: interrupted.append(signum))
    try:
        main = importlib.import_module(f"{package}.cli").main
    finally:
        signal.signal(signal.SIGINT, previous)
    try:
        if interrupted:
            raise KeyboardInterrupt
        code = main(argv)
    except KeyboardInterrupt:
        sys.stderr.write("error: interrupted\n")
        code = 130
    # the run is over (its outputs written or taken back): a Ctrl-C while the interpreter
    # shuts down must not turn it into a traceback or a death by SIGINT
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    return code


def latlong(argv: list[str] | None = None) -> int:
    """The ``latlong`` command (``argv``: default the process's arguments)."""
    return _run("latlong", argv)


def dem(argv: list[str] | None = None) -> int:
    """The ``dem`` command (``argv``: default the process's arguments)."""
    return _run("dem", argv)


def craters(argv: list[str] | None = None) -> int:
    """The ``craters`` command (``argv``: default the process's arguments)."""
    return _run("craters", argv)
