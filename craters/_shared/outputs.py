"""The safety of a run's outputs: the project's temporary names, sweeping the temporaries
of killed runs, output locks, output groups that appear together or not at all, outputs
that are never an input.

Every temporary the project writes next to an output is named
``.<name>.<pid>.<8 random characters>.tmp<suffix>`` (:func:`temp_file`,
:func:`temp_folder`), so the next run into the same folder can remove what a killed run
left (:func:`sweep_temporaries`: only these names, only when their process is gone or
they are a week old; never another file).

An output group (:func:`output_group`; the command lines run every command but batches
in one) is a run: each output it checks is locked (:func:`claim`: ``.<name>.lock``,
``flock``) so that a second run writing it fails at once naming this one, or inside
:func:`waiting` (``--wait``) waits until this one ends; each output
finished inside (:func:`replace_output`) is staged under a temporary name, and when the
group ends without an error all are moved into place back to back, after a journal that
lets the next run take them back if this one is killed in between. A failed run (an
error, Ctrl-C, SIGTERM) writes nothing, and a ``.glb`` never stands next to another run's
``.json``. Groups nest: an inner group that succeeds hands its outputs to the outer one.
"""

from __future__ import annotations

import contextlib
import contextvars
import fcntl
import json
import logging
import os
import re
import secrets
import shutil
import time
from collections.abc import Iterable, Iterator
from dataclasses import dataclass, field
from pathlib import Path

__all__ = ["TEMP_MAX_AGE_S", "check_outside_folder", "claim", "lock_output", "output_group",
           "replace_output", "same_file", "staged_path", "sweep_temporaries", "temp_file",
           "temp_folder", "unlock_output", "waiting"]

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
    entries.sort(key=lambda e: not e.name.endswith(".journal"))  # take back killed runs first
    for entry in entries:
        m = _TEMP_NAME.match(entry.name)
        if m is None and entry.name.endswith(".lock"):
            _remove_stale_lock(Path(entry.path))
        if m is None or int(m["pid"]) == me:
            continue
        try:
            st = entry.stat(follow_symlinks=False)
        except OSError:
            continue
        if not (_process_gone(int(m["pid"])) or now - st.st_mtime > TEMP_MAX_AGE_S):
            continue
        if entry.name.endswith(".journal"):
            _recover(Path(entry.path))
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


# --------------------------------------------------------------------------- locks
_HELD: dict[str, tuple[int, Path]] = {}  # this process's output locks: path -> (fd, lock file)
_WAIT: contextvars.ContextVar[bool] = contextvars.ContextVar("craterform_wait", default=False)
_WAIT_POLL_S = 0.2


@contextlib.contextmanager
def waiting(wait: bool = True) -> Iterator[None]:
    """Inside (with ``wait``), :func:`lock_output` waits for another run writing the output
    to end (polling its lock; logged once) instead of refusing at once."""
    token = _WAIT.set(bool(wait))
    try:
        yield
    finally:
        _WAIT.reset(token)


def lock_output(path) -> bool:
    """Take the advisory lock of the output ``path``: ``.<name>.lock`` beside it, locked
    with ``flock`` and holding this process's id (the kernel drops the lock when the process
    dies, however it dies). False if this process holds it already; if another run holds
    it, a one-line ValueError naming it, or inside :func:`waiting` the wait for its end."""
    key = os.path.abspath(path)
    if key in _HELD:
        return False
    name = _folder_of(Path(path)) / f".{Path(path).name}.lock"
    told = False
    while True:
        fd = os.open(name, os.O_RDWR | os.O_CREAT | os.O_NOFOLLOW | os.O_CLOEXEC, 0o666)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            other = os.pread(fd, 32, 0).decode("ascii", "replace").split()[-1:] or ["?"]
            os.close(fd)
            if _WAIT.get():
                if not told:
                    logger.warning("waiting for process %s to finish writing %s", other[0],
                                   path)
                    told = True
                time.sleep(_WAIT_POLL_S)
                continue
            raise ValueError(f"output {str(path)!r} is being written by another run (process "
                             f"{other[0]}, lock {str(name)!r}); let it finish first") from None
        if _ident(name) == tuple(os.fstat(fd))[1:3]:  # the file it locked is still there
            break
        os.close(fd)  # its last holder removed it meanwhile: lock the file there now
    os.ftruncate(fd, 0)
    os.pwrite(fd, f"craterform {os.getpid()}\n".encode(), 0)  # what a stale lock shows
    _HELD[key] = (fd, name)
    return True


