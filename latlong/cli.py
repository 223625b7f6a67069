"""The ``latlong`` command line: ``latlong build`` and ``latlong info``.

Every ``build`` option has a key of the same name (dashes -> underscores) in a TOML
scene file given with ``--config``; options on the command line override the file.
"""

from __future__ import annotations

import argparse
import dataclasses
import logging
import math
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from craters._infra import (
    CliError,
    OneLineParser,
    check_output_path,
    load_toml,
    package_version,
    parse_seed,
    physical_memory_bytes,
    progress_bar,
    run_cli,
)

from .body import EXPORT_SUFFIXES, Body, load
from .faulting import FAULTING_PRESETS, FaultingParams, two_phase_faulting
from .grid import LatLongGrid
from .perlin import FBM_PRESETS, perlin_fbm

logger = logging.getLogger(__name__)

BASES = ("sphere", "faulting", "fbm")
OUTPUT_SUFFIXES = (".npz", *EXPORT_SUFFIXES)
# memory per vertex for a build with export (radii, unit vectors, vertices, caches)
_BYTES_PER_VERTEX = 160
# the faulting presets are the paper's ~100 m asteroid: phase 1 (1000 faults <= 5 m)
# gives a relief of std ~25 m, so a 100 m radius keeps the deepest pits (faulting is
# antisymmetric: every bump has an antipodal pit) well above 0. Their stretch (2 on x)
# comes with the preset.
_FAULTING_PRESET_RADIUS_M = 100.0


# --------------------------------------------------------------------------- options
@dataclass(frozen=True)
class Opt:
    """One ``build`` option: its flags, config key, parser, default and help."""

    flags: tuple[str, ...]
    key: str
    parse: Any
    default: Any
    help: str
    group: str = "body"
    action: str = "store"


def _stretch(text: str) -> tuple[float, float, float]:
    parts = str(text).split(",")
    try:
        vals = tuple(float(p) for p in parts)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected X,Y,Z factors; got {text!r}") from None
    if len(vals) != 3:
        raise argparse.ArgumentTypeError(f"expected three factors X,Y,Z; got {text!r}")
    return vals


BUILD_OPTIONS: tuple[Opt, ...] = (
    Opt(("--magnitude",), "magnitude", int, 200,
        "grid magnitude M >= 1 (6M^2+2 vertices)"),
    Opt(("--radius-m",), "radius_m", float, 50.0, "reference radius in metres"),
    Opt(("--stretch",), "stretch", _stretch, (1.0, 1.0, 1.0),
        "scale factors X,Y,Z applied to the body (e.g. 2,1,1)"),
    Opt(("--base",), "base", str, "fbm", "base shape: sphere, faulting or fbm"),
    Opt(("--preset",), "preset", str, None,
        "parameter set: faulting: paper (default), fig4; fbm: fig5a (default), fig5b, fig5c"),
    Opt(("--seed",), "seed", parse_seed, None,
        "random seed (non-negative integer); default: a fresh one, recorded in the model"),
    # two-phase faulting
    Opt(("--faults-1",), "faults_1", int, None, "phase-1 fault count", "faulting"),
    Opt(("--max-fault-1-m",), "max_fault_1_m", float, None,
        "largest phase-1 fault offset, metres", "faulting"),
    Opt(("--smooth-width-m",), "smooth_width_m", float, None,
        "smoothing filter width (Gaussian FWHM) in metres", "faulting"),
    Opt(("--smooth-passes",), "smooth_passes", int, None, "smoothing passes", "faulting"),
    Opt(("--faults-2",), "faults_2", int, None, "phase-2 fault count", "faulting"),
    Opt(("--max-fault-2-m",), "max_fault_2_m", float, None,
        "largest phase-2 fault offset, metres", "faulting"),
    # fBm
    Opt(("--frequency",), "frequency", float, None, "first-octave frequency on the unit sphere",
        "fbm"),
    Opt(("--octaves",), "octaves", int, None, "number of octaves", "fbm"),
    Opt(("--persistence",), "persistence", float, None, "amplitude ratio per octave", "fbm"),
    Opt(("--lacunarity",), "lacunarity", float, None, "frequency ratio per octave (>= 1)",
        "fbm"),
    Opt(("--amplitude-m",), "amplitude_m", float, None,
        "fBm height scale in metres (default: the preset's fraction of the radius)", "fbm"),
    # outputs
    Opt(("-o", "--output"), "output", str, [],
        "output file, format by suffix: " + " ".join(OUTPUT_SUFFIXES) + " (repeatable)",
        "output", "append"),
    Opt(("--preview",), "preview", str, None, "write a preview picture (PNG)", "output"),
    Opt(("--sun-azimuth-deg",), "sun_azimuth_deg", float, 60.0,
        "preview sun azimuth from the viewer, degrees (90 = from the right)", "output"),
    Opt(("--sun-elevation-deg",), "sun_elevation_deg", float, 20.0,
        "preview sun elevation above the equator, degrees", "output"),
    Opt(("-q", "--quiet"), "quiet", bool, False, "no progress bars or messages", "output",
        "store_true"),
    Opt(("--force",), "force", bool, False, "overwrite existing outputs", "output", "store_true"),
)
_BY_KEY = {o.key: o for o in BUILD_OPTIONS}


