"""The one option table of ``latlong build`` / ``render``: it drives the flags, the TOML
keys of a scene file, the help texts (with every default) and the flag shown in a
message about a setting.

Scene options are the settings of :meth:`latlong.Scene.from_settings` (same names with
underscores); run options (outputs, ``--force``, ``--quiet``) are the command's own.
"""

from __future__ import annotations

import argparse
from dataclasses import dataclass
from typing import Any

from craters._shared import ParameterError, ParameterTypeError, load_toml, physical_memory_bytes
from craters.cli.kit import CliError, parse_seed
from latlong import SETTING_DEFAULTS

from ..settings import MEMORY_SHARE

__all__ = ["BUILD_OPTIONS", "OUTPUT_KEYS", "RENDER_OPTIONS", "Opt", "add_options",
           "flag_of", "given_options", "read_config", "shown"]


@dataclass(frozen=True)
class Opt:
    """One option: flags, key (the setting / TOML key), argparse type, help, group, action."""

    flags: tuple[str, ...]
    key: str
    parse: Any
    help: str
    group: str = "body"
    action: str = "store"

    @property
    def flag(self) -> str:
        return self.flags[-1]


def _stretch(text) -> tuple[float, float, float]:
    parts = str(text).split(",")
    try:
        vals = tuple(float(p) for p in parts)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected X,Y,Z factors; got {text!r}") from None
    if len(vals) != 3:
        raise argparse.ArgumentTypeError(f"expected three factors X,Y,Z; got {text!r}")
    return vals


RENDER_OPTIONS: tuple[Opt, ...] = (
    Opt(("--sun-azimuth-deg",), "sun_azimuth_deg", float,
        "sun azimuth from the viewer, degrees (0 = behind the camera, 90 = from the right)",
        "render"),
    Opt(("--sun-elevation-deg",), "sun_elevation_deg", float,
        "sun elevation above the picture's horizontal plane, degrees", "render"),
    Opt(("--view-lon-deg",), "view_lon_deg", float,
        "longitude of the camera direction (body-fixed), degrees", "render"),
    Opt(("--view-lat-deg",), "view_lat_deg", float,
        "latitude of the camera direction, degrees", "render"),
    Opt(("--camera-distance-m",), "camera_distance_m", float,
        "camera distance from the body centre, metres (default: frame the body)", "render"),
    Opt(("--width-px",), "width_px", int, "picture width, pixels", "render"),
    Opt(("--height-px",), "height_px", int, "picture height, pixels", "render"),
    Opt(("--views",), "views", int,
        "1 = one view; 6 = a contact sheet from +x, -x, +y, -y, +z, -z", "render"),
)

OUTPUT_SUFFIXES = (".npz", ".ply", ".obj", ".stl", ".vtp", ".vtk", ".glb")

