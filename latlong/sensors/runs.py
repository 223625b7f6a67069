"""Run folders of the sensors (:func:`~latlong.sensors.camera_files.camera_run`,
:func:`~latlong.sensors.lidar_files.lidar_run`): the output folder is checked before any
work (:func:`check_output_folder`), a run is written into a hidden temporary folder next
to it and moved into place at the end as one unit (:func:`run_folder`), so that an
error leaves nothing behind, a reader finds the whole old run or the whole new one, and
files the project did not write there are kept.
"""

from __future__ import annotations

import contextlib
import json
import os
import shutil
from collections.abc import Iterator
from pathlib import Path

from craters._shared import replace_output, sweep_temporaries, temp_folder
from craters._shared.outputs import claim

__all__ = ["check_output_folder", "move_run", "run_folder"]


def check_output_folder(folder, *, force: bool) -> Path:
    """An output folder: not a symlink, not a file, its parent exists; an existing folder
    only with ``force`` (ValueError otherwise)."""
    folder = Path(folder)
    if folder.is_symlink():
        raise ValueError(f"output folder {str(folder)!r} is a symbolic link; give a real "
                         "folder")
    if folder.exists() and not folder.is_dir():
        raise ValueError(f"output {str(folder)!r} exists and is not a folder")
    parent = folder.parent if str(folder.parent) else Path(".")
    if not parent.is_dir():
        raise ValueError(f"output folder {str(folder)!r}: {str(parent)!r} does not exist")
    if not os.access(parent, os.W_OK | os.X_OK):
        raise ValueError(f"output folder {str(folder)!r}: {str(parent)!r} is not writable")
    if folder.exists() and any(folder.iterdir()) and not force:
        raise ValueError(f"output folder {str(folder)!r} exists and is not empty; use "
                         "--force to write into it")
    sweep_temporaries(parent)
    claim(folder, force=force)
    return folder


@contextlib.contextmanager
def run_folder(folder, manifest: str) -> Iterator[Path]:
    """A temporary folder next to ``folder`` to write a run into; when the block ends
    without an error it is moved into place (:func:`move_run`); on an error it is removed."""
    folder = Path(folder)
    tmp = temp_folder(folder)
    try:
        yield tmp
        move_run(tmp, folder, manifest)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


#: Files of a run that its manifest does not name (the datasets, a descent's strip).
RUN_EXTRAS = ("coco.json", "colmap", "transforms.json", "strip.png")


def move_run(tmp: Path, folder: Path, manifest: str) -> None:
    """Move the finished run in ``tmp`` into place as one unit (its files and folders have
    the umask's modes: :func:`~craters._shared.outputs.temp_folder`). A run already in
    ``folder`` is replaced whole - no old frame stays beside the new ones - but what the
    project did not write there (not named by its ``manifest``) is carried over."""
    if folder.is_dir():
        ours = _run_entries(folder / manifest) | {manifest, *RUN_EXTRAS}
        for entry in folder.iterdir():
            if entry.name not in ours and not os.path.lexists(tmp / entry.name):
                _carry(entry, tmp / entry.name)
    replace_output(tmp, folder)


def _run_entries(manifest: Path) -> set[str]:
    """The top-level names a run's manifest mentions (its frames' files)."""
    try:
        doc = json.loads(manifest.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return set()
    names: set[str] = set()
    todo = [doc]
    while todo:
        item = todo.pop()
        if isinstance(item, dict):
            todo.extend(item.values())
        elif isinstance(item, list):
            todo.extend(item)
        elif isinstance(item, str) and 0 < len(item) < 256:
            names.add(item.split("/", 1)[0])
    return names


def _carry(src: Path, dst: Path) -> None:
    """A hard link of ``src`` (a file, a link, or a folder's files) at ``dst``; a copy where
    links cannot be made."""
    def link(a, b):
        try:
            os.link(a, b, follow_symlinks=False)
        except OSError:
            shutil.copy2(a, b, follow_symlinks=False)

    if src.is_dir() and not src.is_symlink():
        shutil.copytree(src, dst, symlinks=True, copy_function=link)
    else:
        link(src, dst)
