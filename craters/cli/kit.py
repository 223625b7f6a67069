"""Command-line plumbing shared by the ``latlong``, ``dem`` and ``craters`` commands.

Only command-line modules import this (it loads argparse): one-line errors with exit
code 2 (:func:`run_cli`), the ``--seed`` type, the checks of outputs before any work, the
lines a batch prints. The options themselves come from declared settings
(:mod:`craters.cli.options`).
"""

from __future__ import annotations

import argparse
import contextlib
import logging
import os
import signal
import sys
import threading
from collections.abc import Callable, Iterator, Mapping

from .._shared.files import check_output_path
from .._shared.outputs import output_group, same_file, staged_path
from .._shared.system import human_bytes
from .._shared.validation import ParameterError, ParameterTypeError, parameter_of

__all__ = ["CliError", "OneLineParser", "batch_reporter", "batch_summary", "check_not_input",
           "check_report_outputs", "parse_seed", "print_written", "run_cli",
           "wrote_line"]


class CliError(Exception):
    """An error the CLI reports as one line and exit code 2."""


def parse_seed(text) -> int:
    """argparse type for ``--seed``: a non-negative integer below 2**63."""
    try:
        value = int(str(text), 10)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be a non-negative integer; got {text!r}") from None
    if not 0 <= value < 2**63:
        raise argparse.ArgumentTypeError(f"must be in [0, 2**63); got {text!r}")
    return value


class OneLineParser(argparse.ArgumentParser):
    """ArgumentParser whose parse errors are one line ``error: ...`` and exit code 2."""

    def error(self, message: str):  # noqa: D401 - argparse API
        sys.stderr.write(f"error: {self.prog}: {message}\n")
        sys.exit(2)


class Terminated(KeyboardInterrupt):
    """SIGTERM, raised like Ctrl-C so that the same cleanup runs."""


def _terminate(signum, frame):
    raise Terminated


@contextlib.contextmanager
def _sigterm_raises() -> Iterator[None]:
    """SIGTERM raises :class:`Terminated` (a KeyboardInterrupt) while inside: temporaries
    are removed and the run's outputs taken back as for Ctrl-C."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    old = signal.signal(signal.SIGTERM, _terminate)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, old)


def run_cli(func: Callable[[], int | None], *, flags: Mapping[str, str] | None = None,
            atomic: bool = True) -> int:
    """Run a CLI body; user errors become one line on stderr and exit code 2.

    With ``atomic`` (every command but batches, whose finished variants must stay) the
    run's outputs appear together or not at all: a failed, interrupted (Ctrl-C) or
    terminated (SIGTERM) run takes back the files it wrote and restores those it replaced.

    ``flags`` maps library parameters / setting keys to the command's flags: an error
    about one of them (:class:`~craters._shared.ParameterError`) is shown under its flag.
    Set the environment variable ``CRATERFORM_DEBUG=1`` to get the traceback instead.
    """
    logging.basicConfig(format="%(levelname)s: %(message)s", level=logging.WARNING)
    try:
        with _sigterm_raises(), (output_group() if atomic else contextlib.nullcontext()):
            code = int(func() or 0)
            sys.stdout.flush()  # a closed pipe shows here, not at exit
        return code
    except BrokenPipeError:  # `latlong info x | head`: the reader has what it wanted
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 128 + 13  # as a process killed by SIGPIPE, without a message
    except (CliError, ValueError, TypeError, OSError, MemoryError) as exc:
        if os.environ.get("CRATERFORM_DEBUG"):
            raise
        tag = parameter_of(exc)
        if isinstance(exc, ParameterError | ParameterTypeError) and flags is not None \
                and exc.name in flags:
            msg = exc.shown_as(flags[exc.name], lambda k: flags.get(k, f"`{k}`"))
        elif isinstance(exc, OSError) and flags is not None and tag is not None and tag in flags:
            msg = f"{flags[tag]}: {exc}"  # a missing file of a setting
        else:
            msg = str(exc) if str(exc) else exc.__class__.__name__
        sys.stderr.write(f"error: {msg}\n".replace("\n", " ").rstrip() + "\n")
        return 2
    except KeyboardInterrupt as exc:
        if isinstance(exc, Terminated):
            sys.stderr.write("error: terminated (SIGTERM); nothing written\n")
            return 143
        sys.stderr.write("error: interrupted\n")
        return 130


def check_not_input(output, inputs, *, flag: str = "-o/--output") -> None:
    """Raise a one-line ValueError if ``output`` is one of ``inputs`` (pairs of (what,
    path); None paths skipped): inputs are never modified."""
    for what, inp in inputs:
        if inp is not None and str(inp) and same_file(output, inp):
            raise ValueError(f"{flag} {str(output)!r} is the input {what} {str(inp)!r}; "
                             f"inputs are never modified")


def check_report_outputs(args, inputs=()) -> None:
    """``--csv``/``--plot``: something to do, the right suffixes, no silent overwrite, not
    one of ``inputs`` (pairs of (what, path))."""
    if args.csv is None and args.plot is None and args.quiet:
        raise CliError("nothing to do: give --csv, --plot or drop --quiet for the table")
    if args.csv:
        check_not_input(args.csv, inputs, flag="--csv")
        check_output_path(args.csv, force=args.force, suffixes=(".csv",))
    if args.plot:
        check_not_input(args.plot, inputs, flag="--plot")
        check_output_path(args.plot, force=args.force, suffixes=(".png",))


def wrote_line(path) -> str:
    """``wrote PATH (SIZE)`` for an output of this run (its staged temporary until the run
    ends: :func:`~craters._shared.outputs.staged_path`)."""
    return f"wrote {path} ({human_bytes(staged_path(path).stat().st_size)})"


def print_written(args) -> None:
    """A ``wrote`` line for each of ``--csv`` and ``--plot`` given (unless ``--quiet``)."""
    for path in (args.csv, args.plot):
        if path and not args.quiet:
            print(f"wrote {path}")


# --------------------------------------------------------------------------- batches
def batch_reporter(quiet: bool):
    """(progress, on_done) of a batch command: a bar on a terminal, else one line per
    finished variant on stderr; nothing with ``quiet``."""
    if quiet:
        return False, None
    if sys.stderr.isatty():
        return True, None

    def line(row: dict) -> None:
        tail = f"  {row['error']}" if row["error"] else ""
        sys.stderr.write(f"{row['status']:<6} {row['variant']}  {row['seconds'] or '-'} s  "
                         f"{row['peak_mb'] or '-'} MB{tail}\n")
        sys.stderr.flush()

    return False, line


def batch_summary(result, quiet: bool) -> int:
    """One line about a finished batch; the exit code (1 if a variant failed)."""
    n = len(result.rows)
    text = (f"{n} variants: {result.done} built, {result.skipped} kept, {result.failed} "
            f"failed in {result.seconds:.0f} s")
    if result.done:
        text += f" ({result.variants_per_hour:.0f} variants/hour)"
    if result.failed:
        sys.stderr.write(f"error: batch: {text}; see status=failed in {result.index}\n")
        return 1
    if not quiet:
        print(f"batch: {text}; {result.index}")
    return 0
