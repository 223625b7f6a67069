"""Sums over data that arrives in pieces, bit for bit the sum numpy makes of the whole.

``numpy.sum`` of a float64 array adds by *pairwise summation*: an array of ``n`` values
is split at ``n2 = n // 2`` rounded down to a multiple of 8, each half summed the same
way, down to blocks of at most 128 values, which are added with eight running partial
sums (numpy's ``pairwise_sum``). The tree depends only on ``n``. So when ``n`` is known
in advance, the same sum can be made from the values arriving chunk by chunk (e.g. strip
by strip of a raster bigger than memory): :class:`PairwiseSum` walks the same tree,
hands every node that lies within one chunk to numpy (which sums it with the very same
tree) and splits the nodes that straddle chunks. Statistics of a tiled raster then equal
those of the whole raster exactly, not just to rounding (``dem.fill_to_file`` relies on
it for the fractal dimension it fills with).
"""

from __future__ import annotations

from collections import deque

import numpy as np

__all__ = ["PairwiseSum"]

# numpy's pairwise_sum: blocks of at most this many values are summed directly
_BLOCK = 128


class PairwiseSum:
    """The float64 sum of ``n`` values pushed in pieces, equal to ``numpy.sum`` of them
    concatenated (the mean: ``total / n``, as ``numpy.mean``).

    Examples
    --------
    >>> x = np.random.default_rng(0).standard_normal(1000) * 1e3
    >>> s = PairwiseSum(1000)
    >>> for a in range(0, 1000, 37):
    ...     s.push(x[a:a + 37])
    >>> s.total == float(np.sum(x))
    True
    """

    def __init__(self, n: int):
        self.n = int(n)
        self._chunks: deque = deque()
        self._pos = 0  # read position in the first chunk
        self._buffered = 0
        self._pushed = 0
        self._result: float | None = 0.0 if self.n == 0 else None
        self._walk = self._node(self.n) if self.n else None
        if self._walk is not None:
            next(self._walk)  # runs until it needs values

    def push(self, values) -> None:
        """Add the next values (any 1-D array; float64 is used as numpy.sum would)."""
        v = np.ascontiguousarray(values, dtype=np.float64).ravel()
        if not v.size:
            return
        self._pushed += v.size
        if self._pushed > self.n:
            raise ValueError(f"more values pushed ({self._pushed}) than announced ({self.n})")
        self._chunks.append(v)
        self._buffered += v.size
        assert self._walk is not None  # n > 0, as values came within the announced n
        try:
            self._walk.send(None)
        except StopIteration as done:
            self._result = done.value

    @property
    def total(self) -> float:
        """The sum; an error until all ``n`` values are pushed."""
        if self._result is None:
            raise ValueError(f"{self._pushed} of {self.n} values pushed; the sum needs all")
        return self._result

    def _head(self) -> int:
        """Values left in the first chunk."""
        while self._chunks and self._pos >= self._chunks[0].size:
            self._chunks.popleft()
            self._pos = 0
        return self._chunks[0].size - self._pos if self._chunks else 0

    def _take(self, m: int) -> np.ndarray:
        if m <= self._head():
            out = self._chunks[0][self._pos:self._pos + m]
            self._pos += m
        else:
            parts, got = [], 0
            while got < m:
                t = min(self._head(), m - got)
                parts.append(self._chunks[0][self._pos:self._pos + t])
                self._pos += t
                got += t
            out = np.concatenate(parts)
        self._buffered -= m
        return out

    def _node(self, m: int):
        """Generator: the pairwise sum of the next ``m`` values (yields while waiting)."""
        if m <= _BLOCK or m <= self._head():
            while self._buffered < m:
                yield
            # one call of numpy's pairwise_sum over these m values (-0.0: the identity)
            return float(np.add.reduce(self._take(m), initial=-0.0))
        half = m // 2
        half -= half % 8
        left = yield from self._node(half)
        right = yield from self._node(m - half)
        return left + right
