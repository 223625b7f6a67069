"""The ``craters`` command line: ``craters profile`` (:mod:`.profile`) and ``craters
population`` (:mod:`.population`)."""

from __future__ import annotations

import sys

from .kit import run_cli
from .options import main_parser

__all__ = ["build_parser", "main"]


def build_parser():
    """The ``craters`` argument parser with both commands."""
    from . import population, profile

    parser, sub = main_parser("craters", "Crater profiles and populations.")
    profile.register(sub)
    population.register(sub)
    return parser


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    return run_cli(lambda: args.func(args))


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
