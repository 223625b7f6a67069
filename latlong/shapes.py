"""Real shape models as the base of a lat/long body: readers and ray-cast import.

Reading (:func:`read_shape_model`): any mesh file of the reader registry
(:func:`latlong.meshio.readers.read_mesh`: OBJ, PDS plate models, PLY, STL, VTK, glTF). Units
are explicit (``units="km"`` or ``"m"``; bodies are built in metres). Meshes are checked:
non-empty, finite, closed and 2-manifold (every edge in exactly two faces); coincident
vertices are merged (STL stores them per facet) and inward-facing models are flipped.

Import (:func:`from_shape_model`): the model is moved so that the chosen centre (its
volume centroid by default) is the origin, optionally smoothed by interpolating
subdivision, and every grid direction is cast from the centre: the distance to the
surface is the vertex radius. Directions that cross the surface more than once show
that the body is not star-shaped from the centre; their share of the sphere is
reported, and they are refused or resolved by the outermost or innermost crossing.
"""

from __future__ import annotations

import dataclasses
import logging
import os

import numpy as np

from craters._shared import ParameterError, check_choice, check_int

from .body import Body
from .geometry.meshes import PlainMeshSurface, centre_point, polydata
from .geometry.surface import Surface
from .grid import LatLongGrid
from .meshio.readers import read_mesh
from .meshio.writers import MeshSource, array_source

__all__ = ["ShapeModel", "as_shape_model", "cast_radii", "from_shape_model",
           "mean_surface_distance", "read_shape_model", "sample_surface"]

logger = logging.getLogger(__name__)
#: Share of the grid directions that may cross a model more than once and still be cast
#: with ``crossings="error"`` (the outermost crossing kept, with a warning): below one
#: grid vertex in 10^4 (a Eros plate model's 2 vertices of 2.9e5) is a pinhole in the
#: model, not a shape that is not star-shaped.
NON_STAR_TOLERANCE = 1e-4
#: Extent a shape model may span, metres (a boulder to a gas giant): the geometry
#: (volumes ~ extent^3, edge lengths) stays within float64 and divides safely.
SIZE_RANGE_M = (1e-3, 1e9)


@dataclasses.dataclass(frozen=True)
class ShapeModel(PlainMeshSurface):
    """A closed, outward-oriented triangle mesh in metres: a
    :class:`~latlong.geometry.surface.Surface` with no catalogs (its measures, normals and
    writing: :class:`~latlong.geometry.meshes.PlainMeshSurface`)."""

    vertices: np.ndarray
    """(V, 3) float64 positions, metres."""
    faces: np.ndarray
    """(F, 3) int64 vertex indices, counter-clockwise seen from outside."""
    source: str = ""
    """Where it came from (path or description)."""

    def mesh_source(self) -> MeshSource:
        """The mesh for the shared mesh writers."""
        return array_source(self.vertices, self.faces, "craterform shape model, metres")


# --------------------------------------------------------------------------- readers
def _check_and_orient(verts: np.ndarray, faces: np.ndarray, source: str) -> ShapeModel:
    if len(verts) == 0 or len(faces) == 0:
        raise ValueError(f"shape model {source!r} is empty (no vertices or no faces)")
    if not np.isfinite(verts).all():
        raise ValueError(f"shape model {source!r} has non-finite vertex coordinates")
    extent = float(np.ptp(verts, axis=0).max())
    if not SIZE_RANGE_M[0] <= extent <= SIZE_RANGE_M[1]:
        raise ValueError(f"shape model {source!r} spans {extent:.6g} m; allowed "
                         f"{SIZE_RANGE_M[0]:g} m to {SIZE_RANGE_M[1]:g} m (check its units)")
    # merge coincident vertices (STL facets, duplicated seams); lexicographic order as
    # np.unique(axis=0) gives, by lexsort (np.unique(axis=0) takes ~40 s on 1 M vertices)
    order = np.lexsort((verts[:, 2], verts[:, 1], verts[:, 0]))
    ordered = verts[order]
    new = np.r_[True, (ordered[1:] != ordered[:-1]).any(axis=1)]
    inverse = np.empty(len(verts), dtype=np.int64)
    inverse[order] = np.cumsum(new) - 1
    faces = inverse[faces]
    verts = ordered[new]
    degenerate = (faces[:, 0] == faces[:, 1]) | (faces[:, 1] == faces[:, 2]) | (
        faces[:, 0] == faces[:, 2])
    faces = faces[~degenerate]
    used = np.flatnonzero(np.bincount(faces.ravel(), minlength=len(verts)))  # sorted
    remap = np.full(len(verts), -1, dtype=np.int64)
    remap[used] = np.arange(len(used))
    verts, faces = verts[used], remap[faces]
    # closed and 2-manifold: every undirected edge in exactly two faces
    e = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
    key = np.sort(e, axis=1)
    key = np.sort(key[:, 0] * len(verts) + key[:, 1])  # one int64 per undirected edge
    counts = np.diff(np.flatnonzero(np.r_[True, key[1:] != key[:-1], True]))
    if (counts > 2).any():
        raise ValueError(f"shape model {source!r} is not 2-manifold: "
                         f"{int((counts > 2).sum())} edges belong to more than two faces")
    if (counts == 1).any():
        raise ValueError(f"shape model {source!r} is open: {int((counts == 1).sum())} edges "
                         "belong to a single face (holes); close it first")
    # consistent orientation: each directed edge once
    directed = np.sort(e[:, 0] * len(verts) + e[:, 1])
    if (directed[1:] == directed[:-1]).any():
        raise ValueError(f"shape model {source!r} has inconsistently oriented faces")
    model = ShapeModel(verts, faces, source)
    if model.volume_m3 < 0:  # inward-facing: flip
        model = ShapeModel(verts, faces[:, ::-1].copy(), source)
    return model