def _flag(key: str) -> str:
    return _BY_KEY[key].flags[-1]


def _config_settings(path) -> dict:
    """Read a TOML scene: keys are the option names with underscores."""
    raw = load_toml(path)
    out = {}
    for key, value in raw.items():
        if key == "config" or key not in _BY_KEY:
            allowed = ", ".join(sorted(_BY_KEY))
            raise ValueError(f"config {str(path)!r}: unknown key {key!r}; allowed: {allowed}")
        opt = _BY_KEY[key]
        try:
            if opt.action == "append":
                value = [value] if isinstance(value, str) else list(value)
                value = [str(v) for v in value]
            elif opt.action == "store_true":
                if not isinstance(value, bool):
                    raise TypeError
            elif opt.parse is _stretch:
                value = _stretch(",".join(str(v) for v in value)) if isinstance(
                    value, list) else _stretch(value)
            elif opt.parse is int or opt.parse is parse_seed:
                if isinstance(value, bool) or not isinstance(value, int):
                    raise TypeError
                value = opt.parse(value)
            elif opt.parse is float:
                if isinstance(value, bool) or not isinstance(value, int | float):
                    raise TypeError
                value = float(value)
            else:
                value = opt.parse(value)
        except (TypeError, ValueError, argparse.ArgumentTypeError):
            raise ValueError(f"config {str(path)!r}: key {key!r} has a bad value {value!r} "
                             f"({opt.help})") from None
        out[key] = value
    return out


# --------------------------------------------------------------------------- checks
def _finite(key: str, value: float, *, positive: bool = False, nonneg: bool = False) -> float:
    flag = _flag(key)
    if not math.isfinite(value):
        raise CliError(f"{flag} must be finite; got {value!r}")
    if positive and value <= 0:
        raise CliError(f"{flag} must be > 0; got {value!r}")
    if nonneg and value < 0:
        raise CliError(f"{flag} must be >= 0; got {value!r}")
    return value


def _count(key: str, value: int, lo: int, hi: int) -> int:
    if not lo <= value <= hi:
        raise CliError(f"{_flag(key)} must be an integer in [{lo}, {hi}]; got {value}")
    return value


def _human_bytes(n: float) -> str:
    for unit in ("B", "KiB", "MiB", "GiB", "TiB", "PiB", "EiB"):
        if n < 1024 or unit == "EiB":
            return f"{n:.1f} {unit}"
        n /= 1024
    return f"{n:.1f} EiB"  # pragma: no cover


def _check_memory(magnitude: int) -> None:
    need = LatLongGrid.estimate_bytes(magnitude, _BYTES_PER_VERTEX)
    have = physical_memory_bytes()
    if need > 0.85 * have:
        n = 6 * magnitude * magnitude + 2
        raise CliError(
            f"--magnitude {magnitude} needs about {_human_bytes(need)} of memory "
            f"({n:.3g} vertices x {_BYTES_PER_VERTEX} B); this machine has "
            f"{_human_bytes(have)}"
        )


