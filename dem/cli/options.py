"""The options of the ``dem`` commands: one table drives the flags, the TOML config keys,
the help texts (each with its default) and the names in error messages.

Every option has a config key of the same name (dashes -> underscores, ``input`` for
the positional argument) in the TOML file given with ``--config``; an option on the
command line overrides the file, the file overrides the default. A row's key is also
the name of the library parameter it sets (plus ``also``, e.g. ``rng`` for ``seed``): a
library error about that parameter (``craters._shared.parameter_of``) is reported under
the flag, or the config key when the value came from the file.

The command line converts its text to values (syntax only: ``--levels two`` is an
argparse error); the library checks the values, once. The values of a TOML file are
typed already: those that only the command line uses (file names, switches, lists of
inputs) are checked here, the others go to the library as they are.
"""

from __future__ import annotations

import argparse
import contextlib
import dataclasses
import math
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

from craters._shared import (
    ParameterError,
    ParameterTypeError,
    check_not_input,
    check_output_path,
    load_toml,
    parameter_of,
)
from craters.cli.kit import CliError

from ..config import EnhanceConfig
from ..core import parse_region
from ..io import read
from ..zarrio import check_zarr_output, is_zarr

__all__ = ["OPTIONS", "Opt", "Settings", "add_command", "check_output", "options_for",
           "read_input"]


# --------------------------------------------------------------------------- text -> value
def _number(text) -> float:
    try:
        value = float(text)
    except (TypeError, ValueError):
        raise argparse.ArgumentTypeError(f"expected a number; got {text!r}") from None
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"must be finite; got {text!r}")
    return value


def _integer(text) -> int:
    try:
        return int(str(text), 10)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected an integer; got {text!r}") from None


def _target(text) -> tuple[float, float]:
    """``X,Y`` in world coordinates (CRS units)."""
    parts = str(text).split(",")
    try:
        if len(parts) == 2:
            x, y = (float(p) for p in parts)
            if math.isfinite(x) and math.isfinite(y):
                return x, y
    except ValueError:
        pass
    raise argparse.ArgumentTypeError(f"expected X,Y in world coordinates; got {text!r}")


def _region(text):
    """The text forms of :func:`dem.core.parse_region` (the one definition)."""
    try:
        return parse_region(str(text))
    except ParameterError as exc:  # the flag is argparse's, in front
        raise argparse.ArgumentTypeError(exc.rule) from None


# --------------------------------------------------------------------------- the table
@dataclasses.dataclass(frozen=True)
class Opt:
    """One option of one or more commands."""

    flags: tuple[str, ...]
    """``("-o", "--output")``; ``("input",)`` for the positional argument."""
    key: str
    """Config key, argparse dest and library parameter name."""
    parse: Callable[[str], Any]
    """Command-line text -> value (syntax only)."""
    default: Any
    help: str
    commands: tuple[str, ...]
    shown_default: str | None = None
    """The default as ``--help`` says it (None: ``default`` itself)."""
    kind: str = "value"
    """``value``, ``switch`` (store_true), ``append`` (repeatable, a list) or ``list``
    (one or more values, a list)."""
    toml: type | None = None
    """Type a config value must have when only the command line uses the option (the
    library checks the others)."""
    metavar: str | None = None
    choices: tuple[str, ...] | None = None
    also: tuple[str, ...] = ()
    """Other library parameter names the option sets."""

    @property
    def name(self) -> str:
        """How messages name the option: ``-o/--output``, ``--levels``, ``INPUT``."""
        return "INPUT" if self.flags == ("input",) else "/".join(self.flags)

    @property
    def full_help(self) -> str:
        shown = self.shown_default
        if shown is None:
            shown = "off" if self.kind == "switch" else str(self.default)
        return f"{self.help} (default: {shown})"


_E = {f.name: f.default for f in dataclasses.fields(EnhanceConfig) if f.init}
_INFO, _FILL, _EXPAND, _ENHANCE, _MESH = "info", "fill", "expand", "enhance", "mesh"
_SLOPES, _SPECTRUM, _CONVERT = "slopes", "spectrum", "convert"
_DEM_IN = (_INFO, _FILL, _EXPAND, _ENHANCE, _CONVERT)
_READ = (*_DEM_IN, _MESH, _SLOPES, _SPECTRUM)
_WRITE = (_FILL, _EXPAND, _ENHANCE, _MESH, _SLOPES, _SPECTRUM, _CONVERT)
_REPORT = (_SLOPES, _SPECTRUM)
_NO_INPUT = "none: the config file's `input`"

