"""How Python calls a numba kernel: its array inputs read-only, so that it compiles once."""

from __future__ import annotations

import functools
import inspect
from collections.abc import Callable
from typing import Any

import numpy as np

__all__ = ["read_only", "read_only_inputs"]


def read_only(array: np.ndarray) -> np.ndarray:
    """A read-only view of ``array`` (no copy)."""
    view = array.view()
    view.flags.writeable = False
    return view


def read_only_inputs(*outputs: str) -> Callable[[Any], Any]:
    """Decorator of a numba kernel that Python calls: every array argument but the named
    ``outputs`` reaches the kernel as a read-only view (no copy).

    Numba compiles a kernel once per combination of argument types, and a read-only array
    is another type than a writable one: a caller holding read-only arrays (a body's radii,
    a mesh's vertices) and one holding writable copies compiled the same kernel twice, for
    seconds each with ``parallel=True`` (106 of the 350 s a cold test run spent compiling,
    2026-12-06). Writing into an argument not named here is a typing error. The kernel
    stays reachable as ``.kernel`` (``.py_func`` is its Python source); numba code calls
    the kernel, not this wrapper."""

    def wrap(kernel):
        names = list(inspect.signature(kernel.py_func).parameters)
        unknown = [name for name in outputs if name not in names]
        if unknown:
            raise TypeError(f"{kernel.py_func.__name__} has no argument {unknown[0]!r}")
        writes = frozenset(names.index(name) for name in outputs)

        @functools.wraps(kernel.py_func)
        def call(*args):
            return kernel(*(read_only(a) if i not in writes and isinstance(a, np.ndarray)
                            and a.flags.writeable else a for i, a in enumerate(args)))

        call.kernel = kernel
        call.py_func = kernel.py_func
        return call

    return wrap