def _remove_stale_lock(name: Path) -> None:
    """Remove an output lock (:func:`lock_output`) its killed run left: a pid line of a
    process that is gone, and nobody holds it."""
    try:
        fd = os.open(name, os.O_RDWR | os.O_NOFOLLOW | os.O_CLOEXEC)
    except OSError:
        return
    try:
        text = os.pread(fd, 32, 0).decode("ascii", "replace")
        m = re.fullmatch(r"craterform ([0-9]{1,10})\n", text)
        if m is not None and _process_gone(int(m[1])):
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            if _ident(name) == tuple(os.fstat(fd))[1:3]:
                os.unlink(name)
    except OSError:
        pass
    finally:
        os.close(fd)


def unlock_output(path) -> None:
    """Release (and remove) the lock :func:`lock_output` took on ``path``."""
    fd, name = _HELD.pop(os.path.abspath(path), (-1, Path()))
    if fd >= 0:
        with contextlib.suppress(OSError):
            os.unlink(name)
        os.close(fd)


def claim(path, *, force: bool) -> None:
    """Inside an output group (a command's run): lock ``path`` until the run ends, and
    without ``force`` make its move into place refuse a file that appeared meanwhile (the
    check at the start is repeated at the rename, atomically)."""
    root = _ROOT.get()
    if root is None:
        return
    if lock_output(path):
        root.locked.append(os.path.abspath(path))
    if not force:
        root.keep.add(os.path.abspath(path))


# --------------------------------------------------------------------------- groups
@dataclass
class _Entry:
    path: str
    backup: str | None  # where the replaced output waits until the run ends
    new: tuple[int, int] | None  # (inode, device) of the new output


@dataclass
class _Group:
    staged: list[tuple[Path, Path]] = field(default_factory=list)  # (temporary, output)
    parent: _Group | None = None
    locked: list[str] = field(default_factory=list)
    keep: set[str] = field(default_factory=set)

    def commit(self) -> None:
        """Journal, then move every staged output into place back to back; a failure (or a
        signal) in between takes back what moved. A run killed in between is taken back
        by the next sweep of one of its folders (:func:`sweep_temporaries` reads the
        journal): readers find the complete old outputs or the complete new ones."""
        if not self.staged:
            return
        entries = [_Entry(os.path.abspath(path), _backup_name(path), _ident(tmp))
                   for tmp, path in self.staged]
        journals = _write_journals(entries)
        try:
            for (tmp, _), entry in zip(self.staged, entries, strict=True):
                _install(tmp, entry, keep=entry.path in self.keep)
        except BaseException:
            _take_back(entries)
            raise
        finally:
            self.discard()
            for j in journals:
                _remove(j)
        for e in entries:
            if e.backup is not None:
                _remove(Path(e.backup))

    def discard(self) -> None:
        for tmp, _ in self.staged:
            _remove(tmp)
        self.staged.clear()


_GROUP: contextvars.ContextVar[_Group | None] = contextvars.ContextVar("craterform_outputs",
                                                                     default=None)
_ROOT: contextvars.ContextVar[_Group | None] = contextvars.ContextVar("craterform_run",
                                                                    default=None)


def _ident(path) -> tuple[int, int] | None:
    """(inode, device) of ``path`` itself (a link is not followed)."""
    try:
        return tuple(os.lstat(path))[1:3]  # type: ignore[return-value]
    except OSError:
        return None


def _remove(path: Path) -> None:
    if os.path.isdir(path) and not os.path.islink(path):
        shutil.rmtree(path, ignore_errors=True)
    else:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(path)


def _backup_name(path: Path) -> str | None:
    if not os.path.lexists(path):
        return None
    name = temp_file(path, ".bak")  # reserves the name; the backup takes it
    os.unlink(name)
    return str(name.absolute())


def _write_journals(entries: list[_Entry]) -> list[Path]:
    """One journal in each folder the run writes into (a sweep of any of them finds it)."""
    folders = dict.fromkeys(_folder_of(Path(e.path)) for e in entries)
    journals = [temp_file(f / "outputs", ".journal") for f in folders]
    text = json.dumps({"outputs": [[e.path, e.backup, e.new] for e in entries],
                       "journals": [str(j.absolute()) for j in journals]})
    for j in journals:
        j.write_text(text, encoding="utf-8")
    return journals


