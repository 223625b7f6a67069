"""Numba code calls each compiled (not inlined) kernel with one type per argument.

numba compiles a jitted function once per combination of argument types, and a constant
``True``, ``False`` or ``0`` passed from numba code is a *literal* type of its own
(``Literal[bool](True)`` is not ``Literal[bool](False)``, nor ``bool``): a kernel called
with ``True`` at one call site and ``False`` at another was compiled twice on first use.
``latlong._crater_kernels._stamp_one`` cost ~10 s a compile that way (first
``latlong build`` 68 -> 58 s on the README demo, 2026-12-08). Flags are passed as
``np.bool_(...)`` and counts as ``np.int64(...)``, which numba types as plain ``bool``
and ``int64``. This test reads the source (``ast``) and fails where one argument
position of a non-inlined jitted function receives two different literal constants, or a
literal at one call site and an expression at another.
"""

from __future__ import annotations

import ast
from collections import defaultdict
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("craters", "latlong", "dem")


def _jit_decorator(node: ast.FunctionDef) -> ast.expr | None:
    for dec in node.decorator_list:
        func = dec.func if isinstance(dec, ast.Call) else dec
        name = func.attr if isinstance(func, ast.Attribute) else getattr(func, "id", "")
        if name in ("njit", "jit"):
            return dec
    return None


def _inlined(dec: ast.expr) -> bool:
    return isinstance(dec, ast.Call) and any(
        k.arg == "inline" and isinstance(k.value, ast.Constant) and k.value.value == "always"
        for k in dec.keywords)


def _kind(arg: ast.expr) -> str:
    """How numba types the argument: a literal of its value, or by its expression."""
    if isinstance(arg, ast.Constant) and isinstance(arg.value, bool | int):
        return f"literal {arg.value!r}"
    return "expression"


def _modules() -> dict[str, ast.Module]:
    out = {}
    for pkg in PACKAGES:
        for path in sorted((ROOT / pkg).rglob("*.py")):
            parts = list(path.relative_to(ROOT).with_suffix("").parts)
            if parts[-1] == "__init__":
                parts.pop()
            out[".".join(parts)] = ast.parse(path.read_text(encoding="utf-8"))
    return out


def _imported(module: str, node: ast.ImportFrom) -> str:
    """The absolute module name of ``from ... import`` in ``module``."""
    if not node.level:
        return node.module or ""
    base = module.split(".")[:-node.level] if not _is_package(module) else \
        module.split(".")[:len(module.split(".")) - node.level + 1]
    return ".".join(base + ([node.module] if node.module else []))


def _is_package(module: str) -> bool:
    return (ROOT / module.replace(".", "/") / "__init__.py").exists()


class _Kernels:
    """The jitted functions of the packages, by (module, name), and what a name used in a
    module stands for (followed through ``from ... import`` re-exports)."""

    def __init__(self):
        self.modules = _modules()
        self.inlined: dict[tuple[str, str], bool] = {}
        self.bodies: list[tuple[str, ast.FunctionDef]] = []
        self.imports: dict[str, dict[str, tuple[str, str]]] = {}
        for mod, tree in self.modules.items():
            names = self.imports.setdefault(mod, {})
            for node in tree.body:
                if isinstance(node, ast.ImportFrom):
                    src = _imported(mod, node)
                    for alias in node.names:
                        names[alias.asname or alias.name] = (src, alias.name)
            for node in ast.walk(tree):
                if isinstance(node, ast.FunctionDef) and (dec := _jit_decorator(node)):
                    self.inlined[(mod, node.name)] = _inlined(dec)
                    self.bodies.append((mod, node))

    def resolve(self, module: str, name: str, depth: int = 0) -> tuple[str, str] | None:
        if (module, name) in self.inlined:
            return module, name
        src = self.imports.get(module, {}).get(name)
        if src is None or depth > 8:
            return None
        return self.resolve(*src, depth + 1)


def _argument_kinds() -> dict[tuple[str, str, int], dict[str, list[str]]]:
    """{(module, kernel, argument position): {kind: [call sites]}} over the calls from
    numba code to jitted functions that are compiled on their own (not inlined)."""
    kernels = _Kernels()
    kinds: dict = defaultdict(lambda: defaultdict(list))
    for mod, fn in kernels.bodies:
        for call in ast.walk(fn):
            if not (isinstance(call, ast.Call) and isinstance(call.func, ast.Name)):
                continue
            target = kernels.resolve(mod, call.func.id)
            if target is None or kernels.inlined[target]:
                continue
            for i, arg in enumerate(call.args):
                kinds[(*target, i)][_kind(arg)].append(f"{mod}:{call.lineno}")
    return kinds


def test_compiled_kernels_get_one_type_per_argument_from_numba_code():
    kinds = _argument_kinds()
    assert len(kinds) > 50  # the calls were found
    clashes = [f"{mod}.{name} argument {i}: " + "; ".join(f"{k} at {', '.join(w)}"
                                                          for k, w in sorted(found.items()))
               for (mod, name, i), found in sorted(kinds.items())
               if len(found) > 1 and any(k.startswith("literal") for k in found)]
    assert not clashes, ("a jitted function compiled once per literal (pass np.bool_(...) "
                         "/ np.int64(...)):\n" + "\n".join(clashes))


def test_the_check_sees_a_literal_clash(tmp_path):
    code = ast.parse("def f():\n    g(x, True)\n    g(x, False)\n    g(x, y)\n")
    call_kinds = [[_kind(a) for a in c.args] for c in ast.walk(code)
                  if isinstance(c, ast.Call)]
    assert sorted(k[1] for k in call_kinds) == ["expression", "literal False", "literal True"]
    assert _kind(ast.parse("np.bool_(True)", mode="eval").body) == "expression"
