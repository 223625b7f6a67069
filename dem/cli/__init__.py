"""The ``dem`` command line: ``dem info``, ``convert``, ``fill``, ``expand`` (:mod:`.raster`),
``enhance``, ``mesh`` (:mod:`.stack`), ``batch`` (:mod:`.batch`), ``slopes`` and ``spectrum``
(:mod:`.analysis`), ``camera`` and ``lidar`` (:mod:`.sensors`: latlong's sensor commands
over a site).

Every command takes its input (a DEM, or for ``mesh``, ``slopes`` and ``spectrum`` also
a stack manifest) as its positional argument, or as the key ``input`` of a TOML file
given with ``--config`` whose keys are the option names (dashes -> underscores); options
on the command line override the file, file names are relative to the working folder.
One table drives the options of every command (:mod:`.options`). ``-q/--quiet``
silences progress bars and messages everywhere; ``--help`` shows every default. Errors
are one line ``error: ...`` with exit code 2, and nothing is written.

This package imports the library, never the reverse (``import dem`` loads no argparse).
"""

from __future__ import annotations

import sys

from craters._shared import package_version
from craters.cli.kit import OneLineParser, run_cli

from . import analysis, batch, raster, sensors, stack

__all__ = ["build_parser", "main"]


def build_parser() -> OneLineParser:
    """The ``dem`` argument parser with every command."""
    parser = OneLineParser(prog="dem", description="DEMs: gap filling, RMD expansion, "
                                                   "layer stacks with craters, meshes, info.")
    parser.add_argument("--version", action="version", version=f"craterform {package_version()}")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=OneLineParser)
    for group in (raster, stack, batch, analysis, sensors):
        group.register(sub)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Run ``dem`` with ``argv`` (default: the process's arguments); the exit code."""
    args = build_parser().parse_args(argv)
    return run_cli(lambda: args.func(args), atomic=args.command != "batch")


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
