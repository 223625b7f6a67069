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
from craters.cli.options import flag_of, main_parser

from . import (
    batch,
    build,
    camera,
    descent,
    export,
    info,
    lidar,
    presets,
    render,
    slopes,
    spectrum,
    tile,
)

__all__ = ["build_parser", "main"]


def build_parser() -> argparse.ArgumentParser:
    parser, sub = main_parser("latlong", "Asteroid bodies on the lat/long mesh.")
    for command in (build, batch, info, presets, render, export, slopes, spectrum, camera,
                    lidar, tile, descent):
        command.register(sub)
    return parser


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    flags = {k: flag_of(k, s) for k, s in build.OPTIONS.items()}
    return run_cli(lambda: args.func(args), flags=flags, atomic=args.command != "batch")


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
