"""The ``dem`` command line: ``dem info``, ``fill``, ``expand``, ``enhance`` and ``mesh``.

Every option of ``fill``, ``expand`` and ``mesh`` has a key of the same name (dashes ->
underscores) in a TOML file given with ``--config``; ``dem enhance SCENE.toml`` takes the
scene file as its argument, whose keys are the options of ``enhance`` (and of
:class:`dem.EnhanceConfig`). Options on the command line override the file; file names
are relative to the working folder. Errors are one line ``error: ...`` with exit code 2,
and nothing is written.
"""

from __future__ import annotations

import argparse
import math
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from rasterio.coords import BoundingBox
from rasterio.windows import Window

import craters
from craters._shared import check_output_path, load_toml, package_version, progress_bar
from craters._shared.cli import CliError, OneLineParser, parse_seed, run_cli

from .analysis_cli import add_parsers as add_analysis_parsers
from .core import crs_label
from .enhance import EnhanceConfig, enhance
from .expansion import expand
from .fractal import fractal_fit
from .gaps import fill_gaps
from .io import GEOTIFF_SUFFIXES, read, write
from .mesh import MESH_SUFFIXES, to_mesh
from .stack import check_stack_folder, read_stack


# --------------------------------------------------------------------------- parsing
def _region(text) -> Window | BoundingBox:
    """``ROW,COL,SIZE`` (pixels) or ``LEFT,BOTTOM,RIGHT,TOP`` (CRS units)."""
    parts = [p.strip() for p in str(text).split(",")]
    try:
        if len(parts) == 3:
            row, col, size = (int(p) for p in parts)
            return Window(col, row, size, size)
        if len(parts) == 4:
            vals = [float(p) for p in parts]
            if all(math.isfinite(v) for v in vals):
                return BoundingBox(*vals)
    except ValueError:
        pass
    raise argparse.ArgumentTypeError(
        f"expected ROW,COL,SIZE (pixels) or LEFT,BOTTOM,RIGHT,TOP (CRS units); got {text!r}")


def _number(text) -> float:
    try:
        value = float(text)
    except (TypeError, ValueError):
        raise argparse.ArgumentTypeError(f"expected a number; got {text!r}") from None
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"must be finite; got {text!r}")
    return value


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


def _spec_checker(parse):
    """An argparse type that validates a layer spec with ``parse`` and keeps the text."""
    def check(text) -> str:
        try:
            parse(text)
        except (TypeError, ValueError) as exc:
            raise argparse.ArgumentTypeError(str(exc)) from None
        return text
    return check


_crater_spec = _spec_checker(craters.parse_layer_spec)
_boulder_spec = _spec_checker(craters.parse_boulder_spec)


def _count(text) -> int:
    try:
        return int(str(text), 10)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected an integer; got {text!r}") from None


@dataclass(frozen=True)
class Opt:
    """One option: flags, config key, parser, default, help, the commands that take it."""

    flags: tuple[str, ...]
    key: str
    parse: Any
    default: Any
    help: str
    commands: tuple[str, ...] = ("fill", "expand")
    flag_only: bool = False  # a store_true switch
    metavar: str | None = None
    many: bool = False  # repeatable; the values form a list


_READ = ("info", "fill", "expand", "enhance", "mesh")
_WRITE = ("fill", "expand", "enhance", "mesh")