def read_shape_model(path, *, units: str) -> ShapeModel:
    """Read a closed triangle mesh (OBJ, PDS plate ``.tab``/``.plt``, PLY, STL, VTK, glTF:
    :func:`latlong.meshio.readers.read_mesh`) as a shape model.

    Parameters
    ----------
    path : str or Path
    units : {"km", "m"}
        Length unit of the file's coordinates (explicit: models come in both).

    Returns
    -------
    ShapeModel in metres, outward-oriented, with merged coincident vertices; a mesh that
    is empty, not finite, open or not 2-manifold is refused (``ValueError``).
    """
    mesh = read_mesh(path, units=units, what="shape model")
    return _check_and_orient(mesh.vertices, mesh.faces, mesh.source)


def as_shape_model(model, *, units: str | None = None, what: str = "shape model",
                   name: str = "model") -> ShapeModel:
    """``model`` itself, or a path read with :func:`read_shape_model` (which needs
    ``units``; ``what`` names the file in messages)."""
    if isinstance(model, str | os.PathLike):
        if units is None:
            raise ParameterError("units", f"(km or m) is required when reading a {what} file")
        return read_shape_model(model, units=units)
    if not isinstance(model, ShapeModel):
        raise TypeError(f"`{name}` must be a ShapeModel or a path; got {type(model).__name__}")
    return model


# --------------------------------------------------------------------------- import
def cast_radii(model: ShapeModel, grid: LatLongGrid, *, brute_force: bool = False):
    """Cast every grid direction from the origin onto ``model``.

    Returns ``(count, nearest, farthest)``: distinct crossings per direction (1 for a
    star-shaped body; an edge or vertex hit through two triangles counts once when it is
    the nearest or farthest crossing) and the nearest and farthest distances in metres.
    ``brute_force`` tests every triangle for every direction (the reference).
    """
    verts = np.ascontiguousarray(model.vertices, dtype=np.float64)
    faces = np.ascontiguousarray(model.faces, dtype=np.int64)
    n = grid.n_vertices
    count = np.zeros(n, dtype=np.int64)
    tmin = np.zeros(n)
    tmax = np.zeros(n)
    unit = grid.unit_vectors()
    from ._shape_kernels import _brute_force_kernel, _raycast_kernel  # numba loads here

    if brute_force:
        _brute_force_kernel(unit, verts, faces, count, tmin, tmax)
    else:
        margin = 2.0 * np.pi / (2 * grid.magnitude)
        _raycast_kernel(grid.magnitude, grid.ring_offsets(), unit, verts, faces, margin,
                        count, tmin, tmax)
    return count, tmin, tmax


def _smoothed(model: ShapeModel, smooth: str, subdivisions: int) -> ShapeModel:
    if smooth == "none" or subdivisions == 0:
        return model
    mesh = model.to_pyvista().subdivide(subdivisions, subfilter=smooth)
    faces = np.asarray(mesh.faces).reshape(-1, 4)[:, 1:].astype(np.int64)
    return ShapeModel(np.asarray(mesh.points, dtype=np.float64), faces, model.source)


def _share(fraction: float) -> str:
    """A fraction in words that never rounds a non-zero share to "0.00 %"."""
    return f"{fraction:.2%}" if fraction >= 1e-3 else f"{100 * fraction:.2g}%"