def _install(tmp: Path, entry: _Entry, *, keep: bool) -> None:
    """Move one staged output into place; the one it replaces waits as ``entry.backup``
    (a hard link to a file, the moved folder)."""
    path = entry.path
    appeared = ValueError(f"output {path!r} appeared while this run wrote it; nothing was "
                          f"replaced")
    if os.path.lexists(path) and (keep or entry.backup is None):
        raise appeared
    if entry.backup is not None and os.path.lexists(path):
        if os.path.isdir(tmp):
            os.replace(path, entry.backup)
        else:
            try:
                os.link(path, entry.backup, follow_symlinks=False)
            except OSError:  # no hard links here: a copy
                shutil.copy2(path, entry.backup, follow_symlinks=False)
    if keep and not os.path.isdir(tmp):
        try:
            os.link(tmp, path)  # never replaces a file that appeared this instant
            return
        except FileExistsError:
            raise appeared from None
        except OSError:  # no hard links here
            pass
    os.replace(tmp, path)


def _take_back(entries: list[_Entry]) -> None:
    """Put back what ``entries`` replaced: the new output removed where it is in place,
    the backup moved back where the output is missing; a backup not needed removed."""
    for e in reversed(entries):
        try:
            if e.new is not None and _ident(e.path) == e.new:
                _remove(Path(e.path))
            if e.backup is not None and os.path.lexists(e.backup):
                if os.path.lexists(e.path):  # the old output is in place: a spare link
                    _remove(Path(e.backup))
                else:
                    os.replace(e.backup, e.path)
        except OSError as exc:
            logger.warning("could not take back %s: %s", e.path, exc)


def _recover(journal: Path) -> None:
    """Take back the outputs of a run killed while it moved them into place."""
    try:
        record = json.loads(journal.read_text(encoding="utf-8"))
        entries = [_Entry(p, b, None if n is None else (int(n[0]), int(n[1])))
                   for p, b, n in record["outputs"]]
        journals = [Path(j) for j in record["journals"]]
    except (OSError, ValueError, KeyError, TypeError):
        return
    _take_back(entries)
    for j in journals:
        _remove(j)
    logger.warning("took back the outputs of a killed run: %s",
                   ", ".join(e.path for e in entries))


@contextlib.contextmanager
def output_group() -> Iterator[None]:
    """Outputs moved into place inside (:func:`replace_output`) appear together or not at
    all: they are staged, and moved into place back to back when the outermost group ends
    without an error; on any exception (KeyboardInterrupt included) nothing is moved. The
    outermost group is a run: the outputs it :func:`claim` stay locked until it ends."""
    outer = _GROUP.get()
    group = _Group(parent=outer)
    token = _GROUP.set(group)
    root = _ROOT.set(group) if outer is None else None
    try:
        yield
        if outer is None:
            group.commit()
        else:
            outer.staged.extend(group.staged)
    except BaseException:
        group.discard()
        raise
    finally:
        _GROUP.reset(token)
        if root is not None:
            _ROOT.reset(root)
            for path in group.locked:
                unlock_output(path)


def replace_output(tmp, path) -> None:
    """Move the finished temporary ``tmp`` (a file or a folder) onto ``path``; inside an
    :func:`output_group` it is staged (renamed to a temporary name of ``path``'s) and moved
    when the group ends (at once inside a temporary folder: that is not an output yet).
    A folder replaces a folder whole."""
    tmp, path = Path(tmp), Path(path)
    group = _GROUP.get()
    # inside a temporary folder (work in progress, itself an output later): at once
    if group is not None and not any(_TEMP_NAME.match(p.name) for p in path.parents):
        staged = (temp_folder if tmp.is_dir() and not tmp.is_symlink() else temp_file)(
            path, ".new")
        os.replace(tmp, staged)
        group.staged.append((staged, path))
        return
    if tmp.is_dir() and not tmp.is_symlink() and os.path.lexists(path):
        entry = _Entry(os.path.abspath(path), _backup_name(path), None)
        _install(tmp, entry, keep=False)
        if entry.backup is not None:
            _remove(Path(entry.backup))
        return
    os.replace(tmp, path)


def staged_path(path) -> Path:
    """Where the output ``path`` is now: its staged temporary while the run that wrote it
    goes on (:func:`replace_output`), else ``path``."""
    group, key = _GROUP.get(), os.path.abspath(path)
    while group is not None:
        for tmp, out in reversed(group.staged):
            if os.path.abspath(out) == key:
                return tmp
        group = group.parent
    return Path(path)


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
