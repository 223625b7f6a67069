"""``latlong build``: a scene from options and a scene file, the build, the outputs.

Every option has a key of the same name (dashes -> underscores) in a TOML scene file
given with ``--config`` (crater layers as ``[[craters]]`` tables or spec strings);
options on the command line override the file. The scene is validated and every output
checked before any work; outputs are written atomically.
"""

from __future__ import annotations

from pathlib import Path

import craters
from craters._shared import check_output_path, human_bytes, progress_bar
from craters._shared.cli import CliError
from latlong import EXPORT_SUFFIXES, Scene, ShapeBase, build, render_preview
from latlong.implicit import MESH_SUFFIXES
from latlong.surface import band_areas

from .options import BUILD_OPTIONS, OUTPUT_KEYS, given_options, read_config, shown

__all__ = ["add_build_parser"]

_SUFFIXES = {"latlong": (".npz", *EXPORT_SUFFIXES), "implicit": (".npz", *MESH_SUFFIXES),
             "mesh": MESH_SUFFIXES}


def _kind(scene: Scene) -> str:
    """latlong, implicit or mesh (a shape base cratered on its own mesh)."""
    mesh = isinstance(scene.base, ShapeBase) and scene.base.surface == "mesh"
    return "mesh" if mesh else scene.backend


def _settings(args) -> tuple[dict, dict, set]:
    """(scene settings, run options, keys that came from the config file)."""
    from_file = read_config(args.config) if args.config else {}
    given = {**from_file, **given_options(args, BUILD_OPTIONS)}
    run = {k: given.pop(k) for k in OUTPUT_KEYS if k in given}
    file_keys = {k for k in from_file if k not in given_options(args, BUILD_OPTIONS)}
    return given, run, file_keys


def _check_outputs(scene: Scene, run: dict) -> list[str]:
    """Something to write, no file twice, known suffixes, folders writable, nothing
    overwritten without --force. Returns every file that will be written."""
    outputs = [str(x) for x in run.get("output") or []]
    extras = {k: run[k] for k in ("catalog", "boulder_catalog", "preview") if run.get(k)}
    if scene.backend == "implicit" and "boulder_catalog" in extras:
        raise CliError("--boulder-catalog does not apply to --backend implicit")
    if not outputs and not extras:
        raise CliError("nothing to write: give -o/--output, --catalog or --preview")
    if _kind(scene) == "mesh" and any(str(x).lower().endswith(".npz") for x in outputs):
        raise CliError("--surface mesh writes meshes (" + " ".join(MESH_SUFFIXES) + "), not "
                       ".npz (a lat/long body)")
    if scene.backend == "latlong":
        if extras.get("catalog") and not scene.craters.layers:
            raise CliError("--catalog needs crater layers (--craters or a cratered --preset)")
        if extras.get("boulder_catalog") and not scene.boulders.layers:
            raise CliError("--boulder-catalog needs boulder layers (--boulders)")
    seen = set()
    for x in [*outputs, *extras.values()]:
        key = Path(x).resolve()
        if key in seen:
            raise CliError(f"output {x!r} is given twice")
        seen.add(key)
    force = bool(run.get("force"))
    for x in outputs:
        check_output_path(x, force=force, suffixes=_SUFFIXES[_kind(scene)])
    suffixes = {"preview": (".png",), "catalog": (".csv", ".scc")}
    for k, x in extras.items():
        check_output_path(x, force=force, suffixes=suffixes.get(k, (".csv",)))
    columns = run.get("catalog_columns", "craterform")
    if columns not in craters.CATALOG_COLUMNS:
        raise CliError(f"--catalog-columns must be one of {', '.join(craters.CATALOG_COLUMNS)}; "
                       f"got {columns!r}")
    if columns != "craterform" and not str(extras.get("catalog", "")).lower().endswith(".csv"):
        raise CliError("--catalog-columns applies to a CSV --catalog")
    return [*outputs, *extras.values()]


def _write_craters(catalog, run: dict, *, area_m2: float, axes_m) -> None:
    """The crater catalog as CSV (in the chosen column names) or craterstats .scc."""
    path = run["catalog"]
    if str(path).lower().endswith(".scc"):
        craters.write_scc(catalog, path, area_m2=area_m2, axes_m=axes_m,
                          note="latlong build: the craters as stamped on the whole body")
    else:
        craters.write_catalog(catalog, path, columns=run.get("catalog_columns", "craterform"))