def _resolve(s: dict) -> dict:
    """Validate and complete the merged settings (everything before any work)."""
    _count("magnitude", s["magnitude"], 1, 10**9)
    _check_memory(s["magnitude"])
    base = s["base"]
    if base not in BASES:
        raise CliError(f"--base must be one of {', '.join(BASES)}; got {base!r}")
    for key, opt in _BY_KEY.items():
        if opt.group in ("faulting", "fbm") and opt.group != base and s.get(key) is not None:
            raise CliError(f"{opt.flags[-1]} applies to --base {opt.group}, not --base {base}")
    presets = {"faulting": FAULTING_PRESETS, "fbm": FBM_PRESETS, "sphere": {}}[base]
    preset = s.get("preset")
    if preset is not None and preset not in presets:
        names = ", ".join(presets) or "(none)"
        raise CliError(f"--preset for --base {base} must be one of {names}; got {preset!r}")
    if preset is None and presets:
        preset = "paper" if base == "faulting" else "fig5a"
    s["preset"] = preset
    if base == "faulting":
        if s.get("radius_m") is None:
            s["radius_m"] = _FAULTING_PRESET_RADIUS_M
        if s.get("stretch") is None:
            s["stretch"] = FAULTING_PRESETS[preset].stretch
    for key in ("radius_m", "stretch"):
        if s.get(key) is None:
            s[key] = _BY_KEY[key].default
    _finite("radius_m", s["radius_m"], positive=True)
    for v in s["stretch"]:
        if not math.isfinite(v) or v <= 0:
            raise CliError(f"--stretch factors must be finite and > 0; got {s['stretch']}")
    if base == "faulting":
        p = FAULTING_PRESETS[preset]
        fields = {"faults_1": "n_faults_1", "max_fault_1_m": "max_fault_1_m",
                  "smooth_width_m": "smooth_width_m", "smooth_passes": "smooth_passes",
                  "faults_2": "n_faults_2", "max_fault_2_m": "max_fault_2_m"}
        for key, field in fields.items():
            if s.get(key) is None:
                s[key] = getattr(p, field)
        for key in ("faults_1", "faults_2"):
            _count(key, s[key], 0, 10**8)
        _count("smooth_passes", s["smooth_passes"], 0, 1000)
        for key in ("max_fault_1_m", "max_fault_2_m", "smooth_width_m"):
            _finite(key, s[key], nonneg=True)
    elif base == "fbm":
        p = FBM_PRESETS[preset]
        for key in ("frequency", "octaves", "persistence", "lacunarity"):
            if s.get(key) is None:
                s[key] = getattr(p, key)
        if s.get("amplitude_m") is None:
            s["amplitude_m"] = p.amplitude * s["radius_m"]
        _finite("frequency", s["frequency"], positive=True)
        _count("octaves", s["octaves"], 1, 30)
        _finite("persistence", s["persistence"], positive=True)
        _finite("lacunarity", s["lacunarity"])
        if s["lacunarity"] < 1:
            raise CliError(f"--lacunarity must be >= 1; got {s['lacunarity']!r}")
        _finite("amplitude_m", s["amplitude_m"], nonneg=True)
    for key in ("sun_azimuth_deg", "sun_elevation_deg"):
        _finite(key, s[key])
    if not -90 <= s["sun_elevation_deg"] <= 90:
        raise CliError(f"--sun-elevation-deg must be in [-90, 90]; got {s['sun_elevation_deg']}")
    outputs = [Path(p) for p in s["output"]]
    if not outputs and not s.get("preview"):
        raise CliError("nothing to write: give at least one -o/--output or --preview")
    seen = set()
    for p in outputs + ([Path(s["preview"])] if s.get("preview") else []):
        key = p.resolve()
        if key in seen:
            raise CliError(f"output {str(p)!r} is given twice")
        seen.add(key)
    for p in outputs:
        check_output_path(p, force=s["force"], suffixes=OUTPUT_SUFFIXES)
    if s.get("preview"):
        check_output_path(s["preview"], force=s["force"], suffixes=(".png",))
    if s.get("seed") is None:
        s["seed"] = int(np.random.SeedSequence().entropy % (2**63))
    return s


# --------------------------------------------------------------------------- build
def build_body(s: dict, *, progress: bool = False) -> Body:
    """Make the body described by resolved settings ``s``."""
    grid = LatLongGrid(s["magnitude"])
    rng = np.random.default_rng(s["seed"])
    base = s["base"]
    if base == "sphere":
        heights = np.zeros(grid.n_vertices)
        params: dict = {}
    elif base == "faulting":
        fp = FaultingParams(s["faults_1"], s["max_fault_1_m"], s["smooth_width_m"],
                            s["smooth_passes"], s["faults_2"], s["max_fault_2_m"],
                            tuple(s["stretch"]))
        heights = two_phase_faulting(grid, s["radius_m"], fp, rng=rng, progress=progress)
        params = dataclasses.asdict(fp)
    else:
        heights = perlin_fbm(grid, s["frequency"], s["octaves"], s["persistence"],
                             s["lacunarity"], s["amplitude_m"], rng=rng)
        params = {k: s[k] for k in ("frequency", "octaves", "persistence", "lacunarity",
                                    "amplitude_m")}
    metadata = {
        "generator": "craterform latlong build",
        "version": package_version(),
        "seed": s["seed"],
        "base": base,
        "preset": s["preset"],
        "parameters": params,
    }
    return Body.from_heights(grid, s["radius_m"], heights, stretch=s["stretch"],
                             metadata=metadata)


