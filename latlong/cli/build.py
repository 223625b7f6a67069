"""``latlong build``: a scene from options and a scene file, the build, the outputs.

Every option has a key of the same name (dashes -> underscores) in a TOML scene file
given with ``--config`` (crater layers as ``[[craters]]`` tables or spec strings);
options on the command line override the file. The scene is validated and every output
checked before any work; outputs are written atomically.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from craters._shared import progress_bar, staged_path
from craters.cli.kit import CliError, wrote_line
from craters.cli.options import FORCE, QUIET, Setting, Values, command, declared_keys, flag_of
from latlong import LatLongGrid, Scene
from latlong.parallel.backends import CONNECT_TIMEOUT
from latlong.scratch import drop_pages

from ..outputs import OUTPUT_SETTINGS, Outputs, companions, output_kind, write_outputs
from ..scene import SETTING_PARTS, SETTINGS

HELP = {
    "build": "generate a body and write meshes / catalogs / pictures",
}

__all__ = ["GROUPS", "OPTIONS", "register"]

#: Every option of ``latlong build`` (the scene's settings, the outputs, --quiet,
#: --force): also the keys of a scene file.
#: How an on-demand build (``--on-demand``) runs: patches, and where.
ON_DEMAND_RUN = {
    "patches": Setting(help="independent patches of vertices of an --on-demand build (the same "
                       "bytes for any number; default: patches of at most 4 194 304 vertices, "
                       "so memory is bounded by a patch)", kind=int, range=(1, 10**9),
                       run=True),
    "workers": Setting(help="patches on a local dask cluster of this many worker processes "
                       "(--on-demand)", kind=int, range=(1, 1024), run=True),
    "scheduler": Setting(help="patches on the dask scheduler at this address, e.g. "
                         "tcp://127.0.0.1:8786 (--on-demand)", run=True),
    "connect_timeout_s": CONNECT_TIMEOUT,
}
OPTIONS = declared_keys(*SETTING_PARTS, ("output", Outputs),
                        ("output", {"quiet": QUIET, "force": FORCE}), ("body", ON_DEMAND_RUN))
#: The titles of the option groups of ``latlong build --help``.
GROUPS = {"body": "body", "faulting": "two-phase faulting (--base faulting)",
          "fbm": "Perlin fBm (--base fbm; detail on --base shape)",
          "shape": "shape models (--base shape:PATH)", "craters": "craters",
          "boulders": "boulders", "implicit": "implicit backend (--backend implicit)",
          "output": "output", "render": "preview picture"}


def _outputs(scene: Scene, v: Values) -> Outputs:
    """The run's outputs, checked against the scene before any work (something to write,
    known suffixes, folders writable, nothing overwritten without --force)."""
    outputs = Outputs.from_settings({k: v[k] for k in OUTPUT_SETTINGS})
    if not outputs.files():
        raise CliError("nothing to write: give -o/--output, --catalog or --preview")
    outputs.check(scene, force=v["force"],
                  inputs=[("config", v.config_file)] if v.config_file else ())
    return outputs


def _summary(made, scene: Scene) -> str:
    if scene.backend == "implicit":
        meta = made.metadata
        pk = meta["packing"]
        return (f"implicit body: {len(made.faces)} triangles ({meta['voxel_m']:.4g} m voxels), "
                f"{pk['spheres']} spheres (coverage {pk['coverage']:.1%}), "
                f"{len(made.catalog)} craters, seed {scene.seed}, volume "
                f"{made.volume_m3 / meta['constraint_volume_m3']:.3f} x the constraint's")
    if output_kind(scene) == "mesh":
        meta = made.metadata
        skipped = meta.get("craters_skipped_no_height_field", 0)
        n_craters = 0 if made.craters is None else len(made.craters)
        n_boulders = 0 if made.boulders is None else len(made.boulders)
        return (f"mesh surface: {made.n_vertices} vertices, {len(made.faces)} triangles (mean "
                f"edge {meta['mean_edge_m']:.3g} m), {n_craters} craters ({skipped} left out "
                f"on folds), {n_boulders} boulders, seed {scene.seed}")
    lo, hi = _distance_range(made)
    n_craters = 0 if made.craters is None else len(made.craters)
    n_boulders = 0 if made.boulders is None else len(made.boulders)
    assert scene.base is not None  # a lat/long scene
    return (f"body: magnitude {made.magnitude}, {made.n_vertices} vertices, base "
            f"{scene.base.name} ({scene.preset or '-'}), {n_craters} craters, {n_boulders} "
            f"boulders, seed {scene.seed}, surface {lo:.4g}..{hi:.4g} m from the centre")


def _distance_range(body) -> tuple[float, float]:
    """Nearest and farthest surface points from the centre: the radii when unstretched,
    else |stretch * r * u| (a stretched body's radii are not its size), in 1 M-vertex
    blocks (a disk-backed body's pages are dropped between them)."""
    lo, hi = np.inf, 0.0
    plain = tuple(body.stretch) == (1.0, 1.0, 1.0)
    for s in range(0, body.n_vertices, 1 << 20):
        e = min(s + (1 << 20), body.n_vertices)
        d = body.radii_m[s:e] if plain else np.linalg.norm(body.vertices(s, e), axis=1)
        lo, hi = min(lo, float(d.min())), max(hi, float(d.max()))
        drop_pages(body.radii_m, s, e)
    return lo, hi


def _build(v: Values) -> int:
    scene = Scene.from_settings({k: v[k] for k in SETTINGS if k in v.given})
    outputs = _outputs(scene, v)
    files = outputs.files()
    show = not v["quiet"]
    bar = progress_bar(total=1 + len(files), enabled=show, desc="build")
    bar.set_description("body")
    scratch = None
    if scene.radii_on_disk():
        scratch = Path(files[0]).parent
        if show:
            n = LatLongGrid(scene.body.magnitude).n_vertices
            print(f"keeping the {n:.3g} radii ({n * 8 / 1e9:.3g} GB) in a scratch file in "
                  f"{str(scratch)!r} (--radii-on-disk)", file=sys.stderr)
    run = {k: v[k] for k in ("patches", "workers", "scheduler", "connect_timeout_s")
           if k in v.given}
    if run and not scene.on_demand:
        key = next(iter(run))
        raise CliError(f"{flag_of(key, ON_DEMAND_RUN[key])} applies to an --on-demand build")
    if scene.on_demand:
        from latlong.ondemand.patches import build_patches, patch_count
        from latlong.scratch import disk_radii

        n = LatLongGrid(scene.body.magnitude).n_vertices
        patches = patch_count(n, v["patches"])
        patch_bar = progress_bar(total=patches, enabled=show, desc="patches")
        made = build_patches(scene, patches=patches, workers=v["workers"],
                             scheduler=v["scheduler"], connect_timeout_s=v["connect_timeout_s"],
                             progress=lambda *_: patch_bar.update(),
                             out=None if scratch is None else disk_radii(n, scratch))
        patch_bar.close()
    else:
        from latlong.build import build  # numba and the science load where they run

        made = build(scene, progress=show, scratch_dir=scratch)
    bar.update()
    write_outputs(made, scene, outputs, progress=show, done=bar.update)
    bar.close()
    if show:
        print(_summary(made, scene))
        for out in [f for path in files for f in (path, *companions(path))]:
            if staged_path(out).exists():  # a .glb's external buffer only past 4 GiB
                print(wrote_line(out))
    return 0


def register(sub) -> None:
    """Register ``latlong build``."""
    command(sub, "build", _build, OPTIONS, groups=GROUPS, config=True, prog="latlong",
            help=HELP["build"],
            description="Generate a body (base shape, craters, boulders) or an implicit body "
            "and write it.")
