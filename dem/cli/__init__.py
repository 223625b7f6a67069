"""The ``dem`` command line, one module a command: ``dem info``, ``convert``, ``fill``,
``expand``, ``enhance``, ``mesh``, ``batch``, ``slopes`` and ``spectrum``; ``camera`` and
``lidar`` (:mod:`.sensors`: latlong's sensor commands over a site); ``tile`` (a window of
a DEM with craters and rocks made on demand, :mod:`dem.ondemand`) and ``descent`` (camera
frames of a descent over a DEM site, terrain made on demand per frame).

Every command takes its input (a DEM, or for ``mesh``, ``slopes`` and ``spectrum`` also
a stack manifest) as its positional argument, or as the key ``input`` of a TOML file
given with ``--config`` whose keys are the option names (dashes -> underscores); options
on the command line override the file, file names are relative to the working folder.
Every option comes from a declared setting (:mod:`craters.cli.options`; the stack's on
:class:`dem.EnhanceConfig`, the shared ones in :mod:`.options`). ``-q/--quiet``
silences progress bars and messages everywhere; ``--help`` shows every default. Errors
are one line ``error: ...`` with exit code 2, and nothing is written.

This package imports the library, never the reverse (``import dem`` loads no argparse).
"""

from __future__ import annotations

import sys

from craters.cli.kit import run_cli
from craters.cli.options import add_commands, main_parser

__all__ = ["COMMANDS", "build_parser", "main"]

#: The commands, in the order ``dem --help`` lists them, and their modules.
COMMANDS = {name: "sensors" if name in ("camera", "lidar") else name
            for name in ("info", "convert", "fill", "expand", "enhance", "mesh", "batch",
                         "slopes", "spectrum", "camera", "lidar", "tile", "descent")}


def build_parser(argv: list[str] | None = None):
    """The ``dem`` argument parser: every command, or only the one ``argv`` names."""
    parser, sub = main_parser("dem", "DEMs: gap filling, RMD expansion, layer stacks with "
                              "craters, meshes, info.")
    add_commands(sub, __name__, COMMANDS, argv)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Run ``dem`` with ``argv`` (default: the process's arguments); the exit code."""
    argv = sys.argv[1:] if argv is None else list(argv)
    args = build_parser(argv).parse_args(argv)
    return run_cli(lambda: args.func(args), atomic=args.command != "batch")


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
