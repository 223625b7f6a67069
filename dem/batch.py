"""Batches of layer stacks: one ``dem enhance`` description, many seeds and varied keys,
built on dask.distributed (or serially).

:func:`batch` builds every variant -- each seed of ``seeds`` with each combination of the
values in ``vary`` (a cartesian product) -- as one task (the engine:
``latlong.parallel.batch``) and writes each variant's stack into its own folder of the
batch folder, ``FOLDER/seed0001_layers=9/`` (``manifest.json``, layer GeoTIFFs, crater
catalogs), with ``FOLDER/index.csv`` listing every file, its sha256, seconds, peak memory
and status. Every variant's description is checked before anything runs. A variant's
files are the bytes ``dem enhance --config CONFIG --seed S -o FOLDER/NAME`` writes: the
input file is recorded in the manifest as the description names it, and read by the
workers from where the caller's working folder puts it.
"""

from __future__ import annotations

import dataclasses
import json
from collections.abc import Callable, Mapping
from pathlib import Path

from craters._shared import (
    ParameterError,
    ParameterTypeError,
    load_toml,
    package_version,
)
from craters._shared.files import check_regular_file
from latlong.parallel.batch import (
    BatchResult,
    Job,
    combinations,
    run_batch,
    variants,
    vary_error,
)

from .config import EnhanceConfig
from .enhance import enhance

__all__ = ["batch"]

#: Keys of a ``dem enhance`` config file that say how to write a stack; a batch writes
#: each variant's stack into its own folder.
_RUN_KEYS = ("output", "force", "quiet")


def batch(config, seeds, *, out, vary: Mapping | None = None, backend: str | None = None,
          scheduler: str | None = None, workers: int | None = None, resume: bool = False,
          force: bool = False, progress: bool = False, retries: int = 2,
          on_done: Callable[[dict], None] | None = None,
          connect_timeout_s: float | None = None) -> BatchResult:
    """Build every variant of a stack description (on dask.distributed) into ``out``.

    Parameters
    ----------
    config : str, Path, Mapping or EnhanceConfig
        A ``dem enhance`` config file (TOML; its ``output``, ``force`` and ``quiet`` are
        not used), its keys as a mapping, or an :class:`EnhanceConfig`. Its seed is
        replaced by each variant's; a relative ``input`` is relative to the working folder.
    seeds : str or iterable of int
        ``"1-1000"``, ``"1,5,9"``, ``"1-3,7"`` or integers.
    out : str or Path
        The batch folder (made if missing; its parent must exist).
    vary : Mapping, optional
        Key -> list of values (:meth:`EnhanceConfig.keys` but ``seed``; values as in the
        file); every combination is built.
    backend, scheduler, workers, resume, force, progress, retries, on_done, connect_timeout_s
        As :func:`latlong.batch`: dask (default) or ``"serial"`` in this process, a
        running scheduler's address (answering within ``connect_timeout_s``) or a local
        cluster of ``workers`` processes, keep
        finished variants, redo all, a progress bar, retries of tasks that raised
        something other than a bad-input error, a callback per finished variant's index
        row.

    Returns
    -------
    BatchResult
        Counts (``done``, ``skipped``, ``failed``), wall time, the index rows.
    """
    settings = _config_keys(config)
    seeds_of = variants(seeds, vary)  # checks seeds and vary
    allowed = [k for k in EnhanceConfig.keys() if k != "seed"]
    configs = {repr(values): _combo_config(settings, values, seeds_of[0].seed)
               for values in combinations(vary, allowed)}
    jobs = []
    for v in seeds_of:
        cfg = dataclasses.replace(configs[repr(v.values)], seed=v.seed)
        where = None if cfg.input is None else str(Path(cfg.input).resolve())
        describe = json.dumps({"config": cfg.to_dict(), "version": package_version()},
                              sort_keys=True, default=str)
        jobs.append(Job(v, (cfg, where), describe, (v.name,)))
    return run_batch(jobs, _enhance_variant, out, backend=backend, scheduler=scheduler,
                     workers=workers, resume=resume, force=force, progress=progress,
                     retries=retries, on_done=on_done, connect_timeout_s=connect_timeout_s)


def _config_keys(config) -> dict:
    if isinstance(config, EnhanceConfig):
        return {k: getattr(config, k) for k in EnhanceConfig.keys()}
    if isinstance(config, str | Path):
        config = load_toml(config)
    if not isinstance(config, Mapping):
        raise ParameterTypeError("config", f"must be a config file, a mapping of keys or an "
                                 f"EnhanceConfig; got {type(config).__name__}")
    return {k: v for k, v in config.items() if k not in _RUN_KEYS}


def _combo_config(settings: dict, values: tuple, seed: int) -> EnhanceConfig:
    """The description of one combination of varied values (its input file must exist);
    a bad value is an error of ``vary`` naming it."""
    try:
        cfg = EnhanceConfig.from_mapping({**settings, **dict(values), "seed": seed})
        if cfg.input is None:
            raise ParameterError("input", "is required: the base DEM file")
        check_regular_file(cfg.input, "input DEM")
        return cfg
    except (TypeError, ValueError) as exc:
        if not values:
            raise
        raise vary_error(exc, values) from None


def _enhance_variant(payload, folder: Path, name: str) -> None:
    """In a worker: build one stack (the input read from the caller's path, recorded as
    the description names it) and write it into ``folder / name``."""
    cfg, where = payload
    stack = enhance(cfg if where is None else dataclasses.replace(cfg, input=where))
    if where is not None and where != cfg.input:
        info = stack.info
        info["parameters"]["input"] = cfg.input
        stack = stack.replace(info=info)
    stack.write(folder / name)
