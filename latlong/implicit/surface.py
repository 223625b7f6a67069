"""The result of the implicit build (:func:`~latlong.implicit.build.implicit_surface`):
:class:`ImplicitSurface`, a closed, outward oriented triangle mesh and the crater catalog
that made it.

For star-shaped results :meth:`ImplicitSurface.to_body` casts the mesh onto a
:class:`~latlong.LatLongGrid` (:func:`latlong.shapes.from_shape_model`), so slopes,
strips, boulders and exports of the lat/long toolkit apply; it is the only place where
the implicit backend meets the lat/long grid.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from ..geometry.meshes import TriangleMeshSurface
from ..meshio.writers import MESH_SUFFIXES, MeshSource, array_source
from ..shapes import ShapeModel
from . import _kernels as _k
from .metaballs import Metaballs
from .packing import SpherePacking

__all__ = ["MESH_SUFFIXES", "ImplicitSurface"]


@dataclasses.dataclass(frozen=True)
class ImplicitSurface(TriangleMeshSurface):
    """A marching-cubes mesh of an implicit body and the crater catalog that made it: a
    :class:`~latlong.geometry.surface.Surface` (normals, frames and measures:
    :class:`~latlong.geometry.meshes.TriangleMeshSurface`)."""

    vertices: np.ndarray
    """(V, 3) float64 positions, metres, in the frame of the constraint moved so that its
    volume centroid is the origin."""
    faces: np.ndarray
    """(F, 3) int64, counter-clockwise seen from outside; closed."""
    catalog: np.ndarray
    """Crater catalog (structured array; see :func:`implicit_surface`)."""
    metadata: dict
    """Parameters, packing and fit figures (JSON-serialisable, deterministic)."""
    packing: SpherePacking | None = None
    metaballs: Metaballs | None = None
    timings_s: dict = dataclasses.field(default_factory=dict)
    """Wall time of each stage, seconds (not part of the metadata)."""
    base_vertices: np.ndarray | None = None
    """The coarse metaball surface (before craters and noise): (V, 3) metres."""
    base_faces: np.ndarray | None = None
    """Its triangles (F, 3)."""
    impulses: dict | None = None
    """The crater kernels as added (catalog order): ``centers, normals, kinds, params``
    (kappa, beta, gamma, a, b per row, heights already weighted), ``support, zhalf``."""

    def crater_heights(self, points, rows=None) -> np.ndarray:
        """Sum of the crater kernels (metres, up = outward) at points (n, 3), as added
        to the field; ``rows`` restricts it to some craters (catalog rows)."""
        pts = np.ascontiguousarray(np.asarray(points, dtype=np.float64).reshape(-1, 3))
        imp = self.impulses or {}
        sel = slice(None) if rows is None else np.atleast_1d(np.asarray(rows, dtype=np.int64))
        out = np.zeros(len(pts))
        if imp and len(imp["centers"]):
            centers, normals, kinds, params, support, zhalf = (
                np.ascontiguousarray(imp[k][sel]) for k in (
                    "centers", "normals", "kinds", "params", "support", "zhalf"))
            _k._crater_points_kernel(pts, centers, normals, kinds, params, support, zhalf, out)
        return out

    @property
    def craters(self) -> np.ndarray:
        """The crater catalog (:attr:`catalog`): the surface's craters."""
        return self.catalog

    @property
    def boulders(self) -> None:
        """No boulders: the implicit backend places none."""
        return None

    def is_watertight(self) -> bool:
        """Every edge belongs to exactly two faces, each direction once."""
        e = np.concatenate([self.faces[:, [0, 1]], self.faces[:, [1, 2]],
                            self.faces[:, [2, 0]]])
        directed = e[:, 0] * len(self.vertices) + e[:, 1]
        undirected = np.sort(e, axis=1)
        _, counts = np.unique(undirected, axis=0, return_counts=True)
        return bool((counts == 2).all() and np.unique(directed).size == directed.size)

    def mesh_source(self) -> MeshSource:
        """The mesh for the shared mesh writers."""
        return array_source(self.vertices, self.faces, "craterform implicit body, metres")

    def to_body(self, magnitude: int, *, crossings: str = "error"):
        """Cast the mesh onto a lat/long grid of ``magnitude`` from the origin.

        ``crossings="error"`` raises ValueError (with the affected share of directions)
        unless the surface is star-shaped from the origin; ``"outermost"`` or
        ``"innermost"`` keep one crossing (overhangs are then lost). The body keeps the
        crater catalog (:func:`latlong.shapes.from_shape_model`).
        """
        from ..shapes import from_shape_model  # the backend's one meeting with the grid

        model = ShapeModel(self.vertices, self.faces, "implicit surface")
        body = from_shape_model(model, magnitude, center="origin", crossings=crossings,
                                smooth="none", subdivisions=0,
                                metadata={"implicit": self.metadata})
        return body.replace(craters=self.catalog if len(self.catalog) else None)
