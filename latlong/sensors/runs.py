"""Run folders of the sensors (:func:`~latlong.sensors.camera_files.camera_run`,
:func:`~latlong.sensors.lidar_files.lidar_run`): the output folder is checked before any
work (:func:`check_output_folder`), a run is written into a hidden temporary folder next
to it and moved into place at the end, its manifest last (:func:`run_folder`), so that
an error leaves nothing behind and a reader that finds the manifest finds every file it
names.
"""

from __future__ import annotations

import contextlib
import os
import shutil
from collections.abc import Iterator
from pathlib import Path

from craters._shared import replace_output, sweep_temporaries, temp_folder

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
    return folder


@contextlib.contextmanager
def run_folder(folder, manifest: str) -> Iterator[Path]:
    """A temporary folder next to ``folder`` to write a run into; when the block ends
    without an error its files are moved into ``folder`` (:func:`move_run`), and the
    temporary folder is removed in any case."""
    folder = Path(folder)
    tmp = temp_folder(folder)
    try:
        yield tmp
        move_run(tmp, folder, manifest)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


def move_run(tmp: Path, folder: Path, manifest: str) -> None:
    """Move the finished run in ``tmp`` into ``folder`` (its files and folder have the
    umask's modes: :func:`~craters._shared.outputs.temp_folder`): a rename when
    ``folder`` does not exist yet, else file by file with ``manifest`` last."""
    if not folder.exists():
        replace_output(tmp, folder)
        return
    names = sorted(p.name for p in tmp.iterdir())
    names.sort(key=lambda n: n == manifest)
    for name in names:
        replace_output(tmp / name, folder / name)
