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


def _warm_numba() -> None:
    """Set up numba's typing and target contexts (the modules it imports at the first call
    of any kernel, ~0.25 s): a Ctrl-C inside those imports made the process die by SIGINT
    after its "interrupted" line; here it is only noted."""
    from numba.core.registry import cpu_target

    cpu_target.typing_context.refresh()
    cpu_target.target_context.refresh()


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
        interrupted.append(signum)
        if not loading[0]:
            raise KeyboardInterrupt

    if signal.getsignal(signal.SIGINT) is not signal.SIG_IGN:
        signal.signal(signal.SIGINT, on_sigint)
    try:
        module = importlib.import_module(cli_module)
        main = module.main
        args = sys.argv[1:] if argv is None else list(argv)
        if hasattr(module, "load"):  # the command's own modules (and its libraries)
            module.load(args)
        if "numba" in sys.modules and not {"-h", "--help"} & set(args):
            _warm_numba()
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
