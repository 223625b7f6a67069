"""Progress: a tqdm bar on a terminal when asked; when stderr is not a terminal (CI and
batch logs, ``2> log``) a plain line every :data:`LOG_INTERVAL_S` seconds of long work, so
logs are not silent for minutes; nothing when not asked."""

from __future__ import annotations

import os
import sys
import time

__all__ = ["LOG_INTERVAL_S", "progress_bar"]

#: Seconds between progress lines when stderr is not a terminal (environment variable
#: ``CRATERFORM_PROGRESS_S`` overrides it); work shorter than this prints nothing.
LOG_INTERVAL_S = 10.0


def progress_bar(iterable=None, *, enabled: bool, total: int | None = None, desc: str = ""):
    """A tqdm bar when ``enabled`` and stderr is a terminal; when ``enabled`` and it is
    not, progress lines (``desc: 40/100 (40 %), 12 s``) every :data:`LOG_INTERVAL_S`
    seconds; else a silent iterable."""
    if enabled and sys.stderr.isatty():
        from tqdm.auto import tqdm

        return tqdm(iterable, total=total, desc=desc, leave=False)
    if enabled:
        return _LogLines(iterable, total, desc)
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
        self.close()
        return False


class _LogLines(_Silent):
    """Progress as a line on stderr at most every LOG_INTERVAL_S seconds."""

    def __init__(self, iterable, total, desc: str):
        super().__init__(iterable)
        if total is None and iterable is not None and hasattr(iterable, "__len__"):
            total = len(iterable)
        self._total, self._desc, self._n, self._lines = total, desc or "progress", 0, 0
        try:
            self._every = float(os.environ.get("CRATERFORM_PROGRESS_S", LOG_INTERVAL_S))
        except ValueError:
            self._every = LOG_INTERVAL_S
        self._t0 = self._last = time.monotonic()

    def __iter__(self):
        for item in self._iterable:
            yield item
            self.update(1)

    def update(self, n: int = 1) -> None:
        self._n += n
        now = time.monotonic()
        if now - self._last >= self._every:
            self._last = now
            self._write(now)

    def set_description(self, desc: str) -> None:
        self._desc = desc

    def close(self) -> None:
        if self._lines:  # a long job said where it was: say that it ended
            self._write(time.monotonic(), done=True)

    def _write(self, now: float, done: bool = False) -> None:
        of = f"/{self._total}" if self._total else ""
        pct = f" ({100.0 * self._n / self._total:.0f} %)" if self._total else ""
        state = "done, " if done else ""
        sys.stderr.write(f"{self._desc}: {self._n}{of}{pct}, {state}{now - self._t0:.0f} s\n")
        sys.stderr.flush()
        self._lines += 1