def _write_body(body, run: dict, progress: bool, done) -> None:
    for out in run.get("output") or []:
        if out.lower().endswith(".npz"):
            body.save(out)
        else:
            body.export(out, progress=progress)
        done()
    if run.get("catalog"):
        area = float(band_areas(body).sum()) if run["catalog"].lower().endswith(".scc") else 0.0
        _write_craters(body.craters, run, area_m2=area, axes_m=body.radius_m * body.stretch)
        done()
    if run.get("boulder_catalog"):
        craters.write_catalog(body.boulders, run["boulder_catalog"])
        done()


def _write_implicit(surf, scene: Scene, run: dict, done) -> None:
    outs = run.get("output") or []
    body = None
    if any(o.lower().endswith(".npz") for o in outs):  # before anything is written
        try:
            body = surf.to_body(scene.body.magnitude, crossings=scene.implicit.crossings)
        except ValueError as exc:
            raise CliError(f".npz output (lat/long projection): {exc}") from None
    for out in outs:
        (body.save if out.lower().endswith(".npz") else surf.save)(out)
        done()
    if run.get("catalog"):
        _write_craters(surf.catalog, run, area_m2=surf.area_m2, axes_m=None)
        done()


def _write_mesh(surf, run: dict, progress: bool, done) -> None:
    for out in run.get("output") or []:
        surf.save(out, progress=progress)
        done()
    if run.get("catalog"):
        _write_craters(surf.craters, run, area_m2=surf.area_m2, axes_m=None)
        done()
    if run.get("boulder_catalog"):
        craters.write_catalog(surf.boulders, run["boulder_catalog"])
        done()


def _summary(made, scene: Scene) -> str:
    if scene.backend == "implicit":
        meta = made.metadata
        pk = meta["packing"]
        return (f"implicit body: {len(made.faces)} triangles ({meta['voxel_m']:.4g} m voxels), "
                f"{pk['spheres']} spheres (coverage {pk['coverage']:.1%}), "
                f"{len(made.catalog)} craters, seed {scene.seed}, volume "
                f"{made.volume_m3 / meta['constraint_volume_m3']:.3f} x the constraint's")
    if _kind(scene) == "mesh":
        meta = made.metadata
        skipped = meta.get("craters_skipped_no_height_field", 0)
        n_craters = 0 if made.craters is None else len(made.craters)
        n_boulders = 0 if made.boulders is None else len(made.boulders)
        return (f"mesh surface: {made.n_vertices} vertices, {len(made.faces)} triangles (mean "
                f"edge {meta['mean_edge_m']:.3g} m), {n_craters} craters ({skipped} left out "
                f"on folds), {n_boulders} boulders, seed {scene.seed}")
    r = made.radii_m
    n_craters = 0 if made.craters is None else len(made.craters)
    return (f"body: magnitude {made.magnitude}, {made.n_vertices} vertices, base "
            f"{scene.base.name} ({scene.preset or '-'}), {n_craters} craters, seed "
            f"{scene.seed}, radius {r.min():.4g}..{r.max():.4g} m")


def cmd_build(args) -> int:
    settings, run, from_file = _settings(args)
    try:
        scene = Scene.from_settings(settings)
    except (ValueError, TypeError) as exc:
        raise CliError(shown(exc, from_file, args.config)) from None
    files = _check_outputs(scene, run)
    show = not run.get("quiet")
    bar = progress_bar(total=1 + len(files), enabled=show, desc="build")
    bar.set_description("body")
    made = build(scene, progress=show)
    bar.update()
    if scene.backend == "implicit":
        _write_implicit(made, scene, run, bar.update)
    elif _kind(scene) == "mesh":
        _write_mesh(made, run, show, bar.update)
    else:
        _write_body(made, run, show, bar.update)
    if run.get("preview"):
        view = made if _kind(scene) == "latlong" else made.to_pyvista()
        render_preview(view, run["preview"], scene.preview)
        bar.update()
    bar.close()
    if show:
        print(_summary(made, scene))
        for out in files:
            print(f"wrote {out} ({human_bytes(Path(out).stat().st_size)})")
    return 0


def add_build_parser(sub, add_groups) -> None:
    """Register ``latlong build`` (``add_groups(parser)`` makes the option groups)."""
    b = sub.add_parser("build", help="generate a body and write meshes / catalogs / pictures",
                       description="Generate a body (base shape, craters, boulders) or an "
                       "implicit body and write it.")
    b.add_argument("--config", metavar="TOML",
                   help="scene file; options override its keys (default: none)")
    add_groups(b, BUILD_OPTIONS)
    b.set_defaults(func=cmd_build)