BUILD_OPTIONS: tuple[Opt, ...] = (
    Opt(("--preset",), "preset", str,
        "named scene (see `latlong presets`): sets the base and its parameters, the body "
        "and crater layers"),
    Opt(("--magnitude",), "magnitude", int, "grid magnitude M >= 1 (6M^2+2 vertices)"),
    Opt(("--max-memory-gb",), "max_memory_gb", float,
        "memory the build may use, GB (1e9 bytes): a --magnitude whose estimate (radii and "
        "bounded buffers, written as .npz) is larger is refused up front, or built with "
        "its radii on disk (--radii-on-disk auto)"),
    Opt(("--radii-on-disk",), "radii_on_disk", str,
        "keep the body's radii in a memory-mapped scratch file beside the first output "
        "(bodies bigger than memory; the same bytes): auto = when the in-memory estimate "
        "exceeds --max-memory-gb (sphere and fbm bases), yes, no"),
    Opt(("--radius-m",), "radius_m", float, "reference radius in metres"),
    Opt(("--stretch",), "stretch", _stretch,
        "scale factors X,Y,Z applied to the body (e.g. 2,1,1; the faulting presets "
        "stretch 2,1,1)"),
    Opt(("--base",), "base", str,
        "base shape: sphere, faulting, fbm or shape:PATH (a real shape model: OBJ, PDS "
        "plate .tab/.plt, PLY, STL)"),
    Opt(("--body",), "body", str,
        "what kind of body the craters are on (morphology, transition diameters, "
        "diffusivity): small-body (gravity from the size and --density-kg-m3) or moon, "
        "mars, mercury, earth, ceres, vesta"),
    Opt(("--gravity-m-s2",), "gravity_m_s2", float,
        "surface gravity, m/s^2: crater transition diameters scale as 1/g (default: the "
        "body's)"),
    Opt(("--density-kg-m3",), "density_kg_m3", float,
        "bulk density of a small body, kg/m^3 (its gravity from its size)"),
    Opt(("--crater-depth-ratio",), "crater_depth_ratio", float,
        "fresh crater depth/diameter on a small body, 0.01-0.5 (default: 0.2, Marchi et al. "
        "2015; Bennu's measured 0.10)"),
    Opt(("--seed",), "seed", parse_seed,
        "random seed (non-negative integer); default: a fresh one, recorded in the model"),
    # two-phase faulting
    Opt(("--faults-1",), "faults_1", int, "phase-1 fault count", "faulting"),
    Opt(("--max-fault-1-m",), "max_fault_1_m", float,
        "largest phase-1 fault offset, metres", "faulting"),
    Opt(("--smooth-width-m",), "smooth_width_m", float,
        "smoothing filter width (Gaussian FWHM) in metres", "faulting"),
    Opt(("--smooth-passes",), "smooth_passes", int, "smoothing passes", "faulting"),
    Opt(("--faults-2",), "faults_2", int, "phase-2 fault count", "faulting"),
    Opt(("--max-fault-2-m",), "max_fault_2_m", float,
        "largest phase-2 fault offset, metres", "faulting"),
    # shape models
    Opt(("--shape-units",), "shape_units", str,
        "units of the shape model file: km or m (required with --base shape:PATH and "
        "--backend implicit)", "shape"),
    Opt(("--shape-center",), "shape_center", str,
        "ray origin: volume-centroid, area-centroid, origin or X,Y,Z in metres", "shape"),
    Opt(("--shape-crossings",), "shape_crossings", str,
        "where a ray crosses the surface more than once: error, outermost, innermost",
        "shape"),
    Opt(("--shape-smooth",), "shape_smooth", str,
        "subdivision before casting: butterfly (interpolating), linear (keep the facets), "
        "loop, none (--surface mesh: butterfly or linear)", "shape"),
    Opt(("--surface",), "surface", str,
        "where a shape model is cratered: latlong (ray-cast onto the lat/long grid; the "
        "model must be star-shaped from its centre) or mesh (its own refined triangle "
        "mesh: any closed shape, e.g. Itokawa; outputs .ply .obj .stl .vtp .vtk .glb)",
        "shape"),
    Opt(("--spacing-m",), "spacing_m", float,
        "mean edge of the refined mesh with --surface mesh, metres", "shape"),
    # fBm
    Opt(("--frequency",), "frequency", float,
        "first-octave frequency on the unit sphere (with a shape base: fBm detail, "
        "default wavelength = the model's resolution)", "fbm"),
    Opt(("--octaves",), "octaves", int, "number of octaves", "fbm"),
    Opt(("--persistence",), "persistence", float, "amplitude ratio per octave", "fbm"),
    Opt(("--lacunarity",), "lacunarity", float, "frequency ratio per octave (>= 1)", "fbm"),
    Opt(("--amplitude-m",), "amplitude_m", float,
        "fBm height scale in metres (default: the preset's fraction of the radius; 0 on a "
        "shape base)", "fbm"),
    # craters
    Opt(("--craters",), "craters", str,
        "crater layer: a power law c=0.5,k=-2,d_min_m=2,d_max_m=50[,age_min_gyr=0,"
        "age_max_gyr=3.5,degradation=0.2,kind=mare] (the fields of craters.CraterLayer): "
        "N_cum = c D^k per m^2, D in metres, ages in Gyr; or a model age npf=moon,age_gyr="
        "3.8,d_min_m=100,d_max_m=5000[,equilibrium=trask|hartmann,degradation,kind] "
        "(craters.ModelAgeLayer: the body's production function and chronology, npf one "
        "of craters.CHRONOLOGY_SYSTEMS) (repeatable)", "craters", "append"),
    Opt(("--no-crater-roughness",), "crater_roughness", bool,
        "ideal craters: no fractal overlay, circular rims", "craters", "store_false"),
    Opt(("--max-crater-extent-deg",), "max_crater_extent_deg", float,
        "largest angular size of a crater's ejecta blanket, degrees of arc", "craters"),
    # boulders
    Opt(("--boulders",), "boulders", str,
        "boulder layer c=0.05,k=-3,d_min_m=0.5,d_max_m=10[,burial_max=0.5,near=0.3] (the "
        "fields of craters.BoulderLayer): N_cum = c D^k per m^2, D in metres; burial_max = "
        "largest buried fraction of the height (<= 0.9); near = share around crater rims "
        "(repeatable)", "boulders", "append"),
    Opt(("--boulder-flatten",), "boulder_flatten", float,
        "boulder up-axis scale relative to its width", "boulders"),
    Opt(("--boulder-elongation",), "boulder_elongation", float,
        "boulder length relative to its width", "boulders"),
    Opt(("--boulder-roughness",), "boulder_roughness", float,
        "boulder midpoint-displacement amplitude (fraction of the edge length)", "boulders"),
    # the implicit backend
    Opt(("--backend",), "backend", str,
        "latlong (the lat/long mesh) or implicit (Li et al.: metaballs over a sphere "
        "packing of --shape, LCSN craters, Gabor detail, marching cubes)", "implicit"),
    Opt(("--shape",), "shape", str,
        "constraint mesh of --backend implicit (OBJ, PDS plate .tab/.plt, PLY, STL, VTK; "
        "units from --shape-units)", "implicit"),
    Opt(("--polygons",), "polygons", int,
        "about how many triangles the implicit mesh has", "implicit"),
    Opt(("--voxel-m",), "voxel_m", float,
        "marching-cubes spacing, metres (instead of --polygons)", "implicit"),
    Opt(("--packing-voxels",), "packing_voxels", int,
        "voxels along the constraint's longest side for the sphere packing", "implicit"),
    Opt(("--min-sphere-m",), "min_sphere_m", float,
        "smallest packed sphere, metres (default 2 packing voxels)", "implicit"),
    Opt(("--constraint-weight",), "constraint_weight", float,
        "weight in [0, 1] of the constraint's own signed distance in the coarse field: 1 "
        "follows the constraint (smooth where it is smooth), 0 the bare metaballs over the "
        "packing (one dome per ball)", "implicit"),
    Opt(("--cell-m",), "cell_m", float,
        "cell size of grid level 0, metres (default: the largest d_max_m)", "implicit"),
    Opt(("--lcsn",), "lcsn", str,
        "LCSN crater layer kernel=NAME,d_min_m=M,d_max_m=M[,exponent=3,probability=0.5,"
        "weight=1,depth_ratio=LO:HI] (the fields of latlong.LcsnLayer): NAME of "
        "craters.LCSN_PRESETS scaled to D in [d_min_m, d_max_m] (metres), N(>D) ~ "
        "D^-exponent, probability = impulse chance per surface cell, depth_ratio = "
        "depth/diameter (repeatable)", "implicit", "append"),
    Opt(("--gabor",), "gabor", str,
        "Gabor micro-detail frequency=CYCLES_PER_M,bandwidth=PER_M,amplitude_m=RMS_M"
        "[,orientation_deg=DEG,density=N]", "implicit"),
    Opt(("--gabor-example",), "gabor_example", str,
        "fit the Gabor noise to an example (.npy heights in metres, or a .png/.jpg/.tif "
        "picture)", "implicit"),
    Opt(("--gabor-pixel-m",), "gabor_pixel_m", float,
        "pixel size of --gabor-example on the body, metres", "implicit"),
    Opt(("--gabor-amplitude-m",), "gabor_amplitude_m", float,
        "rms of the fitted Gabor noise, metres (default: the .npy example's)", "implicit"),
    # outputs (run options: not part of the scene)
    Opt(("-o", "--output"), "output", str,
        "output file, format by suffix: " + " ".join(OUTPUT_SUFFIXES) + " (repeatable; .glb "
        "is the patched strip export with its .json manifest, full resolution only - "
        "`latlong export` adds levels of detail)",
        "output", "append"),
    Opt(("--catalog",), "catalog", str,
        "write the ground-truth crater catalog as stamped: .csv, or .scc (craterstats "
        "spatial crater count: the body's area in km^2, diameters in km, lon/lat)", "output"),
    Opt(("--catalog-columns",), "catalog_columns", str,
        "column names of a CSV --catalog: craterform (units in the names) or robbins "
        "(LAT_CIRC_IMG, LON_CIRC_IMG, DIAM_CIRC_IMG in km, as the Robbins 2019 lunar "
        "crater database)", "output"),
    Opt(("--boulder-catalog",), "boulder_catalog", str,
        "write the boulder catalog as placed (CSV)", "output"),
    Opt(("--preview",), "preview", str, "write a preview picture (PNG)", "output"),
    *RENDER_OPTIONS,
    Opt(("-q", "--quiet"), "quiet", bool, "no progress bars or messages", "output",
        "store_true"),
    Opt(("--force",), "force", bool, "overwrite existing outputs", "output", "store_true"),
)
#: Run options of ``latlong build``: what to write and how, not what to make.
OUTPUT_KEYS = ("output", "catalog", "boulder_catalog", "preview", "quiet", "force",
               "catalog_columns")
