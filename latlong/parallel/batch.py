"""Batches: one build per variant (a seed and one value of each varied setting), run on a
backend (:mod:`.backends`: dask.distributed by default, or serial in this process); the
engine under ``latlong.batch`` and ``dem.batch``, which give the task that builds and
writes one variant.

Each variant is one task. A task is pure: it writes all its files into a temporary
folder inside the batch folder (under their final names, so files that name themselves
are the bytes a single build writes), hashes them and only then renames them into place;
the index lists a variant only once all its files are in place, and running it again
gives the same bytes. Tasks are submitted with ``retries`` (an exception that is not a
bad input, e.g. a full disk, is tried again elsewhere); a worker that dies has its tasks
rescheduled by the scheduler (``distributed.scheduler.allowed-failures``). A task that
fails with a ``ValueError`` or ``TypeError`` (a variant that passed the checks but cannot
be built) is recorded as failed at once and never stops the others.

The folder's ``index.csv`` has one row per variant: name, seed, the varied values, the
files (``;``-separated, relative to the folder), the sha256 of each, the task's seconds
and its worker's peak resident memory (MB), status (``ok`` / ``failed``), the error and
the sha256 of everything that defines the variant's bytes (settings, file names,
craterform version). Rows are appended and flushed as tasks finish, so a killed batch
loses nothing finished, and the file is rewritten in variant order at the end.
``resume`` keeps a variant whose row says ``ok`` with the same settings hash and whose
files are all there with the recorded sha256, and redoes the others.

Without a scheduler address (and unless the serial backend is asked for) the batch runs
on a :class:`distributed.LocalCluster` on 127.0.0.1: one single-threaded worker process
per core, each task limited to one numba thread, so variants do not oversubscribe the
cores; no dashboard. Workers of an existing cluster keep their own numba setting (start
them with ``NUMBA_NUM_THREADS=1`` and ``--nthreads 1``). The workers must see the batch
folder and the scene's input files at the same paths as the caller. The serial backend
builds the variants one after the other in this process (no retries), the same bytes.
"""

from __future__ import annotations

import contextlib
import csv
import dataclasses
import hashlib
import itertools
import re
import shutil
import time
from collections.abc import Callable, Collection, Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any

from craters._shared.files import atomic_path, check_parent_folder
from craters._shared.outputs import lock_output, unlock_output
from craters._shared.progress import progress_bar
from craters._shared.validation import ParameterError, ParameterTypeError, parameter_of

from .backends import Backend, choose_backend, open_backend
from .batch_tasks import TMP_SUFFIX, one_line, run_variant, sha256_file

__all__ = ["INDEX", "BatchResult", "Job", "Variant", "combinations", "parse_seeds",
           "read_index", "run_batch", "sha256_file", "value_text", "variants", "vary_error"]

#: The index file of a batch folder.
INDEX = "index.csv"
#: Most variants one batch takes.
MAX_VARIANTS = 1_000_000
_SAFE = re.compile(r"[A-Za-z0-9.+-]{1,40}")


