"""Triangle meshes held as arrays: their measures (area, volume, centroids, resolution) and
the :class:`~.surface.Surface` members every such mesh shares.

:class:`TriangleMeshSurface` is a mixin for classes with ``vertices`` (V, 3) metres and
``faces`` (F, 3) (counter-clockwise seen from outside): cratered meshes
(:class:`latlong.mesh.MeshSurface`), implicit bodies (:class:`latlong.ImplicitSurface`),
shape models (:class:`latlong.ShapeModel`) and mesh files (:class:`latlong.meshio.MeshData`)
get ``mesh()``, ``vertex_normals(weighting)``, ``local_frames(points)``, ``save(path)``
and the measures from it, computed here once; :class:`PlainMeshSurface` adds the empty
catalogs of a mesh that has none.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np

from craters._shared import ParameterError

from ..meshio.writers import MeshSource, write_mesh
from .normals import face_normals, tangent_frames, vertex_normals

__all__ = ["CENTRES", "PlainMeshSurface", "TriangleMeshSurface", "area_centroid", "bounds",
           "centre_point", "mean_edge_m", "polydata", "surface_area_m2", "volume_centroid",
           "volume_m3"]


def bounds(points) -> tuple[np.ndarray, np.ndarray]:
    """(lowest, highest) value of each column of ``points`` (n, k), n >= 1: the values of
    ``points.min(axis=0)`` and ``points.max(axis=0)`` (NaN where a column holds one),
    column by column - numpy reduces a narrow C-ordered array along axis 0 ~7x slower
    (0.1 s for a descent frame's 2.9 M vertices)."""
    p = np.asarray(points)
    cols = range(p.shape[1])
    return (np.array([p[:, k].min() for k in cols], dtype=p.dtype),
            np.array([p[:, k].max() for k in cols], dtype=p.dtype))


def _corners(vertices, faces):
    v = np.asarray(vertices)
    f = np.asarray(faces)
    return (v[f[:, k]] for k in range(3))


def volume_m3(vertices, faces) -> float:
    """Enclosed volume of a closed, outward mesh, m^3 (divergence theorem)."""
    a, b, c = _corners(vertices, faces)
    return float(np.einsum("ij,ij->", a, np.cross(b, c)) / 6.0)


def surface_area_m2(vertices, faces) -> float:
    """Total area of the faces, m^2."""
    a, b, c = _corners(vertices, faces)
    return float(0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1).sum())


def volume_centroid(vertices, faces) -> np.ndarray:
    """Centroid of the enclosed volume (sum of signed tetrahedra from the origin), m."""
    a, b, c = _corners(vertices, faces)
    vol = np.einsum("ij,ij->i", a, np.cross(b, c)) / 6.0
    return ((a + b + c) / 4.0 * vol[:, None]).sum(axis=0) / vol.sum()


def area_centroid(vertices, faces) -> np.ndarray:
    """Centroid of the surface (area-weighted face centroids), m."""
    a, b, c = _corners(vertices, faces)
    area = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1)
    return ((a + b + c) / 3.0 * area[:, None]).sum(axis=0) / area.sum()


def mean_edge_m(vertices, faces) -> float:
    """Mean length of the (undirected, distinct) edges, m: the mesh's resolution."""
    f = np.asarray(faces)
    e = np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]])
    e.sort(axis=1)
    e = np.unique(e, axis=0)
    v = np.asarray(vertices)
    return float(np.linalg.norm(v[e[:, 0]] - v[e[:, 1]], axis=1).mean())


#: The named points a mesh can be seen from (:func:`centre_point`).
CENTRES = ("volume-centroid", "area-centroid", "origin")


def centre_point(mesh, center) -> np.ndarray:
    """The point ``center`` names on ``mesh`` (a :class:`TriangleMeshSurface`), metres:
    ``"volume-centroid"`` (the centre of mass at constant density), ``"area-centroid"``,
    ``"origin"``, or (x, y, z) metres."""
    if isinstance(center, str):
        if center not in CENTRES:
            raise ParameterError("center", f"must be volume-centroid, area-centroid, origin "
                                 f"or (x, y, z) metres; got {center!r}")
        if center == "origin":
            return np.zeros(3)
        return mesh.volume_centroid if center == "volume-centroid" else mesh.area_centroid
    c = np.asarray(center, dtype=np.float64).reshape(-1)
    if c.shape != (3,) or not np.isfinite(c).all():
        raise ParameterError("center", f"must be a name or three finite coordinates (m); "
                             f"got {center!r}")
    return c


