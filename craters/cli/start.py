"""The start of the commands ``latlong``, ``dem`` and ``craters`` (their console scripts
and ``python -m``, the packages' ``__main__``): start-up without tracebacks.

Loading a command line loads numpy, numba, pyvista and rasterio (a second or more), and
problems of that start-up would show a traceback. This module and the packages' lazy
``__init__`` (:mod:`craters._shared.lazy`) import nothing heavy, so a command starts here
before any of it loads: a Ctrl-C while the libraries load is ``error: interrupted`` and
exit code 130 (as a Ctrl-C later in a run, :func:`craters.cli.kit.run_cli`), and a
``NUMBA_NUM_THREADS`` numba would refuse at import is one ``error:`` line and exit code 2.
"""

from __future__ import annotations

import importlib
import os
import signal
import sys
import threading

__all__ = ["environment_problem", "start_command"]


def environment_problem() -> str | None:
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


#: Code a KeyboardInterrupt must not interrupt: the import machinery (numba imports
#: dozens of modules at the first call of any kernel; an interrupt there made the process
#: die by SIGINT after its line) and numba's and llvmlite's own Python code (an interrupt
#: inside llvmlite's object-cache callback was swallowed and the run went on).
_DEFERRED = ("<frozen importlib", f"{os.sep}numba{os.sep}", f"{os.sep}llvmlite{os.sep}")


def _deferred(frame) -> bool:
    """Whether ``frame`` (or a caller) runs code of :data:`_DEFERRED`."""
    while frame is not None:
        name = frame.f_code.co_filename
        if name.startswith(_DEFERRED[0]) or any(part in name for part in _DEFERRED[1:]):
            return True
        frame = frame.f_back
    return False


def start_command(cli_module: str, argv: list[str] | None) -> int:
    """Import the command line ``cli_module`` (``"latlong.cli"``) and run its ``main`` with
    ``argv`` (default the process's arguments); the exit code."""
    problem = environment_problem()
    if problem is not None:
        sys.stderr.write(f"error: {problem}\n")
        return 2
    # a Ctrl-C while the libraries load is noted, not raised: a KeyboardInterrupt inside
    # the import machinery can be swallowed ("Exception ignored in ...") and the run go on.
    # One handler for the whole run (swapping handlers after loading left a window in
    # which the process died by SIGINT after its message); a SIGINT already ignored (a
    # background job) stays ignored.
    loading = [True]
    interrupted: list[int] = []

    def on_sigint(signum, frame) -> None:
        if loading[0] or _deferred(frame):
            if not loading[0]:  # raised once out of that code: the signal again
                again = threading.Timer(0.05, os.kill, (os.getpid(), signal.SIGINT))
                again.daemon = True
                again.start()
            interrupted.append(signum)
            return
        raise KeyboardInterrupt

    if signal.getsignal(signal.SIGINT) is not signal.SIG_IGN:
        signal.signal(signal.SIGINT, on_sigint)
    try:
        module = importlib.import_module(cli_module)
        main = module.main
        if hasattr(module, "COMMANDS"):  # the command's own modules (and its libraries)
            from .options import command_modules

            command_modules(cli_module, module.COMMANDS,
                            sys.argv[1:] if argv is None else list(argv))
        loading[0] = False
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
