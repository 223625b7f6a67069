"""Counter-based random words: the randomness of terrain generated on demand.

A terrain that is a function of position draws each crater, boulder or noise value from
the words of a keyed bijection of a counter, not from a generator's stream: the value of
(seed, cell, size bin, index, purpose) is the same whichever other values are asked for
with it, in whatever order, on whatever core or machine (DESIGN: locality). craterform
uses Philox4x64-10 (Salmon, Moraes, Dror & Shaw 2011, ``craters.reference("salmon2011")``),
the generator behind numpy's :class:`numpy.random.Philox`, which the tests use as the
reference: ``Philox(key=k, counter=c).random_raw(4)`` are the words of counter ``c + 1``
(the four counter words a 256-bit number, word 0 the lowest). The splitmix64 hash of the
existing noise kernels (``craters._rng_kernels``) stays where it is; whole catalogues are
drawn from Philox, a keyed bijection that passes BigCrush for every key.

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

from ._counter_kernels import (
    _exp_kernel,
    _log_kernel,
    _philox_kernel,
    _philox_rows,
    _poisson_kernel,
    _power_law_kernel,
)

__all__ = ["MAX_POISSON_MEAN", "philox4x64", "poisson_from_uniform", "portable_exp",
           "portable_geomspace", "portable_log", "power_law_from_uniform",
           "uniform_from_words"]

_U53 = 2.0 ** -53
#: Largest Poisson mean drawn by inversion (its cost grows with the mean; a cell hierarchy
#: keeps the mean count of a cell and size bin small).
MAX_POISSON_MEAN = 500.0


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
        if len(c) <= 8192:  # a parallel region costs more than a few thousand rows
            _philox_rows(c, k, out, 0, len(c))
        else:
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


def portable_geomspace(start: float, stop: float, num: int) -> np.ndarray:
    """``num`` numbers from ``start`` to ``stop`` (both > 0, kept exactly) evenly spaced
    in their logarithm, as ``np.geomspace``, the same bytes on every machine
    (:func:`portable_exp` and :func:`portable_log`; numpy's own goes through its SIMD
    ``log10``/``power`` loops, whose last bits differ between AVX2 and SSE).

    Examples
    --------
    >>> portable_geomspace(1.0, 1000.0, 4).round(12).tolist()
    [1.0, 10.0, 100.0, 1000.0]
    """
    out = start * portable_exp(np.linspace(0.0, 1.0, num)
                               * float(portable_log(stop / start)))
    if num:
        out[0] = start
        out[-1] = stop
    return out


def _uniforms(u) -> np.ndarray:
    arr = np.asarray(u, dtype=np.float64)
    if arr.size and not ((arr >= 0.0) & (arr < 1.0)).all():
        raise ValueError("`u` must hold numbers in [0, 1) (uniform_from_words)")
    return arr


def poisson_from_uniform(u, mean) -> np.ndarray:
    """Poisson counts of ``mean`` (broadcast with ``u``) by inversion of uniforms ``u`` in
    [0, 1): the same count for the same (u, mean) everywhere (:func:`portable_exp`).

    Examples
    --------
    >>> poisson_from_uniform([0.0, 0.5, 0.99], 3.0).tolist()
    [0, 3, 8]
    """
    u = _uniforms(u)
    mean = np.asarray(mean, dtype=np.float64)
    if mean.size and not ((mean >= 0.0) & (mean <= MAX_POISSON_MEAN)).all():
        raise ValueError(f"`mean` must be in [0, {MAX_POISSON_MEAN:g}]; got "
                         f"{mean.min():g} .. {mean.max():g}")
    uu, mm = np.broadcast_arrays(u, mean)
    out = np.empty(uu.size, dtype=np.int64)
    _poisson_kernel(np.ascontiguousarray(uu.ravel()), np.ascontiguousarray(mm.ravel()), out)
    return out.reshape(uu.shape)


def power_law_from_uniform(u, d_min, d_max, slope) -> np.ndarray:
    """Sizes in [``d_min``, ``d_max``) of a cumulative power law N(>D) ~ D**``slope``
    (``slope`` < 0; a crater size-frequency distribution) from uniforms ``u`` in [0, 1)
    by inversion; all broadcast; the same bytes everywhere (:func:`portable_exp`).

    Examples
    --------
    >>> power_law_from_uniform([0.0, 0.75], 1.0, 4.0, -2.0).round(12).tolist()
    [1.0, 1.835325870964]
    """
    u = _uniforms(u)
    uu, lo, hi, s = np.broadcast_arrays(u, np.asarray(d_min, np.float64),
                                        np.asarray(d_max, np.float64),
                                        np.asarray(slope, np.float64))
    if uu.size and not ((lo > 0) & (hi > lo) & np.isfinite(hi)).all():
        raise ValueError("`d_min` and `d_max` must satisfy 0 < d_min < d_max < inf")
    if uu.size and not ((s < 0) & np.isfinite(s)).all():
        raise ValueError("`slope` must be finite and < 0 (a cumulative size-frequency law)")
    out = np.empty(uu.size, dtype=np.float64)
    flat = [np.ascontiguousarray(a.ravel()) for a in (uu, lo, hi, s)]
    _power_law_kernel(flat[0], flat[1], flat[2], flat[3], out)
    return out.reshape(uu.shape)
