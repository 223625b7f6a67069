"""Triangle strips and recursive patch trees of the lat/long mesh (Martin 2014, III.B).

Each latitude band (ring r to ring r+1, the pole fans included) is one triangle strip.
The band's triangles come from the zipper triangulation in longitude order, each made
of the current vertex pair and the next vertex on one of the two rings, so a strip
follows the band adding one vertex per triangle. Where the advance does not match the
strip's alternating winding (two steps on the same ring: six times per band, at the
sector boundaries, and at every triangle of a pole fan) one repeated vertex - a
degenerate triangle - re-aligns it: about 1.006 strip vertices per triangle at M = 200.
Degenerate triangles have zero area and renderers skip them; without them a strip's
triangles are exactly the band's, with the same winding (``GL_TRIANGLE_STRIP``
convention: triangle k is (s[k], s[k+1], s[k+2]) for even k, (s[k+1], s[k], s[k+2])
for odd k).

A patch is a set of consecutive bands, each cut to the same fraction of its
triangles (the same range of longitudes, roughly). :func:`patch_tree` splits the
whole mesh recursively as in the paper: a patch with at least K strips whose longest
strip has at least K triangles is split into four (two groups of strips, each strip
halved); leaves carry their strips' triangle ranges and a bounding sphere.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from craters._shared import check_int

from .grid import LatLongGrid

__all__ = ["Patch", "band_strip", "join_strips", "patch_bounds", "patch_tree",
           "strip_triangles", "triangle_strips"]


def strip_triangles(strip: np.ndarray, *, keep_degenerate: bool = False) -> np.ndarray:
    """The triangles a strip draws (GL convention), degenerate ones dropped by default."""
    s = np.asarray(strip, dtype=np.int64)
    if len(s) < 3:
        return np.zeros((0, 3), dtype=np.int64)
    k = np.arange(len(s) - 2)
    a, b, c = s[k], s[k + 1], s[k + 2]
    odd = (k % 2) == 1
    tri = np.stack([np.where(odd, b, a), np.where(odd, a, b), c], axis=1)
    if not keep_degenerate:
        tri = tri[(tri[:, 0] != tri[:, 1]) & (tri[:, 1] != tri[:, 2]) & (tri[:, 0] != tri[:, 2])]
    return tri


def band_strip(grid: LatLongGrid, band: int, lo: int = 0, hi: int | None = None) -> np.ndarray:
    """The strip of band ``band`` (its triangles ``lo .. hi - 1`` in longitude order)."""
    from ._grid_kernels import _band_strip_kernel  # numba loads here
    m = grid.magnitude
    n_tri = int(grid.band_offsets()[band + 1] - grid.band_offsets()[band])
    hi = n_tri if hi is None else min(int(hi), n_tri)
    lo = max(0, int(lo))
    if hi <= lo:
        return np.zeros(0, dtype=np.int64)
    south = band >= m
    ra, rb = (band + 1, band) if south else (band, band + 1)
    sizes, offs = grid.ring_sizes(), grid.ring_offsets()
    out = np.empty(2 + 2 * (hi - lo), dtype=np.int64)
    k = _band_strip_kernel(offs[ra], sizes[ra], offs[rb], sizes[rb], south, lo, hi, out)
    return out[:k]


def triangle_strips(grid: LatLongGrid) -> list[np.ndarray]:
    """One strip per band, north to south: 2M strips whose triangles are the grid's.

    Examples
    --------
    >>> g = LatLongGrid(3)
    >>> strips = triangle_strips(g)
    >>> len(strips), sum(len(strip_triangles(s)) for s in strips) == g.n_triangles
    (6, True)
    """
    if not isinstance(grid, LatLongGrid):
        raise TypeError(f"`grid` must be a LatLongGrid; got {type(grid).__name__}")
    return [band_strip(grid, b) for b in range(2 * grid.magnitude)]


def join_strips(strips: list[np.ndarray]) -> np.ndarray:
    """One strip from several, stitched with degenerate triangles (parity kept)."""
    parts: list[np.ndarray] = []
    length = 0
    for s in strips:
        if len(s) == 0:
            continue
        if parts:
            bridge = [parts[-1][-1], s[0]] if length % 2 == 0 else [parts[-1][-1]] * 2 + [s[0]]
            parts.append(np.array(bridge, dtype=np.int64))
            length += len(bridge)
        parts.append(np.asarray(s, dtype=np.int64))
        length += len(s)
    return np.concatenate(parts) if parts else np.zeros(0, dtype=np.int64)


@dataclasses.dataclass
class Patch:
    """A node of the patch tree: bands ``band_lo .. band_hi - 1``, each cut to the
    fraction ``[frac_lo, frac_hi)`` of its triangles; leaves have no children."""

    band_lo: int
    band_hi: int
    frac_lo: float
    frac_hi: float
    depth: int = 0
    children: list = dataclasses.field(default_factory=list)
    centre: np.ndarray | None = None
    """Bounding sphere centre (metres), set for leaves by :func:`patch_bounds`."""
    radius: float = 0.0
    """Bounding sphere radius (metres)."""

    def triangle_range(self, grid: LatLongGrid, band: int) -> tuple[int, int]:
        """(lo, hi) triangle indices of ``band`` inside this patch."""
        n = int(grid.band_offsets()[band + 1] - grid.band_offsets()[band])
        return int(np.floor(self.frac_lo * n + 0.5)), int(np.floor(self.frac_hi * n + 0.5))

    def n_strips(self) -> int:
        return self.band_hi - self.band_lo

    def triangle_ranges(self, grid: LatLongGrid) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`triangle_range` of every band of the patch: (lo, hi) int64 arrays."""
        bo = grid.band_offsets()
        n = (bo[self.band_lo + 1:self.band_hi + 1] - bo[self.band_lo:self.band_hi])
        n = n.astype(np.float64)
        return (np.floor(self.frac_lo * n + 0.5).astype(np.int64),
                np.floor(self.frac_hi * n + 0.5).astype(np.int64))

    def longest(self, grid: LatLongGrid) -> int:
        lo, hi = self.triangle_ranges(grid)
        return int((hi - lo).max())

    def leaves(self):
        if not self.children:
            yield self
        for c in self.children:
            yield from c.leaves()

    def strips(self, grid: LatLongGrid) -> list[np.ndarray]:
        """This patch's strips (global vertex indices)."""
        out = []
        for b in range(self.band_lo, self.band_hi):
            lo, hi = self.triangle_range(grid, b)
            if hi > lo:
                out.append(band_strip(grid, b, lo, hi))
        return out


