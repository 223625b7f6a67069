"""Command-line plumbing shared by the ``latlong``, ``dem`` and ``craters`` commands.

Only command-line modules import this (it loads argparse): one-line errors with exit
code 2, the ``--seed`` type, and the report options of the analysis commands.
"""

from __future__ import annotations

import argparse
import logging
import os
import sys
from collections.abc import Callable, Mapping

from .files import check_output_path
from .validation import ParameterError, ParameterTypeError

__all__ = ["CliError", "OneLineParser", "add_report_arguments", "check_report_outputs",
           "parse_seed", "run_cli"]


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


def run_cli(func: Callable[[], int | None], *, flags: Mapping[str, str] | None = None) -> int:
    """Run a CLI body; user errors become one line on stderr and exit code 2.

    ``flags`` maps library parameters / setting keys to the command's flags: an error
    about one of them (:class:`~craters._shared.ParameterError`) is shown under its flag.
    Set the environment variable ``CRATERFORM_DEBUG=1`` to get the traceback instead.
    """
    logging.basicConfig(format="%(levelname)s: %(message)s", level=logging.WARNING)
    try:
        return int(func() or 0)
    except (CliError, ValueError, TypeError, OSError, MemoryError) as exc:
        if os.environ.get("CRATERFORM_DEBUG"):
            raise
        if isinstance(exc, ParameterError | ParameterTypeError) and exc.name in (flags or {}):
            msg = exc.shown_as(flags[exc.name], lambda k: flags.get(k, f"`{k}`"))
        else:
            msg = str(exc) if str(exc) else exc.__class__.__name__
        sys.stderr.write(f"error: {msg}\n".replace("\n", " ").rstrip() + "\n")
        return 2
    except KeyboardInterrupt:
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


def check_report_outputs(args) -> None:
    """``--csv``/``--plot``: something to do, the right suffixes, no silent overwrite."""
    if args.csv is None and args.plot is None and args.quiet:
        raise CliError("nothing to do: give --csv, --plot or drop --quiet for the table")
    if args.csv:
        check_output_path(args.csv, force=args.force, suffixes=(".csv",))
    if args.plot:
        check_output_path(args.plot, force=args.force, suffixes=(".png",))
