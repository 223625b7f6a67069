"""The size of a window of terrain on demand, checked before any work: its pixels a
side and the memory they need (:func:`check_window`), imported by the command lines
before the terrain's kernels load, so a window this machine cannot hold is refused in a
fraction of a second.
"""

from __future__ import annotations

import math

from craters._shared import (
    ParameterError,
    check_positive,
    check_range,
    human_bytes,
    physical_memory_bytes,
)

__all__ = ["DESCENT_MARGIN", "MAX_TILE_PX", "TILE_BASE_BYTES", "TILE_BYTES_PER_PIXEL",
           "check_descent_memory", "check_tile_memory", "check_window"]

#: Largest tile side in pixels (a 16384^2 float64 tile is 2 GiB).
MAX_TILE_PX = 16384
#: Peak memory of a window a pixel, and its base, bytes: ``latlong tile`` with a GeoTIFF,
#: a .ply mesh and a picture peaked at 1.15 GB at 2048^2 and 3.73 GB at 4096^2 pixels
#: (``/usr/bin/time -v``, fbm-cratered, 0.1 m pixels, 2026-12-07): 205 B a pixel over
#: 0.3 GB. A 16384^2 window (55 GB) was killed by the kernel's OOM killer here.
TILE_BYTES_PER_PIXEL = 205.0
TILE_BASE_BYTES = 0.3e9
#: A descent frame's terrain window, in camera footprints (wider than the frame, so its
#: corners never see the window's edge).
DESCENT_MARGIN = 1.6


def check_tile_memory(size_px: int, name: str, what: str, change: str,
                      extra_bytes: float = 0.0) -> None:
    """Refuse up front (one line naming ``name``) a window of ``size_px`` pixels a side (plus
    ``extra_bytes``, e.g. a camera frame) that this machine's memory cannot hold."""
    need = TILE_BASE_BYTES + TILE_BYTES_PER_PIXEL * size_px**2 + extra_bytes
    have = physical_memory_bytes()
    if need > 0.8 * have:
        raise ParameterError(name, f"{what}, which need about {human_bytes(need)} of memory; "
                             f"this machine has {human_bytes(have)}: {change}")


def check_window(lat_deg, size_m, pixel_m, min_crater_px) -> tuple[int, float, float]:
    """(pixels a side, pixel size, smallest crater in pixels) of a window, checked."""
    check_range("lat_deg", lat_deg, -90.0, 90.0)
    pixel_m = check_positive("pixel_m", pixel_m)
    size_m = check_positive("size_m", size_m)
    min_crater_px = check_range("min_crater_px", min_crater_px, 1.0, 1000.0)
    size_px = int(round(size_m / pixel_m))
    if not 1 <= size_px <= MAX_TILE_PX:
        raise ParameterError("size_m", f"must give 1 to {MAX_TILE_PX} pixels of {pixel_m:g} m; "
                             f"got {size_m:g} m ({size_px} pixels)")
    check_tile_memory(size_px, "size_m", f"gives {size_px} x {size_px} pixels of {pixel_m:g} m",
                      "a smaller window or larger pixels")
    return size_px, pixel_m, min_crater_px


def check_descent_memory(width_px: int) -> None:
    """Refuse up front (one line naming ``width_px``) frames ``width_px`` wide that this
    machine cannot hold with their terrain (the widest window, :data:`DESCENT_MARGIN` x
    the frame)."""
    from ..sensors.camera_files import FRAME_BYTES_PER_PIXEL

    window_px = min(MAX_TILE_PX, math.ceil(DESCENT_MARGIN * width_px))
    check_tile_memory(window_px, "width_px", f"{width_px} px frames over {window_px} px of "
                      f"terrain", "a smaller frame", FRAME_BYTES_PER_PIXEL * width_px**2)
