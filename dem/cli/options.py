"""What the ``dem`` commands share: the input and output options, the settings of a DEM
input (band, pixel size, body; declared on :class:`dem.EnhanceConfig`), the registration
of a command with ``--config`` (:func:`dem_command`), the output check and the reading of
the input.

Every option has a config key of the same name (dashes -> underscores, ``input`` for the
positional argument) in the TOML file given with ``--config``; an option on the command
line overrides the file, the file overrides the default. A library error about an
option's parameter (``craters._shared.parameter_of``, a seed's ``rng`` too) is reported
under the flag, or under the config key when the value came from the file
(:mod:`craters.cli.options`).

The command line converts its text to values (syntax only: ``--levels two`` is an
argparse error); the library checks the values, once. The values of a TOML file are
typed already: those that only the command line uses (file names, switches, lists of
inputs) are checked by the kit, the others go to the library as they are.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from pathlib import Path

import numpy as np

from craters._shared import about, check_output_path, normalize_rng, progress_bar
from craters.cli.kit import CliError, check_not_input
from craters.cli.options import FORCE, QUIET, REPORT, Setting, Values, command, declared_keys

from ..config import EnhanceConfig
from ..core import Dem
from ..io import DEM_SUFFIXES, read
from ..stack import read_stack
from ..zarrio import check_zarr_output, is_zarr

__all__ = ["DEM", "DEM_OUTPUT", "INPUT", "READ", "REPORT_OPTIONS", "RUN", "begin",
           "check_output", "dem_command", "legend", "output", "read_input", "report_inputs",
           "seed_of", "summary"]

#: The settings of a stack (:class:`dem.EnhanceConfig`), which several commands share.
DEM = declared_keys(EnhanceConfig)
#: The input DEM of a command.
INPUT = dataclasses.replace(DEM["input"], run=True)
#: How a DEM input is read (band, pixel size, body radius, body).
READ = {k: DEM[k] for k in ("band", "pixel_size_m", "body_radius_m", "body", "crs")}
#: How a command writes (every command that writes).
RUN = {"quiet": QUIET, "force": FORCE}
#: The inputs and outputs of ``dem slopes`` and ``dem spectrum``.
REPORT_OPTIONS = {
    "input": dataclasses.replace(INPUT, help="a DEM (GeoTIFF, PDS .lbl/.img) or a stack "
                                 "manifest (.json: every layer is one input)"),
    "compare": Setting(help="more inputs to overlay", many="+", metavar="OTHER", run=True),
    "label": Setting(help="legend labels, one per input (a stack counts one per layer)",
                     many="+", metavar="LABEL", run=True, default_text="the file names"),
    **{k: READ[k] for k in ("pixel_size_m", "body_radius_m", "body", "crs")},
    "csv": REPORT["csv"], "plot": REPORT["plot"], **RUN,
}


def output(what: str, metavar: str = "OUT") -> Setting:
    """``-o/--output``: ``what`` the command writes (required, by the option or the file)."""
    return Setting(help=what, flag="-o/--output", metavar=metavar, run=True,
                   default_text="none: required")


#: The output of the commands that write one DEM.
DEM_OUTPUT = output("output DEM: a cloud-optimised GeoTIFF (.tif) or a Zarr store (.zarr)")


def dem_command(sub, name: str, run: Callable[[Values], int], options: dict, help: str):
    """Register ``dem NAME`` with ``--config``: its input comes from the argument or the
    file's key ``input``."""
    def checked(v: Values) -> int:
        if v["input"] is None:
            raise CliError(f"`dem {name}` needs an input (argument or config key 'input')")
        return run(v)

    return command(sub, name, checked, options, help=help, config=True, prog="dem")


def check_output(v: Values, suffixes) -> Path:
    """The output file: given, not the input, a known suffix, overwritten only with
    ``--force``; checked before any work."""
    if not v["output"]:
        raise CliError("nothing to write: give -o/--output")
    out = Path(v["output"])
    check_not_input(out, (("DEM", v["input"]), ("config", v.config_file)))
    if is_zarr(out) and out.suffix.lower() in suffixes:  # a folder
        return check_zarr_output(out, force=v["force"])
    return check_output_path(out, force=v["force"], suffixes=suffixes)


def read_input(v: Values, path=None, **kw):
    """Read the input DEM (or ``path``) with the band, pixel size and body radius options
    (``kw``: more of :func:`dem.read`'s, e.g. a window)."""
    return read(v["input"] if path is None else path, band=v.get("band", 1),
                pixel_size_m=v["pixel_size_m"], body_radius_m=v["body_radius_m"],
                body=v.get("body"), crs=v.get("crs"), **kw)


def begin(v: Values, name: str):
    """(seed, show, progress bar) of ``dem fill`` / ``dem expand``: the output and the seed
    checked before any work."""
    check_output(v, DEM_SUFFIXES)
    seed = seed_of(v)
    bar = progress_bar(total=3, enabled=not v["quiet"], desc=name)
    bar.set_description(f"read {v['input']}")
    return seed, not v["quiet"], bar


def seed_of(v: Values) -> int:
    """The given seed (checked before any work) or a fresh one; recorded in the output."""
    if v["seed"] is None:
        entropy = np.random.SeedSequence().entropy
        assert isinstance(entropy, int)  # a fresh SeedSequence's own
        return int(entropy % (2**63))
    with about("rng"):
        normalize_rng(v["seed"])
    return v["seed"]


def summary(v: Values, seed: int, shape_in, shape, params: dict) -> None:
    """The two lines ``dem fill`` / ``dem expand`` print unless ``--quiet``."""
    if v["quiet"]:
        return
    detail = ", ".join(f"{k} {params[k]:.4g}" if isinstance(params[k], float)
                       else f"{k} {params[k]}" for k in params
                       if k in ("levels", "fractal_dimension", "roughness",
                                "filled_pixels", "holes", "craters"))
    print(f"{v.command}: {shape_in[0]} x {shape_in[1]} -> {shape[0]} x "
          f"{shape[1]} pixels, seed {seed}, {detail}")
    print(f"wrote {v['output']}")


def report_inputs(v: Values) -> list[tuple[str, Dem]]:
    """(label, DEM) of the inputs of ``dem slopes`` / ``dem spectrum``: every layer of a
    stack manifest is one input."""
    out = []
    for path in [v["input"], *(v["compare"] or [])]:
        p = Path(path)
        if p.suffix.lower() == ".json":
            stack = read_stack(p)
            out += [(f"{p.stem} layer {k}", layer) for k, layer in enumerate(stack.layers)]
        else:
            out.append((p.stem, read_input(v, p)))
    if v["label"]:
        if len(v["label"]) != len(out):
            raise CliError(f"{v.where('label')}: give one label per input ({len(out)}, stack "
                           f"layers count one each); got {len(v['label'])}")
        out = [(lab, d) for lab, (_, d) in zip(v["label"], out, strict=True)]
    return out


def legend(label: str, pixel_m: float) -> str:
    """A plot legend entry: the input's label and its pixel size ('layer 3, 0.25 m/px')."""
    return f"{label}, {pixel_m:.3g} m/px"
