"""Files: output checks before any work, atomic writes, TOML scene files."""

from __future__ import annotations

import contextlib
import os
import stat
import tomllib
from collections.abc import Iterator, Sequence
from pathlib import Path

from .outputs import claim, replace_output, sweep_temporaries, temp_file

__all__ = ["atomic_path", "check_output_path", "check_parent_folder", "check_regular_file",
           "check_suffix", "load_toml"]


def check_parent_folder(path) -> None:
    """The folder an output goes into exists and is writable (one-line ValueError)."""
    path = Path(path)
    folder = path.parent if str(path.parent) else Path(".")
    if not folder.is_dir():
        raise ValueError(f"output {str(path)!r}: folder {str(folder)!r} does not exist")
    if not os.access(folder, os.W_OK | os.X_OK):
        raise ValueError(f"output {str(path)!r}: folder {str(folder)!r} is not writable")


def check_suffix(path, suffixes: Sequence[str]) -> Path:
    """The output's suffix is one of ``suffixes`` (one-line ValueError)."""
    path = Path(path)
    if path.suffix.lower() not in suffixes:
        raise ValueError(f"output {str(path)!r}: unknown format {path.suffix or '(no suffix)'!r}"
                         f"; allowed: {' '.join(suffixes)}")
    return path


def check_output_path(path, *, force: bool, suffixes: Sequence[str] | None = None) -> Path:
    """Validate an output path before any work is done.

    Raises ValueError for an unknown suffix, an existing file without ``force``, or a
    folder that does not exist or is not writable.
    """
    path = Path(path) if suffixes is None else check_suffix(path, suffixes)
    check_parent_folder(path)
    claim(path, force=force)  # a run's outputs: locked until it ends (or waited for)
    if path.is_dir():
        raise ValueError(f"output {str(path)!r} is a folder")
    if os.path.lexists(path) and not force:  # a dangling symlink too
        raise ValueError(f"output {str(path)!r} exists; use --force to overwrite")
    sweep_temporaries(path.parent if str(path.parent) else Path("."))
    return path


@contextlib.contextmanager
def atomic_path(path) -> Iterator[Path]:
    """Yield a temporary path in the target folder; move it onto ``path`` on success.

    On any exception the temporary file is removed and ``path`` is left untouched. Inside
    an output group (:func:`~craters._shared.outputs.output_group`) the move can be taken
    back if a later output of the group fails.
    """
    tmp = temp_file(path, Path(path).suffix)
    try:
        yield tmp
        replace_output(tmp, path)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            tmp.unlink()
        raise


def check_regular_file(path, what: str, max_bytes: int | None = None) -> Path:
    """``path`` names an existing regular file (not a FIFO, device or folder) of at
    most ``max_bytes``; returns it as a Path, else a one-line ``FileNotFoundError`` (no
    such file) or ``ValueError``.

    Examples
    --------
    >>> check_regular_file("/dev/null", "config file")
    Traceback (most recent call last):
    ...
    ValueError: config file '/dev/null' is not a regular file (a device, FIFO or folder)
    """
    path = Path(path)
    try:
        st = os.stat(path)
    except FileNotFoundError:
        raise FileNotFoundError(f"{what} {str(path)!r} does not exist") from None
    except OSError as exc:
        raise ValueError(f"cannot read {what} {str(path)!r}: {exc.strerror or exc}") from None
    if not stat.S_ISREG(st.st_mode):
        raise ValueError(f"{what} {str(path)!r} is not a regular file (a device, FIFO or "
                         f"folder)")
    if max_bytes is not None and st.st_size > max_bytes:
        raise ValueError(f"{what} {str(path)!r} has {st.st_size} bytes; at most {max_bytes} "
                         f"are read")
    return path


#: Largest TOML scene or config file read, bytes (a scene is a few kilobytes).
MAX_TOML_BYTES = 16 << 20


def load_toml(path) -> dict:
    """Read a TOML scene file; errors become ValueError naming the file."""
    path = check_regular_file(path, "config file", MAX_TOML_BYTES)
    try:
        with open(path, "rb") as fh:
            return tomllib.load(fh)
    except FileNotFoundError:  # removed since the check
        raise FileNotFoundError(f"config file {str(path)!r} does not exist") from None
    except tomllib.TOMLDecodeError as exc:
        raise ValueError(f"config file {str(path)!r} is not valid TOML: {exc}") from None
    except RecursionError:
        raise ValueError(f"config file {str(path)!r} nests arrays or tables too deeply") from None
