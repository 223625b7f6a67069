"""``latlong build --backend implicit``: settings, build and outputs of the implicit backend.

:func:`latlong.scene.resolve_settings` hands settings with ``backend = "implicit"`` to
:func:`resolve_implicit` and the ``build`` command hands the result to
:func:`run_implicit`. Everything is checked before any work: the constraint is read,
the crater layers and the Gabor noise are parsed, the outputs are checked. Outputs by
suffix: meshes (``.ply .obj .stl .vtp .vtk``), ``.npz`` (the mesh cast onto a
lat/long grid of ``--magnitude`` from the constraint's centroid; star-shaped results
only unless ``--shape-crossings outermost|innermost``, checked before anything is
written), ``--catalog`` CSV, ``--preview`` PNG.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from craters._shared import package_version
from craters._shared.cli import CliError

from .implicit import MESH_SUFFIXES

__all__ = ["IMPLICIT_KEYS", "resolve_implicit", "run_implicit"]

#: Scene keys the implicit backend reads (besides the render and output keys).
IMPLICIT_KEYS = ("backend", "shape", "shape_units", "polygons", "voxel_m", "packing_voxels",
                 "min_sphere_m", "cell_m", "lcsn", "gabor", "gabor_example", "gabor_pixel_m",
                 "gabor_amplitude_m", "magnitude", "shape_crossings", "seed")
_OUTPUT_KEYS = ("output", "catalog", "preview", "quiet", "force")
OUTPUT_SUFFIXES = (*MESH_SUFFIXES, ".npz")
_DEFAULTS = {"polygons": 200_000, "packing_voxels": 128}
#: Library parameter names in error messages -> the build options that set them.
_OPTION_NAMES = {"`n_voxels`": "--packing-voxels", "`voxel_m`": "--voxel-m",
                 "`target_polygons`": "--polygons", "`cell_m`": "--cell-m",
                 "`min_radius_m`": "--min-sphere-m"}


def _flag(key: str) -> str:
    from .scene import flag

    return flag(key)


def _positive(s: dict, key: str) -> None:
    value = s.get(key)
    if value is not None and not (math.isfinite(value) and value > 0):
        raise CliError(f"{_flag(key)} must be finite and > 0; got {value!r}")


def _gabor(s: dict):
    from .implicit import fit_gabor, parse_gabor_spec, read_example

    if s.get("gabor") and s.get("gabor_example"):
        raise CliError("give either --gabor or --gabor-example, not both")
    if s.get("gabor"):
        for key in ("gabor_pixel_m", "gabor_amplitude_m"):
            if s.get(key) is not None:
                raise CliError(f"{_flag(key)} applies to --gabor-example")
        try:
            return parse_gabor_spec(s["gabor"])
        except ValueError as exc:
            raise CliError(f"--gabor: {exc}") from None
    if not s.get("gabor_example"):
        for key in ("gabor_pixel_m", "gabor_amplitude_m"):
            if s.get(key) is not None:
                raise CliError(f"{_flag(key)} applies to --gabor-example")
        return None
    if s.get("gabor_pixel_m") is None:
        raise CliError("--gabor-example needs --gabor-pixel-m (the example's pixel size on "
                       "the body, metres)")
    _positive(s, "gabor_pixel_m")
    if s.get("gabor_amplitude_m") is not None and not (
            math.isfinite(s["gabor_amplitude_m"]) and s["gabor_amplitude_m"] >= 0):
        raise CliError(f"--gabor-amplitude-m must be finite and >= 0; got "
                       f"{s['gabor_amplitude_m']!r}")
    try:
        image, is_heights = read_example(s["gabor_example"])
        if not is_heights and s.get("gabor_amplitude_m") is None:
            raise CliError("--gabor-example is a picture (grey levels, not metres): give "
                           "--gabor-amplitude-m")
        return fit_gabor(image, s["gabor_pixel_m"], amplitude_m=s.get("gabor_amplitude_m"))
    except ValueError as exc:
        raise CliError(f"--gabor-example {s['gabor_example']}: {exc}") from None


def resolve_implicit(given: dict, defaults: dict) -> dict:
    """Validate and complete the settings of ``--backend implicit`` (``defaults``: the
    option defaults of the build command). Raises CliError naming the option."""
    from .implicit import parse_lcsn_spec
    from .scene import RENDER_OPTIONS, check_outputs, check_render
    from .shapes import read_shape_model

    allowed = set(IMPLICIT_KEYS) | set(_OUTPUT_KEYS)
    render = {o.key for o in RENDER_OPTIONS}
    for key, value in given.items():
        if value is not None and key not in allowed | render:
            raise CliError(f"{_flag(key)} does not apply to --backend implicit")
    s = {k: defaults[k] for k in (*IMPLICIT_KEYS, *_OUTPUT_KEYS, *render) if k in defaults}
    s.update({k: v for k, v in _DEFAULTS.items()})
    s.update({k: v for k, v in given.items() if v is not None})
    if not s.get("shape"):
        raise CliError("--backend implicit needs --shape FILE (the constraint mesh)")
    if s.get("shape_units") not in ("km", "m"):
        raise CliError(f"--shape-units must be km or m with --backend implicit; got "
                       f"{s.get('shape_units')!r}")
    try:
        model = read_shape_model(s["shape"], units=s["shape_units"])
    except ValueError as exc:
        raise CliError(f"--shape {s['shape']}: {exc}") from None
    s["_constraint"] = model
    if not 100 <= s["polygons"] <= 10**9:
        raise CliError(f"--polygons must be an integer in [100, 1000000000]; got {s['polygons']}")
    if not 8 <= s["packing_voxels"] <= 1024:
        raise CliError(f"--packing-voxels must be an integer in [8, 1024]; got "
                       f"{s['packing_voxels']}")
    for key in ("voxel_m", "min_sphere_m", "cell_m"):
        _positive(s, key)
    s["shape_crossings"] = s.get("shape_crossings") or "error"
    if s["shape_crossings"] not in ("error", "outermost", "innermost"):
        raise CliError(f"--shape-crossings must be error, outermost or innermost; got "
                       f"{s['shape_crossings']!r}")
    layers = []
    for spec in s.get("lcsn") or []:
        try:
            layers.append(parse_lcsn_spec(spec))
        except ValueError as exc:
            raise CliError(f"--lcsn: {exc}") from None
    s["_layers"] = layers
    if layers and s.get("cell_m") is not None:
        biggest = max(la.d_max_m for la in layers)
        if s["cell_m"] < biggest:
            raise CliError(f"--cell-m {s['cell_m']:g} is smaller than the largest crater "
                           f"(dmax {biggest:g} m): level-0 cells must hold it")
    s["_gabor"] = _gabor(s)
    check_render(s)
    check_outputs(s, OUTPUT_SUFFIXES, ("preview", "catalog"))
    if any(Path(x).suffix.lower() == ".npz" for x in s["output"]):
        from .scene import _check_memory, _count

        _count("magnitude", s["magnitude"], 1, 10**9)
        _check_memory(s["magnitude"])
    if s.get("seed") is None:
        s["seed"] = int(np.random.SeedSequence().entropy % (2**63))
    return s


def run_implicit(s: dict) -> int:
    """Build the implicit body of resolved settings and write its outputs."""
    from craters import write_catalog
    from craters._shared import progress_bar

    from .implicit import implicit_surface
    from .scene import human_bytes

    show = not s["quiet"]
    try:
        surf = implicit_surface(s["_constraint"], s["_layers"], gabor=s["_gabor"],
                                voxel_m=s.get("voxel_m"), target_polygons=s["polygons"],
                                cell_m=s.get("cell_m"), packing_voxels=s["packing_voxels"],
                                min_sphere_m=s.get("min_sphere_m"), rng=s["seed"],
                                progress=show)
    except ValueError as exc:  # name the options, not the library's parameters
        msg = str(exc)
        for name, flag in _OPTION_NAMES.items():
            msg = msg.replace(name, flag)
        raise CliError(msg) from None
    meta = {**surf.metadata, "seed": s["seed"], "version": package_version(),
            "shape_units": s["shape_units"]}
    surf = type(surf)(surf.vertices, surf.faces, surf.catalog, meta, surf.packing,
                      surf.metaballs, surf.timings_s)
    body = None
    if any(out.lower().endswith(".npz") for out in s["output"]):
        try:
            body = surf.to_body(s["magnitude"], crossings=s["shape_crossings"])  # before writing
        except ValueError as exc:
            raise CliError(f".npz output (lat/long projection): {exc}") from None
    outs = [*s["output"], *[s[k] for k in ("catalog", "preview") if s.get(k)]]
    for out in progress_bar(s["output"], enabled=show, desc="write"):
        if out.lower().endswith(".npz"):
            body.save(out)
        else:
            surf.save(out)
    if s.get("catalog"):
        write_catalog(surf.catalog, s["catalog"])
    if s.get("preview"):
        from .preview import render_from_settings

        render_from_settings(surf.to_pyvista(), s["preview"], s)
    if show:
        pk = meta["packing"]
        print(f"implicit body: {len(surf.faces)} triangles ({meta['voxel_m']:.4g} m voxels), "
              f"{pk['spheres']} spheres (coverage {pk['coverage']:.1%}), "
              f"{len(surf.catalog)} craters, seed {s['seed']}, volume "
              f"{surf.volume_m3 / meta['constraint_volume_m3']:.3f} x the constraint's")
        for out in outs:
            print(f"wrote {out} ({human_bytes(Path(out).stat().st_size)})")
    return 0
