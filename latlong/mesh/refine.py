"""Refining a shape model to a requested vertex spacing.

A real shape model's facets are metres to hundreds of metres across; craters and
boulders need vertices at their own scale. The model is refined in two steps: ``L``
levels of interpolating (butterfly) subdivision, as the lat/long import smooths a model
before casting it (:func:`latlong.from_shape_model`; each level halves the edges and
keeps the model's vertices on the surface), then an exact n-section of every triangle
(each edge cut into ``n`` equal parts, every triangle into n^2; flat, so it adds vertices
without changing the surface), with ``L`` and ``n`` chosen so that the mean edge is
within 15 % of the request when it can be (the most butterfly levels that allow it,
between :data:`MIN_BUTTERFLY_LEVELS` and :data:`MAX_BUTTERFLY_LEVELS`; integer factors
2^L n cannot hit every ratio: 9.65 m facets give 1.2 m or 0.8 m, not 1 m).
"""

from __future__ import annotations

import math

import numpy as np

from craters._shared import (
    ParameterError,
    check_choice,
    check_positive,
    human_bytes,
    physical_memory_bytes,
)

from ..shapes import ShapeModel
from ._kernels import _nsection_kernel

__all__ = ["BYTES_PER_VERTEX", "MAX_BUTTERFLY_LEVELS", "MIN_BUTTERFLY_LEVELS", "refine_mesh",
           "refinement_plan"]

#: Butterfly levels at most (each x4 faces); the rest is n-section.
MAX_BUTTERFLY_LEVELS = 3
#: Butterfly levels at least when the model is that much coarser than the request (the
#: lat/long import's default, :func:`latlong.from_shape_model`).
MIN_BUTTERFLY_LEVELS = 2
#: Memory per vertex of a mesh-surface build (positions, heights, normals, adjacency,
#: faces, the triangle grid, output buffers), bytes.
BYTES_PER_VERTEX = 600
_TOLERANCE = math.log(1.15)


def refinement_plan(edge_m: float, spacing_m: float, smooth: str = "butterfly") -> tuple:
    """(butterfly levels L, n-section n) taking a mean edge of ``edge_m`` to about
    ``spacing_m``: at least :data:`MIN_BUTTERFLY_LEVELS` butterfly levels when the ratio
    allows them (as the lat/long import smooths a model: its flat facets must not become
    the body's), the most (<= MAX_BUTTERFLY_LEVELS) whose n = round(ratio / 2^L) lands
    within 15 % of the request, else the closest; (0, 1) when the model is already as
    fine.

    Examples
    --------
    >>> refinement_plan(9.65, 0.8)   # 9.65 m facets -> 2 butterfly levels, then thirds
    (2, 3)
    >>> refinement_plan(9.65, 1.0), refinement_plan(9.65, 3.0), refinement_plan(1.0, 2.0)
    ((3, 1), (1, 2), (0, 1))
    """
    ratio = edge_m / spacing_m
    if ratio <= 1.0:
        return 0, 1
    most = int(math.floor(math.log2(ratio * 1.15)))  # within 15 % of a level
    top = 0 if smooth in ("none", "linear") else min(MAX_BUTTERFLY_LEVELS, most)
    least = min(top, MIN_BUTTERFLY_LEVELS)
    best: tuple[float, int, int] | None = None
    for levels in range(top, least - 1, -1):
        n = max(1, round(ratio / 2**levels))
        err = abs(math.log(2**levels * n / ratio))
        if err <= _TOLERANCE:
            return levels, n
        if best is None or err < best[0] - 1e-12:
            best = (err, levels, n)
    assert best is not None  # the loop ran at least once (least <= top)
    return best[1], best[2]


def _edges(faces: np.ndarray):
    """(edge vertices (E, 2) lower id first, edge id of each face's three edges (F, 3))."""
    e = np.stack([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]], axis=1).reshape(-1, 2)
    e.sort(axis=1)
    n = int(faces.max()) + 1
    uniq, inverse = np.unique(e[:, 0] * n + e[:, 1], return_inverse=True)
    edge_v = np.stack([uniq // n, uniq % n], axis=1)
    return edge_v, inverse.reshape(-1, 3)


def nsection(vertices: np.ndarray, faces: np.ndarray, n: int):
    """Every edge cut into ``n`` equal parts, every triangle into n^2 (flat); returns
    (vertices, faces), the input vertices first with their indices."""
    if n == 1:
        return vertices, faces
    edge_v, face_edges = _edges(faces)
    nv, ne, nf = len(vertices), len(edge_v), len(faces)
    total = nv + ne * (n - 1) + nf * (n - 1) * (n - 2) // 2
    out_pos = np.empty((total, 3))
    out_faces = np.empty((nf * n * n, 3), dtype=np.int64)
    _nsection_kernel(np.ascontiguousarray(vertices, dtype=np.float64),
                     np.ascontiguousarray(faces, dtype=np.int64), face_edges, edge_v, n,
                     out_pos, out_faces)
    return out_pos, out_faces


def _butterfly(model: ShapeModel, levels: int) -> ShapeModel:
    if levels == 0:
        return model
    mesh = model.to_pyvista().subdivide(levels, subfilter="butterfly")
    faces = np.asarray(mesh.faces).reshape(-1, 4)[:, 1:].astype(np.int64)
    return ShapeModel(np.asarray(mesh.points, dtype=np.float64), faces, model.source)


def refine_mesh(model: ShapeModel, spacing_m: float, *, smooth: str = "butterfly") -> ShapeModel:
    """The model refined to a mean edge of about ``spacing_m`` (module notes).

    Parameters
    ----------
    model : ShapeModel
        Closed, outward-oriented mesh (:func:`latlong.read_shape_model`), metres.
    spacing_m : float
        Wanted mean edge, metres.
    smooth : {"butterfly", "linear"}
        ``butterfly``: interpolating subdivision first (a coarse model's flat facets do
        not become the body's), then n-section; ``linear``: n-section only (the facets
        kept exactly).

    Returns
    -------
    ShapeModel with the model's vertices first (same indices), refused up front (with
    the estimate) when it cannot fit in this machine's memory.

    Examples
    --------
    >>> import pyvista as pv
    >>> from latlong.shapes import ShapeModel
    >>> s = pv.Icosphere(radius=10.0, nsub=1)
    >>> m = ShapeModel(np.asarray(s.points, float), np.asarray(s.faces).reshape(-1, 4)[:, 1:])
    >>> fine = refine_mesh(m, m.mean_edge_m / 3, smooth="linear")
    >>> len(fine.faces) // len(m.faces), bool(np.allclose(fine.vertices[:42], m.vertices))
    (9, True)
    """
    if not isinstance(model, ShapeModel):
        raise TypeError(f"`model` must be a ShapeModel; got {type(model).__name__}")
    spacing_m = check_positive("spacing_m", spacing_m)
    smooth = check_choice("smooth", smooth, ("butterfly", "linear"))
    levels, n = refinement_plan(model.mean_edge_m, spacing_m, smooth)
    factor = (2**levels * n) ** 2
    need = len(model.vertices) * factor * BYTES_PER_VERTEX
    have = physical_memory_bytes()
    if need > 0.85 * have:
        count = len(model.vertices) * factor
        raise ParameterError("spacing_m", f"{spacing_m:g} m on a model with "
                             f"{model.mean_edge_m:.3g} m edges needs about {count:.3g} vertices "
                             f"({human_bytes(need)}); this machine has {human_bytes(have)}")
    smoothed = _butterfly(model, levels)
    verts, faces = nsection(smoothed.vertices, smoothed.faces, n)
    return ShapeModel(verts, faces, model.source)
