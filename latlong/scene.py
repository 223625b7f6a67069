"""Scenes: the settings that describe a body reproducibly, the named presets, and the build.

A scene is a flat dictionary whose keys are the ``latlong build`` option names with
underscores (``magnitude``, ``radius_m``, ``base``, ``craters``, ...). The same keys are
the TOML scene-file keys (``[[craters]]`` tables or spec strings for crater layers).
Precedence: option defaults < preset < scene file < command line.
"""

from __future__ import annotations

import argparse
import dataclasses
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

import craters as _craters
from craters._shared import (
    check_output_path,
    human_bytes,
    load_toml,
    normalize_rng,
    package_version,
    physical_memory_bytes,
)
from craters._shared.cli import CliError, parse_seed

from .body import EXPORT_SUFFIXES, Body
from .faulting import FAULTING_PRESETS, FaultingParams, two_phase_faulting
from .grid import LatLongGrid
from .perlin import FBM_PRESETS, perlin_fbm

__all__ = ["BUILD_OPTIONS", "PRESETS", "Opt", "body_population", "build_body",
           "config_settings", "resolve_settings", "surface_positions", "write_outputs"]

BASES = ("sphere", "faulting", "fbm")
OUTPUT_SUFFIXES = (".npz", *EXPORT_SUFFIXES, ".glb")
# memory per vertex for a build with export (radii, unit vectors, vertices, caches)
BYTES_PER_VERTEX = 160


# --------------------------------------------------------------------------- options
@dataclass(frozen=True)
class Opt:
    """One option: its flags, scene key, parser, default, help, group and argparse action."""

    flags: tuple[str, ...]
    key: str
    parse: Any
    default: Any
    help: str
    group: str = "body"
    action: str = "store"


def _stretch(text) -> tuple[float, float, float]:
    parts = text if isinstance(text, list | tuple) else str(text).split(",")
    try:
        vals = tuple(float(p) for p in parts)
    except (TypeError, ValueError):
        raise argparse.ArgumentTypeError(f"expected X,Y,Z factors; got {text!r}") from None
    if len(vals) != 3:
        raise argparse.ArgumentTypeError(f"expected three factors X,Y,Z; got {text!r}")
    return vals


RENDER_OPTIONS: tuple[Opt, ...] = (
    Opt(("--sun-azimuth-deg",), "sun_azimuth_deg", float, 60.0,
        "sun azimuth from the viewer, degrees (0 = behind the camera, 90 = from the right)",
        "render"),
    Opt(("--sun-elevation-deg",), "sun_elevation_deg", float, 20.0,
        "sun elevation above the picture's horizontal plane, degrees", "render"),
    Opt(("--view-lon-deg",), "view_lon_deg", float, -90.0,
        "longitude of the camera direction (body-fixed), degrees", "render"),
    Opt(("--view-lat-deg",), "view_lat_deg", float, 0.0,
        "latitude of the camera direction, degrees", "render"),
    Opt(("--camera-distance-m",), "camera_distance_m", float, None,
        "camera distance from the body centre, metres (default: frame the body)", "render"),
    Opt(("--width-px",), "width_px", int, 1024, "picture width, pixels", "render"),
    Opt(("--height-px",), "height_px", int, 768, "picture height, pixels", "render"),
    Opt(("--views",), "views", int, 1,
        "1 = one view; 6 = a contact sheet from +x, -x, +y, -y, +z, -z", "render"),
)

