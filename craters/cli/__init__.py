"""Command lines: the ``craters`` command (:mod:`.commands`, one module a command:
:mod:`.profile`, :mod:`.population`) and the kit the three commands ``latlong``, ``dem``
and ``craters`` share (:mod:`.options`: every option from a declared setting; :mod:`.kit`:
one-line errors and exit codes, output checks; :mod:`.report`: the tables and plots of the
analysis commands; :mod:`.start`: start-up without tracebacks). The libraries never import
it.

This ``__init__`` imports nothing, so that :mod:`.start` loads before numpy and numba.
"""

from __future__ import annotations


def build_parser(argv: list[str] | None = None):
    """The ``craters`` command's parser (:func:`craters.cli.commands.build_parser`)."""
    from .commands import build_parser

    return build_parser(argv)


def main(argv: list[str] | None = None) -> int:
    """The ``craters`` command (:func:`craters.cli.commands.main`)."""
    from .commands import main

    return main(argv)