OPTIONS: tuple[Opt, ...] = (
    Opt(("input",), "input", str, None, "input DEM (GeoTIFF, PDS .lbl/.img)", _DEM_IN,
        _NO_INPUT, toml=str),
    Opt(("input",), "input", str, None, "input stack manifest (.json) or DEM", (_MESH,),
        _NO_INPUT, toml=str),
    Opt(("input",), "input", str, None, "a DEM (GeoTIFF, PDS .lbl/.img) or a stack manifest "
        "(.json: every layer is one input)", _REPORT, _NO_INPUT, toml=str),
    Opt(("-o", "--output"), "output", str, None,
        "output DEM: a cloud-optimised GeoTIFF (.tif) or a Zarr store (.zarr)",
        (_FILL, _EXPAND, _CONVERT), "none: required", toml=str, metavar="OUT"),
    Opt(("-o", "--output"), "output", str, None,
        "output folder of the stack (layer GeoTIFFs, crater catalogs, manifest.json)",
        (_ENHANCE,), "none: required", toml=str, metavar="DIR"),
    Opt(("-o", "--output"), "output", str, None, "output mesh (.ply or .vtp)", (_MESH,),
        "none: required", toml=str, metavar="OUT"),
    Opt(("--target",), "target", _target, None,
        "site in world coordinates (CRS units), X,Y", (_ENHANCE,), "the base DEM's centre",
        metavar="X,Y"),
    Opt(("--layers",), "layers", _integer, _E["layers"],
        "number of layers, each 2x finer (1..24)", (_ENHANCE,), metavar="N"),
    Opt(("--size",), "size", _integer, _E["size"], "pixels per side of every layer, 2^n + 1",
        (_ENHANCE,), metavar="W"),
    Opt(("--craters",), "craters", str, _E["craters"],
        "crater layer: a power law c=..,k=..,d_min_m=..,d_max_m=..[,age_min_gyr=..,"
        "age_max_gyr=..,degradation=..,kind=..] (the fields of craters.CraterLayer; N_cum = "
        "c D^k per m^2, D in metres, ages in Gyr) or a model age npf=moon,age_gyr=..,"
        "d_min_m=..,d_max_m=..[,equilibrium=trask|hartmann,degradation=..,kind=..] "
        "(craters.ModelAgeLayer: the body's production function and chronology) or "
        "source[,d_min_m=..,age_min_gyr=..,age_max_gyr=..] (the source DEM's own crater "
        "density, measured, continued below what it resolves); repeat for several. Each "
        "layer's crater count is also written as craters_NN.scc (craterstats)", (_ENHANCE,),
        "none", kind="append", metavar="SPEC"),
    Opt(("--source-crater-px",), "source_crater_px", _number, _E["source_crater_px"],
        "synthetic craters stay below this many source (layer-0) pixels: the source's own "
        "craters are the truth above (0: no limit)", (_ENHANCE,), metavar="PX"),
    Opt(("--min-crater-px",), "min_crater_px", _number, _E["min_crater_px"],
        "smallest crater diameter a layer takes, in its pixels (>= 1)", (_ENHANCE,),
        metavar="PX"),
    Opt(("--smooth-craters",), "smooth_craters", bool, _E["smooth_craters"],
        "ideal craters: no fractal overlay, circular rims", (_ENHANCE,), kind="switch"),
    Opt(("--boulders",), "boulders", str, _E["boulders"],
        "boulder layer c=..,k=..,d_min_m=..,d_max_m=..[,burial_max=..] (N_cum = c D^k per "
        "m^2, D in metres; burial_max = largest buried fraction of the height); stamped as "
        "a heightfield "
        "maximum in the finest layer holding each; repeat for several", (_ENHANCE,), "none",
        kind="append", metavar="SPEC"),
    Opt(("--min-boulder-px",), "min_boulder_px", _number, _E["min_boulder_px"],
        "smallest boulder a layer takes, in its pixels (>= 1)", (_ENHANCE,), metavar="PX"),
    Opt(("--no-boulders",), "no_boulders", bool, False,
        "leave the stack's boulders out of the mesh", (_MESH,), kind="switch", toml=bool),
    Opt(("--craters",), "craters", str, "auto",
        "craters in gaps large enough to hold them (4 px and their ejecta): auto (at the "
        "density the crater detector finds around each gap), none, or a crater layer "
        "c=..,k=..,d_min_m=..,d_max_m=.. (N_cum = c D^k per m^2, D in metres)", (_FILL,),
        metavar="SPEC"),
    Opt(("--max-memory-gb",), "max_memory_gb", _number, None,
        "memory the fill may use, GB: a DEM whose whole-raster fill would need more is "
        "filled tile by tile from the file (the same bytes); a gap too large to fill "
        "within it is refused", (_FILL,), "0.8 x this machine's memory", metavar="GB"),
    Opt(("--levels",), "levels", _integer, 1, "number of 2x expansions (1..16)", (_EXPAND,),
        metavar="N"),
    Opt(("--tile-px",), "tile_px", _integer, None,
        "largest side of an output tile in pixels (>= 3): the unit of memory and of work "
        "(one dask task a tile)", (_EXPAND,), "2049, about 80 MB a tile", metavar="PX"),
    Opt(("--scheduler",), "scheduler", str, None,
        "expand the tiles as tasks on the dask scheduler at ADDRESS, e.g. "
        "tcp://127.0.0.1:8786 (its workers must see the input and output paths; the same "
        "bytes)", (_EXPAND,), "tiles in this process", metavar="ADDRESS"),
    Opt(("--workers",), "workers", _integer, None,
        "expand the tiles as tasks on a local dask cluster of N worker processes on "
        "127.0.0.1 (the same bytes)", (_EXPAND,), "tiles in this process", metavar="N"),
    Opt(("--fractal-dimension",), "fractal_dimension", _number, None,
        "fractal dimension F in [2, 3]", (_FILL, _EXPAND, _ENHANCE), "estimated from the input",
        metavar="F"),
    Opt(("--roughness",), "roughness", _number, None,
        "RMS slope between neighbouring pixels, m/m, >= 0", (_FILL, _EXPAND, _ENHANCE),
        "from the input; for expand and enhance the local relief of each input pixel",
        metavar="R"),
    Opt(("--region",), "region", _region, None,
        "square to expand, 2^n+1 pixels: ROW,COL,SIZE in pixels or LEFT,BOTTOM,RIGHT,TOP "
        "in CRS units", (_EXPAND,), "the whole DEM", metavar="REGION"),
    Opt(("--seed",), "seed", _integer, None, "random seed, a non-negative integer",
        (_FILL, _EXPAND, _ENHANCE), "a fresh one, recorded in the outputs", metavar="S",
        also=("rng",)),
    Opt(("--band",), "band", _integer, 1, "band of the input (1-based)", (*_DEM_IN, _MESH),
        metavar="B"),
    Opt(("--compare",), "compare", str, None, "more inputs to overlay", _REPORT, "none",
        kind="list", toml=list, metavar="OTHER"),
    Opt(("--label",), "label", str, None,
        "legend labels, one per input (a stack counts one per layer)", _REPORT,
        "the file names", kind="list", toml=list, metavar="LABEL"),
    Opt(("--pixel-size-m",), "pixel_size_m", _number, None,
        "pixel size in metres, for inputs without a CRS", _READ, "none", metavar="M"),
    Opt(("--body-radius-m",), "body_radius_m", _number, None,
        "body radius in metres, for inputs with a geographic CRS (e.g. 1737400 for the Moon)",
        _READ, "from the file's tags or PDS label", metavar="M"),
    Opt(("--body",), "body", str, None,
        "the DEM's body: the craters' target (morphology, transition diameters, "
        "diffusivity) and, for a geographic CRS the file gives no radius for, its mean "
        "radius", _READ, "the body the DEM's CRS names, else moon", metavar="NAME",
        choices=("moon", "mars", "mercury", "earth", "ceres", "vesta")),
    Opt(("--gravity-m-s2",), "gravity_m_s2", _number, None,
        "surface gravity, m/s^2: crater transition diameters scale as 1/g",
        (_ENHANCE, _FILL), "the body's", metavar="G"),
    Opt(("--method",), "method", str, "horn", "slope estimator", (_SLOPES,),
        choices=("horn", "central")),
    Opt(("--bin-deg",), "bin_deg", _number, 3.0, "histogram bin, degrees (0.01..90)",
        (_SLOPES,), metavar="DEG"),
    Opt(("--csv",), "csv", str, None, "write the table (CSV, units in the header)", _REPORT,
        "none", toml=str),
    Opt(("--plot",), "plot", str, None, "write the plot (PNG)", _REPORT, "none", toml=str),
    Opt(("-q", "--quiet"), "quiet", bool, False, "no progress bars or messages", _WRITE,
        kind="switch", toml=bool),
    Opt(("--force",), "force", bool, False, "overwrite an existing output", _WRITE,
        kind="switch", toml=bool),
)