_BY_KEY = {o.key: o for o in BUILD_OPTIONS}


def flag_of(key: str) -> str:
    """The flag of a setting or run option (the key itself if it has none)."""
    opt = _BY_KEY.get(key)
    return opt.flag if opt else f"`{key}`"


def _default_text(opt: Opt) -> str:
    if opt.action == "store_true":
        return "off"
    if opt.action == "store_false":
        return "on"
    if opt.key in OUTPUT_KEYS or opt.key in ("seed", "preset", "base"):
        return {"base": "fbm (preset fig5a)", "catalog_columns": "craterform"}.get(opt.key,
                                                                                  "none")
    value = SETTING_DEFAULTS.get(opt.key)
    if value is None:
        if opt.key == "spacing_m":
            return "the lat/long spacing at --magnitude, (pi/2) R / M"
        if opt.key == "max_memory_gb":
            have = physical_memory_bytes()
            return (f"{MEMORY_SHARE:g} x this machine's memory, "
                    f"{MEMORY_SHARE * have / 1e9:.3g} GB")
        return "the preset's / base's" if opt.group in ("faulting", "fbm", "body") else "none"
    if isinstance(value, tuple):
        return ",".join(f"{v:g}" if isinstance(v, float) else str(v) for v in value) or "none"
    return str(value)


