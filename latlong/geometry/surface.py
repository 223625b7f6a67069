"""The one interface of every surface craterform makes or reads: :class:`Surface`.

Lat/long bodies (:class:`latlong.Body`), cratered meshes (:class:`latlong.mesh.MeshSurface`),
implicit bodies (:class:`latlong.ImplicitSurface`), shape models
(:class:`latlong.ShapeModel`), mesh files as read
(:class:`latlong.meshio.readers.MeshData`) and DEM sites (``dem``'s surfaces of a DEM or a
layer stack) all implement it, so that what uses a surface (sensors, writers, previews,
gravity) never asks which kind it holds. It is a :class:`typing.Protocol`:
a class implements it by having these members, without inheriting from it.

What is not common to every kind stays with the kind: a lat/long body's grid, a mesh
surface's refinement; a capability some kinds have is a protocol of its own
(:class:`Resamplable`). Normals are named by their weighting
(:mod:`latlong.geometry.normals`); meshes held as arrays share their members through
:class:`latlong.geometry.meshes.TriangleMeshSurface`.

Frames and units: positions in metres in the surface's own frame (body-fixed, origin at
the body's centre; for a DEM site the site's local frame, x east, y north, z up, metres
from the target pixel); faces counter-clockwise seen from outside (from above for a DEM).
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Protocol, runtime_checkable

if TYPE_CHECKING:
    import numpy as np

    from ..meshio.writers import MeshSource

__all__ = ["Resamplable", "Surface"]


@runtime_checkable
class Surface(Protocol):
    """A triangulated surface, the catalogs of what was put on it, and how it was made."""

    @property
    def craters(self) -> np.ndarray | None:
        """The crater catalog as stamped (a structured array, :mod:`craters.catalog`), or
        None."""
        ...

    @property
    def boulders(self) -> np.ndarray | None:
        """The boulders as placed (a structured array), or None."""
        ...

    @property
    def metadata(self) -> dict:
        """JSON-serialisable description: seed, parameters, source, version."""
        ...

    def mesh(self) -> tuple[np.ndarray, np.ndarray]:
        """``(vertices, faces)``: (V, 3) float64 positions in metres and (F, 3) int64
        vertex indices, counter-clockwise seen from outside (boulders not included)."""
        ...

    def vertex_normals(self, weighting: str = "area") -> np.ndarray:
        """(V, 3) unit vertex normals of :meth:`mesh`'s vertices, outward; ``weighting``
        names how the facets around a vertex are weighted
        (:data:`latlong.geometry.normals.WEIGHTINGS`)."""
        ...

    def local_frames(self, points) -> np.ndarray:
        """(n, 3, 3) orthonormal frames at points on (or near) the surface, rows east,
        north, up (up = outward; for a DEM site +z), in the surface's frame."""
        ...

    def mesh_source(self) -> MeshSource:
        """The surface (and its boulders, with per-vertex fields) for the mesh writers."""
        ...

    def save(self, path, *, progress: bool = False) -> Path:
        """Write the surface to a file chosen by suffix, atomically; the path written."""
        ...


@runtime_checkable
class Resamplable(Protocol):
    """A surface that can put itself on a coarser mesh cheaply (a lat/long body onto a
    coarser grid), for pictures and quick looks."""

    def resampled(self, max_vertices: int) -> Surface:
        """This surface with at most ``max_vertices`` vertices (itself when it has no
        more), its catalogs kept."""
        ...