def patch_tree(grid: LatLongGrid, k: int) -> Patch:
    """The paper's recursive patch split with parameter ``k`` (>= 2).

    A patch with at least ``k`` strips whose longest strip has at least ``k`` triangles
    is split into four: its strips in two groups (north and south halves) and every strip
    halved (west and east); leaves have fewer than ``k`` strips or strips shorter than
    ``k`` triangles.

    Examples
    --------
    >>> root = patch_tree(LatLongGrid(16), 8)
    >>> leaves = list(root.leaves())
    >>> len(leaves) > 1 and all(p.n_strips() < 8 or p.longest(LatLongGrid(16)) < 8
    ...                         for p in leaves)
    True
    """
    if not isinstance(grid, LatLongGrid):
        raise TypeError(f"`grid` must be a LatLongGrid; got {type(grid).__name__}")
    k = check_int("k", k, 2, 1_000_000)
    root = Patch(0, 2 * grid.magnitude, 0.0, 1.0)
    stack = [root]
    while stack:
        p = stack.pop()
        if p.n_strips() >= k and p.longest(grid) >= k:
            mid_b = (p.band_lo + p.band_hi) // 2
            mid_f = 0.5 * (p.frac_lo + p.frac_hi)
            p.children = [Patch(bl, bh, fl, fh, p.depth + 1)
                          for bl, bh in ((p.band_lo, mid_b), (mid_b, p.band_hi))
                          for fl, fh in ((p.frac_lo, mid_f), (mid_f, p.frac_hi))]
            stack.extend(p.children)
    return root


def patch_bounds(patch: Patch, strips: list[np.ndarray], vertices_of) -> None:
    """Set a leaf's bounding sphere from its strips' vertices (``vertices_of(idx)``)."""
    idx = np.unique(np.concatenate(strips)) if strips else np.zeros(0, np.int64)
    if len(idx) == 0:
        patch.centre, patch.radius = np.zeros(3), 0.0
        return
    v = vertices_of(idx)
    lo, hi = v.min(axis=0), v.max(axis=0)
    c = 0.5 * (lo + hi)
    patch.centre = c
    patch.radius = float(np.sqrt(((v - c) ** 2).sum(axis=1).max()))