def _cmd_build(args: argparse.Namespace) -> int:
    given = {k: v for k, v in vars(args).items() if k in _BY_KEY and v is not None}
    settings = {o.key: o.default for o in BUILD_OPTIONS}
    for key in ("radius_m", "stretch"):
        settings[key] = None  # may come from a preset
    if args.config:
        settings.update(_config_settings(args.config))
    settings.update({k: v for k, v in given.items() if not (k == "output" and v == [])})
    if given.get("quiet"):
        settings["quiet"] = True
    if given.get("force"):
        settings["force"] = True
    s = _resolve(settings)
    show = not s["quiet"]
    stages = ["base shape"] + [str(p) for p in s["output"]] + (
        [s["preview"]] if s.get("preview") else [])
    bar = progress_bar(total=len(stages), enabled=show, desc="build")
    bar.set_description("base shape")
    body = build_body(s, progress=show)
    bar.update()
    for out in s["output"]:
        bar.set_description(out)
        if out.lower().endswith(".npz"):
            body.save(out)
        else:
            body.export(out, progress=show)
        bar.update()
    if s.get("preview"):
        from .preview import render_preview

        bar.set_description(s["preview"])
        render_preview(body, s["preview"], sun_azimuth_deg=s["sun_azimuth_deg"],
                       sun_elevation_deg=s["sun_elevation_deg"])
        bar.update()
    bar.close()
    if show:
        r = body.radii_m
        print(f"body: magnitude {body.magnitude}, {body.n_vertices} vertices, base {s['base']}"
              f" ({s['preset'] or '-'}), seed {s['seed']}, radius {r.min():.4g}..{r.max():.4g} m")
        for out in [*s["output"], *([s["preview"]] if s.get("preview") else [])]:
            print(f"wrote {out} ({_human_bytes(Path(out).stat().st_size)})")
    return 0


def _cmd_info(args: argparse.Namespace) -> int:
    body = load(args.model)
    meta = body.metadata
    r = body.radii_m
    g = body.grid
    print(f"model      {args.model}")
    print(f"magnitude  {g.magnitude}  ({g.n_vertices} vertices, {g.n_triangles} triangles)")
    print(f"radius_m   reference {body.radius_m:.6g}; min {r.min():.6g}  mean {r.mean():.6g}"
          f"  max {r.max():.6g}")
    print(f"stretch    {', '.join(f'{v:g}' for v in body.stretch)}")
    print(f"spacing_m  {g.spacing(body.radius_m):.4g} (ring spacing at the reference radius)")
    for key in ("generator", "version", "seed", "base", "preset"):
        if key in meta:
            print(f"{key:<10} {meta[key]}")
    for key, value in (meta.get("parameters") or {}).items():
        print(f"  {key:<16} {value}")
    return 0


# --------------------------------------------------------------------------- parser
def build_parser() -> argparse.ArgumentParser:
    parser = OneLineParser(prog="latlong", description="Asteroid bodies on the lat/long mesh.")
    parser.add_argument("--version", action="version", version=f"craterform {package_version()}")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=OneLineParser)
    b = sub.add_parser("build", help="generate a body and write meshes / previews",
                       description="Generate a body (base shape) and write it.")
    b.add_argument("--config", metavar="TOML", help="scene file; options override its keys")
    groups = {"body": b.add_argument_group("body"),
              "faulting": b.add_argument_group("two-phase faulting (--base faulting)"),
              "fbm": b.add_argument_group("Perlin fBm (--base fbm)"),
              "output": b.add_argument_group("output")}
    for opt in BUILD_OPTIONS:
        kw: dict = {"dest": opt.key, "help": opt.help, "default": None}
        if opt.action == "store_true":
            kw["action"] = "store_true"
        else:
            kw["type"] = opt.parse
            if opt.action == "append":
                kw["action"] = "append"
        groups[opt.group].add_argument(*opt.flags, **kw)
    b.set_defaults(func=_cmd_build)
    i = sub.add_parser("info", help="describe a saved body (.npz)")
    i.add_argument("model", help="a .npz written by latlong build")
    i.set_defaults(func=_cmd_info)
    return parser


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    return run_cli(lambda: args.func(args))


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
