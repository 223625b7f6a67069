"""``dem batch``: every variant of a ``dem enhance`` config (seeds x varied keys) on
dask.distributed (:func:`dem.batch`), each variant's stack in its own folder.

``--vary`` values are parsed like the ``dem enhance`` option of the same key. Errors (a
bad seed list, key, value or scheduler, a bad config) are one line, exit code 2, before
anything runs; a failed variant is recorded in index.csv and makes the exit code 1.
"""

from __future__ import annotations

from craters.cli.kit import batch_reporter, batch_summary
from craters.cli.options import Setting, Values, batch_error, batch_options, command, parse_vary
from latlong.parallel.backends import CONNECT_TIMEOUT

from ..batch import batch
from .options import DEM

HELP = {
    "batch": "build every variant of a `dem enhance` config (seeds x --vary) on "
             "dask.distributed",
}

__all__ = ["register"]

OPTIONS = {
    "config": Setting(help="a `dem enhance` config file (TOML; its output, force and quiet are "
                      "not used: each variant's stack goes to FOLDER/NAME)", flag="CONFIG",
                      required=True, run=True),
    **batch_options("one stack folder per variant, named seedNNNN[_KEY=VALUE...]"),
    "connect_timeout_s": CONNECT_TIMEOUT,
}
#: The settings a batch varies: every key of the stack's description but the seed.
VARY = {k: s for k, s in DEM.items() if k != "seed"}


def _batch(v: Values) -> int:
    vary = parse_vary(v.vary, VARY)
    progress, on_done = batch_reporter(v.quiet)
    try:
        result = batch(v["config"], v.seeds, vary=vary, out=v.output, scheduler=v.scheduler,
                       workers=v.workers, resume=v.resume, force=v.force, progress=progress,
                       on_done=on_done, connect_timeout_s=v["connect_timeout_s"])
    except (TypeError, ValueError) as exc:
        raise batch_error(exc, v, v["config"]) from None
    return batch_summary(result, v.quiet)


def register(sub) -> None:
    """Register ``dem batch``."""
    command(sub, "batch", _batch, OPTIONS, prog="dem",
            help=HELP["batch"],
            description="Build a `dem enhance` config for every seed and every combination "
            "of --vary values, one dask task per variant (a local cluster, or --scheduler), "
            "each variant's stack in FOLDER/NAME/, with FOLDER/index.csv (files, sha256, "
            "seconds, peak MB, status).")
