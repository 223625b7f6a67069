"""``latlong presets``: the named scenes and their settings."""

from __future__ import annotations

from craters.cli.options import Values, command

from ..presets import preset_table

HELP = {
    "presets": "list the named scenes and their parameters",
}

__all__ = ["register"]


def _presets(v: Values) -> int:
    for name, description, settings in preset_table():
        print(f"{name}\n  {description}")
        for key, value in settings.items():
            print(f"    {key} = {value!r}")
    return 0


def register(sub) -> None:
    """Register ``latlong presets``."""
    command(sub, "presets", _presets, {}, prog="latlong",
            help=HELP["presets"])