def options_for(command: str) -> dict[str, Opt]:
    """The options of ``command`` by key."""
    return {o.key: o for o in OPTIONS if command in o.commands}


# --------------------------------------------------------------------------- settings
class Settings(dict):
    """The values of a command's options (key -> value): defaults, then the config
    file, then the command line; knows where each came from."""

    def __init__(self, command: str, values: dict, config: str | None, from_config: set):
        super().__init__(values)
        self.command = command
        self.config = config
        self.from_config = from_config

    def where(self, parameter: str | None) -> str | None:
        """How to name the option that sets a library ``parameter`` (None: not an
        option of this command)."""
        for opt in options_for(self.command).values():
            if parameter in (opt.key, *opt.also):
                if opt.key in self.from_config:
                    return f"config {self.config!r}: key {opt.key!r}"
                return opt.name
        return None

    @contextlib.contextmanager
    def named_errors(self) -> Iterator[None]:
        """Library errors about an option's parameter get the option's name in front."""
        try:
            yield
        except (TypeError, ValueError) as exc:
            named = isinstance(exc, ParameterError | ParameterTypeError)
            if named and self.where(exc.name):  # its own name first, then the tag of a caller
                raise CliError(exc.shown_as(self.where(exc.name),
                                            lambda k: self.where(k) or f"`{k}`")) from None
            where = self.where(parameter_of(exc))
            if where is None:
                raise
            raise CliError(f"{where}: {exc}") from None


