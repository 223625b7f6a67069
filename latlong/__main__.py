"""The ``latlong`` command, as its console script and as ``python -m latlong``: started by
:mod:`craters.cli.start` (a Ctrl-C or a bad ``NUMBA_NUM_THREADS`` while the libraries
load is one error line)."""

import sys

from craters.cli.start import start_command


def main(argv: list[str] | None = None) -> int:
    """The ``latlong`` command (``argv``: default the process's arguments)."""
    return start_command("latlong.cli", argv)


if __name__ == "__main__":
    sys.exit(main())
