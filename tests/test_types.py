"""The type check of the three packages (``python -m mypy``, configured in pyproject.toml)
runs with the tests: on one pytest-xdist worker while the other runs tests (CI ran it
after them, single-threaded, 39 s on a cold cache)."""

from __future__ import annotations

import importlib.util
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def test_the_packages_type_check():
    if importlib.util.find_spec("mypy") is None:
        pytest.skip("the type check needs mypy, part of the test extra: pip install '.[test]'")
    done = subprocess.run([sys.executable, "-m", "mypy"], cwd=ROOT, capture_output=True,
                          text=True, timeout=900)
    assert done.returncode == 0, done.stdout[-4000:] + done.stderr[-2000:]
    assert "Success: no issues found" in done.stdout