BUILD_OPTIONS: tuple[Opt, ...] = (
    Opt(("--preset",), "preset", str, None,
        "named scene (see `latlong presets`): sets the base and its parameters, the body "
        "and crater layers"),
    Opt(("--magnitude",), "magnitude", int, 200, "grid magnitude M >= 1 (6M^2+2 vertices)"),
    Opt(("--radius-m",), "radius_m", float, 50.0, "reference radius in metres"),
    Opt(("--stretch",), "stretch", _stretch, None,
        "scale factors X,Y,Z applied to the body (e.g. 2,1,1; default 1,1,1 or the "
        "preset's)"),
    Opt(("--base",), "base", str, None,
        "base shape: sphere, faulting, fbm (default) or shape:PATH (a real shape model: "
        "OBJ, PDS plate .tab/.plt, PLY, STL)"),
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
    # shape models
    Opt(("--shape-units",), "shape_units", str, None,
        "units of the shape model file: km or m (required with --base shape:PATH)", "shape"),
    Opt(("--shape-center",), "shape_center", str, None,
        "ray origin: volume-centroid (default), area-centroid, origin or X,Y,Z in metres",
        "shape"),
    Opt(("--shape-crossings",), "shape_crossings", str, None,
        "where a ray crosses the surface more than once: error (default), outermost, "
        "innermost", "shape"),
    Opt(("--shape-smooth",), "shape_smooth", str, None,
        "subdivision before casting: butterfly (default, interpolating), linear (keep "
        "the facets), loop, none", "shape"),
    # fBm
    Opt(("--frequency",), "frequency", float, None,
        "first-octave frequency on the unit sphere (with a shape base: fBm detail, "
        "default wavelength = the model's resolution)", "fbm"),
    Opt(("--octaves",), "octaves", int, None, "number of octaves", "fbm"),
    Opt(("--persistence",), "persistence", float, None, "amplitude ratio per octave", "fbm"),
    Opt(("--lacunarity",), "lacunarity", float, None, "frequency ratio per octave (>= 1)",
        "fbm"),
    Opt(("--amplitude-m",), "amplitude_m", float, None,
        "fBm height scale in metres (default: the preset's fraction of the radius)", "fbm"),
    # craters
    Opt(("--craters",), "craters", str, None,
        "crater layer c=0.5,k=-2,dmin=2,dmax=50[,amin=0,amax=3.5,deg=0.2,kind=simple]: "
        "N_cum = c D^k per m^2, D in metres (repeatable for piecewise laws)", "craters",
        "append"),
    Opt(("--crater-morphometry",), "crater_morphometry", str, "lunar-simple",
        "fresh crater laws: lunar-simple (Pike 1977) or asteroid-fresh (d/D = 0.2)",
        "craters"),
    Opt(("--crater-lifetime-gyr",), "crater_lifetime_gyr", float, 10.0,
        "time for a 1 km crater to degrade fully, Gyr (ages -> degradation)", "craters"),
    Opt(("--no-crater-roughness",), "crater_roughness", bool, True,
        "ideal craters: no fractal overlay, circular rims", "craters", "store_false"),
    Opt(("--max-crater-extent-deg",), "max_crater_extent_deg", float, 60.0,
        "largest angular size of a crater's ejecta blanket, degrees of arc", "craters"),
    # boulders
    Opt(("--boulders",), "boulders", str, None,
        "boulder layer c=0.05,k=-3,dmin=0.5,dmax=10[,burial=0.5,near=0.3]: N_cum = c D^k "
        "per m^2, D in metres; burial = largest buried fraction of the height (<= 0.9); "
        "near = share around crater rims (repeatable)", "boulders", "append"),
    Opt(("--boulder-flatten",), "boulder_flatten", float, 0.6,
        "boulder up-axis scale relative to its width", "boulders"),
    Opt(("--boulder-elongation",), "boulder_elongation", float, 1.4,
        "boulder length relative to its width", "boulders"),
    Opt(("--boulder-roughness",), "boulder_roughness", float, 0.22,
        "boulder midpoint-displacement amplitude (fraction of the edge length)", "boulders"),
    # the implicit backend (latlong/implicit_cli.py)
    Opt(("--backend",), "backend", str, None,
        "latlong (default: the lat/long mesh) or implicit (Li et al.: metaballs over a "
        "sphere packing of --shape, LCSN craters, Gabor detail, marching cubes)", "implicit"),
    Opt(("--shape",), "shape", str, None,
        "constraint mesh of --backend implicit (OBJ, PDS plate .tab/.plt, PLY, STL, VTK; "
        "units from --shape-units)", "implicit"),
    Opt(("--polygons",), "polygons", int, None,
        "about how many triangles the implicit mesh has (default 200000)", "implicit"),
    Opt(("--voxel-m",), "voxel_m", float, None,
        "marching-cubes spacing, metres (instead of --polygons)", "implicit"),
    Opt(("--packing-voxels",), "packing_voxels", int, None,
        "voxels along the constraint's longest side for the sphere packing (default 128)",
        "implicit"),
    Opt(("--min-sphere-m",), "min_sphere_m", float, None,
        "smallest packed sphere, metres (default 2 packing voxels)", "implicit"),
    Opt(("--cell-m",), "cell_m", float, None,
        "cell size of grid level 0, metres (default: the largest dmax)", "implicit"),
    Opt(("--lcsn",), "lcsn", str, None,
        "LCSN crater layer kernel=NAME,dmin=M,dmax=M[,B=3,p=0.5,w=1,hd=LO:HI]: NAME of "
        "craters.LCSN_PRESETS scaled to D in [dmin, dmax] (metres), N(>D) ~ D^-B, p = "
        "impulse chance per surface cell, w = weight, hd = depth/diameter (repeatable)",
        "implicit", "append"),
    Opt(("--gabor",), "gabor", str, None,
        "Gabor micro-detail f=CYCLES_PER_M,bw=PER_M,amp=RMS_M[,orient=DEG,density=N]",
        "implicit"),
    Opt(("--gabor-example",), "gabor_example", str, None,
        "fit the Gabor noise to an example (.npy heights in metres, or a .png/.jpg/.tif "
        "picture)", "implicit"),
    Opt(("--gabor-pixel-m",), "gabor_pixel_m", float, None,
        "pixel size of --gabor-example on the body, metres", "implicit"),
    Opt(("--gabor-amplitude-m",), "gabor_amplitude_m", float, None,
        "rms of the fitted Gabor noise, metres (default: the .npy example's)", "implicit"),
    # outputs
    Opt(("-o", "--output"), "output", str, None,
        "output file, format by suffix: " + " ".join(OUTPUT_SUFFIXES) + " (repeatable; .glb "
        "is the patched strip export with its .json manifest, full resolution only - "
        "`latlong export` adds levels of detail)",
        "output", "append"),
    Opt(("--catalog",), "catalog", str, None,
        "write the ground-truth crater catalog as stamped (CSV)", "output"),
    Opt(("--boulder-catalog",), "boulder_catalog", str, None,
        "write the boulder catalog as placed (CSV)", "output"),
    Opt(("--preview",), "preview", str, None, "write a preview picture (PNG)", "output"),
    *RENDER_OPTIONS,
    Opt(("-q", "--quiet"), "quiet", bool, False, "no progress bars or messages", "output",
        "store_true"),
    Opt(("--force",), "force", bool, False, "overwrite existing outputs", "output", "store_true"),
)
_BY_KEY = {o.key: o for o in BUILD_OPTIONS}
_BASE_GROUPS = ("faulting", "fbm")