OPTIONS: tuple[Opt, ...] = (
    Opt(("-o", "--output"), "output", str, None, "output GeoTIFF (.tif)", metavar="OUT"),
    Opt(("-o", "--output"), "output", str, None,
        "output folder of the stack (layer GeoTIFFs, crater catalogs, manifest.json)",
        ("enhance",), metavar="DIR"),
    Opt(("-o", "--output"), "output", str, None, "output mesh (.ply or .vtp)", ("mesh",),
        metavar="OUT"),
    Opt(("--input",), "input", str, None, "base DEM (GeoTIFF, PDS .lbl/.img)", ("enhance",),
        metavar="DEM"),
    Opt(("--target",), "target", _target, None,
        "site in world coordinates (CRS units), X,Y (default: the base DEM's centre)",
        ("enhance",), metavar="X,Y"),
    Opt(("--layers",), "layers", _count, 11, "number of layers, each 2x finer (1..24)",
        ("enhance",), metavar="N"),
    Opt(("--size",), "size", _count, 1025, "pixels per side of every layer, 2^n + 1",
        ("enhance",), metavar="W"),
    Opt(("--craters",), "craters", _crater_spec, (),
        "crater layer c=..,k=..,dmin=..,dmax=..[,amin=..,amax=..,deg=..,kind=..] (N_cum = "
        "c D^k per m^2, D in metres, ages in Gyr); repeat for several", ("enhance",),
        metavar="SPEC", many=True),
    Opt(("--min-crater-px",), "min_crater_px", _number, 2.0,
        "smallest crater diameter a layer takes, in its pixels (>= 1)", ("enhance",),
        metavar="PX"),
    Opt(("--smooth-craters",), "smooth_craters", bool, False,
        "ideal craters: no fractal overlay, circular rims", ("enhance",), flag_only=True),
    Opt(("--boulders",), "boulders", _boulder_spec, (),
        "boulder layer c=..,k=..,dmin=..,dmax=..[,burial=..] (N_cum = c D^k per m^2, D in "
        "metres; burial = largest buried fraction of the height); stamped as a heightfield "
        "maximum in the finest layer holding each; repeat for several", ("enhance",),
        metavar="SPEC", many=True),
    Opt(("--min-boulder-px",), "min_boulder_px", _number, 2.0,
        "smallest boulder a layer takes, in its pixels (>= 1)", ("enhance",), metavar="PX"),
    Opt(("--no-boulders",), "no_boulders", bool, False,
        "leave the stack's boulders out of the mesh", ("mesh",), flag_only=True),
    Opt(("--levels",), "levels", _count, 1, "number of 2x expansions (1..16)", ("expand",),
        metavar="N"),
    Opt(("--fractal-dimension",), "fractal_dimension", _number, None,
        "fractal dimension F in [2, 3] (default: estimated from the input)",
        ("expand", "enhance"), metavar="F"),
    Opt(("--roughness",), "roughness", _number, None,
        "RMS slope between neighbouring pixels, m/m, >= 0 (default: from the input; for "
        "expand and enhance the local relief of each input pixel)",
        ("fill", "expand", "enhance"), metavar="R"),
    Opt(("--region",), "region", _region, None,
        "square to expand, 2^n+1 pixels: ROW,COL,SIZE in pixels or LEFT,BOTTOM,RIGHT,TOP "
        "in CRS units (default: the whole DEM)", ("expand",), metavar="REGION"),
    Opt(("--seed",), "seed", parse_seed, None,
        "random seed (non-negative integer); default: a fresh one, recorded in the tags",
        ("fill", "expand", "enhance"), metavar="S"),
    Opt(("--band",), "band", _count, 1, "band of the input (1-based)", _READ, metavar="B"),
    Opt(("--pixel-size-m",), "pixel_size_m", _number, None,
        "pixel size in metres, for inputs without a CRS", _READ, metavar="M"),
    Opt(("--body-radius-m",), "body_radius_m", _number, None,
        "body radius in metres, for inputs with a geographic CRS (e.g. 1737400 for the Moon)",
        _READ, metavar="M"),
    Opt(("-q", "--quiet"), "quiet", bool, False, "no progress bars or messages", _WRITE,
        flag_only=True),
    Opt(("--force",), "force", bool, False, "overwrite an existing output", _WRITE,
        flag_only=True),
)


def _options(command: str) -> dict[str, Opt]:
    return {o.key: o for o in OPTIONS if command in o.commands}


def _from_config(path, command: str) -> dict:
    """Settings from a TOML file whose keys are the option names (plus ``input``)."""
    opts = _options(command)
    out = {}
    for key, value in load_toml(path).items():
        if key == "input":
            if not isinstance(value, str):
                raise CliError(f"config {str(path)!r}: key 'input' must be a file name")
            out[key] = value
            continue
        opt = opts.get(key)
        if opt is None:
            allowed = ", ".join(["input", *sorted(opts)])
            raise CliError(f"config {str(path)!r}: unknown key {key!r} for `dem {command}`; "
                           f"allowed: {allowed}")
        good = (isinstance(value, bool) if opt.flag_only
                else isinstance(value, str | int | float) and not isinstance(value, bool))
        try:
            if not good:
                raise TypeError
            out[key] = value if opt.flag_only or opt.parse is str else opt.parse(value)
        except (TypeError, ValueError, argparse.ArgumentTypeError):
            raise CliError(f"config {str(path)!r}: key {key!r} has a bad value {value!r} "
                           f"({opt.help})") from None
    return out


def _settings(args: argparse.Namespace, command: str) -> dict:
    """Defaults, then the config file, then the command line."""
    opts = _options(command)
    s = {key: opt.default for key, opt in opts.items()}
    s["input"] = None
    if getattr(args, "config", None):
        s.update(_from_config(args.config, command))
    for key in [*opts, "input"]:
        value = getattr(args, key, None)
        if value is not None and value is not False:
            s[key] = value
    if s["input"] is None:
        raise CliError(f"`dem {command}` needs an input DEM (argument or config key 'input')")
    return s


