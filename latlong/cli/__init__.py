"""The ``latlong`` command line (a private subpackage: the library never imports it).

``build`` (:mod:`.build`), ``batch`` (:mod:`.batch`), ``info`` / ``presets`` / ``render`` /
``export`` (:mod:`.body`), ``slopes`` / ``spectrum`` (:mod:`.analysis`), ``camera``
(:mod:`.camera`); the option table of build
and render, which also gives the TOML keys, is :mod:`.options`. Bad input: one line
``error: ...`` naming the flag, exit code 2.
"""

from __future__ import annotations

import argparse
import sys

from craters._shared import package_version
from craters.cli.kit import OneLineParser, run_cli

from .analysis import add_parsers as add_analysis_parsers
from .batch import add_batch_parser
from .body import add_body_parsers
from .build import add_build_parser
from .camera import add_camera_parser
from .lidar import FLAGS as LIDAR_FLAGS
from .lidar import add_lidar_parser
from .options import BUILD_OPTIONS, RENDER_OPTIONS, add_options, flag_of

__all__ = ["BUILD_OPTIONS", "RENDER_OPTIONS", "build_parser", "main"]

_GROUPS = {"body": "body", "faulting": "two-phase faulting (--base faulting)",
           "fbm": "Perlin fBm (--base fbm; detail on --base shape)",
           "shape": "shape models (--base shape:PATH)", "craters": "craters",
           "boulders": "boulders", "implicit": "implicit backend (--backend implicit)",
           "output": "output", "render": "preview picture"}


def _add_groups(parser, options) -> None:
    used = dict.fromkeys(o.group for o in options)
    groups = {g: parser.add_argument_group(_GROUPS[g]) for g in used}
    add_options(groups, options)


def build_parser() -> argparse.ArgumentParser:
    parser = OneLineParser(prog="latlong", description="Asteroid bodies on the lat/long mesh.")
    parser.add_argument("--version", action="version", version=f"craterform {package_version()}")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=OneLineParser)
    add_build_parser(sub, _add_groups)
    add_batch_parser(sub)
    add_body_parsers(sub, _add_groups)
    add_analysis_parsers(sub)
    add_camera_parser(sub)
    add_lidar_parser(sub)
    return parser


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    flags = {o.key: flag_of(o.key) for o in BUILD_OPTIONS}
    if args.command == "lidar":
        flags = LIDAR_FLAGS
    return run_cli(lambda: args.func(args), flags=flags, atomic=args.command != "batch")


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
