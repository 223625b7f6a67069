"""What several ``latlong`` commands read: a saved body (``MODEL``), and the inputs of the
analysis commands (bodies or closed meshes, ``--compare``, ``--label``)."""

from __future__ import annotations

import functools
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from craters.cli.kit import CliError
from craters.cli.options import Setting
from latlong import from_shape_model, load, mesh_slopes, read_shape_model, slopes_and_areas

__all__ = ["INPUTS", "MODEL", "Input", "labels", "load_input"]

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


@dataclass(frozen=True)
class Input:
    """An input as loaded: the surface and what each command does with it (a body .npz
    and a mesh file are measured differently: slopes over grid caps or direction caps)."""

    surface: object
    """The Body or ShapeModel."""
    slopes: Callable
    """``(radius_deg, weighted=, gravity=) -> (slopes_deg, areas_m2)``."""
    radii_m: Callable
    """``() -> distances (m) of the vertices from the centre the caps are taken around``."""
    as_body: Callable
    """``magnitude -> Body`` (a body: itself; a mesh: cast onto that grid)."""


def load_input(path: str, units: str | None) -> Input:
    """A body (.npz) or a shape model (a mesh file in ``units``), as an :class:`Input`."""
    p = Path(path)
    if p.suffix.lower() == ".npz":
        body = load(p)
        return Input(body, functools.partial(slopes_and_areas, body),
                     lambda: np.linalg.norm(body.vertices(), axis=1), lambda _: body)
    if units is None:
        raise CliError(f"{path}: a mesh file needs --shape-units km or m")
    model = read_shape_model(p, units=units)
    return Input(model, functools.partial(mesh_slopes, model),
                 lambda: np.linalg.norm(model.vertices - model.volume_centroid, axis=1),
                 lambda m: from_shape_model(model, m, crossings="outermost", smooth="linear"))


def labels(inputs, given) -> list[str]:
    """The legend labels: ``given`` (one per input), else the file names."""
    if given:
        if len(given) != len(inputs):
            raise CliError(f"--label: give one label per input ({len(inputs)}); "
                           f"got {len(given)}")
        return list(given)
    names = [Path(p).stem for p in inputs]
    return [n if names.count(n) == 1 else f"{n} ({k})" for k, n in enumerate(names)]