def flag(key: str) -> str:
    """The command-line flag of a scene key."""
    return _BY_KEY[key].flags[-1]


# --------------------------------------------------------------------------- presets
@dataclass(frozen=True)
class Preset:
    """A named scene: base shape, base parameter set and other settings."""

    description: str
    base: str
    base_params: str | None = None
    settings: dict = dataclasses.field(default_factory=dict)
    amplitude: float | None = None
    """fBm amplitude as a fraction of the radius (default: the parameter set's)."""


PRESETS: dict[str, Preset] = {
    "paper": Preset("Martin 2014 IV.A two-phase faulting: 1000 faults <= 5 m, 3 x 20 m "
                    "smoothing, 20 000 faults <= 0.03 m; 100 m radius stretched 2x on x",
                    "faulting", "paper", {"radius_m": 100.0}),
    "fig4": Preset("Martin 2014 Fig. 4: as 'paper' with 500 phase-2 faults <= 0.5 m",
                   "faulting", "fig4", {"radius_m": 100.0}),
    "fig5a": Preset("Martin 2014 Fig. 5 Perlin set: f 1.5, persistence 0.5, lacunarity "
                    "1.75, 10 octaves", "fbm", "fig5a"),
    "fig5b": Preset("Martin 2014 Fig. 5 Perlin set: f 2.5, persistence 0.5, lacunarity 1.5",
                    "fbm", "fig5b"),
    "fig5c": Preset("Martin 2014 Fig. 5 Perlin set: f 4.0, persistence 0.3, lacunarity 2.5",
                    "fbm", "fig5c"),
    "fbm-cratered": Preset(
        "Martin 2014 Fig. 8: Perlin base (fig5a) on a 100 m body with N_cum = 0.5 D^-2 "
        "craters, 1-15 m (resolved from magnitude ~400)", "fbm", "fig5a",
        {"radius_m": 100.0, "craters": ["c=0.5,k=-2,dmin=1,dmax=15"]}),
    "faulted-cratered": Preset(
        "Martin 2014 Fig. 8: two-phase faulting (paper), stretch 2 on x, with N_cum = "
        "0.1 D^-2 craters, 1-20 m", "faulting", "paper",
        {"radius_m": 100.0, "craters": ["c=0.1,k=-2,dmin=1,dmax=20"]}),
    "eros-like": Preset(
        "433 Eros-like: 8 km radius stretched to ~34 x 11 x 11 km, lumpy fBm base, a "
        "saturated crater population near equilibrium (N_cum = 0.1 D^-2, 40 m-1.5 km), "
        "asteroid d/D = 0.2 (magnitude >= 700 resolves it)",
        "fbm", None,
        {"radius_m": 8000.0, "stretch": (2.15, 0.7, 0.7), "frequency": 1.2, "octaves": 8,
         "persistence": 0.45, "lacunarity": 2.0, "crater_morphometry": "asteroid-fresh",
         "craters": ["c=0.1,k=-2,dmin=40,dmax=1500"]},
        amplitude=0.12),
    "itokawa-like": Preset(
        "25143 Itokawa-like rubble pile: 165 m radius, elongated (535 x 294 x 209 m), "
        "rough low-frequency fBm, few and degraded craters (N_cum = 0.005 D^-2, 2-20 m)",
        "fbm", None,
        {"radius_m": 165.0, "stretch": (1.6, 0.9, 0.65), "frequency": 1.0, "octaves": 10,
         "persistence": 0.55, "lacunarity": 2.0, "crater_morphometry": "asteroid-fresh",
         "crater_lifetime_gyr": 0.5, "craters": ["c=0.005,k=-2,dmin=2,dmax=20,amin=0.5,amax=3"]},
        amplitude=0.15),
    "bennu-like": Preset(
        "101955 Bennu-like: 245 m radius, slightly flattened, gentle fBm, craters as Li "
        "et al. 2022 Fig. A.3 (B = 3, ~19 % saturation: N_cum = 0.9 D^-3, 10-70 m)",
        "fbm", None,
        {"radius_m": 245.0, "stretch": (1.0, 1.0, 0.92), "frequency": 2.0, "octaves": 8,
         "persistence": 0.5, "lacunarity": 2.0, "crater_morphometry": "asteroid-fresh",
         "crater_lifetime_gyr": 1.0, "craters": ["c=0.9,k=-3,dmin=10,dmax=70"]},
        amplitude=0.05),
}
_DEFAULT_PRESET = {"faulting": "paper", "fbm": "fig5a", "sphere": None}