def from_shape_model(model, magnitude: int, *, units: str | None = None,
                     center="volume-centroid", crossings: str = "error",
                     smooth: str = "butterfly", subdivisions: int = 2,
                     metadata: dict | None = None) -> Body:
    """A lat/long :class:`Body` of ``magnitude`` from a closed shape model.

    Parameters
    ----------
    model : ShapeModel, str or Path
        The mesh (a path is read with :func:`read_shape_model`, which needs ``units``).
    magnitude : int
        Grid magnitude M.
    units : {"km", "m"}, optional
        Units of the file when ``model`` is a path.
    center : "volume-centroid", "area-centroid", "origin" or (x, y, z) metres
        Where the rays start; the body's origin. The model is moved so that it is 0.
    crossings : {"error", "outermost", "innermost"}
        What to do where a direction crosses the surface more than once (the body is
        not star-shaped from the centre): refuse with the affected area fraction (a
        :class:`~craters._shared.ParameterError` pointing to the mesh path,
        :mod:`latlong.mesh`), or keep the outermost / innermost crossing. Fewer such
        directions than :data:`NON_STAR_TOLERANCE` of the grid are accepted under
        ``error`` with a warning that counts them (the outermost crossing kept).
    smooth : {"butterfly", "loop", "linear", "none"}
        Subdivision before casting. ``butterfly`` interpolates the model's vertices with
        a smooth surface (a coarse model's flat facets otherwise become the body's);
        ``linear`` keeps the facets exactly; ``loop`` approximates (shrinks convex parts).
    subdivisions : int
        Subdivision levels (each x4 triangles).

    Returns
    -------
    Body with one radius per grid direction; metadata holds the source, centre, non-star
    area fraction and the model's resolution (mean edge length).
    """
    model = as_shape_model(model, units=units)
    magnitude = check_int("magnitude", magnitude, 1, 100_000)
    check_choice("crossings", crossings, ("error", "outermost", "innermost"))
    check_choice("smooth", smooth, ("butterfly", "loop", "linear", "none"))
    subdivisions = check_int("subdivisions", subdivisions, 0, 5)
    c = centre_point(model, center)
    resolution = model.mean_edge_m
    moved = ShapeModel(model.vertices - c, model.faces, model.source)
    cast = _smoothed(moved, smooth, subdivisions)
    grid = LatLongGrid(magnitude)
    count, tmin, tmax = cast_radii(cast, grid)
    areas = grid.vertex_areas()
    if (count == 0).any():
        missed = float(areas[count == 0].sum() / areas.sum())
        raise ParameterError("center", f"is outside the model: {missed:.2%} of the directions "
                             "from it miss the surface; choose another")
    multi = count > 1
    fraction = float(areas[multi].sum() / areas.sum())
    n_multi = int(multi.sum())
    tiny = 0 < n_multi < NON_STAR_TOLERANCE * grid.n_vertices
    if multi.any() and crossings == "error" and not tiny:
        raise ParameterError(
            "crossings", f"must be outermost or innermost (or another centre): the shape is "
            f"not star-shaped from its centre, {_share(fraction)} of the sphere of "
            f"directions ({n_multi} of {grid.n_vertices} grid directions) crosses the "
            "surface more than once; crater it on its own mesh instead: {} mesh",
            see=("surface",))
    if tiny and crossings == "error":
        logger.warning("%s: %d of %d grid directions (%s of the sphere) cross the surface "
                       "more than once (below 1 in %d): the outermost crossing is kept there",
                       model.source or "shape model", n_multi, grid.n_vertices,
                       _share(fraction), round(1 / NON_STAR_TOLERANCE))
    radii = tmin if crossings == "innermost" else tmax
    meta = {"source": model.source, "center_m": [float(v) for v in c],
            "non_star_fraction": fraction, "crossings": crossings, "smooth": smooth,
            "subdivisions": subdivisions, "model_resolution_m": resolution,
            "model_volume_m3": model.volume_m3}
    meta.update(metadata or {})
    if multi.any():
        logger.info("%.2f %% of directions cross the surface more than once (%s kept)",
                    100 * fraction, crossings)
    return Body(grid, radii, metadata=meta)



# --------------------------------------------------------------------------- comparison
def _as_polydata(obj):
    import pyvista as pv

    if isinstance(obj, Surface):
        return polydata(*obj.mesh())
    if isinstance(obj, pv.PolyData):
        return obj
    raise TypeError(f"expected a Surface (Body, ShapeModel ...) or pyvista.PolyData; got "
                    f"{type(obj).__name__}")


def sample_surface(mesh, n: int, *, rng=None) -> np.ndarray:
    """``n`` points uniform on a triangle surface (any Surface or a PolyData), (n, 3)."""
    from craters._shared import normalize_rng

    rng = normalize_rng(rng)
    poly = _as_polydata(mesh).triangulate()
    p = np.asarray(poly.points, dtype=np.float64)
    f = np.asarray(poly.faces).reshape(-1, 4)[:, 1:]
    a, b, c = p[f[:, 0]], p[f[:, 1]], p[f[:, 2]]
    w = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1)
    k = rng.choice(len(f), n, p=w / w.sum())
    u, v = rng.random(n), rng.random(n)
    flip = u + v > 1
    u[flip], v[flip] = 1 - u[flip], 1 - v[flip]
    return a[k] + u[:, None] * (b[k] - a[k]) + v[:, None] * (c[k] - a[k])


def mean_surface_distance(a, b, *, n_points: int = 20000, rng=None) -> float:
    """Symmetric mean distance (metres) between two closed surfaces.

    ``n_points`` points uniform on each surface; the distance of each to the other
    surface (VTK implicit distance); the mean of the two means.
    """
    import pyvista as pv

    from craters._shared import normalize_rng

    rng = normalize_rng(rng)
    n_points = check_int("n_points", n_points, 10, 10**8)
    pa, pb = _as_polydata(a), _as_polydata(b)
    da = pv.PolyData(sample_surface(pa, n_points, rng=rng)).compute_implicit_distance(pb)
    db = pv.PolyData(sample_surface(pb, n_points, rng=rng)).compute_implicit_distance(pa)
    return 0.5 * float(np.abs(da["implicit_distance"]).mean() +
                       np.abs(db["implicit_distance"]).mean())
