"""Progress bars: tqdm on a terminal when asked, silent otherwise."""

from __future__ import annotations

import sys

__all__ = ["progress_bar"]


def progress_bar(iterable=None, *, enabled: bool, total: int | None = None, desc: str = ""):
    """A tqdm bar when ``enabled`` (and stderr is a terminal), else a silent iterable."""
    if enabled and sys.stderr.isatty():
        from tqdm.auto import tqdm

        return tqdm(iterable, total=total, desc=desc, leave=False)
    return _Silent(iterable)


class _Silent:
    """Stand-in for a tqdm bar that does nothing."""

    def __init__(self, iterable):
        self._iterable = iterable

    def __iter__(self):
        return iter(self._iterable)

    def update(self, n: int = 1) -> None:
        pass

    def set_description(self, desc: str) -> None:
        pass

    def close(self) -> None:
        pass

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        return False
