"""``latlong batch``: every variant of a scene file (seeds x varied settings) on
dask.distributed (:func:`latlong.batch`).

The scene file is what ``latlong build --config`` reads; ``--vary`` values are parsed
like the option of the same key. Errors (a bad seed list, key, value or scheduler, a bad
scene) are one line, exit code 2, before anything runs; a failed variant is recorded
in index.csv and makes the exit code 1.
"""

from __future__ import annotations

from craters.cli.kit import batch_reporter, batch_summary
from craters.cli.options import (
    Setting,
    Values,
    batch_error,
    batch_options,
    command,
    parse_vary,
    read_config,
)
from latlong import batch as run_batch
from latlong.parallel.backends import CONNECT_TIMEOUT

from ..outputs import OUTPUT_SETTINGS
from ..scene import SETTINGS
from .build import OPTIONS as BUILD_OPTIONS

HELP = {
    "batch": "build every variant of a scene (seeds x --vary) on dask.distributed",
}

__all__ = ["register"]

OPTIONS = {
    "scene": Setting(help="scene file (TOML): the keys of `latlong build --config`, outputs "
                     f"({', '.join(OUTPUT_SETTINGS)}) included", flag="SCENE", required=True,
                     run=True),
    **batch_options("each variant's files named seedNNNN[_KEY=VALUE...][_FILE]"),
    "connect_timeout_s": CONNECT_TIMEOUT,
}
#: The settings a batch varies: every scene setting but the seed.
VARY = {k: s for k, s in BUILD_OPTIONS.items() if k in SETTINGS and k != "seed"}


def _batch(v: Values) -> int:
    scene = read_config(v.scene, BUILD_OPTIONS, "latlong build")
    vary = parse_vary(v.vary, VARY)
    progress, on_done = batch_reporter(v.quiet)
    try:
        result = run_batch(scene, v.seeds, vary=vary, out=v.output, scheduler=v.scheduler,
                           workers=v.workers, resume=v.resume, force=v.force,
                           progress=progress, on_done=on_done,
                           connect_timeout_s=v["connect_timeout_s"])
    except (TypeError, ValueError) as exc:
        raise batch_error(exc, v, v.scene) from None
    return batch_summary(result, v.quiet)


def register(sub) -> None:
    """Register ``latlong batch``."""
    command(sub, "batch", _batch, OPTIONS, prog="latlong",
            help=HELP["batch"],
            description="Build a scene file for every seed and every combination of --vary "
            "values, one dask task per variant (a local cluster, or --scheduler), and write "
            "each variant's outputs (the scene's, else .npz and the crater catalog) under its "
            "name into the folder, with index.csv (files, sha256, seconds, peak MB, status).")
