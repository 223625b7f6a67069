"""The worker side of a batch (:mod:`latlong.parallel.batch`): one variant in a temporary
folder inside the batch folder, hashed, renamed into place, timed, with the worker's peak
resident memory during the task (the backend's worker, or this process when serial)."""

from __future__ import annotations

import contextlib
import hashlib
import os
import shutil
import sys
import tempfile
import time
import uuid
from pathlib import Path

__all__ = ["TMP_SUFFIX", "one_line", "run_variant", "sha256_file"]

#: Suffix of a variant's temporary folder (stale ones are removed when a batch starts).
TMP_SUFFIX = ".batch-tmp"


def sha256_file(path) -> str:
    """The sha256 of a file's bytes (hex)."""
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def one_line(exc: BaseException) -> str:
    """An error as one line (its type named unless it is a bad-input error)."""
    text = str(exc) or type(exc).__name__
    if not isinstance(exc, ValueError | TypeError):
        text = f"{type(exc).__name__}: {text}"
    return " ".join(text.split())


def run_variant(task, payload, folder: str, name: str) -> dict:
    """Run one variant in a worker: the task writes into a temporary folder inside the
    batch folder, then each entry is hashed and moved into place."""
    start = time.perf_counter()
    _reset_peak()
    dest = Path(folder)
    tmp = Path(tempfile.mkdtemp(prefix=f".{name}.", suffix=TMP_SUFFIX, dir=dest))
    try:
        try:
            task(payload, tmp, name)
        except (ValueError, TypeError) as exc:  # a bad variant: the same on any worker
            return {"status": "failed", "error": one_line(exc),
                    "seconds": time.perf_counter() - start, "peak_mb": _peak_mb()}
        files = sorted(p.relative_to(tmp).as_posix() for p in tmp.rglob("*") if p.is_file())
        shas = [sha256_file(tmp / f) for f in files]
        for entry in sorted(os.listdir(tmp)):
            _move(tmp / entry, dest / entry, tmp)
        return {"status": "ok", "files": files, "sha256": shas,
                "seconds": time.perf_counter() - start, "peak_mb": _peak_mb()}
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


def _move(src: Path, dst: Path, tmp: Path) -> None:
    """Move a file or folder into place (a folder already there is swapped out first)."""
    if src.is_dir() and dst.is_dir() and not dst.is_symlink():
        os.replace(dst, tmp / f".old-{uuid.uuid4().hex}")
    os.replace(src, dst)


def _reset_peak() -> None:
    """Reset this process's peak resident memory (Linux >= 4.0: /proc/self/clear_refs)."""
    with contextlib.suppress(OSError):
        with open("/proc/self/clear_refs", "w") as fh:
            fh.write("5")


def _peak_mb() -> float | None:
    """This process's peak resident memory since :func:`_reset_peak`, MB (elsewhere than
    Linux: since the process started)."""
    with contextlib.suppress(OSError, ValueError):
        with open("/proc/self/status") as fh:
            for line in fh:
                if line.startswith("VmHWM:"):
                    return int(line.split()[1]) / 1024.0
    with contextlib.suppress(ImportError):
        import resource

        peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
        return peak / (2**20 if sys.platform == "darwin" else 1024.0)
    return None