def add_options(groups: dict, options) -> None:
    """Add ``options`` to the argparse groups (by ``Opt.group``); every help shows the
    default. Nothing given stays None (the scene's defaults and presets then apply)."""
    for opt in options:
        kw: dict = {"dest": opt.key, "help": f"{opt.help} (default: {_default_text(opt)})"}
        if opt.action in ("store_true", "store_false"):
            kw.update(action=opt.action, default=opt.action == "store_false")
        else:
            kw.update(type=opt.parse, default=None)
            if opt.action == "append":
                kw["action"] = "append"
        groups[opt.group].add_argument(*opt.flags, **kw)


def given_options(args: argparse.Namespace, options) -> dict:
    """The options given on the command line (switches only when switched)."""
    out = {}
    for opt in options:
        value = getattr(args, opt.key, None)
        if value is None or (opt.action == "store_true" and value is False) or (
                opt.action == "store_false" and value is True):
            continue
        out[opt.key] = value
    return out


def read_config(path) -> dict:
    """The keys of a TOML scene file (the option keys); run options type-checked here,
    scene settings by :meth:`latlong.Scene.from_settings`."""
    raw = load_toml(path)
    where = f"config {str(path)!r}"
    for key, value in raw.items():
        opt = _BY_KEY.get(key)
        if opt is None:
            raise CliError(f"{where}: unknown key {key!r}; allowed: "
                           f"{', '.join(sorted(_BY_KEY))}")
        if key in ("quiet", "force") and not isinstance(value, bool):
            raise CliError(f"{where}: key {key!r} must be true or false; got {value!r}")
        if key == "output":
            value = [value] if isinstance(value, str) else value
            if not isinstance(value, list) or not all(isinstance(v, str) for v in value):
                raise CliError(f"{where}: key 'output' must be a file name or a list of "
                               f"them; got {value!r}")
            raw[key] = value
        elif key in (*OUTPUT_KEYS[1:4], "catalog_columns") and not isinstance(value, str):
            raise CliError(f"{where}: key {key!r} must be a file name; got {value!r}")
    return raw


def shown(exc: Exception, from_file: set[str], config) -> str:
    """A one-line message for a setting's error: under its flag, or under the config
    file's key when the value came from the file."""
    if isinstance(exc, ParameterError | ParameterTypeError):
        def name_of(key):
            return f"key {key!r}" if key in from_file else flag_of(key)

        if exc.name in from_file:
            return exc.shown_as(f"config {str(config)!r}: key {exc.name!r}", name_of)
        if exc.name in _BY_KEY:
            return exc.shown_as(flag_of(exc.name), name_of)
    return str(exc)
