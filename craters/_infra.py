"""Shared plumbing for the three packages: validation, RNG, atomic files, CLI helpers.

``craters`` sits at the bottom of the import graph (``latlong -> craters <- dem``), so the
small pieces every package needs live here, privately. Nothing in this module knows about
craters; it is infrastructure only.
"""

from __future__ import annotations

import argparse
import contextlib
import logging
import math
import numbers
import os
import sys
import tempfile
import tomllib
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path

import numpy as np

__all__ = [
    "CliError",
    "area_slope_summary",
    "OneLineParser",
    "atomic_path",
    "check_choice",
    "check_parent_folder",
    "check_finite",
    "check_int",
    "check_output_path",
    "check_positive",
    "check_range",
    "load_toml",
    "normalize_rng",
    "package_version",
    "parse_seed",
    "parse_spec",
    "physical_memory_bytes",
    "progress_bar",
    "run_cli",
]

RngLike = int | np.random.Generator | None


# --------------------------------------------------------------------------- validation
def normalize_rng(rng: RngLike) -> np.random.Generator:
    """Return a Generator from ``rng`` (int seed, Generator or None), SPEC 7 style."""
    if isinstance(rng, np.random.Generator):
        return rng
    if rng is None:
        return np.random.default_rng()
    if isinstance(rng, bool | float) or not isinstance(rng, numbers.Integral):
        raise TypeError(
            f"`rng` must be an int seed, a numpy.random.Generator or None; got {rng!r}"
        )
    if int(rng) < 0:
        raise ValueError(f"`rng` seed must be >= 0; got {rng!r}")
    return np.random.default_rng(int(rng))


