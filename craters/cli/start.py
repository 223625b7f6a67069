"""The start of the commands ``latlong``, ``dem`` and ``craters`` (their console scripts
and ``python -m``, the packages' ``__main__``): start-up without tracebacks.

Loading a command line loads numpy, numba, pyvista and rasterio (a second or more), and
problems of that start-up would show a traceback. This module and the packages' lazy
``__init__`` (:mod:`craters._shared.lazy`) import nothing heavy, so a command starts here
before any of it loads: a Ctrl-C while the libraries load is ``error: interrupted`` and
exit code 130 (as a Ctrl-C later in a run, :func:`craters.cli.kit.run_cli`), and a
``NUMBA_NUM_THREADS`` numba would refuse at import is one ``error:`` line and exit code 2.

The start also caps numpy's SIMD dispatch at AVX2 (:func:`cap_numpy_simd`), so that a
command writes the same bytes on any x86-64 CPU.
"""

from __future__ import annotations

import importlib
import os
import signal
import sys
import threading

__all__ = ["NUMPY_SIMD_CAP", "cap_numpy_simd", "environment_problem", "start_command"]

#: What ``NPY_DISABLE_CPU_FEATURES`` names (numpy >= 2.4 groups the x86 features in
#: levels; earlier releases name them one by one): every dispatch target beyond AVX2.
NUMPY_SIMD_CAP = {"2.4": "X86_V4 AVX512_ICL AVX512_SPR",
                  "": ("AVX512F AVX512CD AVX512_KNL AVX512_KNM AVX512_SKX AVX512_CLX "
                       "AVX512_CNL AVX512_ICL AVX512_SPR")}


def cap_numpy_simd() -> str | None:
    """Keep numpy's loops at AVX2 (X86_V3) and below in this process and the processes it
    starts; what ``NPY_DISABLE_CPU_FEATURES`` is set to, or None where nothing was done.

    numpy picks a loop for each CPU at import: its AVX-512 ``exp``/``log``, SVML's ``sin``,
    ``cos``, ``arcsin`` ... and the AVX-512 sorts round or order differently from the AVX2
    and SSE loops (an AVX-512 machine's golden outputs differed from an AVX2 one's in 17 of
    29 steps, stop 50). The AVX2 and SSE loops give the project's outputs the same bytes
    (the golden set under ``NPY_DISABLE_CPU_FEATURES=X86_V3``), numba's kernels do
    without fast-math (``NUMBA_CPU_NAME=generic``: the same bytes) and the sums that
    decide bytes avoid BLAS (:mod:`craters.exact`); with this cap an AVX-512 machine runs
    the loops an AVX2 one runs. Only before numpy is imported (a library user sets the
    variable before starting Python), on x86-64, and only where the variable is unset: set
    it, even empty, to keep numpy's own choice."""
    if "numpy" in sys.modules or "NPY_DISABLE_CPU_FEATURES" in os.environ:
        return None
    import platform

    if platform.machine().lower() not in ("x86_64", "amd64"):
        return None  # the names are x86's (another architecture would warn of them)
    from importlib.metadata import PackageNotFoundError, version

    try:
        major, minor = (int(p) for p in version("numpy").split(".")[:2])
    except (PackageNotFoundError, ValueError):
        return None
    names = NUMPY_SIMD_CAP["2.4" if (major, minor) >= (2, 4) else ""]
    os.environ["NPY_DISABLE_CPU_FEATURES"] = names
    return names


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
    cap_numpy_simd()
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
