"""Placed boulders merged into a surface's mesh for the writers: their vertices, faces and
facets a chunk of rocks at a time, after the surface's own.

Every surface that writes its boulders (a lat/long body, a mesh surface) does it the
same way: the boulders at their finest level, after the surface's vertices and faces,
with a per-vertex ``boulder_id`` (-1 on the surface, else the catalog row: ground truth
for hazard detection) and a ``height_m`` the surface defines (above the reference
radius on a body, above the ground under the rock on a mesh).
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from dataclasses import dataclass

import numpy as np

from craters.boulders import boulder_faces, catalog_shape, iter_boulder_meshes

__all__ = ["BoulderMeshes", "mesh_fields"]


@dataclass(frozen=True)
class BoulderMeshes:
    """The boulders of ``catalog`` (a placed catalog, :func:`latlong.place_boulders`)
    after ``first_vertex`` surface vertices (module notes)."""

    catalog: np.ndarray
    """The placed boulder catalog (non-empty)."""
    first_vertex: int
    """The surface's vertex count: the first boulder vertex's index."""

    @classmethod
    def of(cls, catalog, first_vertex: int) -> BoulderMeshes | None:
        """The boulders of a surface, or None when it has none."""
        if catalog is None or not len(catalog):
            return None
        return cls(catalog, int(first_vertex))

    @property
    def level(self) -> int:
        """The finest level of the catalog's boulder shape (the one written)."""
        return catalog_shape(self.catalog).levels[-1]

    @property
    def rock_vertices(self) -> int:
        """Vertices of one boulder."""
        return 10 * 4**self.level + 2

    @property
    def n_vertices(self) -> int:
        return len(self.catalog) * self.rock_vertices

    @property
    def n_faces(self) -> int:
        return len(self.catalog) * 20 * 4**self.level

    def vertex_chunks(self, height_m: Callable[[int, np.ndarray], np.ndarray]
                      ) -> Iterator[tuple[np.ndarray, dict]]:
        """``(xyz, {"height_m", "boulder_id"})`` a chunk of rocks at a time; ``height_m(first
        row, vertices (k, V, 3))`` gives the chunk's heights."""
        nv = self.rock_vertices
        for s0, world, _ in iter_boulder_meshes(self.catalog):
            k = world.shape[0]
            yield world.reshape(-1, 3), {
                "height_m": np.asarray(height_m(s0, world)).reshape(-1),
                "boulder_id": np.repeat(np.arange(s0, s0 + k, dtype=np.int32), nv)}

    def face_chunks(self) -> Iterator[np.ndarray]:
        """(k, 3) global vertex indices, a chunk of rocks at a time."""
        faces, nv = boulder_faces(self.level), self.rock_vertices
        for s0, world, _ in iter_boulder_meshes(self.catalog):
            offsets = self.first_vertex + (s0 + np.arange(len(world)))[:, None, None] * nv
            yield (faces[None] + offsets).reshape(-1, 3)

    def facet_chunks(self) -> Iterator[np.ndarray]:
        """(k, 3, 3) triangle corners, a chunk of rocks at a time."""
        for _, world, faces in iter_boulder_meshes(self.catalog):
            yield world[:, faces].reshape(-1, 3, 3)

    def comment(self, after: str) -> str:
        """The writers' comment line: how many boulders come after ``after``."""
        return f"{len(self.catalog)} boulders after {after}, boulder_id = catalog row"


def mesh_fields(rocks: BoulderMeshes | None) -> tuple[tuple[str, str], ...]:
    """The per-vertex fields of a surface's mesh: ``height_m``, and ``boulder_id`` with
    boulders."""
    return (("height_m", "<f4"),) + ((("boulder_id", "<i4"),) if rocks is not None else ())

