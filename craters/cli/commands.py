"""The ``craters`` command line: ``craters profile`` (:mod:`.profile`) and ``craters
population`` (:mod:`.population`)."""

from __future__ import annotations

import sys

from .kit import run_cli
from .options import add_commands, main_parser

__all__ = ["COMMANDS", "build_parser", "main"]

#: The commands, in the order ``craters --help`` lists them, and their modules.
COMMANDS = {"profile": "profile", "population": "population"}


def build_parser(argv: list[str] | None = None):
    """The ``craters`` argument parser: both commands, or only the one ``argv`` names."""
    parser, sub = main_parser("craters", "Crater profiles and populations.")
    add_commands(sub, "craters.cli", COMMANDS, argv)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Run ``craters`` with ``argv`` (default: the process's arguments); the exit code."""
    argv = sys.argv[1:] if argv is None else list(argv)
    args = build_parser(argv).parse_args(argv)
    return run_cli(lambda: args.func(args))


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
