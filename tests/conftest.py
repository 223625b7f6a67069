"""Shared fixtures: a seeded generator, tiny grids, and the entry-point runner."""

from __future__ import annotations

import os
import subprocess
import sys

import numpy as np
import pytest


@pytest.fixture
def rng() -> np.random.Generator:
    return np.random.default_rng(12345)


@pytest.fixture
def tiny_grid():
    from latlong import LatLongGrid

    return LatLongGrid(6)


def run_entry_point(*args: str, env: dict | None = None, cwd=None) -> subprocess.CompletedProcess:
    """Run a console script through ``python -m <package>`` (the real entry point)."""
    full_env = dict(os.environ)
    full_env.pop("CRATERFORM_DEBUG", None)
    full_env.update(env or {})
    return subprocess.run([sys.executable, "-m", *args], capture_output=True, text=True,
                          env=full_env, cwd=cwd, timeout=600)


@pytest.fixture
def run_cli():
    return run_entry_point
