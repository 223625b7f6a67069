"""The distribution ships every subpackage (a wheel with only the top-level packages
imports in the source tree and fails once installed)."""

from __future__ import annotations

import re
import tomllib
from pathlib import Path

from setuptools import find_packages

ROOT = Path(__file__).resolve().parents[1]


def test_every_package_with_an_init_is_in_the_distribution():
    config = tomllib.loads((ROOT / "pyproject.toml").read_text())
    find = config["tool"]["setuptools"]["packages"]["find"]
    shipped = set(find_packages(str(ROOT), include=find["include"]))
    on_disk = {str(p.parent.relative_to(ROOT)).replace("/", ".")
               for top in ("latlong", "craters", "dem") for p in (ROOT / top).rglob("__init__.py")}
    assert on_disk <= shipped and {"craters._shared", "latlong.cli", "latlong.implicit",
                                   "dem.cli", "craters.lcsn", "craters.boulders"} <= shipped


def test_the_readme_architecture_names_every_subpackage():
    """The README's architecture section stays a map of the packages: each subpackage
    (``latlong/sensors/`` ...) is named there, as ``sensors/`` or ``latlong/sensors/``."""
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    section = readme.split("\n## Architecture\n", 1)[1].split("\n## ", 1)[0]
    subpackages = {p.parent.relative_to(ROOT).as_posix() for top in ("latlong", "craters", "dem")
                   for p in (ROOT / top).glob("*/__init__.py")}
    assert len(subpackages) >= 10
    missing = sorted(s for s in subpackages
                     if not re.search(rf"[`/]{re.escape(s.split('/', 1)[1])}/`", section))
    assert not missing, missing


def test_the_longest_first_files_exist():
    """tests/conftest.py's run order names real test files (a renamed file would silently
    fall back to the collection order and leave a long file to the end of a CI run)."""
    import importlib.util

    spec = importlib.util.spec_from_file_location("_conftest", ROOT / "tests" / "conftest.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    LONGEST_FIRST = module.LONGEST_FIRST
    missing = [f for f in LONGEST_FIRST if not (ROOT / f).is_file()]
    assert not missing and len(set(LONGEST_FIRST)) == len(LONGEST_FIRST), missing
