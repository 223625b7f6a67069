"""``dem batch``: every variant of a ``dem enhance`` config (seeds x varied keys) on
dask.distributed (:func:`dem.batch`), each variant's stack in its own folder.

``--vary`` values are parsed like the ``dem enhance`` option of the same key. Errors (a
bad seed list, key, value or scheduler, a bad config) are one line, exit code 2, before
anything runs; a failed variant is recorded in index.csv and makes the exit code 1.
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

from ..batch import batch
from ..config import EnhanceConfig
from .options import options_for

__all__ = ["register"]

_OPTS = {k: o for k, o in options_for("enhance").items()
         if k in EnhanceConfig.keys() and k != "seed"}
#: Keys whose one value holds commas (a whole --vary text is one value without ';').
_COMMA_KEYS = ("target", "craters", "boulders")


def _value(key: str, text: str):
    """A --vary value as the ``dem enhance`` option of the same key parses it."""
    opt = _OPTS[key]
    if opt.kind == "switch":
        if text.lower() not in ("true", "false"):
            raise argparse.ArgumentTypeError(f"expected true or false; got {text!r}")
        return text.lower() == "true"
    value = opt.parse(text)
    if opt.choices and value not in opt.choices:
        raise argparse.ArgumentTypeError(f"must be one of {', '.join(opt.choices)}; got "
                                         f"{text!r}")
    return [value] if opt.kind == "append" else value


def _batch(args) -> int:
    vary = parse_vary(args.vary, _value, _OPTS, _COMMA_KEYS)
    progress, on_done = batch_reporter(args.quiet)
    try:
        result = batch(args.config, args.seeds, vary=vary, out=args.output,
                       scheduler=args.scheduler, workers=args.workers, resume=args.resume,
                       force=args.force, progress=progress, on_done=on_done)
    except (TypeError, ValueError) as exc:
        raise batch_error(exc, args.config) from None
    return batch_summary(result, args.quiet)


def register(sub) -> None:
    """Add ``batch`` to the sub-command parser."""
    p = sub.add_parser(
        "batch", help="build every variant of a `dem enhance` config (seeds x --vary) on "
        "dask.distributed",
        description="Build a `dem enhance` config for every seed and every combination of "
        "--vary values, one dask task per variant (a local cluster, or --scheduler), each "
        "variant's stack in FOLDER/NAME/, with FOLDER/index.csv (files, sha256, seconds, peak "
        "MB, status).")
    p.add_argument("config", metavar="CONFIG",
                   help="a `dem enhance` config file (TOML; its output, force and quiet are "
                   "not used: each variant's stack goes to FOLDER/NAME)")
    add_batch_arguments(p, "one stack folder per variant, named seedNNNN[_KEY=VALUE...]")
    p.set_defaults(func=_batch)
