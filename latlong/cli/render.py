"""``latlong render MODEL -o PNG``: a saved body rendered off-screen."""

from __future__ import annotations

from craters._shared import check_output_path
from craters.cli.kit import check_not_input, wrote_line
from craters.cli.options import FORCE, QUIET, Setting, Values, command, declared_keys
from latlong import PreviewSettings, load, render_preview

from .inputs import MODEL

HELP = {
    "render": "render a saved body to a PNG (off-screen)",
}

__all__ = ["register"]

OPTIONS = {
    "model": MODEL,
    "output": Setting(help="PNG to write", flag="-o/--output", required=True, run=True),
    "force": FORCE, "quiet": QUIET,
    **declared_keys(("render", PreviewSettings)),
}


def _render(v: Values) -> int:
    settings = PreviewSettings(**{k: v[k] for k in declared_keys(PreviewSettings)})
    check_not_input(v["output"], [("MODEL", v["model"])])
    check_output_path(v["output"], force=v["force"], suffixes=(".png",))
    body = load(v["model"])
    render_preview(body, v["output"], settings)
    if not v["quiet"]:
        print(wrote_line(v["output"]))
    return 0


def register(sub) -> None:
    """Register ``latlong render``."""
    command(sub, "render", _render, OPTIONS, groups={"render": "preview picture"},
            prog="latlong", help=HELP["render"])