def parse_seeds(seeds) -> tuple[int, ...]:
    """The seeds of a batch: ``"1-1000"`` (inclusive), ``"1,5,9"``, ``"1-3,7"``, an int or
    integers; each in [0, 2**63), none twice.

    Examples
    --------
    >>> parse_seeds("1-3,7")
    (1, 2, 3, 7)
    >>> parse_seeds("5-1")
    Traceback (most recent call last):
    ...
    craters._shared.validation.ParameterError: `seeds` range '5-1' runs backwards
    """
    if isinstance(seeds, bool):
        raise ParameterTypeError("seeds", f"must be seeds like '1-1000' or '1,5,9'; got {seeds!r}")
    if isinstance(seeds, int):
        seeds = [seeds]
    out: list[int] = []
    if isinstance(seeds, str):
        parts = [p.strip() for p in seeds.split(",")]
        for part in parts:
            m = re.fullmatch(r"(\d+)(?:-(\d+))?", part)
            if m is None:
                raise ParameterError("seeds", f"must be seeds like '1-1000' or '1,5,9' "
                                     f"(non-negative integers); got {seeds!r}")
            lo, hi = int(m[1]), int(m[2] if m[2] is not None else m[1])
            if hi < lo:
                raise ParameterError("seeds", f"range {part!r} runs backwards")
            if hi - lo >= MAX_VARIANTS or len(out) + hi - lo >= MAX_VARIANTS:
                raise ParameterError("seeds", f"must be at most {MAX_VARIANTS} seeds; got "
                                     f"{seeds!r}")
            out.extend(range(lo, hi + 1))
    else:
        try:
            given = list(seeds)
            out = [int(s) for s in given if not isinstance(s, bool) and int(s) == s]
        except (TypeError, ValueError, OverflowError):
            given = None
        if given is None or len(out) != len(given):
            raise ParameterTypeError("seeds", f"must be integers or text like '1-1000'; got "
                                     f"{seeds!r}")
    if not out:
        raise ParameterError("seeds", "must name at least one seed")
    seen = set()
    for s in out:
        if not 0 <= s < 2**63:
            raise ParameterError("seeds", f"must be in [0, 2**63); got {s}")
        if s in seen:
            raise ParameterError("seeds", f"names seed {s} twice")
        seen.add(s)
    return tuple(out)


def value_text(value) -> str:
    """A varied value as text (index and file names): ``1000.0`` -> ``1000``.

    Examples
    --------
    >>> value_text(1000.0), value_text(0.25), value_text(["c=1,k=-2"]), value_text(False)
    ('1000', '0.25', 'c=1,k=-2', 'false')
    """
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return str(int(value)) if value.is_integer() and abs(value) < 1e15 else repr(value)
    if isinstance(value, list | tuple):
        sep = "," if all(isinstance(v, int | float) for v in value) else " + "
        return sep.join(value_text(v) for v in value)
    return str(value)


@dataclasses.dataclass(frozen=True, slots=True)
class Variant:
    """One build of a batch."""

    name: str
    """Unique name, also the stem of its files: ``seed0001_radius-m=1000``."""
    seed: int
    """Its seed."""
    values: tuple[tuple[str, Any], ...] = ()
    """(setting, value) of each varied setting, in the order given."""


def _checked(vary, allowed: Collection[str] | None) -> Mapping:
    """``vary`` (setting -> non-empty list of distinct values; settings of ``allowed``,
    never ``seed``), or {} for None."""
    if vary is None:
        return {}
    if not isinstance(vary, Mapping):
        raise ParameterTypeError("vary", f"must map settings to lists of values; got "
                                 f"{type(vary).__name__}")
    for key, values in vary.items():
        if key == "seed":
            raise ParameterError("vary", "cannot vary `seed`: give the seeds as {}",
                                 see=("seeds",))
        if allowed is not None and key not in allowed:
            raise ParameterError("vary", f"{key!r} is not a setting of this batch; allowed: "
                                 f"{', '.join(allowed)}")
        if isinstance(values, str) or not isinstance(values, Sequence) or not values:
            raise ParameterError("vary", f"{key}: must be a non-empty list of values; got "
                                 f"{values!r}")
        for i, v in enumerate(values):
            if any(_same(v, w) for w in values[:i]):
                raise ParameterError("vary", f"{key}: value {value_text(v)!r} is given twice")
    return vary


def combinations(vary: Mapping | None, allowed: Collection[str] | None = None) -> list[tuple]:
    """Every combination of the values of ``vary`` (setting -> values) as (setting, value)
    pairs, in the order of :func:`variants`; ``[()]`` without ``vary``. Settings must be
    in ``allowed`` (None: any) and never ``seed``.

    Examples
    --------
    >>> combinations({"layers": [9, 11], "size": [129]})
    [(('layers', 9), ('size', 129)), (('layers', 11), ('size', 129))]
    """
    vary = _checked(vary, allowed)
    keys = list(vary)
    return [tuple(zip(keys, c, strict=True)) for c in itertools.product(*vary.values())]


