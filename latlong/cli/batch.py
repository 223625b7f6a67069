"""``latlong batch``: every variant of a scene file (seeds x varied settings) on
dask.distributed (:func:`latlong.batch`).

The scene file is what ``latlong build --config`` reads; ``--vary`` values are parsed
like the option of the same key. Errors (a bad seed list, key, value or scheduler, a bad
scene) are one line, exit code 2, before anything runs; a failed variant is recorded
in index.csv and makes the exit code 1.
"""

from __future__ import annotations

import argparse

from craters.cli.kit import (
    add_batch_arguments,
    batch_error,
    batch_reporter,
    batch_summary,
    parse_vary,
)
from latlong import SETTINGS
from latlong import batch as run_batch

from .options import BUILD_OPTIONS, OUTPUT_KEYS, read_config

__all__ = ["add_batch_parser"]

_OPTS = {o.key: o for o in BUILD_OPTIONS if o.key in SETTINGS and o.key != "seed"}
#: Settings whose one value holds commas (a whole --vary text is one value without ';').
_COMMA_KEYS = ("stretch", "craters", "boulders", "lcsn", "gabor", "shape_center")


def _value(key: str, text: str):
    """A --vary value as the option of the same key parses it (a layer: a list of one)."""
    opt = _OPTS[key]
    if opt.action in ("store_true", "store_false"):
        if text.lower() not in ("true", "false"):
            raise argparse.ArgumentTypeError(f"expected true or false; got {text!r}")
        return text.lower() == "true"
    value = opt.parse(text)
    return [value] if opt.action == "append" else value


def cmd_batch(args) -> int:
    scene = read_config(args.scene)
    vary = parse_vary(args.vary, _value, _OPTS, _COMMA_KEYS)
    progress, on_done = batch_reporter(args.quiet)
    try:
        result = run_batch(scene, args.seeds, vary=vary, out=args.output, scheduler=args.scheduler,
                           workers=args.workers, resume=args.resume, force=args.force,
                           progress=progress, on_done=on_done)
    except (TypeError, ValueError) as exc:
        raise batch_error(exc, args.scene) from None
    return batch_summary(result, args.quiet)


def add_batch_parser(sub) -> None:
    """Register ``latlong batch``."""
    b = sub.add_parser(
        "batch", help="build every variant of a scene (seeds x --vary) on dask.distributed",
        description="Build a scene file for every seed and every combination of --vary "
        "values, one dask task per variant (a local cluster, or --scheduler), and write each "
        "variant's outputs (the scene's, else .npz and the crater catalog) under its name "
        "into the folder, with index.csv (files, sha256, seconds, peak MB, status).")
    b.add_argument("scene", metavar="SCENE",
                   help="scene file (TOML): the keys of `latlong build --config`, outputs "
                   f"({', '.join(k for k in OUTPUT_KEYS if k not in ('quiet', 'force'))}) "
                   "included")
    add_batch_arguments(b, "each variant's files named seedNNNN[_KEY=VALUE...][_FILE]")
    b.set_defaults(func=cmd_batch)
