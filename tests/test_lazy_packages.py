"""The packages' lazy ``__init__`` (craters._shared.lazy, PEP 562): every public name
works as with eager imports (``pkg.Name``, ``from pkg import Name``, ``dir``, ``*``),
the names a module shares with its own function stay the function, and the names the
type checkers see are the names that load."""

from __future__ import annotations

import importlib
import subprocess
import sys
from pathlib import Path

import pytest

from craters._shared.lazy import lazy_names

ROOT = Path(__file__).resolve().parents[1]
LAZY = ("latlong", "dem", "craters", "craters._shared", "latlong.ondemand", "latlong.sensors")


def _names(package: str) -> dict[str, tuple[str, str]]:
    path = ROOT.joinpath(*package.split("."), "__init__.py")
    return lazy_names(path.read_text())


@pytest.mark.parametrize("package", LAZY)
def test_every_public_name_loads(package):
    module = importlib.import_module(package)
    names = _names(package)
    assert set(names) == set(module.__all__)
    for name, (submodule, real) in names.items():
        source = importlib.import_module(f"{package}.{submodule}")
        assert getattr(module, name) is getattr(source, real), name
    assert set(module.__all__) <= set(dir(module))
    star: dict = {}
    exec(f"from {package} import *", star)
    assert set(module.__all__) <= set(star)


@pytest.mark.parametrize("package", LAZY)
def test_unknown_names_are_attribute_errors(package):
    module = importlib.import_module(package)
    assert not hasattr(module, "no_such_name")
    with pytest.raises(AttributeError, match="no_such_name"):
        module.no_such_name  # noqa: B018
    with pytest.raises(ImportError):
        exec(f"from {package} import no_such_name", {})


def test_fresh_interpreter_names_submodules_and_shared_names():
    """In a fresh interpreter: a submodule imported on its own first (``import
    latlong.batch``) leaves ``latlong.batch`` the function, as the eager imports did; a
    submodule not imported yet is an attribute (``latlong.export``)."""
    shared = {p: sorted(n for n, (m, r) in _names(p).items() if n == m == r) for p in LAZY}
    assert shared["latlong"] and shared["dem"] and shared["craters"]
    code = "\n".join([
        "import importlib, types",
        f"shared = {shared!r}",
        "for pkg, names in shared.items():",
        "    for name in names:",
        "        importlib.import_module(f'{pkg}.{name}')",
        "for pkg, names in shared.items():",
        "    module = importlib.import_module(pkg)",
        "    for name in names:",
        "        value = getattr(module, name)",
        "        assert callable(value) and not isinstance(value, types.ModuleType), (pkg, name)",
        "        exec(f'from {pkg} import {name} as v; import {pkg}.{name} as w', g := {})",
        "        assert g['v'] is g['w'] is value, (pkg, name)",
        "import latlong, dem",
        "assert isinstance(latlong.export, types.ModuleType)",
        "assert latlong.export.__name__ == 'latlong.export' and 'export' in dir(latlong)",
        "assert dem.io.read is dem.read",
        "print('ok')",
    ])
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          cwd=ROOT)
    assert proc.returncode == 0 and proc.stdout == "ok\n", proc.stderr


def test_the_type_checking_block_holds_only_relative_imports():
    source = "from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n    import numpy\n"
    with pytest.raises(ValueError, match="line 3"):
        lazy_names(source)
    ok = "if TYPE_CHECKING:\n    from .a import b as c, d\nfrom .e import f\n"
    assert lazy_names(ok) == {"c": ("a", "b"), "d": ("a", "d")}


if __name__ == "__main__":
    sys.exit(pytest.main([__file__, "-q"]))