def vary_error(exc: Exception, values: tuple) -> ParameterError:
    """An error of a combination of varied values as an error of ``vary`` naming the value
    it is about (or the whole combination)."""
    bad = [(k, v) for k, v in values if k == parameter_of(exc)] or values
    return ParameterError("vary", ", ".join(f"{k}={value_text(v)}" for k, v in bad) + f": {exc}")


def variants(seeds, vary: Mapping[str, Sequence] | None = None) -> list[Variant]:
    """Every (seed, varied values) of a batch, seeds first: the cartesian product of the
    values of the settings in ``vary`` (setting -> values), for each seed. A value whose
    text is not a short plain word (a crater spec) is named by its place, ``v1``, ``v2``.

    Examples
    --------
    >>> [v.name for v in variants("1-2", {"radius_m": [1000.0, 2000.0]})]
    ['seed0001_radius-m=1000', 'seed0001_radius-m=2000', 'seed0002_radius-m=1000', \
'seed0002_radius-m=2000']
    """
    seeds = parse_seeds(seeds)
    vary = _checked(vary, None)
    count = len(seeds)
    for values in vary.values():
        count *= len(values)
    if count > MAX_VARIANTS:
        raise ParameterError("vary", f"makes {count} variants; at most {MAX_VARIANTS}")
    labels = {}
    for key, values in vary.items():
        texts = [value_text(v) for v in values]
        labels[key] = [t if _SAFE.fullmatch(t) else f"v{i + 1}" for i, t in enumerate(texts)]
    width = max(4, len(str(max(seeds))))
    keys = list(vary)
    out = []
    for seed in seeds:
        for picks in itertools.product(*(range(len(vary[k])) for k in keys)):
            pairs = tuple(zip(keys, picks, strict=True))
            name = f"seed{seed:0{width}d}" + "".join(
                f"_{k.replace('_', '-')}={labels[k][i]}" for k, i in pairs)
            out.append(Variant(name, seed, tuple((k, vary[k][i]) for k, i in pairs)))
    return out


def _same(a, b) -> bool:
    try:
        return bool(a == b)
    except (TypeError, ValueError):
        return False


@dataclasses.dataclass(frozen=True)
class Job:
    """A variant, what its task takes, and what defines its bytes."""

    variant: Variant
    payload: Any
    """The task's input (pickled to a worker)."""
    describe: str
    """Text of everything that makes the variant's bytes (its settings hash)."""
    expected: tuple[str, ...]
    """The names the variant puts in the batch folder (files, or a stack's folder)."""


@dataclasses.dataclass(frozen=True)
class BatchResult:
    """What a batch did."""

    folder: Path
    """The batch folder (holding ``index.csv``)."""
    rows: tuple[dict, ...]
    """The index rows of this batch's variants, in variant order."""
    done: int
    """Variants built by this run."""
    skipped: int
    """Variants kept from an earlier run (``resume``)."""
    failed: int
    """Variants that failed."""
    seconds: float
    """Wall time of the run."""

    @property
    def index(self) -> Path:
        return self.folder / INDEX

    @property
    def variants_per_hour(self) -> float:
        """Variants built per hour of wall time (0 if none were built)."""
        return 3600.0 * self.done / self.seconds if self.done and self.seconds > 0 else 0.0


def _columns(keys: Sequence[str]) -> list[str]:
    return ["variant", "seed", *keys, "files", "sha256", "seconds", "peak_mb", "status",
            "error", "settings_sha256"]


def read_index(path) -> list[dict]:
    """The rows of a batch's ``index.csv`` (a row cut short by a killed batch is left out);
    the last row of a variant wins."""
    with open(path, newline="", encoding="utf-8") as fh:
        reader = csv.DictReader(fh)
        try:
            rows = {r["variant"]: r for r in reader
                    if None not in r.values() and r.get("status") in ("ok", "failed")
                    and len(r.get("settings_sha256") or "") == 64}
        except (csv.Error, KeyError) as exc:  # a field over 128 KiB; no variant column
            raise ValueError(f"batch index {str(path)!r} is not one a batch wrote: "
                             f"{exc}") from None
    return list(rows.values())