def preset_table() -> list[tuple[str, str, dict]]:
    """(name, description, settings incl. base-shape parameters) of every preset."""
    rows = []
    for name, p in PRESETS.items():
        s = {"base": p.base, **p.settings}
        if p.base_params in FAULTING_PRESETS and p.base == "faulting":
            s.update(dataclasses.asdict(FAULTING_PRESETS[p.base_params]))
        elif p.base_params in FBM_PRESETS:
            s.update(dataclasses.asdict(FBM_PRESETS[p.base_params]))
        if p.amplitude is not None:
            s["amplitude"] = p.amplitude
        rows.append((name, p.description, s))
    return rows


# --------------------------------------------------------------------------- config
def _layer_from_table(table: dict, where: str) -> _craters.CraterLayer:
    allowed = {f.name for f in dataclasses.fields(_craters.CraterLayer)}
    unknown = set(table) - allowed
    if unknown:
        raise ValueError(f"{where}: unknown crater key(s) {', '.join(sorted(unknown))}; "
                         f"allowed: {', '.join(sorted(allowed))}")
    try:
        return _craters.CraterLayer(**table)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{where}: {exc}") from None


def _boulder_from_table(table: dict, where: str):
    from .boulders import BoulderLayer

    allowed = {f.name for f in dataclasses.fields(BoulderLayer)}
    unknown = set(table) - allowed
    if unknown:
        raise ValueError(f"{where}: unknown boulder key(s) {', '.join(sorted(unknown))}; "
                         f"allowed: {', '.join(sorted(allowed))}")
    try:
        return BoulderLayer(**table)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{where}: {exc}") from None


def config_settings(path) -> dict:
    """Read a TOML scene file: keys are the option names with underscores."""
    raw = load_toml(path)
    out = {}
    where = f"config {str(path)!r}"
    for key, value in raw.items():
        if key not in _BY_KEY:
            allowed = ", ".join(sorted(_BY_KEY))
            raise ValueError(f"{where}: unknown key {key!r}; allowed: {allowed}")
        opt = _BY_KEY[key]
        try:
            if key == "craters":
                items = value if isinstance(value, list) else [value]
                value = [_layer_from_table(v, where) if isinstance(v, dict) else str(v)
                         for v in items]
            elif key == "boulders":
                items = value if isinstance(value, list) else [value]
                value = [_boulder_from_table(v, where) if isinstance(v, dict) else str(v)
                         for v in items]
            elif opt.action == "append":
                value = [value] if isinstance(value, str) else [str(v) for v in value]
            elif opt.action in ("store_true", "store_false"):
                if not isinstance(value, bool):
                    raise TypeError
            elif opt.parse is _stretch:
                value = _stretch(value)
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
        except (TypeError, argparse.ArgumentTypeError):
            raise ValueError(f"{where}: key {key!r} has a bad value {value!r} "
                             f"({opt.help})") from None
        out[key] = value
    return out


# --------------------------------------------------------------------------- checks
def _finite(key: str, value: float, *, positive: bool = False, nonneg: bool = False) -> float:
    if not math.isfinite(value):
        raise CliError(f"{flag(key)} must be finite; got {value!r}")
    if positive and value <= 0:
        raise CliError(f"{flag(key)} must be > 0; got {value!r}")
    if nonneg and value < 0:
        raise CliError(f"{flag(key)} must be >= 0; got {value!r}")
    return value


def _count(key: str, value: int, lo: int, hi: int) -> int:
    if not lo <= value <= hi:
        raise CliError(f"{flag(key)} must be an integer in [{lo}, {hi}]; got {value}")
    return value




def _check_memory(magnitude: int) -> None:
    need = LatLongGrid.estimate_bytes(magnitude, BYTES_PER_VERTEX)
    have = physical_memory_bytes()
    if need > 0.85 * have:
        n = 6 * magnitude * magnitude + 2
        raise CliError(
            f"--magnitude {magnitude} needs about {human_bytes(need)} of memory "
            f"({n:.3g} vertices x {BYTES_PER_VERTEX} B); this machine has {human_bytes(have)}"
        )


def check_render(s: dict) -> None:
    for key in ("sun_azimuth_deg", "sun_elevation_deg", "view_lon_deg", "view_lat_deg"):
        _finite(key, s[key])
    for key in ("sun_elevation_deg", "view_lat_deg"):
        if not -90 <= s[key] <= 90:
            raise CliError(f"{flag(key)} must be in [-90, 90]; got {s[key]}")
    if s.get("camera_distance_m") is not None:
        _finite("camera_distance_m", s["camera_distance_m"], positive=True)
    _count("width_px", s["width_px"], 16, 8192)
    _count("height_px", s["height_px"], 16, 8192)
    if s["views"] not in (1, 6):
        raise CliError(f"--views must be 1 or 6; got {s['views']}")