# --------------------------------------------------------------------------- checks
def _check(s: dict, command: str) -> None:
    """Validate everything (flags named in the messages) before any work."""
    flag = {key: opt.flags[-1] for key, opt in _options(command).items()}
    if s.get("band", 1) < 1:
        raise CliError(f"--band must be >= 1; got {s['band']}")
    for key in ("pixel_size_m", "body_radius_m"):
        if s.get(key) is not None and s[key] <= 0:
            raise CliError(f"{flag[key]} must be > 0; got {s[key]!r}")
    if command == "info":
        return
    if s.get("roughness") is not None and s["roughness"] < 0:
        raise CliError(f"--roughness must be >= 0; got {s['roughness']!r}")
    if command == "expand":
        if not 1 <= s["levels"] <= 16:
            raise CliError(f"--levels must be an integer in [1, 16]; got {s['levels']}")
        fd = s.get("fractal_dimension")
        if fd is not None and not 2.0 <= fd <= 3.0:
            raise CliError(f"--fractal-dimension must be in [2, 3]; got {fd!r}")
    if not s.get("output"):
        raise CliError("nothing to write: give -o/--output")
    out = Path(s["output"])
    if Path(s["input"]).resolve() == out.resolve():
        raise CliError(f"output {str(out)!r} is the input; inputs are never modified")
    check_output_path(out, force=s["force"],
                      suffixes=MESH_SUFFIXES if command == "mesh" else GEOTIFF_SUFFIXES)
    if s.get("seed") is None:
        s["seed"] = int(np.random.SeedSequence().entropy % (2**63))


def _read(s: dict):
    return read(s["input"], band=s["band"], pixel_size_m=s.get("pixel_size_m"),
                body_radius_m=s.get("body_radius_m"))


# --------------------------------------------------------------------------- commands
def _run(args: argparse.Namespace, command: str) -> int:
    s = _settings(args, command)
    _check(s, command)
    show = not s["quiet"]
    bar = progress_bar(total=3, enabled=show, desc=command)
    bar.set_description(f"read {s['input']}")
    dem = _read(s)
    bar.update()
    bar.set_description(command)
    if command == "fill":
        out = fill_gaps(dem, s["roughness"], rng=s["seed"])
    else:
        out = expand(dem, s["levels"], s["fractal_dimension"], s["roughness"], s["region"],
                     rng=s["seed"], progress=show)
    bar.update()
    bar.set_description(f"write {s['output']}")
    write(out, s["output"])
    bar.update()
    bar.close()
    if show:
        params = out.history[-1]["parameters"]
        detail = ", ".join(f"{k} {params[k]:.4g}" if isinstance(params[k], float)
                           else f"{k} {params[k]}" for k in params
                           if k in ("levels", "fractal_dimension", "roughness",
                                    "filled_pixels", "waves"))
        print(f"dem {command}: {dem.shape[0]} x {dem.shape[1]} -> {out.shape[0]} x "
              f"{out.shape[1]} pixels, seed {s['seed']}, {detail}")
        print(f"wrote {s['output']}")
    return 0


def _cmd_info(args: argparse.Namespace) -> int:
    s = _settings(args, "info")
    _check(s, "info")
    dem = _read(s)
    z = dem.heights[dem.known]
    t = dem.transform
    px = dem.pixel_size_m
    rows = [
        ("file", s["input"]),
        ("size", f"{dem.shape[0]} x {dem.shape[1]} pixels (rows x cols)"),
        ("crs", crs_label(dem.crs)),
        ("pixel_m", f"{px[0]:.6g} x {px[1]:.6g} (x, y; resolution {dem.resolution_m:.6g})"),
        ("transform", ", ".join(f"{v:.10g}" for v in tuple(t)[:6])),
        ("body_m", "-" if dem.body_radius_m is None else f"{dem.body_radius_m:.10g}"),
        ("unknown", f"{100 * dem.nan_fraction:.3f} % ({dem.heights.size - z.size} pixels)"),
        ("height_m", f"min {z.min():.6g}  mean {z.mean():.6g}  max {z.max():.6g}"),
    ]
    try:
        fit = fractal_fit(dem)
        method = "locally normalised variogram, lags 1-4 px"
        rows += [("fractal_d", f"{fit.fractal_dimension:.4f} ({method})"),
                 ("roughness", f"{fit.roughness:.6g} (RMS neighbour slope, m/m)")]
    except ValueError as exc:
        rows.append(("fractal_d", f"n/a ({exc})"))
    for step in dem.history:
        rows.append(("history", f"{step['op']} seed {step['seed']}"))
    for key, value in rows:
        print(f"{key:<10} {value}")
    return 0