def _intact(row: dict | None, job: Job, folder: Path) -> bool:
    """The variant's row says ok for the same settings and every file has its sha256."""
    if row is None or row["status"] != "ok" or row["settings_sha256"] != _sha_text(job.describe):
        return False
    files, shas = row["files"].split(";"), row["sha256"].split(";")
    if not row["files"] or len(files) != len(shas):
        return False
    tops = {f.split("/")[0] for f in files}
    return set(job.expected) <= tops and all(
        (folder / f).is_file() and sha256_file(folder / f) == s
        for f, s in zip(files, shas, strict=True))


def _sha_text(text: str) -> str:
    return hashlib.sha256(text.encode("utf-8")).hexdigest()


def _check_folder(out, jobs: Sequence[Job], *, resume: bool, force: bool) -> Path:
    if out is None:
        raise ParameterError("out", "is required: the batch folder")
    folder = Path(out).resolve()
    check_parent_folder(folder)
    if folder.exists() and not folder.is_dir():
        raise ParameterError("out", f"{str(out)!r} exists and is not a folder")
    if resume and force:
        raise ParameterError("resume", "and {} cannot be combined", see=("force",))
    if not (resume or force) and folder.is_dir():
        if (folder / INDEX).exists():
            raise ParameterError("out", f"{str(out)!r} holds a batch ({INDEX}): give {{}} to "
                                 "finish it or {} to redo it", see=("resume", "force"))
        for job in jobs:
            for name in job.expected:
                if (folder / name).exists() or (folder / name).is_symlink():
                    raise ParameterError("out", f"{str(folder / name)!r} exists; use {{}} to "
                                         "overwrite", see=("force",))
    return folder


def _row(job: Job, rec: dict) -> dict:
    row = {"variant": job.variant.name, "seed": job.variant.seed,
           **{k: value_text(v) for k, v in job.variant.values},
           "files": ";".join(rec.get("files", ())), "sha256": ";".join(rec.get("sha256", ())),
           "seconds": f"{rec['seconds']:.2f}" if "seconds" in rec else "",
           "peak_mb": f"{rec['peak_mb']:.0f}" if rec.get("peak_mb") is not None else "",
           "status": rec["status"], "error": rec.get("error", ""),
           "settings_sha256": _sha_text(job.describe)}
    return row


def _write_index(path: Path, columns: list[str], rows: Iterable[dict]) -> None:
    with atomic_path(path) as tmp, open(tmp, "w", newline="", encoding="utf-8") as fh:
        writer = csv.DictWriter(fh, columns)
        writer.writeheader()
        writer.writerows(rows)


def run_batch(jobs: Sequence[Job], task: Callable[[Any, Path, str], None], out, *,
              backend: str | None = None, scheduler: str | None = None,
              workers: int | None = None, resume: bool = False, force: bool = False,
              progress: bool = False, retries: int = 2,
              on_done: Callable[[dict], None] | None = None,
              connect_timeout_s: float | None = None) -> BatchResult:
    """Run ``task(payload, folder, name)`` of every job into the folder ``out`` (module
    notes) on ``backend`` (:func:`.backends.choose_backend`; default: dask, a local
    cluster unless a ``scheduler`` is given, which must answer within
    ``connect_timeout_s``); ``on_done(row)`` after each finished variant (in the caller)."""
    started = time.perf_counter()
    names = [j.variant.name for j in jobs]
    if not jobs or len(set(names)) != len(names):
        raise ParameterError("jobs", "must be a non-empty list of uniquely named variants")
    choose_backend(backend, scheduler, workers, connect_timeout_s=connect_timeout_s)
    folder = _check_folder(out, jobs, resume=resume, force=force)
    took = lock_output(folder)  # a second batch into this folder fails fast, naming this one
    try:
        return _fill(folder, jobs, task, backend=backend, scheduler=scheduler, workers=workers,
                     resume=resume, progress=progress, retries=retries, on_done=on_done,
                     started=started, connect_timeout_s=connect_timeout_s)
    finally:
        if took:
            unlock_output(folder)


