"""The holes of a raster bigger than memory: the 8-connected components of its unknown
pixels, labelled tile by tile (:func:`holes_of_file`, step 1 of :mod:`dem.tiledfill`).

Each tile is labelled on its own (scipy); the labels that touch across tile edges
(diagonals included) are joined as the connected components of a graph of labels; each
hole gets its bounding box, pixel count and first pixel in raster order, the order in
which :func:`dem.fill_gaps` fills them. Memory: one tile, the last row and column of the
tiles next to it, the label pairs along the tile edges and a few integers per hole.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from craters._shared import progress_bar

__all__ = ["Holes", "holes_of_file", "tile_windows"]


class Holes(NamedTuple):
    """The holes of a raster, in ``fill_gaps``'s order (first pixel in raster order)."""

    box: np.ndarray
    """(n, 4) int64: row0, row1, col0, col1 (exclusive ends)."""
    first: np.ndarray
    """(n,) int64: raster index (row * cols + col) of each hole's first pixel."""
    pixels: np.ndarray
    """(n,) int64: pixel count."""
    known: int
    """Known pixels of the raster."""


def tile_windows(rows: int, cols: int, tile: int) -> list[tuple[int, int, int, int]]:
    """The windows ``(row_off, col_off, rows, cols)`` of a raster cut into tiles of side
    ``tile``, row by row (the last ones smaller).

    Examples
    --------
    >>> tile_windows(3, 5, 2)
    [(0, 0, 2, 2), (0, 2, 2, 2), (0, 4, 2, 1), (2, 0, 1, 2), (2, 2, 1, 2), (2, 4, 1, 1)]
    """
    return [(r, c, min(tile, rows - r), min(tile, cols - c))
            for r in range(0, rows, tile) for c in range(0, cols, tile)]


def holes_of_file(read_window, shape, tile_px: int, *, progress: bool = False) -> Holes:
    """The 8-connected components of the unknown pixels of a raster read tile by tile.

    ``read_window(r, c, h, w)`` returns that window's heights (NaN = unknown). The same
    components, boxes and order as ``scipy.ndimage.label`` of the whole unknown mask.
    """
    from scipy import ndimage

    rows, cols = shape
    eight = np.ones((3, 3), dtype=bool)
    boxes, firsts, counts = [np.zeros((0, 4), np.int64)], [np.zeros(0, np.int64)], \
        [np.zeros(0, np.int64)]
    edges_a, edges_b = [], []
    bottom: dict = {}  # (tile row, tile col) -> labels of its last row (global ids)
    right: dict = {}
    next_id, known = 1, 0
    tiles = tile_windows(rows, cols, tile_px)
    for r, c, h, w in progress_bar(tiles, enabled=progress, desc="fill: find holes"):
        unknown = np.isnan(read_window(r, c, h, w))
        known += int(unknown.size - unknown.sum())
        lab, n = ndimage.label(unknown, structure=eight)
        lab = lab.astype(np.int64)
        if n:
            objs = ndimage.find_objects(lab)
            box = np.array([[s[0].start + r, s[0].stop + r, s[1].start + c, s[1].stop + c]
                            for s in objs], dtype=np.int64)
            first = np.array([(s[0].start + r) * cols + c + s[1].start
                              + int(np.argmax(lab[s[0].start, s[1]] == k))
                              for k, s in enumerate(objs, 1)], dtype=np.int64)
            boxes.append(box)
            firsts.append(first)
            counts.append(np.bincount(lab.ravel(), minlength=n + 1)[1:].astype(np.int64))
            lab[lab > 0] += next_id - 1
        ti, tj = r // tile_px, c // tile_px
        for a, b in _edge_links(lab, bottom, right, ti, tj):
            both = (a > 0) & (b > 0)
            edges_a.append(a[both])
            edges_b.append(b[both])
        bottom[(ti, tj)] = lab[-1].copy()
        right[(ti, tj)] = lab[:, -1].copy()
        bottom.pop((ti - 2, tj + 1), None)
        right.pop((ti, tj - 1), None)
        next_id += n
    return _joined(np.concatenate(boxes), np.concatenate(firsts), np.concatenate(counts),
                   edges_a, edges_b, known)


def _edge_links(lab: np.ndarray, bottom: dict, right: dict, ti: int, tj: int) -> list:
    """Pairs of label rows that touch (8-connected) across the edges of tile ``(ti, tj)``
    (its labels ``lab``) with the tiles above (three of them, diagonals included) and to
    the left (their last rows / columns in ``bottom`` / ``right``)."""
    h, w = lab.shape
    links = []
    up = bottom.get((ti - 1, tj))
    if up is not None:
        for shift in (-1, 0, 1):
            links.append((up[max(shift, 0):w + min(shift, 0)],
                          lab[0, max(-shift, 0):w - max(shift, 0)]))
    left = right.get((ti, tj - 1))
    if left is not None:
        for shift in (-1, 0, 1):
            links.append((left[max(shift, 0):h + min(shift, 0)],
                          lab[max(-shift, 0):h - max(shift, 0), 0]))
    ul = bottom.get((ti - 1, tj - 1))
    if ul is not None:
        links.append((ul[-1:], lab[0, :1]))
    ur = bottom.get((ti - 1, tj + 1))
    if ur is not None:
        links.append((ur[:1], lab[0, -1:]))
    return links


def _joined(box, first, count, edges_a: list, edges_b: list, known: int) -> Holes:
    """The holes: the tiles' components joined where they touch (the connected
    components of the graph of ``edges``), in the order of their first pixels."""
    from scipy import sparse
    from scipy.sparse.csgraph import connected_components

    n = len(box)
    if n == 0:
        return Holes(box, first, count, known)
    a = np.concatenate(edges_a) - 1 if edges_a else np.zeros(0, np.int64)
    b = np.concatenate(edges_b) - 1 if edges_b else np.zeros(0, np.int64)
    graph = sparse.coo_matrix((np.ones(len(a), np.int8), (a, b)), shape=(n, n))
    m, comp = connected_components(graph, directed=False)
    out_box = np.empty((m, 4), np.int64)
    out_box[:, 0] = out_box[:, 2] = np.iinfo(np.int64).max
    out_box[:, 1] = out_box[:, 3] = np.iinfo(np.int64).min
    for j, fn in ((0, np.minimum), (1, np.maximum), (2, np.minimum), (3, np.maximum)):
        fn.at(out_box[:, j], comp, box[:, j])
    out_first = np.full(m, np.iinfo(np.int64).max, np.int64)
    np.minimum.at(out_first, comp, first)
    out_count = np.bincount(comp, weights=count, minlength=m).astype(np.int64)
    order = np.argsort(out_first, kind="stable")
    return Holes(out_box[order], out_first[order], out_count[order], known)
