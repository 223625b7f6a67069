"""The ``latlong`` command line (a private subpackage: the library never imports it), one
module a command: ``build`` (:mod:`.build`, whose options are the settings of
:class:`latlong.Scene` and also the TOML keys of a scene file), ``batch``, ``info``,
``presets``, ``render``, ``export``, ``slopes``, ``spectrum``, ``camera``, ``lidar`` and
``tile`` and ``descent`` (terrain on demand: a window, frames from orbit to touchdown).
Every option comes from a declared setting (:mod:`craters.cli.options`). Bad input: one
line ``error: ...`` naming the flag, exit code 2.
"""

from __future__ import annotations

import argparse
import sys

from craters.cli.kit import run_cli
from craters.cli.options import add_commands, flag_of, main_parser

__all__ = ["COMMANDS", "build_parser", "main"]

#: The commands, in the order ``latlong --help`` lists them, and their modules.
COMMANDS = {name: name for name in ("build", "batch", "info", "presets", "render", "export",
                                    "slopes", "spectrum", "camera", "lidar", "tile",
                                    "descent")}


def build_parser(argv: list[str] | None = None) -> argparse.ArgumentParser:
    """The ``latlong`` argument parser: every command, or only the one ``argv`` names."""
    parser, sub = main_parser("latlong", "Asteroid bodies on the lat/long mesh.")
    add_commands(sub, __name__, COMMANDS, argv)
    return parser


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else list(argv)
    args = build_parser(argv).parse_args(argv)
    # library errors about a scene's settings are named by their flags (the commands that
    # read a scene load the build module)
    build = sys.modules.get(f"{__name__}.build")
    flags = {k: flag_of(k, s) for k, s in build.OPTIONS.items()} if build else {}
    return run_cli(lambda: args.func(args), flags=flags, atomic=args.command != "batch")


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
