"""Shared fixtures: a seeded generator, tiny grids, and the entry-point runner."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

from craters.cli.start import cap_numpy_simd  # imports nothing heavy

# numpy's loops as the commands choose them (tests/test_golden_outputs.py): before numpy
cap_numpy_simd()

import numpy as np  # noqa: E402
import pytest  # noqa: E402


def _children_import_these_packages() -> None:
    """Every process a test starts imports the packages this one imports.

    ``python -m pytest`` in a checkout puts the checkout first on ``sys.path``: the tests
    import its sources, while a command started in another folder would import the
    installed copy. Two copies of the same code: numba caches each copy's kernels apart,
    and a cold CI run compiled them twice (~5 CPU minutes)."""
    import latlong  # the lazy package: imports nothing heavy

    root = str(Path(latlong.__file__).resolve().parents[1])
    paths = [p for p in os.environ.get("PYTHONPATH", "").split(os.pathsep) if p]
    if root not in paths:
        os.environ["PYTHONPATH"] = os.pathsep.join([root, *paths])


_children_import_these_packages()

#: Test files that take longest on a cold CI run (seconds, 2 xdist workers, 2026-12-05), run
#: first: pytest-xdist hands out whole files (``--dist loadfile``, so the two workers
#: rarely need the same numba kernels at once and compile them twice) in this order, the
#: longest first so that neither worker is left with a long file at the end. Only the
#: order of the run depends on it.
LONGEST_FIRST = (
    "tests/test_readme_commands.py",     # 262 s
    # beside the README from the start: it compiles the on-demand field's kernels (~45 s)
    # and caches them before the README's tile and descent commands need them (the two
    # workers compiled them both at once when this file came after test_cli.py)
    "tests/dem/test_ondemand.py",        # 114
    "tests/test_types.py",               # 39 (mypy, one thread)
    "tests/latlong/test_cli.py",         # 134
    "tests/latlong/test_boulders.py",    # 113
    "tests/latlong/test_gravity.py",     # 75
    "tests/latlong/test_gabor.py",       # 71
    "tests/latlong/test_big_bodies.py",  # 69
    "tests/test_examples.py",            # 62
    "tests/latlong/test_mesh.py",        # 60
    "tests/test_batch.py",               # 58
    "tests/latlong/test_implicit_cli.py",  # 52
    "tests/dem/test_surface.py",         # 51
)


def pytest_collection_modifyitems(config, items):
    """Run the files of :data:`LONGEST_FIRST` first, in its order (stable otherwise)."""
    rank = {name: i for i, name in enumerate(LONGEST_FIRST)}
    root = config.rootpath
    items.sort(key=lambda item: rank.get(item.path.relative_to(root).as_posix()
                                         if item.path.is_relative_to(root) else "",
                                         len(rank)))


@pytest.fixture
def rng() -> np.random.Generator:
    return np.random.default_rng(12345)


def spectral_fbm(n: int, beta: float, rng: np.random.Generator) -> np.ndarray:
    """An n x n periodic fBm surface by spectral synthesis: amplitude f^(-beta/2), random
    phases (psd ~ f^-beta; F = (8 - beta) / 2). Independent of dem's RMD code."""
    f = np.hypot(*np.meshgrid(np.fft.fftfreq(n), np.fft.fftfreq(n), indexing="ij"))
    f[0, 0] = 1.0
    amp = f ** (-beta / 2.0)
    amp[0, 0] = 0.0
    return np.fft.ifft2(amp * np.exp(2j * np.pi * rng.random((n, n)))).real


@pytest.fixture
def fbm_surface():
    """``fbm_surface(n, fractal_dimension, rng)``: :func:`spectral_fbm` of beta = 8 - 2F."""
    return lambda n, fractal_dimension, rng: spectral_fbm(n, 8.0 - 2.0 * fractal_dimension, rng)


@pytest.fixture
def tiny_grid():
    from latlong import LatLongGrid

    return LatLongGrid(6)


#: Set to 1 to run every command of :func:`run_entry_point` in a process of its own.
SUBPROCESS_ENV = "CRATERFORM_TEST_SUBPROCESS"


def run_entry_point(*args: str, env: dict | None = None, cwd=None) -> subprocess.CompletedProcess:
    """Run a command (``"latlong", "build", ...``) through its package's ``__main__.main``,
    the code its console script and ``python -m`` run, and return what a process would.

    With ``env`` (``NUMBA_NUM_THREADS`` and the like, read once per process) or
    ``CRATERFORM_TEST_SUBPROCESS=1`` it runs as ``python -m <package>`` in a process of its
    own; otherwise in this one (:func:`run_in_process`): a new process costs ~2 s here
    loading numba's cached kernels, ~300 commands of the suite.
    """
    if env is None and os.environ.get(SUBPROCESS_ENV, "") in ("", "0"):
        return run_in_process(*args, cwd=cwd)
    return run_process(*args, env=env, cwd=cwd)