def _cmd_enhance(args: argparse.Namespace) -> int:
    s: dict = {}
    if args.config:
        s.update(load_toml(args.config))
    for key, opt in _options("enhance").items():
        value = getattr(args, key, None)
        if value is not None and value is not False:
            s[key] = list(value) if opt.many else value
    output, force, quiet = s.pop("output", None), s.pop("force", False), s.pop("quiet", False)
    if not output:
        raise CliError("nothing to write: give -o/--output (or the scene key 'output')")
    unknown = sorted(set(s) - set(EnhanceConfig.keys()))
    if unknown:
        raise CliError(f"scene {args.config!r}: unknown key(s) {', '.join(map(repr, unknown))}; "
                       f"allowed: {', '.join(EnhanceConfig.keys())}")
    cfg = EnhanceConfig.from_mapping(s)
    if cfg.input is None:
        raise CliError("`dem enhance` needs a base DEM (--input or the scene key 'input')")
    folder = check_stack_folder(output, force=force)
    stack = enhance(cfg, progress=not quiet)
    stack.write(folder, force=force, progress=not quiet)
    if not quiet:
        info = stack.info
        c = info["craters"]
        sizes = stack.pixel_sizes_m()
        print(f"dem enhance: {len(stack)} layers of {cfg.size} x {cfg.size} pixels, "
              f"{sizes[0]:.4g} m -> {sizes[-1]:.4g} m per pixel, seed {info['seed']}; craters "
              f"stamped {sum(c['stamped'])}, erased on steep ground "
              f"{sum(c['erased_on_steep_ground'])}, rejected {c['rejected']} of {c['drawn']}")
        b = info.get("boulders")
        if b:
            print(f"boulders stamped {sum(b['stamped'])}, rejected {b['rejected']} of "
                  f"{b['drawn']} (below {cfg.min_boulder_px:g} px of the finest layer or "
                  f"crossing a layer's border)")
        print(f"wrote {Path(output) / 'manifest.json'}")
    return 0


def _cmd_mesh(args: argparse.Namespace) -> int:
    s = _settings(args, "mesh")
    _check(s, "mesh")
    show = not s["quiet"]
    if Path(s["input"]).suffix.lower() == ".json":
        src = read_stack(s["input"], progress=show)
    else:
        src = _read(s)
    path = to_mesh(src, s["output"], progress=show, boulders=not s.get("no_boulders"))
    if show:
        n = len(src) if hasattr(src, "layers") else 1
        print(f"dem mesh: {n} layer(s), {path.stat().st_size / 2**20:.1f} MiB")
        print(f"wrote {path}")
    return 0


# --------------------------------------------------------------------------- parser
def build_parser() -> OneLineParser:
    parser = OneLineParser(prog="dem", description="DEMs: gap filling, RMD expansion, "
                                                   "layer stacks with craters, meshes, info.")
    parser.add_argument("--version", action="version", version=f"craterform {package_version()}")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=OneLineParser)
    helps = {"info": "describe a DEM (size, CRS, pixel size, heights, fractal dimension)",
             "fill": "fill the unknown pixels of a DEM with fractal terrain, outside in",
             "expand": "double the resolution of a DEM (region) by random midpoint "
                       "displacement",
             "enhance": "build a stack of layers around a site, each 2x finer, with craters "
                        "per layer",
             "mesh": "write the multi-resolution triangle mesh of a stack (or a DEM) as PLY "
                     "or VTP"}
    for command, text in helps.items():
        p = sub.add_parser(command, help=text, description=text[0].upper() + text[1:] + ".")
        if command == "enhance":
            p.add_argument("config", nargs="?", default=None, metavar="SCENE.toml",
                           help="TOML scene whose keys are the option names; flags override "
                                "it")
        else:
            p.add_argument("input", nargs="?", default=None,
                           help="input stack manifest (.json) or DEM" if command == "mesh"
                           else "input DEM (GeoTIFF, PDS .lbl/.img)")
        if command in ("fill", "expand", "mesh"):
            p.add_argument("--config", metavar="TOML",
                           help="TOML file whose keys are the option names (and input); "
                                "flags override it")
        for opt in _options(command).values():
            kw: dict = {"dest": opt.key, "help": opt.help, "default": None}
            if opt.flag_only:
                kw.update(action="store_true", default=False)
            else:
                kw.update(type=opt.parse, metavar=opt.metavar)
                if opt.many:
                    kw.update(action="append")
            p.add_argument(*opt.flags, **kw)
        funcs = {"info": _cmd_info, "enhance": _cmd_enhance, "mesh": _cmd_mesh}
        p.set_defaults(func=funcs.get(command, lambda a, c=command: _run(a, c)))
    add_analysis_parsers(sub)
    return parser


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    return run_cli(lambda: args.func(args))


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