def resolve_settings(given: dict) -> dict:
    """Validate and complete scene settings (option defaults < preset < ``given``).

    Checks everything that can be checked before work starts, including the outputs.
    Raises ``CliError`` (a one-line message naming the option) on bad input.
    """
    unknown = set(given) - set(_BY_KEY)
    if unknown:
        raise CliError(f"unknown setting(s): {', '.join(sorted(unknown))}")
    backend = given.get("backend") or "latlong"
    if backend == "implicit":
        from .implicit_cli import resolve_implicit

        return resolve_implicit(given, {o.key: o.default for o in BUILD_OPTIONS})
    if backend != "latlong":
        raise CliError(f"--backend must be latlong or implicit; got {backend!r}")
    stray = [k for k, v in given.items() if v is not None and _BY_KEY[k].group == "implicit"
             and k != "backend"]
    if stray:
        raise CliError(f"{flag(stray[0])} applies to --backend implicit")
    preset = given.get("preset")
    if preset is not None and preset not in PRESETS:
        raise CliError(f"--preset must be one of {', '.join(PRESETS)}; got {preset!r}")
    base = given.get("base")
    shape_path = None
    if isinstance(base, str) and base.startswith("shape:"):
        shape_path, base = base[len("shape:"):], "shape"
        if preset is not None:
            raise CliError("--preset and --base shape:PATH cannot be combined")
        if not shape_path:
            raise CliError("--base shape:PATH needs a path after 'shape:'")
    elif base is not None and base not in BASES:
        raise CliError(f"--base must be one of {', '.join(BASES)} or shape:PATH; "
                       f"got {base!r}")
    if preset is not None and base is not None and PRESETS[preset].base != base:
        raise CliError(f"--preset {preset} has --base {PRESETS[preset].base}, not {base}")
    if preset is None:
        base = base or "fbm"
        preset = _DEFAULT_PRESET.get(base)
    p = PRESETS[preset] if preset else None
    base = p.base if p else base
    s = {o.key: o.default for o in BUILD_OPTIONS}
    if p:
        s.update(p.settings)
    s.update({k: v for k, v in given.items() if v is not None})
    s["preset"], s["base"] = preset, base
    _count("magnitude", s["magnitude"], 1, 10**9)
    _check_memory(s["magnitude"])
    allowed = {"faulting": ("faulting",), "fbm": ("fbm",), "sphere": (),
               "shape": ("fbm", "shape")}[base]
    for key, opt in _BY_KEY.items():
        if (opt.group in _BASE_GROUPS or opt.group == "shape") and opt.group not in allowed \
                and given.get(key) is not None:
            wanted = "shape:PATH" if opt.group == "shape" else opt.group
            raise CliError(f"{opt.flags[-1]} applies to --base {wanted}, not --base {base}")
    if base == "shape":
        return _resolve_shape(s, given, shape_path)
    _finite("radius_m", s["radius_m"], positive=True)
    if s["stretch"] is None:
        s["stretch"] = FAULTING_PRESETS[p.base_params].stretch if base == "faulting" else (
            1.0, 1.0, 1.0)
    s["stretch"] = tuple(float(v) for v in s["stretch"])
    if any(not math.isfinite(v) or v <= 0 for v in s["stretch"]):
        raise CliError(f"--stretch factors must be finite and > 0; got {s['stretch']}")
    _resolve_base_params(s, p)
    _resolve_craters_and_outputs(s)
    return s


def _resolve_base_params(s: dict, p) -> None:
    """Fill and check the faulting / fBm parameters of resolved settings."""
    base = s["base"]
    if base == "faulting":
        fp = FAULTING_PRESETS[p.base_params]
        fields = {"faults_1": "n_faults_1", "max_fault_1_m": "max_fault_1_m",
                  "smooth_width_m": "smooth_width_m", "smooth_passes": "smooth_passes",
                  "faults_2": "n_faults_2", "max_fault_2_m": "max_fault_2_m"}
        for key, field in fields.items():
            if s.get(key) is None:
                s[key] = getattr(fp, field)
        for key in ("faults_1", "faults_2"):
            _count(key, s[key], 0, 10**8)
        _count("smooth_passes", s["smooth_passes"], 0, 1000)
        for key in ("max_fault_1_m", "max_fault_2_m", "smooth_width_m"):
            _finite(key, s[key], nonneg=True)
    elif base == "fbm":
        fp = FBM_PRESETS[p.base_params] if p.base_params else FBM_PRESETS["fig5a"]
        for key in ("frequency", "octaves", "persistence", "lacunarity"):
            if s.get(key) is None:
                s[key] = getattr(fp, key)
        if s.get("amplitude_m") is None:
            frac = p.amplitude if p.amplitude is not None else fp.amplitude
            s["amplitude_m"] = frac * s["radius_m"]
        _check_fbm(s)


