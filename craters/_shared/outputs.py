"""The safety of a run's outputs: the project's temporary names, sweeping the temporaries
of killed runs, output groups that appear together or not at all, outputs that are never
an input.

Every temporary the project writes next to an output is named
``.<name>.<pid>.<8 random characters>.tmp<suffix>`` (:func:`temp_file`,
:func:`temp_folder`), so the next run into the same folder can remove what a killed run
left (:func:`sweep_temporaries`: only these names, only when their process is gone or
they are a week old; never another file).

An output group (:func:`output_group`; the command lines run every command but batches
in one) remembers each output moved into place (:func:`replace_output`) with a hard link
to the file it replaced; if the group fails (an error, Ctrl-C, SIGTERM) every output of
it is taken back and the replaced files restored, so a failed run writes nothing and a
``.glb`` never stands next to another run's ``.json``. Groups nest: an inner group that
succeeds hands its outputs to the outer one.
"""

from __future__ import annotations

import contextlib
import contextvars
import logging
import os
import re
import secrets
import shutil
import time
from collections.abc import Iterable, Iterator
from dataclasses import dataclass, field
from pathlib import Path

__all__ = ["TEMP_MAX_AGE_S", "check_outside_folder", "output_group",
           "replace_output", "same_file", "sweep_temporaries", "temp_file", "temp_folder"]

logger = logging.getLogger(__name__)

#: A temporary whose process still runs is swept only after this long unchanged.
TEMP_MAX_AGE_S = 7 * 24 * 3600.0

_TEMP_NAME = re.compile(r"^\..+\.(?P<pid>[0-9]{1,10})\.[a-z0-9_]{8}\.tmp[^/]*$")


def _folder_of(path: Path) -> Path:
    return path.parent if str(path.parent) else Path(".")


def _new_temporary(path, suffix: str, make) -> Path:
    """``make`` a new entry next to ``path`` under a fresh temporary name."""
    path = Path(path)
    for _ in range(100):
        name = _folder_of(path) / f".{path.name}.{os.getpid()}.{secrets.token_hex(4)}.tmp{suffix}"
        with contextlib.suppress(FileExistsError):
            make(name)
            return name
    raise FileExistsError(f"no free temporary name next to {str(path)!r}")


def temp_file(path, suffix: str = "") -> Path:
    """Create an empty temporary file next to ``path`` under the project's temporary name
    (``.<name>.<pid>.<random>.tmp<suffix>``) and return its path; its mode is what the
    umask gives a new file (0644 with 022), the output's once it is moved into place."""
    return _new_temporary(path, suffix, lambda p: os.close(
        os.open(p, os.O_CREAT | os.O_EXCL | os.O_WRONLY, 0o666)))


def temp_folder(path, suffix: str = "") -> Path:
    """Create an empty temporary folder next to ``path`` (named like :func:`temp_file`,
    the umask's mode: 0755 with 022)."""
    return _new_temporary(path, suffix, lambda p: os.mkdir(p, 0o777))


def _process_gone(pid: int) -> bool:
    try:
        if pid > 0:  # 0 and -1 would signal process groups
            os.kill(pid, 0)
    except ProcessLookupError:
        return True
    except (OverflowError, OSError):  # another user's process, or not a process number
        pass
    return False


_SWEPT: set = set()


def sweep_temporaries(folder, *, now: float | None = None) -> list[Path]:
    """Remove the temporaries of killed runs from ``folder``: only files and folders under
    the project's temporary name (:func:`temp_file`) whose process is gone (or that have
    not changed for :data:`TEMP_MAX_AGE_S`), never this process's own. Returns what it
    removed; a folder it cannot list is left alone. Each folder is swept once a process."""
    folder = Path(folder) if str(folder) else Path(".")
    key = os.path.abspath(folder)
    if now is None:
        if key in _SWEPT:
            return []
        _SWEPT.add(key)
    now = time.time() if now is None else now
    removed: list[Path] = []
    try:
        entries = list(os.scandir(folder))
    except OSError:
        return removed
    me = os.getpid()
    for entry in entries:
        m = _TEMP_NAME.match(entry.name)
        if m is None or int(m["pid"]) == me:
            continue
        try:
            st = entry.stat(follow_symlinks=False)
        except OSError:
            continue
        if not (_process_gone(int(m["pid"])) or now - st.st_mtime > TEMP_MAX_AGE_S):
            continue
        try:
            if entry.is_dir(follow_symlinks=False):
                shutil.rmtree(entry.path)
            else:
                os.unlink(entry.path)
        except OSError as exc:
            logger.debug("could not remove the temporary %s: %s", entry.path, exc)
            continue
        removed.append(Path(entry.path))
    if removed:
        logger.info("removed %d temporaries of killed runs from %s", len(removed), folder)
    return removed


