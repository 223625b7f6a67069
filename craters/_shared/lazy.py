"""Packages whose public names load on first use (PEP 562), so that importing a package
costs almost nothing: ``import latlong`` loads neither numpy nor numba until a name such
as ``latlong.Body`` is used. The command lines rely on it to start without tracebacks
(:mod:`craters.cli.start`).

A package lists its names once, as relative imports in an ``if TYPE_CHECKING:`` block,
which type checkers and readers see as plain imports; at run time
:func:`lazy_package` reads that block and imports each name's module on first use::

    from typing import TYPE_CHECKING

    from craters._shared.lazy import lazy_package

    if TYPE_CHECKING:
        from .body import Body, load

    __all__ = ["Body", "load"]
    lazy_package(__name__)

``from pkg import Body``, ``pkg.Body``, ``import pkg.body`` (and then ``pkg.body``),
``dir(pkg)`` and ``from pkg import *`` work as with eager imports. Where a name is also the
name of its module (``latlong.batch`` the function from ``latlong/batch.py``) the name
wins, as it does with eager imports, also after the module is imported on its own.
"""

from __future__ import annotations

import ast
import importlib
import importlib.util
import sys
import types
from typing import TYPE_CHECKING, cast

if TYPE_CHECKING:
    from importlib.abc import InspectLoader

__all__ = ["lazy_package", "lazy_names"]


def lazy_names(source: str) -> dict[str, tuple[str, str]]:
    """{name: (relative module, name in it)} of the relative imports in the top-level
    ``if TYPE_CHECKING:`` blocks of a module's ``source``."""
    names = {}
    for node in ast.parse(source).body:
        if isinstance(node, ast.If) and isinstance(node.test, ast.Name) \
                and node.test.id == "TYPE_CHECKING":
            for item in node.body:
                if not (isinstance(item, ast.ImportFrom) and item.level == 1 and item.module):
                    raise ValueError("a lazy package's TYPE_CHECKING block holds only "
                                     f"`from .module import name` lines (line {item.lineno})")
                for alias in item.names:
                    names[alias.asname or alias.name] = (item.module, alias.name)
    return names


class _LazyPackage(types.ModuleType):
    """A package module with lazy names: importing one of its submodules binds the
    submodule to the package, except where the name is the submodule's own function."""

    def __setattr__(self, name: str, value) -> None:
        source = self.__dict__["_lazy_names"].get(name)
        if isinstance(value, types.ModuleType) and source == (name, name) \
                and value.__name__ == f"{self.__name__}.{name}":
            value = getattr(value, name)
        super().__setattr__(name, value)


def lazy_package(name: str) -> None:
    """Make the package ``name`` (being imported: pass ``__name__``) load the names of its
    ``TYPE_CHECKING`` imports on first use, through a module ``__getattr__``
    and ``__dir__`` (PEP 562)."""
    module = sys.modules[name]
    spec = module.__spec__
    # a package's loader reads source files: an InspectLoader (importlib.abc)
    loader = cast("InspectLoader | None", spec.loader if spec else None)
    source = loader.get_source(name) if loader else None
    if source is None:
        raise ImportError(f"lazy package {name} needs its source", name=name)
    names = lazy_names(source)
    namespace = vars(module)

    def __getattr__(attr: str):
        if attr in names:
            submodule, real = names[attr]
            value = getattr(importlib.import_module(f"{name}.{submodule}"), real)
        elif not attr.startswith("__") and importlib.util.find_spec(f"{name}.{attr}"):
            value = importlib.import_module(f"{name}.{attr}")
        else:
            raise AttributeError(f"module {name!r} has no attribute {attr!r}", name=attr,
                                 obj=module)
        namespace[attr] = value
        return value

    def __dir__() -> list[str]:
        import pkgutil

        submodules = {m.name for m in pkgutil.iter_modules(module.__path__)
                      if not m.name.startswith("_")}
        return sorted(set(namespace) | set(names) | submodules)

    namespace.update(_lazy_names=names, __getattr__=__getattr__, __dir__=__dir__)
    module.__class__ = _LazyPackage