def _check_fbm(s: dict) -> None:
    _finite("frequency", s["frequency"], positive=True)
    _count("octaves", s["octaves"], 1, 30)
    _finite("persistence", s["persistence"], positive=True)
    _finite("lacunarity", s["lacunarity"])
    if s["lacunarity"] < 1:
        raise CliError(f"--lacunarity must be >= 1; got {s['lacunarity']!r}")
    _finite("amplitude_m", s["amplitude_m"], nonneg=True)


def _resolve_shape(s: dict, given: dict, path: str) -> dict:
    """Settings for --base shape:PATH: read and check the model up front."""
    from .shapes import read_shape_model

    for key in ("radius_m", "stretch"):
        if given.get(key) is not None:
            raise CliError(f"{flag(key)} does not apply to --base shape:PATH (the model "
                           "sets the size and shape)")
    units = s.get("shape_units")
    if units not in ("km", "m"):
        raise CliError(f"--shape-units must be km or m with --base shape:PATH; got {units!r}")
    crossings = s.get("shape_crossings") or "error"
    if crossings not in ("error", "outermost", "innermost"):
        raise CliError(f"--shape-crossings must be error, outermost or innermost; "
                       f"got {crossings!r}")
    smooth = s.get("shape_smooth") or "butterfly"
    if smooth not in ("butterfly", "linear", "loop", "none"):
        raise CliError(f"--shape-smooth must be butterfly, linear, loop or none; "
                       f"got {smooth!r}")
    center = s.get("shape_center") or "volume-centroid"
    if center not in ("volume-centroid", "area-centroid", "origin"):
        try:
            center = tuple(float(v) for v in center.split(","))
        except ValueError:
            center = ()
        if len(center) != 3 or not all(math.isfinite(v) for v in center):
            raise CliError("--shape-center must be volume-centroid, area-centroid, origin or "
                           f"X,Y,Z in metres; got {s.get('shape_center')!r}")
    try:
        model = read_shape_model(path, units=units)
    except ValueError as exc:
        raise CliError(f"--base shape:{path}: {exc}") from None
    volume = model.volume_m3
    s.update(shape_path=path, shape_units=units, shape_crossings=crossings,
             shape_smooth=smooth, shape_center=center, stretch=(1.0, 1.0, 1.0),
             radius_m=(3.0 * volume / (4.0 * math.pi)) ** (1.0 / 3.0),
             shape_resolution_m=model.mean_edge_m)
    # fBm detail below the model's resolution: off unless an amplitude is given
    detail = {"frequency": s["radius_m"] / model.mean_edge_m, "octaves": 6,
              "persistence": 0.5, "lacunarity": 2.0, "amplitude_m": 0.0}
    for key, value in detail.items():
        if s.get(key) is None:
            s[key] = value
    _check_fbm(s)
    _resolve_craters_and_outputs(s)
    for la in s["craters"]:
        if la.d_max_m > 2.0 * model.mean_edge_m:
            raise CliError(
                f"--craters dmax={la.d_max_m:g} m is above the shape model's resolution "
                f"(mean edge {model.mean_edge_m:.3g} m): the model already holds craters "
                f"that large; keep crater layers below {2 * model.mean_edge_m:.3g} m")
    return s


def _resolve_boulders(s: dict) -> None:
    """Boulder layers and shape."""
    from .boulders import BoulderLayer, BoulderShape, parse_boulder_spec

    layers = []
    for item in s.get("boulders") or []:
        if isinstance(item, BoulderLayer):
            layers.append(item)
            continue
        try:
            layers.append(parse_boulder_spec(item))
        except ValueError as exc:
            raise CliError(f"--boulders: {exc}") from None
    s["boulders"] = layers
    try:
        s["boulder_shape"] = BoulderShape(flatten=s["boulder_flatten"],
                                          elongation=s["boulder_elongation"],
                                          roughness=s["boulder_roughness"])
    except (TypeError, ValueError) as exc:
        raise CliError(f"boulder shape: {exc}") from None
    for la in layers:
        if la.d_max_m > 0.2 * s["radius_m"] * min(s["stretch"] or (1.0,)):
            raise CliError(f"--boulders dmax={la.d_max_m:g} m: boulders larger than a fifth "
                           "of the body's radius are not boulders")