def _fill(folder: Path, jobs: Sequence[Job], task, *, backend, scheduler, workers, resume,
          progress, retries, on_done, started, connect_timeout_s) -> BatchResult:
    """:func:`run_batch` in its checked and locked folder."""
    names = [j.variant.name for j in jobs]
    columns = _columns([k for k, _ in jobs[0].variant.values])
    index = folder / INDEX
    previous = _previous_rows(index, columns) if resume and index.is_file() else {}
    todo = [j for j in jobs if not _intact(previous.get(j.variant.name), j, folder)]
    rows = {name: previous[name] for name in names if name in previous}
    ours = set(names)
    others = [r for name, r in previous.items() if name not in ours]
    redo = {j.variant.name for j in todo}
    with (open_backend(backend, scheduler=scheduler, workers=workers, default="dask",
                       connect_timeout_s=connect_timeout_s)
          if todo else contextlib.nullcontext()) as runner:
        folder.mkdir(exist_ok=True)  # only once the cluster is there
        for stale in folder.glob(f".*{TMP_SUFFIX}"):
            shutil.rmtree(stale, ignore_errors=True)
        _write_index(index, columns, [*others, *(rows[n] for n in names
                                                 if n in rows and n not in redo)])
        if todo:
            assert runner is not None  # open_backend's, as there is work
            _collect(runner, todo, task, folder, columns, rows, retries=retries,
                     progress=progress, on_done=on_done)
    _write_index(index, columns, [*others, *(rows[n] for n in names)])
    mine = [rows[n] for n in names]
    failed = sum(r["status"] != "ok" for r in mine)
    return BatchResult(folder, tuple(mine), done=sum(r["status"] == "ok" for r in mine
                                                     if r["variant"] in redo),
                       skipped=len(jobs) - len(todo), failed=failed,
                       seconds=time.perf_counter() - started)


def _previous_rows(index: Path, columns: list[str]) -> dict[str, dict]:
    """The rows of an earlier run's index by variant (``resume``); its columns must be
    this batch's."""
    with open(index, newline="", encoding="utf-8") as fh:
        try:
            header = next(csv.reader(fh), [])
        except csv.Error as exc:
            raise ParameterError("resume", f"{str(index)!r} is not a batch index: {exc}") \
                from None
    if header != columns:
        raise ParameterError("resume", f"{str(index)!r} has the columns {header}; this "
                             f"batch's are {columns}")
    return {r["variant"]: r for r in read_index(index)}


def _variant_task(shared, item) -> dict:
    """A batch's task on the backend: one variant (:func:`.batch_tasks.run_variant`)."""
    task, folder = shared
    payload, name = item
    return run_variant(task, payload, folder, name)


def _collect(runner: Backend, todo: Sequence[Job], task, folder: Path, columns: list[str],
             rows: dict, *, retries: int, progress: bool, on_done) -> None:
    """Run one task per job, all submitted at once, and append each finished variant's
    row to the index."""
    items = [(j.payload, j.variant.name) for j in todo]
    bar = progress_bar(total=len(todo), enabled=progress, desc="batch")
    try:
        with open(folder / INDEX, "a", newline="", encoding="utf-8") as fh:
            writer = csv.DictWriter(fh, columns)
            for i, rec in runner.map(_variant_task, items, shared=(task, str(folder)),
                                     window=len(items), retries=retries, errors="return",
                                     label="batch"):
                if isinstance(rec, Exception):  # retries spent, worker lost too often, ...
                    rec = {"status": "failed", "error": one_line(rec)}
                job = todo[i]
                row = rows[job.variant.name] = _row(job, rec)
                writer.writerow(row)
                fh.flush()
                bar.update()
                if on_done is not None:
                    on_done(row)
    finally:
        bar.close()