def run_process(*args: str, env: dict | None = None, cwd=None,
                timeout: float = 600) -> subprocess.CompletedProcess:
    """``python -m <args>`` in a process of its own, with this environment (but
    ``CRATERFORM_DEBUG``) updated by ``env``."""
    full_env = dict(os.environ)
    full_env.pop("CRATERFORM_DEBUG", None)
    full_env.update(env or {})
    return subprocess.run([sys.executable, "-m", *args], capture_output=True, text=True,
                          env=full_env, cwd=cwd, timeout=timeout)


def run_in_process(package: str, *argv: str, cwd=None) -> subprocess.CompletedProcess:
    """``python -m <package> <argv>`` in this process: stdout and stderr captured, the
    logging and warning set-up of a new interpreter (``WARNING: ...`` lines on stderr,
    Python's default warning filters), ``cwd`` for the run, ``SystemExit`` as the exit
    code; signal handlers, the working folder and the root logger are restored after."""
    import contextlib
    import importlib
    import io
    import logging
    import signal
    import warnings

    out, err = (io.TextIOWrapper(io.BytesIO(), encoding="utf-8", write_through=True)
                for _ in range(2))
    root = logging.getLogger()
    handlers, level, folder = root.handlers[:], root.level, os.getcwd()
    signals = {s: signal.getsignal(s) for s in (signal.SIGINT, signal.SIGTERM)}
    debug = os.environ.pop("CRATERFORM_DEBUG", None)
    handler = logging.StreamHandler(err)
    handler.setFormatter(logging.Formatter("%(levelname)s: %(message)s"))
    root.handlers[:] = [handler]
    root.setLevel(logging.WARNING)
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err), \
                warnings.catch_warnings():
            warnings.resetwarnings()  # a new interpreter's filters
            for category in (DeprecationWarning, PendingDeprecationWarning, ImportWarning,
                             ResourceWarning):
                warnings.simplefilter("ignore", category)
            if cwd is not None:
                os.chdir(cwd)
            try:
                code = importlib.import_module(f"{package}.__main__").main(list(argv))
            except SystemExit as stop:  # argparse: --help, usage errors
                code = stop.code if isinstance(stop.code, int) else (stop.code is not None)
                if isinstance(stop.code, str):
                    sys.stderr.write(stop.code + "\n")
    finally:
        root.handlers[:] = handlers
        root.setLevel(level)
        os.chdir(folder)
        for sig, old in signals.items():
            signal.signal(sig, old)
        if debug is not None:
            os.environ["CRATERFORM_DEBUG"] = debug
    return subprocess.CompletedProcess([sys.executable, "-m", package, *argv], int(code or 0),
                                       out.buffer.getvalue().decode(),
                                       err.buffer.getvalue().decode())


@pytest.fixture
def run_cli():
    return run_entry_point


@pytest.fixture
def run_module():
    """:func:`run_process`: for commands that must run in a process of their own (those
    that start dask workers or clients)."""
    return run_process


DATA = os.path.join(os.path.dirname(__file__), "data")


@pytest.fixture
def lola_crop():
    """The 257 x 257 equatorial crop of LOLA LDEM_4 in tests/data (a PDS3 .img + .lbl)."""
    import dem

    return dem.read(os.path.join(DATA, "ldem4_crop.lbl"))


@pytest.fixture
def tiny_geotiff(tmp_path):
    """A 33 x 33 projected (metres) GeoTIFF with NoData, made with rasterio directly."""
    import rasterio
    from affine import Affine

    path = tmp_path / "tiny.tif"
    z = np.add.outer(np.arange(33.0), 2 * np.arange(33.0)).astype(np.int16)
    z[3, 4] = -9999
    with rasterio.open(path, "w", driver="GTiff", width=33, height=33, count=1,
                       dtype="int16", nodata=-9999, crs="EPSG:32633",
                       transform=Affine(10.0, 0, 500000.0, 0, -10.0, 4000000.0)) as ds:
        ds.write(z, 1)
    return path


def assert_one_line_error(proc: subprocess.CompletedProcess, *needles: str) -> None:
    """The CLI contract for bad input: exit 2, one ``error: ...`` line naming the problem."""
    assert proc.returncode == 2, proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error:"), proc.stderr
    for needle in needles:
        assert needle in lines[0], lines[0]


@pytest.fixture
def one_line_error():
    return assert_one_line_error