def _resolve_craters_and_outputs(s: dict) -> None:
    """Crater layers, render and output checks shared by every base."""
    # craters
    layers = []
    for item in s.get("craters") or []:
        if isinstance(item, _craters.CraterLayer):
            layers.append(item)
            continue
        try:
            layers.append(_craters.parse_layer_spec(item))
        except ValueError as exc:
            raise CliError(f"--craters: {exc}") from None
    s["craters"] = layers
    if s["crater_morphometry"] not in _craters.MORPHOMETRY_PRESETS:
        names = ", ".join(_craters.MORPHOMETRY_PRESETS)
        raise CliError(f"--crater-morphometry must be one of {names}; "
                       f"got {s['crater_morphometry']!r}")
    _finite("crater_lifetime_gyr", s["crater_lifetime_gyr"], positive=True)
    _finite("max_crater_extent_deg", s["max_crater_extent_deg"], positive=True)
    if s["max_crater_extent_deg"] > 180:
        raise CliError(f"--max-crater-extent-deg must be <= 180; got "
                       f"{s['max_crater_extent_deg']}")
    for la in layers:
        # a crater's ejecta spans 3 D: refuse layers that do not fit on the reference body
        # (the few craters that land where the surface is lower are skipped and counted)
        smallest = s["radius_m"] * min(s["stretch"])
        span = math.degrees(3.0 * la.d_max_m * 1.02 / smallest)
        if span > s["max_crater_extent_deg"]:
            raise CliError(f"--craters dmax={la.d_max_m:g} m: the crater (ejecta "
                           f"{3 * la.d_max_m:g} m across) is larger than the body allows "
                           f"(radius {smallest:g} m, limit {s['max_crater_extent_deg']:g} deg)")
    _resolve_boulders(s)
    check_render(s)
    if s.get("catalog") and not layers:
        raise CliError("--catalog needs crater layers (--craters or a cratered --preset)")
    if s.get("boulder_catalog") and not s["boulders"]:
        raise CliError("--boulder-catalog needs boulder layers (--boulders)")
    check_outputs(s, OUTPUT_SUFFIXES, ("preview", "catalog", "boulder_catalog"))
    if s.get("seed") is None:
        s["seed"] = int(np.random.SeedSequence().entropy % (2**63))


def check_outputs(s: dict, suffixes: tuple[str, ...], extra_keys: tuple[str, ...]) -> None:
    """Check the ``-o`` outputs (by ``suffixes``) and the single-file outputs named by
    ``extra_keys`` (``preview`` a .png, the others .csv): something to write, no file
    twice, folders writable, nothing overwritten without --force. Normalises
    ``s["output"]`` to a list of strings."""
    outputs = [Path(x) for x in (s.get("output") or [])]
    s["output"] = [str(x) for x in outputs]
    extras = {k: Path(s[k]) for k in extra_keys if s.get(k)}
    if not outputs and not extras:
        raise CliError("nothing to write: give -o/--output, --catalog or --preview")
    seen = set()
    for x in [*outputs, *extras.values()]:
        key = x.resolve()
        if key in seen:
            raise CliError(f"output {str(x)!r} is given twice")
        seen.add(key)
    try:
        for x in outputs:
            check_output_path(x, force=s["force"], suffixes=suffixes)
        for k, x in extras.items():
            check_output_path(x, force=s["force"], suffixes=(".png",) if k == "preview"
                              else (".csv",))
    except ValueError as exc:
        raise CliError(str(exc)) from None


# --------------------------------------------------------------------------- populations
def _triangle_areas(body: Body, band_lo: int, band_hi: int):
    """Triangles of bands band_lo..band_hi-1 and their actual areas (m^2)."""
    t = body.grid.band_triangles(band_lo, band_hi)
    v0, v1 = int(t.min()), int(t.max()) + 1
    p = body.vertices(v0, v1)[t - v0]
    return t, 0.5 * np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1)


