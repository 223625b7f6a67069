"""Output file sizes and the disk space a run needs, checked before any work (issue 34:
a build that would fill the disk is refused in a second with the estimate, not hours
later with a writer's error).

:func:`check_free_space` adds up the estimated sizes of the outputs that land on each
file system and refuses (one-line ValueError naming the outputs, the estimate, the free
space and what to change) where one has less room. :func:`mesh_file_bytes` is the size of
a lat/long body's mesh or body file by its suffix, from the bytes a vertex measured for
each format (M = 300 fBm body, 540 002 vertices, 2026-12-07; binary formats are linear
in the vertex count, the text OBJ's numbers vary a little in length).
"""

from __future__ import annotations

import os
import shutil
from collections.abc import Iterable
from pathlib import Path

from craters._shared import human_bytes

__all__ = ["BYTES_PER_VERTEX", "EXPORT_BYTES_PER_VERTEX", "GEOTIFF_BYTES_PER_PIXEL",
           "check_free_space", "mesh_file_bytes"]

#: File bytes per vertex of a lat/long body by suffix (2 triangles a vertex; the .glb's
#: manifest included; .obj: its text at about 81 B, counted at 60 so that a body that
#: fits is never refused).
BYTES_PER_VERTEX = {".npz": 8.0, ".ply": 42.0, ".obj": 60.0, ".stl": 100.0, ".vtk": 56.0,
                    ".vtp": 48.0, ".glb": 34.0}

#: ... of ``latlong export``'s files: the patched-strip .glb with its manifest (each level
#: of detail counted with its own vertices), the triangle-strip .vtp.
EXPORT_BYTES_PER_VERTEX = {".glb": 34.0, ".vtp": 56.0}

#: ... of a float32 height GeoTIFF as the project writes it (deflate, floating-point
#: predictor), a pixel: a 4-layer stack of 257^2 over the LOLA crop measured 3.70 bytes
#: a pixel on 2026-12-07, counted at 3.6 so that a run that fits runs.
GEOTIFF_BYTES_PER_PIXEL = 3.6


def mesh_file_bytes(path, n_vertices: int) -> float:
    """Estimated size of a lat/long body of ``n_vertices`` written to ``path`` (by its
    suffix; 0 for a suffix not in :data:`BYTES_PER_VERTEX`)."""
    return BYTES_PER_VERTEX.get(Path(path).suffix.lower(), 0.0) * float(n_vertices)


def _folder(path) -> Path:
    parent = Path(path).parent
    return parent if str(parent) else Path(".")


def check_free_space(needs: Iterable[tuple[object, float]], *, hint: str) -> None:
    """Refuse up front outputs that do not fit: ``needs`` pairs (output path, estimated
    bytes), summed per file system (the device of each output's folder); where the sum is
    over the free space, a one-line ValueError with the outputs, the estimate, the free
    space and ``hint`` (what to change). Folders that do not exist are left to the output
    checks."""
    by_device: dict[int, tuple[Path, list[str], float]] = {}
    for path, size in needs:
        folder = _folder(path)
        try:
            device = os.stat(folder).st_dev
        except OSError:
            continue
        where, names, total = by_device.get(device, (folder, [], 0.0))
        by_device[device] = (where, [*names, str(path)], total + float(size))
    for where, names, total in by_device.values():
        free = shutil.disk_usage(where).free
        if total > free:
            shown = ", ".join(repr(n) for n in names[:3]) + (" ..." if len(names) > 3 else "")
            raise ValueError(f"output {shown} needs about {human_bytes(total)}; "
                             f"{str(where)!r} has {human_bytes(free)} free; {hint}")