def polydata(vertices, faces):
    """A ``pyvista.PolyData`` of a triangle mesh (the vertices copied, float64)."""
    import pyvista as pv

    f = np.asarray(faces)
    cells = np.hstack([np.full((len(f), 1), 3), f]).ravel()
    return pv.PolyData(np.array(vertices, dtype=np.float64), cells)


class TriangleMeshSurface:
    """Mixin: the :class:`~.surface.Surface` geometry of a class holding ``vertices``
    (V, 3) float64 metres and ``faces`` (F, 3) int64 (module notes)."""

    __slots__ = ()
    mesh_source: Callable[[], MeshSource]
    """The class's own: the mesh and what it merges into it (boulders, fields)."""
    vertices: np.ndarray
    faces: np.ndarray

    def mesh(self) -> tuple[np.ndarray, np.ndarray]:
        """``(vertices, faces)``, metres and vertex indices."""
        return self.vertices, self.faces

    def vertex_normals(self, weighting: str = "area") -> np.ndarray:
        """Unit vertex normals (V, 3) float64 with a named weighting
        (:data:`latlong.geometry.normals.WEIGHTINGS`) of :meth:`mesh` (0 where unused)."""
        return vertex_normals(*self.mesh(), weighting)

    def face_normals(self) -> np.ndarray:
        """Unit face normals (F, 3) float64 (degenerate faces: 0)."""
        return face_normals(self.vertices, self.faces, unit=True)

    def local_frames(self, points) -> np.ndarray:
        """(n, 3, 3) frames, rows east, north, up, at the surface points closest to
        ``points`` (n, 3): up is the area-weighted vertex normals blended over the closest
        face (barycentric), east = z x up (:func:`~.normals.tangent_frames`)."""
        from ..mesh.topology import TriangleGrid

        verts, faces = self.mesh()
        face, uv, _ = TriangleGrid.build(verts, faces).closest(points)
        vn = vertex_normals(verts, faces, "area")
        w = np.stack([1.0 - uv.sum(axis=1), uv[:, 0], uv[:, 1]], 1)
        return tangent_frames(np.einsum("kc,kci->ki", w, vn[np.asarray(faces)[face]]))

    @property
    def volume_m3(self) -> float:
        """Enclosed volume, m^3 (closed, outward meshes)."""
        return volume_m3(self.vertices, self.faces)

    @property
    def area_m2(self) -> float:
        """Surface area, m^2."""
        return surface_area_m2(self.vertices, self.faces)

    @property
    def volume_centroid(self) -> np.ndarray:
        """Centroid of the enclosed volume, metres (the centre of mass at constant
        density)."""
        return volume_centroid(self.vertices, self.faces)

    @property
    def area_centroid(self) -> np.ndarray:
        """Centroid of the surface, metres."""
        return area_centroid(self.vertices, self.faces)

    @property
    def mean_edge_m(self) -> float:
        """Mean edge length, metres: the mesh's resolution."""
        return mean_edge_m(self.vertices, self.faces)

    def to_pyvista(self):
        """A ``pyvista.PolyData`` of the mesh."""
        return polydata(self.vertices, self.faces)

    def save(self, path, *, progress: bool = False) -> Path:
        """Write :meth:`mesh_source` (the mesh and what the class merges into it: boulders,
        fields) to a file chosen by suffix (:mod:`latlong.meshio.writers`), atomically."""
        return write_mesh(self.mesh_source(), path, progress=progress)


class PlainMeshSurface(TriangleMeshSurface):
    """Mixin of a mesh without catalogs (a shape model, a mesh file as read): no craters,
    no boulders, its ``source`` as metadata."""

    __slots__ = ()
    source: str

    @property
    def craters(self) -> None:
        """No crater catalog."""
        return None

    @property
    def boulders(self) -> None:
        """No boulders."""
        return None

    @property
    def metadata(self) -> dict:
        """``{"source": source}``."""
        return {"source": self.source}
