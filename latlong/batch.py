"""Batches of bodies: one scene, many seeds and varied settings, built on dask.distributed
(or serially).

:func:`batch` builds every variant of a scene -- each seed of ``seeds`` with each
combination of the values in ``vary`` (a cartesian product) -- as one task per variant
(the engine: ``latlong.parallel.batch``, on the backend ``backend`` chooses), and writes
per variant the outputs the scene names (or a ``.npz`` and, with crater layers, the
crater catalog) into one folder, each file under the variant's name:
``seed0001_radius-m=1000.npz``, a named output ``body.ply`` as
``seed0001_radius-m=1000_body.ply``. ``index.csv`` lists every variant with its files,
their sha256, seconds, peak memory and status. Every variant's scene and outputs are
checked before anything runs. A variant's files are the bytes ``latlong
build --config SCENE --seed S`` writes to the same file names (the same writer:
:func:`latlong.outputs.write_outputs`; the same seed gives the same bytes whatever the
thread count).
"""

from __future__ import annotations

import dataclasses
import json
from collections.abc import Callable, Mapping
from pathlib import Path

from craters._shared import ParameterError, ParameterTypeError, load_toml, package_version

from .build import build
from .outputs import OUTPUT_SETTINGS, Outputs, output_kind, write_outputs
from .parallel.batch import (
    BatchResult,
    Job,
    combinations,
    run_batch,
    variants,
    vary_error,
)
from .scene import SETTINGS, Scene

__all__ = ["batch"]

#: Run options of a ``latlong build`` scene file that a batch replaces with its own.
_RUN_ONLY = ("quiet", "force")


def batch(scene, seeds, *, out, vary: Mapping | None = None, backend: str | None = None,
          scheduler: str | None = None, workers: int | None = None, resume: bool = False,
          force: bool = False, progress: bool = False, retries: int = 2,
          on_done: Callable[[dict], None] | None = None,
          connect_timeout_s: float | None = None) -> BatchResult:
    """Build every variant of a scene (on dask.distributed) and write it into ``out``.

    Parameters
    ----------
    scene : str, Path, Mapping or Scene
        A scene file (TOML: the keys of ``latlong build --config``, output keys included),
        its settings as a mapping, or a :class:`Scene` (then no ``vary``). Its seed is
        replaced by each variant's.
    seeds : str or iterable of int
        ``"1-1000"``, ``"1,5,9"``, ``"1-3,7"`` or integers.
    out : str or Path
        The batch folder (made if missing; its parent must exist).
    vary : Mapping, optional
        Setting -> list of values (:data:`latlong.SETTINGS` but ``seed``; values as in a
        scene file, a crater layer list as a list of specs); every combination is built.
    backend : {"dask", "serial"}, optional
        Where the variants are built (:mod:`latlong.parallel.backends`): dask (the
        default), or ``"serial"``, one after the other in this process (the same bytes).
    scheduler : str, optional
        Address of a running dask scheduler (``tcp://host:8786``); default: a local
        cluster on 127.0.0.1 with ``workers`` single-threaded worker processes (default:
        one per core).
    resume : bool
        Keep the variants ``index.csv`` lists as done whose files still have their
        sha256; redo the others.
    force : bool
        Redo every variant of a folder that holds a batch (else refused).
    progress : bool
        A progress bar on a terminal.
    retries : int
        How often a task that raised something other than a bad-input error (a full
        disk, ...) is tried again.
    on_done : callable, optional
        Called with each finished variant's index row (a dict), in this process.
    connect_timeout_s : float
        Seconds the ``scheduler`` has to answer (a one-line error after that).

    Returns
    -------
    BatchResult
        Counts (``done``, ``skipped``, ``failed``), wall time, the index rows.
    """
    settings, outputs = _scene_parts(scene, vary)
    seeds_of = variants(seeds, vary)  # checks seeds and vary
    scenes = {}
    for values in combinations(vary, [k for k in SETTINGS if k != "seed"]):
        s = _combo_scene(scene, settings, values, seeds_of[0].seed)
        _outputs_for(s, outputs, "v").check(s, paths=False)
        scenes[repr(values)] = s
    jobs = []
    for v in seeds_of:
        s = dataclasses.replace(scenes[repr(v.values)], seed=v.seed)
        named = _outputs_for(s, outputs, v.name)
        what = ({"scene": repr(s)} if settings is None else
                {"settings": {**settings, **dict(v.values), "seed": v.seed}})
        describe = json.dumps({**what, "outputs": named.files(),
                               "catalog_columns": named.catalog_columns,
                               "version": package_version()}, sort_keys=True, default=str)
        jobs.append(Job(v, (s, named), describe, tuple(named.files())))
    return run_batch(jobs, _build_variant, out, backend=backend, scheduler=scheduler,
                     workers=workers, resume=resume, force=force, progress=progress,
                     retries=retries, on_done=on_done, connect_timeout_s=connect_timeout_s)


def _scene_parts(scene, vary) -> tuple[dict | None, Outputs]:
    """(scene settings or None for a Scene, the outputs it names)."""
    if isinstance(scene, Scene):
        if vary:
            raise ParameterError("vary", "needs the scene as settings (a scene file or a "
                                 "mapping), not a Scene")
        return None, Outputs()
    if isinstance(scene, str | Path):
        scene = load_toml(scene)
    if not isinstance(scene, Mapping):
        raise ParameterTypeError("scene", f"must be a scene file, a mapping of settings or a "
                                 f"Scene; got {type(scene).__name__}")
    settings = {k: v for k, v in scene.items() if k not in _RUN_ONLY}
    outputs = Outputs.from_settings({k: settings.pop(k) for k in OUTPUT_SETTINGS
                                     if k in settings})
    return settings, outputs


def _combo_scene(scene, settings: dict | None, values: tuple, seed: int) -> Scene:
    """The scene of one combination of varied values; a bad value is an error of ``vary``
    naming it."""
    if settings is None:
        return scene
    try:
        return Scene.from_settings({**settings, **dict(values), "seed": seed})
    except (ParameterError, ParameterTypeError) as exc:
        if not values:
            raise
        raise vary_error(exc, values) from None


def _outputs_for(scene: Scene, outputs: Outputs, name: str) -> Outputs:
    """A variant's outputs: the scene's, each file as ``NAME_file``, or by default
    ``NAME.npz`` (``NAME.ply`` for a mesh or implicit surface) and ``NAME_craters.csv``
    with crater layers."""
    if outputs.files():
        return outputs.renamed(lambda f: f"{name}_{Path(f).name}")
    kind = output_kind(scene)
    layers = scene.implicit.layers if scene.implicit is not None else scene.craters.layers
    return Outputs(output=(f"{name}{'.npz' if kind == 'latlong' else '.ply'}",),
                   catalog=f"{name}_craters.csv" if layers else None)


def _build_variant(payload, folder: Path, name: str) -> None:
    """In a worker: build one variant and write its outputs into ``folder``."""
    scene, outputs = payload
    made = build(scene)
    write_outputs(made, scene, outputs.renamed(lambda f: str(folder / f)))
