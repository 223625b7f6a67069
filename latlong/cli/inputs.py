"""What several ``latlong`` commands read: a saved body (``MODEL``), and the inputs of the
analysis commands (bodies or closed meshes, ``--compare``, ``--label``)."""

from __future__ import annotations

from pathlib import Path

from craters.cli.kit import CliError
from craters.cli.options import Setting
from latlong import load, read_shape_model

__all__ = ["INPUTS", "MODEL", "labels", "load_input"]

#: The saved body a command reads.
MODEL = Setting(help="a .npz written by latlong build", flag="MODEL", required=True, run=True)
#: The inputs of ``latlong slopes`` and ``latlong spectrum``.
INPUTS = {
    "input": Setting(help="a body (.npz) or a closed mesh file", flag="INPUT", required=True,
                     run=True),
    "compare": Setting(help="more inputs to overlay", many="+", metavar="OTHER", run=True),
    "label": Setting(help="legend labels, one per input", many="+", run=True,
                     default_text="the file names"),
    "shape_units": Setting(help="units of mesh inputs", choices=("km", "m"), run=True,
                           default_text="none; required for meshes"),
}


def load_input(path: str, units: str | None):
    """A body (.npz) or a shape model (a mesh file in ``units``)."""
    p = Path(path)
    if p.suffix.lower() == ".npz":
        return load(p)
    if units is None:
        raise CliError(f"{path}: a mesh file needs --shape-units km or m")
    return read_shape_model(p, units=units)


def labels(inputs, given) -> list[str]:
    """The legend labels: ``given`` (one per input), else the file names."""
    if given:
        if len(given) != len(inputs):
            raise CliError(f"--label: give one label per input ({len(inputs)}); "
                           f"got {len(given)}")
        return list(given)
    names = [Path(p).stem for p in inputs]
    return [n if names.count(n) == 1 else f"{n} ({k})" for k, n in enumerate(names)]