# --------------------------------------------------------------------------- groups
@dataclass
class _Moved:
    path: Path
    backup: Path | None
    ident: tuple[int, int] | None
    holder: Path | None  # a replaced folder waits in holder/old


@dataclass
class _Group:
    moved: list[_Moved] = field(default_factory=list)

    def commit(self) -> None:
        for m in self.moved:
            gone = m.holder or m.backup
            if gone is not None:
                _remove(gone)
        self.moved.clear()

    def rollback(self) -> None:
        for m in reversed(self.moved):
            try:
                if _ident(m.path) == m.ident:
                    _remove(m.path)
                if m.backup is not None and os.path.lexists(m.backup):
                    if os.path.lexists(m.path):  # never moved: the backup is a link to it
                        _remove(m.backup)
                    else:
                        os.replace(m.backup, m.path)
                if m.holder is not None:
                    _remove(m.holder)
            except OSError as exc:
                logger.warning("could not take back %s: %s", m.path, exc)
        self.moved.clear()


_GROUP: contextvars.ContextVar[_Group | None] = contextvars.ContextVar("craterform_outputs",
                                                                     default=None)


def _ident(path: Path) -> tuple[int, int] | None:
    try:
        st = os.lstat(path)
    except OSError:
        return None
    return st.st_dev, st.st_ino


def _remove(path: Path) -> None:
    if os.path.isdir(path) and not os.path.islink(path):
        shutil.rmtree(path, ignore_errors=True)
    else:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(path)


@contextlib.contextmanager
def output_group() -> Iterator[None]:
    """Outputs moved into place inside (:func:`replace_output`) appear together or not at
    all: on any exception (KeyboardInterrupt included) each is taken back and the file
    it replaced restored."""
    outer = _GROUP.get()
    group = _Group()
    token = _GROUP.set(group)
    try:
        yield
    except BaseException:
        group.rollback()
        raise
    else:
        if outer is None:
            group.commit()
        else:
            outer.moved.extend(group.moved)
    finally:
        _GROUP.reset(token)


def replace_output(tmp, path) -> None:
    """Move the finished temporary ``tmp`` (a file or a folder) onto ``path``; inside an
    :func:`output_group` the group can take it back. A folder replaces a folder: the old
    one is removed once the move is final."""
    tmp, path = Path(tmp), Path(path)
    group = _GROUP.get()
    if tmp.is_dir() and not tmp.is_symlink():
        holder = temp_folder(path, ".old") if os.path.lexists(path) else None
        if group is not None:  # recorded first: a signal from here on is taken back
            group.moved.append(_Moved(path, None if holder is None else holder / "old",
                                      _ident(tmp), holder))
        try:
            if holder is not None:
                os.replace(path, holder / "old")
            os.replace(tmp, path)
        except BaseException:
            if group is None and holder is not None:
                if not os.path.lexists(path) and os.path.lexists(holder / "old"):
                    os.replace(holder / "old", path)
                _remove(holder)
            raise
        if group is None and holder is not None:
            _remove(holder)
        return
    if group is None:
        os.replace(tmp, path)
        return
    backup = None
    if os.path.lexists(path):
        backup = temp_file(path, ".bak")
        os.unlink(backup)
        try:
            os.link(path, backup, follow_symlinks=False)
        except OSError:  # no hard links here: a copy
            shutil.copy2(path, backup, follow_symlinks=False)
    group.moved.append(_Moved(path, backup, _ident(tmp), None))
    os.replace(tmp, path)


# --------------------------------------------------------------------------- inputs
def same_file(a, b) -> bool:
    """``a`` and ``b`` name the same file: the same path through symlinks and ``..``, or
    hard links of one file."""
    a, b = Path(a), Path(b)
    if a.resolve() == b.resolve():
        return True
    try:
        return os.path.samefile(a, b)
    except OSError:
        return False


def check_outside_folder(folder, inputs: Iterable, *, flag: str = "-o/--output") -> None:
    """Raise a one-line ValueError if an input (pairs of (what, path)) lies inside the
    output ``folder`` that a run replaces."""
    root = Path(folder).resolve()
    for what, inp in inputs:
        if inp is None or not str(inp):
            continue
        where = Path(inp).resolve()
        if where == root or where.is_relative_to(root):
            raise ValueError(f"{flag} {str(folder)!r} holds the input {what} {str(inp)!r}; "
                             f"choose another output folder: inputs are never "
                             f"overwritten".lstrip())