def _from_config(path: str, command: str) -> dict:
    """The values of a TOML file whose keys are the option names."""
    opts = options_for(command)
    out = {}
    for key, value in load_toml(path).items():
        opt = opts.get(key)
        if opt is None:
            raise CliError(f"config {path!r}: unknown key {key!r} for `dem {command}`; "
                           f"allowed: {', '.join(sorted(opts))}")
        good = opt.toml is None or (isinstance(value, opt.toml) and (
            opt.toml is not list or all(isinstance(v, str) for v in value)))
        if not good or (opt.toml is str and not value):
            what = {str: "a file name", bool: "true or false",
                    list: "a list of strings"}[opt.toml]
            raise CliError(f"config {path!r}: key {key!r} must be {what}; got {value!r}")
        out[key] = value
    return out


def settings(args: argparse.Namespace, command: str) -> Settings:
    """Defaults, then the config file, then the command line."""
    opts = options_for(command)
    values = {key: opt.default for key, opt in opts.items()}
    from_config: set = set()
    if args.config:
        file_values = _from_config(args.config, command)
        values.update(file_values)
        from_config.update(file_values)
    for key in opts:
        value = getattr(args, key, None)
        if value is not None:
            values[key] = value
            from_config.discard(key)
    if values["input"] is None:
        raise CliError(f"`dem {command}` needs an input (argument or config key 'input')")
    return Settings(command, values, args.config, from_config)


def check_output(s: Settings, suffixes) -> Path:
    """The output file: given, not the input, a known suffix, overwritten only with
    ``--force``; checked before any work."""
    if not s["output"]:
        raise CliError("nothing to write: give -o/--output")
    out = Path(s["output"])
    check_not_input(out, (("DEM", s["input"]), ("config", s.config)))
    if is_zarr(out) and out.suffix.lower() in suffixes:  # a folder
        return check_zarr_output(out, force=s["force"])
    return check_output_path(out, force=s["force"], suffixes=suffixes)


def read_input(s: Settings, path=None, **kw):
    """Read the input DEM (or ``path``) with the band, pixel size and body radius options
    (``kw``: more of :func:`dem.read`'s, e.g. a window)."""
    return read(s["input"] if path is None else path, band=s.get("band", 1),
                pixel_size_m=s["pixel_size_m"], body_radius_m=s["body_radius_m"],
                body=s.get("body"), **kw)


# --------------------------------------------------------------------------- parsers
def add_command(sub, command: str, run: Callable[[Settings], int], text: str):
    """Add ``command`` with its options from the table; ``run(settings)`` does the work."""
    p = sub.add_parser(command, help=text, description=text[0].upper() + text[1:] + ".")
    for opt in options_for(command).values():
        kw: dict = {"help": opt.full_help, "default": None}
        if opt.flags == ("input",):
            p.add_argument("input", nargs="?", metavar="INPUT", **kw)
            continue
        kw["dest"] = opt.key
        if opt.kind == "switch":
            kw["action"] = "store_true"
        else:
            kw.update(type=opt.parse, metavar=opt.metavar, choices=opt.choices)
            if opt.kind == "append":
                kw["action"] = "append"
            elif opt.kind == "list":
                kw["nargs"] = "+"
        p.add_argument(*opt.flags, **kw)
    p.add_argument("--config", metavar="TOML",
                   help="TOML file whose keys are the option names (and input); options "
                        "given here override it (default: none)")

    def call(args: argparse.Namespace) -> int:
        s = settings(args, command)
        with s.named_errors():
            return run(s)

    p.set_defaults(func=call)
    return p