def _band_totals(body: Body) -> np.ndarray:
    """Actual surface area of every band (m^2), streamed a few bands at a time."""
    n_bands = 2 * body.grid.magnitude
    totals = np.empty(n_bands)
    step = max(1, n_bands // 64)
    for lo in range(0, n_bands, step):
        hi = min(lo + step, n_bands)
        t, a = _triangle_areas(body, lo, hi)
        bo = body.grid.band_offsets()
        totals[lo:hi] = np.add.reduceat(a, bo[lo:hi] - bo[lo])
    return totals


def surface_positions(body: Body, n: int, *, rng=None) -> tuple[np.ndarray, np.ndarray, float]:
    """``n`` points uniform on the body's actual surface, as grid (lat_deg, lon_deg).

    Triangles are chosen with probability proportional to their area (a band first, then
    a triangle of it: nothing holds the whole triangulation) and a uniform point is taken
    inside; the point's direction in the unstretched frame gives the grid
    latitude/longitude. Returns (lat_deg, lon_deg, total area in m^2).
    """
    return _sample_surface(body, _band_totals(body), n, normalize_rng(rng))


def _sample_surface(body, totals, n, rng):
    cum = np.cumsum(totals)
    total = float(cum[-1])
    u = rng.random(n) * total
    a, b = rng.random(n), rng.random(n)
    flip = a + b > 1
    a[flip], b[flip] = 1 - a[flip], 1 - b[flip]
    band = np.minimum(np.searchsorted(cum, u, side="right"), len(cum) - 1)
    resid = u - np.concatenate([[0.0], cum[:-1]])[band]
    p = np.empty((n, 3))
    order = np.argsort(band, kind="stable")
    starts = np.searchsorted(band[order], np.arange(len(totals) + 1))
    for bnd in np.flatnonzero(np.diff(starts)):
        sel = order[starts[bnd]:starts[bnd + 1]]
        t, area = _triangle_areas(body, int(bnd), int(bnd) + 1)
        k = np.minimum(np.searchsorted(np.cumsum(area), resid[sel], side="right"), len(t) - 1)
        tri = t[k]
        v = body.vertices(int(tri.min()), int(tri.max()) + 1)
        v0, v1, v2 = (v[tri[:, c] - tri.min()] for c in range(3))
        p[sel] = v0 + a[sel, None] * (v1 - v0) + b[sel, None] * (v2 - v0)
    q = p / np.asarray(body.stretch)
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    lat = np.degrees(np.arcsin(np.clip(q[:, 2], -1, 1)))
    lon = np.mod(np.degrees(np.arctan2(q[:, 1], q[:, 0])), 360.0)
    return lat, lon, total


def body_population(body: Body, layers, *, rng=None, degradation_kwargs=None) -> np.ndarray:
    """A crater catalog for ``body``: counts from its actual surface area, positions
    uniform on its actual surface (:func:`surface_positions`), oldest first."""
    rng = normalize_rng(rng)
    totals = _band_totals(body)
    cat = _craters.population(layers, area_m2=float(totals.sum()), rng=rng,
                              degradation_kwargs=degradation_kwargs)
    lat, lon, _ = _sample_surface(body, totals, len(cat), rng)
    cat["lat_deg"], cat["lon_deg"] = lat, lon
    return cat


# --------------------------------------------------------------------------- build
def build_body(s: dict, *, progress: bool = False) -> Body:
    """Make the body described by resolved settings ``s`` (base shape, then craters)."""
    from .cratering import stamp_craters

    grid = LatLongGrid(s["magnitude"])
    rng = np.random.default_rng(s["seed"])
    base = s["base"]
    shape_meta = None
    if base == "shape":
        from .shapes import from_shape_model, read_shape_model

        model = read_shape_model(s["shape_path"], units=s["shape_units"])
        shaped = from_shape_model(model, s["magnitude"], center=s["shape_center"],
                                  crossings=s["shape_crossings"], smooth=s["shape_smooth"])
        shape_meta = shaped.metadata
        s["radius_m"] = shaped.radius_m
        detail = perlin_fbm(grid, s["frequency"], s["octaves"], s["persistence"],
                            s["lacunarity"], s["amplitude_m"], rng=rng) if s["amplitude_m"] else 0.0
        heights = shaped.radii_m - shaped.radius_m + detail
        params = {k: s[k] for k in ("frequency", "octaves", "persistence", "lacunarity",
                                    "amplitude_m")}
        params["shape"] = shape_meta
    elif base == "sphere":
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
    layers = s["craters"]
    metadata = {
        "generator": "craterform latlong build",
        "version": package_version(),
        "seed": s["seed"],
        "base": base,
        "preset": s["preset"],
        "parameters": params,
        "craters": [dataclasses.asdict(la) for la in layers],
        "crater_morphometry": s["crater_morphometry"],
        "crater_lifetime_gyr": s["crater_lifetime_gyr"],
        "crater_roughness": s["crater_roughness"],
        "boulders": [dataclasses.asdict(la) for la in s.get("boulders") or []],
        "boulder_shape": dataclasses.asdict(s["boulder_shape"]) if s.get("boulders") else None,
    }
    body = Body.from_heights(grid, s["radius_m"], heights, stretch=s["stretch"],
                             metadata=metadata)
    if layers:
        cat = body_population(body, layers, rng=rng, degradation_kwargs={
            "baseline_lifetime_gyr": s["crater_lifetime_gyr"]})
        body = stamp_craters(body, cat, roughness=s["crater_roughness"], rng=rng,
                             progress=progress, max_extent_deg=s["max_crater_extent_deg"],
                             morphometry=s["crater_morphometry"], too_large="skip")
        body = body.replace(metadata={**body.metadata,
                                      "craters_skipped_too_large": len(cat) - len(body.craters)})
    if s.get("boulders"):
        from .boulders import boulder_population, place_boulders

        found = boulder_population(body, s["boulders"], rng=rng)
        body = body.replace(boulders=place_boulders(body, found, shape=s["boulder_shape"]))
    return body


def write_outputs(body: Body, s: dict, *, progress: bool = False, on_written=None) -> None:
    """Write the outputs of resolved settings ``s`` (meshes, catalog, preview)."""
    for out in s["output"]:
        if out.lower().endswith(".npz"):
            body.save(out)
        elif out.lower().endswith(".glb"):
            from .gltf import export_glb

            export_glb(body, out, progress=progress)
        else:
            body.export(out, progress=progress)
        if on_written:
            on_written(out)
    if s.get("catalog"):
        _craters.write_catalog(body.craters, s["catalog"])
        if on_written:
            on_written(s["catalog"])
    if s.get("boulder_catalog"):
        _craters.write_catalog(body.boulders, s["boulder_catalog"])
        if on_written:
            on_written(s["boulder_catalog"])
    if s.get("preview"):
        from .preview import render_from_settings

        render_from_settings(body, s["preview"], s)
        if on_written:
            on_written(s["preview"])
