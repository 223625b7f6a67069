"""Counter-based random words: the randomness of terrain generated on demand.

A terrain that is a function of position draws each crater, boulder or noise value from
the words of a keyed bijection of a counter, not from a generator's stream: the value of
(seed, cell, size bin, index, purpose) is the same whichever other values are asked for
with it, in whatever order, on whatever core or machine (DESIGN: locality). craterform
uses Philox4x64-10 (Salmon, Moraes, Dror & Shaw 2011, ``craters.reference("salmon2011")``),
the generator behind numpy's :class:`numpy.random.Philox`, which the tests use as the
reference: ``Philox(key=k, counter=c).random_raw(4)`` are the words of counter ``c + 1``
(the four counter words a 256-bit number, word 0 the lowest).

Only integer arithmetic makes the words, so they are the same bytes on every x86-64
CPU; the transforms to numbers use exact operations (:func:`uniform_from_words`) or
:func:`portable_exp` and :func:`portable_log`, which use +, -, *, / only (fdlibm's
algorithms), not the platform's libm, whose last bit may depend on the library version
and the CPU's instruction set.

Examples
--------
>>> words = philox4x64([[1, 0, 0, 0]], [1, 2])  # Philox(key=[1, 2]).random_raw()
>>> hex(int(words[0, 0]))
'0x4f2f4313b5536b09'
>>> float(uniform_from_words(np.uint64(2**63)))
0.5
"""

from __future__ import annotations

import numpy as np

from ._counter_kernels import _exp_kernel, _log_kernel, _philox_kernel

__all__ = ["philox4x64", "portable_exp", "portable_log", "uniform_from_words"]

_U53 = 2.0 ** -53


def _rows(values, width: int, name: str) -> np.ndarray:
    arr = np.asarray(values)
    if arr.dtype.kind not in "ui" and arr.size:
        raise TypeError(f"`{name}` must hold integers; got {arr.dtype}")
    if arr.size and arr.dtype.kind == "i" and (arr < 0).any():
        raise ValueError(f"`{name}` must hold integers in [0, 2**64); got a negative one")
    arr = np.ascontiguousarray(arr.astype(np.uint64, copy=False))
    if arr.ndim == 1:
        arr = arr.reshape(1, -1) if arr.shape[0] == width else arr
    if arr.ndim != 2 or arr.shape[1] != width:
        raise ValueError(f"`{name}` must be ({width},) or (n, {width}) unsigned integers; got "
                         f"shape {np.shape(values)}")
    return arr


def philox4x64(counters, key) -> np.ndarray:
    """Philox4x64-10 words of each counter.

    Parameters
    ----------
    counters : (n, 4) or (4,) integers in [0, 2**64)
        The counters (e.g. cell, size bin, index, purpose).
    key : (2,) or (n, 2) integers in [0, 2**64)
        The key (e.g. the seed and a stream tag), one for all counters or one each.

    Returns
    -------
    (n, 4) uint64 words; row ``i`` depends only on ``counters[i]`` and its key.
    """
    c = _rows(counters, 4, "counters")
    k = _rows(key, 2, "key")
    if len(k) == 1 and len(c) != 1:
        k = np.ascontiguousarray(np.broadcast_to(k, (len(c), 2)))
    if len(k) != len(c):
        raise ValueError(f"`key` must be one key or one per counter ({len(c)}); got {len(k)}")
    out = np.empty((len(c), 4), dtype=np.uint64)
    if len(c):
        _philox_kernel(c, k, out)
    return out


def uniform_from_words(words) -> np.ndarray:
    """Numbers in [0, 1) from uint64 words: the top 53 bits times 2**-53 (exact: every
    result is a multiple of 2**-53, the same bytes everywhere)."""
    w = np.asarray(words, dtype=np.uint64)
    return (w >> np.uint64(11)).astype(np.float64) * _U53


def _elementwise(kernel, x) -> np.ndarray:
    arr = np.asarray(x, dtype=np.float64)
    flat = np.ascontiguousarray(arr.ravel())
    out = np.empty_like(flat)
    kernel(flat, out)
    return out.reshape(arr.shape)


def portable_exp(x) -> np.ndarray:
    """e**x elementwise, within 1 ulp of the true value and the same bytes on every
    machine (fdlibm's ``e_exp.c`` algorithm in +, -, *, /).

    Examples
    --------
    >>> float(portable_exp(0.0)), float(portable_exp(1.0))
    (1.0, 2.718281828459045)
    """
    return _elementwise(_exp_kernel, x)


def portable_log(x) -> np.ndarray:
    """Natural logarithm elementwise, within 1 ulp and the same bytes on every machine
    (fdlibm's ``e_log.c`` algorithm); -inf at 0, nan below 0.

    Examples
    --------
    >>> float(portable_log(1.0)), float(portable_log(np.e))
    (0.0, 1.0)
    """
    return _elementwise(_log_kernel, x)
