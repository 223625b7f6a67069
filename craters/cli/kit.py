"""Command-line plumbing shared by the ``latlong``, ``dem`` and ``craters`` commands.

Only command-line modules import this (it loads argparse): one-line errors with exit
code 2, the ``--seed`` type, and the report options of the analysis commands.
"""

from __future__ import annotations

import argparse
import contextlib
import logging
import os
import signal
import sys
import threading
from collections.abc import Callable, Collection, Iterator, Mapping

from .._shared.files import check_output_path
from .._shared.outputs import check_not_input, output_group
from .._shared.validation import ParameterError, ParameterTypeError, parameter_of

__all__ = ["BATCH_FLAGS", "CliError", "OneLineParser", "add_batch_arguments",
           "add_report_arguments", "batch_error", "batch_reporter", "batch_summary",
           "check_report_outputs", "parse_seed", "parse_vary", "run_cli"]


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
        if isinstance(exc, ParameterError | ParameterTypeError) and exc.name in (flags or {}):
            msg = exc.shown_as(flags[exc.name], lambda k: flags.get(k, f"`{k}`"))
        elif isinstance(exc, OSError) and parameter_of(exc) in (flags or {}):
            msg = f"{flags[parameter_of(exc)]}: {exc}"  # a missing file of a setting
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


def add_report_arguments(parser) -> None:
    """The output options every analysis command has: --csv, --plot, --force, --quiet."""
    parser.add_argument("--csv", help="write the table (CSV, units in the header) "
                        "(default: none)")
    parser.add_argument("--plot", help="write the plot (PNG) (default: none)")
    parser.add_argument("--force", action="store_true",
                        help="overwrite existing outputs (default: off)")
    parser.add_argument("-q", "--quiet", action="store_true",
                        help="no progress bars or messages, the summary table included "
                        "(default: off)")


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


# --------------------------------------------------------------------------- batches
#: Parameters of ``latlong.batch`` / ``dem.batch`` -> the flags of the batch commands.
BATCH_FLAGS = {"seeds": "--seeds", "vary": "--vary", "out": "-o/--output",
               "scheduler": "--scheduler", "workers": "--workers", "resume": "--resume",
               "force": "--force"}


def add_batch_arguments(parser, what: str) -> None:
    """The options of ``latlong batch`` and ``dem batch`` (``what``: a variant's output)."""
    parser.add_argument("--seeds", required=True, metavar="SEEDS",
                        help="seeds: a range 1-1000, a list 1,5,9 or both 1-3,7 (required)")
    parser.add_argument("--vary", action="append", metavar="KEY=V1,V2,...",
                        help="build every value of a setting (a key of the file, dashes or "
                        "underscores); several --vary make a cartesian product; values that "
                        "hold commas (crater specs, X,Y,Z) are separated by ';' (repeatable; "
                        "default: none)")
    parser.add_argument("-o", "--output", required=True, metavar="FOLDER",
                        help=f"batch folder: {what}, and index.csv (required)")
    parser.add_argument("--scheduler", metavar="ADDRESS",
                        help="a running dask scheduler, e.g. tcp://127.0.0.1:8786 (default: a "
                        "local cluster on 127.0.0.1, one single-threaded worker process per "
                        "core)")
    parser.add_argument("--workers", type=int, metavar="N",
                        help="worker processes of the local cluster (default: one per core)")
    parser.add_argument("--resume", action="store_true",
                        help="keep the variants index.csv lists as done whose files still "
                        "have their sha256; redo the others (default: off)")
    parser.add_argument("--force", action="store_true",
                        help="redo every variant in a folder that holds a batch (default: off)")
    parser.add_argument("-q", "--quiet", action="store_true",
                        help="no progress bar, lines or summary; failures still reported "
                        "(default: off)")


def parse_vary(items, convert: Callable[[str, str], object], keys: Collection[str],
               comma_keys: Collection[str] = ()) -> dict[str, list]:
    """``--vary KEY=V1,V2`` options -> {key: [values]}: the key with dashes or underscores,
    each value through ``convert(key, text)``; values separated by ``;`` when the text
    holds one, else by ``,`` (a key of ``comma_keys``, whose values hold commas, takes the
    whole text as one value)."""
    out: dict[str, list] = {}
    for item in items or ():
        key, sep, text = item.partition("=")
        key = key.strip().lstrip("-").replace("-", "_")
        if not sep or not text.strip():
            raise CliError(f"--vary {item!r}: expected KEY=V1,V2,...")
        if key == "seed":
            raise CliError("--vary seed: give the seeds with --seeds")
        if key not in keys:
            raise CliError(f"--vary {item!r}: unknown key {key!r}; allowed: "
                           f"{', '.join(sorted(keys))}")
        if key in out:
            raise CliError(f"--vary {key} is given twice; give its values in one --vary")
        if ";" in text:
            texts = text.split(";")
        else:
            texts = [text] if key in comma_keys else text.split(",")
        values = []
        for t in (t.strip() for t in texts):
            try:
                values.append(convert(key, t))
            except (argparse.ArgumentTypeError, ValueError, TypeError) as exc:
                raise CliError(f"--vary {key}={t}: {exc}") from None
        out[key] = values
    return out


def batch_error(exc: Exception, config) -> CliError:
    """A library error of a batch as one line: under its flag, else under the key of the
    file ``config`` it is about."""
    name = parameter_of(exc)

    def name_of(key):
        return BATCH_FLAGS.get(key, f"key {key!r}")

    if isinstance(exc, ParameterError | ParameterTypeError):
        where = BATCH_FLAGS.get(exc.name) or f"config {str(config)!r}: key {exc.name!r}"
        return CliError(exc.shown_as(where, name_of))
    if name is not None:
        return CliError(f"{BATCH_FLAGS.get(name) or f'config {str(config)!r}: key {name!r}'}: "
                        f"{exc}")
    return CliError(str(exc))


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