def check_finite(name: str, value) -> float:
    """Return ``value`` as a float, raising if it is not a finite real number."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise TypeError(f"`{name}` must be a real number; got {value!r}")
    value = float(value)
    if not math.isfinite(value):
        raise ValueError(f"`{name}` must be finite; got {value!r}")
    return value


def check_positive(name: str, value, *, allow_zero: bool = False) -> float:
    """Return ``value`` as a float, raising unless it is finite and > 0 (>= 0)."""
    value = check_finite(name, value)
    if value < 0 or (value == 0 and not allow_zero):
        rule = ">= 0" if allow_zero else "> 0"
        raise ValueError(f"`{name}` must be finite and {rule}; got {value!r}")
    return value


def check_range(name: str, value, lo: float | None, hi: float | None) -> float:
    """Return ``value`` as a float, raising unless lo <= value <= hi (None = open)."""
    value = check_finite(name, value)
    if (lo is not None and value < lo) or (hi is not None and value > hi):
        lo_s = "-inf" if lo is None else f"{lo:g}"
        hi_s = "inf" if hi is None else f"{hi:g}"
        raise ValueError(f"`{name}` must be in [{lo_s}, {hi_s}]; got {value!r}")
    return value


def check_int(name: str, value, lo: int | None = None, hi: int | None = None) -> int:
    """Return ``value`` as an int, raising unless it is an integer in [lo, hi]."""
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        if isinstance(value, float) and value.is_integer():
            value = int(value)
        else:
            raise TypeError(f"`{name}` must be an integer; got {value!r}")
    value = int(value)
    if (lo is not None and value < lo) or (hi is not None and value > hi):
        lo_s = "-inf" if lo is None else str(lo)
        hi_s = "inf" if hi is None else str(hi)
        raise ValueError(f"`{name}` must be an integer in [{lo_s}, {hi_s}]; got {value!r}")
    return value


def check_choice(name: str, value, choices: Sequence[str]) -> str:
    """Return ``value`` if it is one of ``choices``, else raise ValueError."""
    if value not in choices:
        raise ValueError(f"`{name}` must be one of {', '.join(map(str, choices))}; got {value!r}")
    return value


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


# --------------------------------------------------------------------------- files
def check_parent_folder(path) -> None:
    """The folder an output goes into exists and is writable (one-line ValueError)."""
    path = Path(path)
    folder = path.parent if str(path.parent) else Path(".")
    if not folder.is_dir():
        raise ValueError(f"output {str(path)!r}: folder {str(folder)!r} does not exist")
    if not os.access(folder, os.W_OK | os.X_OK):
        raise ValueError(f"output {str(path)!r}: folder {str(folder)!r} is not writable")


def check_output_path(path, *, force: bool, suffixes: Sequence[str] | None = None) -> Path:
    """Validate an output path before any work is done.

    Raises ValueError for an unknown suffix, an existing file without ``force``, or a
    folder that does not exist or is not writable.
    """
    path = Path(path)
    if suffixes is not None and path.suffix.lower() not in suffixes:
        raise ValueError(
            f"output {str(path)!r}: unknown format {path.suffix or '(no suffix)'!r}; "
            f"allowed: {' '.join(suffixes)}"
        )
    check_parent_folder(path)
    if path.is_dir():
        raise ValueError(f"output {str(path)!r} is a folder")
    if path.exists() and not force:
        raise ValueError(f"output {str(path)!r} exists; use --force to overwrite")
    return path


@contextlib.contextmanager
def atomic_path(path) -> Iterator[Path]:
    """Yield a temporary path in the target folder; move it onto ``path`` on success.

    On any exception the temporary file is removed and ``path`` is left untouched.
    """
    path = Path(path)
    folder = path.parent if str(path.parent) else Path(".")
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp" + path.suffix,
                               dir=folder)
    os.close(fd)
    tmp = Path(tmp)
    try:
        yield tmp
        os.chmod(tmp, 0o644)
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            tmp.unlink()
        raise


# --------------------------------------------------------------------------- progress
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


# --------------------------------------------------------------------------- statistics
def area_slope_summary(slopes_deg, areas, *, bin_deg: float = 3.0) -> dict:
    """Area-weighted slope statistics shared by bodies (latlong) and rasters (dem).

    Returns ``edges_deg`` (bin edges from 0), ``area_fraction`` (per bin, sums to 1),
    ``above_percent`` (share of the area steeper than each edge), ``median_deg``,
    ``mean_deg`` and ``percent_above`` for 10, 20 and 30 degrees. NaN slopes (unknown
    terrain) are left out.
    """
    s = np.asarray(slopes_deg, dtype=np.float64).ravel()
    w = np.asarray(areas, dtype=np.float64).ravel()
    if s.shape != w.shape or s.size == 0:
        raise ValueError("`slopes_deg` and `areas` must be non-empty and the same length")
    ok = np.isfinite(s) & np.isfinite(w)
    if not ok.any():
        raise ValueError("no finite slope to summarise")
    s, w = s[ok], w[ok]
    bin_deg = check_range("bin_deg", bin_deg, 0.01, 90.0)
    edges = np.arange(0.0, 180.0 + bin_deg, bin_deg)
    edges = edges[edges <= max(90.0, float(s.max()) + bin_deg)]
    hist, _ = np.histogram(s, bins=edges, weights=w)
    frac = hist / w.sum()
    order = np.argsort(s)
    cw = np.cumsum(w[order]) / w.sum()
    median = float(s[order][min(np.searchsorted(cw, 0.5), len(s) - 1)])
    above = 100.0 * (1.0 - np.concatenate([[0.0], np.cumsum(frac)]))[:len(edges)]
    return {"edges_deg": edges, "area_fraction": frac, "above_percent": above,
            "median_deg": median, "mean_deg": float(np.average(s, weights=w)),
            "percent_above": {a: float(100.0 * w[s > a].sum() / w.sum()) for a in (10, 20, 30)}}


# --------------------------------------------------------------------------- config
def load_toml(path) -> dict:
    """Read a TOML scene file; errors become ValueError naming the file."""
    path = Path(path)
    try:
        with open(path, "rb") as fh:
            return tomllib.load(fh)
    except FileNotFoundError:
        raise ValueError(f"config file {str(path)!r} does not exist") from None
    except tomllib.TOMLDecodeError as exc:
        raise ValueError(f"config file {str(path)!r} is not valid TOML: {exc}") from None


# --------------------------------------------------------------------------- CLI
class CliError(Exception):
    """An error the CLI reports as one line and exit code 2."""


def parse_seed(text) -> int:
    """argparse type for ``--seed``: a non-negative integer below 2**63."""
    try:
        value = int(str(text), 10)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be a non-negative integer; got {text!r}") from None
    if not 0 <= value < 2**63:
        raise argparse.ArgumentTypeError(f"must be in [0, 2**63); got {text!r}")
    return value


def parse_spec(spec, items: dict, required: Sequence[str], what: str) -> dict:
    """Parse a ``key=value,key=value`` spec: ``items`` maps each short key to (field
    name, converter); returns {field: converted value}; ValueError names the spec."""
    if not isinstance(spec, str):
        raise TypeError(f"a {what} spec must be a string; got {spec!r}")
    values = {}
    for part in spec.split(","):
        key, sep, raw = part.partition("=")
        key = key.strip()
        if not sep or key not in items:
            raise ValueError(f"{what} {spec!r}: unknown item {part.strip()!r}; allowed keys: "
                             f"{', '.join(items)}")
        field, convert = items[key]
        try:
            values[field] = convert(raw.strip())
        except ValueError:
            raise ValueError(f"{what} {spec!r}: {key} must be a number; got {raw!r}") from None
    missing = [k for k in required if items[k][0] not in values]
    if missing:
        raise ValueError(f"{what} {spec!r}: missing {', '.join(missing)}")
    return values


class OneLineParser(argparse.ArgumentParser):
    """ArgumentParser whose parse errors are one line ``error: ...`` and exit code 2."""

    def error(self, message: str):  # noqa: D401 - argparse API
        sys.stderr.write(f"error: {self.prog}: {message}\n")
        sys.exit(2)


def run_cli(func: Callable[[], int | None], *, logger_names: Sequence[str] = ()) -> int:
    """Run a CLI body; user errors become one line on stderr and exit code 2.

    Set the environment variable ``CRATERFORM_DEBUG=1`` to get the traceback instead.
    """
    logging.basicConfig(format="%(levelname)s: %(message)s", level=logging.WARNING)
    try:
        return int(func() or 0)
    except (CliError, ValueError, TypeError, OSError, MemoryError) as exc:
        if os.environ.get("CRATERFORM_DEBUG"):
            raise
        msg = str(exc) if str(exc) else exc.__class__.__name__
        sys.stderr.write(f"error: {msg}\n".replace("\n", " ").rstrip() + "\n")
        return 2
    except KeyboardInterrupt:
        sys.stderr.write("error: interrupted\n")
        return 130
