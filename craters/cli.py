"""The ``craters`` command line (its subcommands arrive with the craters issues)."""

from __future__ import annotations

import sys

from craters._infra import OneLineParser, package_version, run_cli


def build_parser() -> OneLineParser:
    parser = OneLineParser(prog="craters", description=__doc__)
    parser.add_argument("--version", action="version", version=f"craterform {package_version()}")
    return parser


def main(argv: list[str] | None = None) -> int:
    build_parser().parse_args(argv)
    return run_cli(lambda: 0)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
