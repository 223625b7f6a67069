"""Facts about the installation and the machine: version, memory, sizes for people."""

from __future__ import annotations

import os

__all__ = ["human_bytes", "package_version", "physical_memory_bytes"]


def package_version() -> str:
    """The installed craterform version (``0+unknown`` when running from a bare tree)."""
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("craterform")
    except PackageNotFoundError:  # pragma: no cover - source tree without metadata
        return "0+unknown"


def physical_memory_bytes() -> int:
    """Physical memory of this machine in bytes (fallback 8 GiB if unknown)."""
    try:
        return int(os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES"))
    except (ValueError, OSError, AttributeError):  # pragma: no cover - non-POSIX
        return 8 * 2**30


def human_bytes(n: float) -> str:
    """A byte count for people: ``1536 -> '1.5 KiB'``.

    Examples
    --------
    >>> human_bytes(1536), human_bytes(3 * 2**40)
    ('1.5 KiB', '3.0 TiB')
    """
    for unit in ("B", "KiB", "MiB", "GiB", "TiB", "PiB"):
        if n < 1024:
            return f"{n:.1f} {unit}"
        n /= 1024
    return f"{n:.1f} EiB"
