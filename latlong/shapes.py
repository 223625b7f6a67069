"""Real shape models as the base of a lat/long body: readers and ray-cast import.

Readers: Wavefront OBJ and PDS plate models (``.tab``/``.plt``/``.obj``: ``v``/``f``
lines, or the count header format ``NV NF`` then ``index x y z`` and
``index i j k`` lines; 0- or 1-based indices detected and checked) are parsed here;
PLY, STL and VTK formats go through pyvista. Units are explicit (``units="km"`` or
``"m"``; bodies are built in metres). Meshes are checked: non-empty, finite, triangles
(polygons are fanned), closed and 2-manifold (every edge in exactly two faces);
coincident vertices are merged (STL stores them per facet) and inward-facing models are
flipped.

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
import re
from pathlib import Path

import numpy as np

from craters._shared import ParameterError, check_choice, check_int
from craters._shared.files import check_regular_file

from ._shape_kernels import _brute_force_kernel, _raycast_kernel
from .body import Body
from .grid import LatLongGrid
from .meshio.checks import check_mesh_file

__all__ = ["ShapeModel", "cast_radii", "from_shape_model", "mean_surface_distance",
           "read_shape_model", "sample_surface"]

logger = logging.getLogger(__name__)
UNITS = {"km": 1000.0, "m": 1.0}
#: Share of the grid directions that may cross a model more than once and still be cast
#: with ``crossings="error"`` (the outermost crossing kept, with a warning): below one
#: grid vertex in 10^4 (a Eros plate model's 2 vertices of 2.9e5) is a pinhole in the
#: model, not a shape that is not star-shaped.
NON_STAR_TOLERANCE = 1e-4
#: Extent a shape model may span, metres (a boulder to a gas giant): the geometry
#: (volumes ~ extent^3, edge lengths) stays within float64 and divides safely.
SIZE_RANGE_M = (1e-3, 1e9)
_PYVISTA_SUFFIXES = (".ply", ".stl", ".vtk", ".vtp")
_TEXT_SUFFIXES = (".obj", ".tab", ".plt", ".txt")


@dataclasses.dataclass(frozen=True)
class ShapeModel:
    """A closed, outward-oriented triangle mesh in metres."""

    vertices: np.ndarray
    """(V, 3) float64 positions, metres."""
    faces: np.ndarray
    """(F, 3) int64 vertex indices, counter-clockwise seen from outside."""
    source: str = ""
    """Where it came from (path or description)."""

    @property
    def volume_m3(self) -> float:
        """Enclosed volume (divergence theorem over the triangles)."""
        a, b, c = (self.vertices[self.faces[:, k]] for k in range(3))
        return float(np.einsum("ij,ij->", a, np.cross(b, c)) / 6.0)

    @property
    def area_m2(self) -> float:
        a, b, c = (self.vertices[self.faces[:, k]] for k in range(3))
        return float(0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1).sum())

    @property
    def volume_centroid(self) -> np.ndarray:
        """Centroid of the enclosed volume (sum of signed tetrahedra), metres."""
        a, b, c = (self.vertices[self.faces[:, k]] for k in range(3))
        vol = np.einsum("ij,ij->i", a, np.cross(b, c)) / 6.0
        return ((a + b + c) / 4.0 * vol[:, None]).sum(axis=0) / vol.sum()

    @property
    def area_centroid(self) -> np.ndarray:
        """Centroid of the surface (area-weighted triangle centroids), metres."""
        a, b, c = (self.vertices[self.faces[:, k]] for k in range(3))
        area = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1)
        return ((a + b + c) / 3.0 * area[:, None]).sum(axis=0) / area.sum()

    @property
    def mean_edge_m(self) -> float:
        """Mean edge length, metres: the model's resolution."""
        e = _edges(self.faces)
        return float(np.linalg.norm(self.vertices[e[:, 0]] - self.vertices[e[:, 1]],
                                    axis=1).mean())

    def to_pyvista(self):
        import pyvista as pv

        cells = np.hstack([np.full((len(self.faces), 1), 3), self.faces]).ravel()
        return pv.PolyData(self.vertices.copy(), cells)


# --------------------------------------------------------------------------- readers
def _parse_index(token: str) -> int:
    return int(token.split("/")[0])


def _read_text_mesh(path: Path):
    """OBJ or PDS plate text: ``v``/``f`` lines, or the ``NV NF`` count format."""
    verts, faces = [], []
    with open(path, encoding="ascii", errors="replace") as fh:
        lines = [ln.split("#", 1)[0].strip() for ln in fh]
    lines = [ln for ln in lines if ln]
    if not lines:
        raise ValueError(f"shape model {str(path)!r} is empty")
    if lines[0].split()[0].lower() in ("v", "vn", "vt", "f", "o", "g", "s", "mtllib",
                                       "usemtl"):
        for ln in lines:
            parts = ln.split()
            key = parts[0].lower()
            if key == "v":
                verts.append([float(x) for x in parts[1:4]])
            elif key == "f":
                idx = [_parse_index(p) for p in parts[1:]]
                for k in range(1, len(idx) - 1):  # fan polygons into triangles
                    faces.append([idx[0], idx[k], idx[k + 1]])
        return np.array(verts, dtype=np.float64), np.array(faces, dtype=np.int64), "vf"
    # PDS count format: "NV NF" (or "NV" then later "NF"), indexed rows
    head = [int(float(x)) for x in re.split(r"[\s,]+", lines[0]) if x]
    nv = head[0]
    rows = [re.split(r"[\s,]+", ln) for ln in lines[1:]]
    vrows, rest = rows[:nv], rows[nv:]
    if rest and len(rest[0]) == 1:  # a separate facet-count line
        nf = int(float(rest[0][0]))
        rest = rest[1:]
    else:
        nf = head[1] if len(head) > 1 else len(rest)
    frows = rest[:nf]
    if len(vrows) != nv or len(frows) != nf:
        raise ValueError(f"shape model {str(path)!r}: header says {nv} vertices and {nf} "
                         f"facets; found {len(vrows)} and {len(frows)}")
    verts = [[float(x) for x in r[-3:]] for r in vrows]
    faces = [[int(float(x)) for x in r[-3:]] for r in frows]
    return np.array(verts, dtype=np.float64), np.array(faces, dtype=np.int64), "counts"


def _zero_based(faces: np.ndarray, n_verts: int, fmt: str, path) -> np.ndarray:
    """Detect 0- or 1-based (or negative, OBJ-relative) indices and check them."""
    if faces.size == 0:
        return faces
    if (faces < 0).any():
        if fmt != "vf" or (faces > 0).any():
            raise ValueError(f"shape model {str(path)!r}: negative and positive facet "
                             "indices mixed")
        faces = faces + n_verts  # OBJ relative indices (all of them negative)
        lo, hi = faces.min(), faces.max()
    else:
        lo, hi = faces.min(), faces.max()
        if fmt == "vf" and lo >= 1 and str(path).lower().endswith(".obj"):
            faces = faces - 1  # OBJ is 1-based by definition
        elif lo == 0 and hi <= n_verts - 1:
            pass
        elif lo >= 1 and hi == n_verts:
            faces = faces - 1
        elif lo == 0 and hi == n_verts:
            raise ValueError(f"shape model {str(path)!r}: facet indices run from 0 to {hi} "
                             f"for {n_verts} vertices: neither 0- nor 1-based")
        lo, hi = faces.min(), faces.max()
    if lo < 0 or hi >= n_verts:
        raise ValueError(f"shape model {str(path)!r}: facet indices out of range "
                         f"[{lo}, {hi}] for {n_verts} vertices")
    return faces


def _edges(faces: np.ndarray) -> np.ndarray:
    e = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
    e.sort(axis=1)
    return np.unique(e, axis=0)


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
    """Read a closed triangle mesh (OBJ, PDS plate ``.tab``/``.plt``, PLY, STL, VTK).

    Parameters
    ----------
    path : str or Path
    units : {"km", "m"}
        Length unit of the file's coordinates (explicit: models come in both).

    Returns
    -------
    ShapeModel in metres, outward-oriented, with merged coincident vertices.
    """
    units = check_choice("units", units, tuple(UNITS))
    path = Path(path)
    check_regular_file(path, "shape model")
    suffix = path.suffix.lower()
    if suffix in _PYVISTA_SUFFIXES:
        import pyvista as pv

        check_mesh_file(path, "shape model")
        try:
            mesh = pv.read(path)
        except Exception as exc:  # noqa: BLE001 - VTK raises many kinds
            raise ValueError(f"cannot read shape model {str(path)!r}: {exc}") from None
        if not isinstance(mesh, pv.PolyData):
            mesh = mesh.extract_surface(algorithm="dataset_surface")
        mesh = mesh.triangulate()
        verts = np.asarray(mesh.points, dtype=np.float64)
        faces = np.asarray(mesh.faces).reshape(-1, 4)[:, 1:].astype(np.int64) if (
            mesh.n_cells) else np.zeros((0, 3), np.int64)
        if faces.size and (faces.min() < 0 or faces.max() >= len(verts)):
            raise ValueError(f"shape model {str(path)!r}: facet indices out of range "
                             f"[{faces.min()}, {faces.max()}] for {len(verts)} vertices")
    elif suffix in _TEXT_SUFFIXES:
        try:
            verts, faces, fmt = _read_text_mesh(path)
        except (ValueError, IndexError) as exc:
            raise ValueError(f"cannot parse shape model {str(path)!r}: {exc}") from None
        except OverflowError:
            raise ValueError(f"cannot parse shape model {str(path)!r}: a count or facet "
                             f"index is not a finite integer below 2**63") from None
        if verts.ndim != 2 or (len(verts) and verts.shape[1] != 3):
            raise ValueError(f"shape model {str(path)!r}: vertices need three coordinates")
        faces = _zero_based(faces, len(verts), fmt, path)
    else:
        raise ValueError(f"shape model {str(path)!r}: unknown format {suffix!r}; allowed: "
                         f"{' '.join(_TEXT_SUFFIXES + _PYVISTA_SUFFIXES)}")
    return _check_and_orient(verts * UNITS[units], faces, str(path))


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
    if brute_force:
        _brute_force_kernel(unit, verts, faces, count, tmin, tmax)
    else:
        margin = 2.0 * np.pi / (2 * grid.magnitude)
        _raycast_kernel(grid.magnitude, grid.ring_offsets(), unit, verts, faces, margin,
                        count, tmin, tmax)
    return count, tmin, tmax


def _centre(model: ShapeModel, center) -> np.ndarray:
    if isinstance(center, str):
        check_choice("center", center, ("volume-centroid", "area-centroid", "origin"))
        if center == "volume-centroid":
            return model.volume_centroid
        if center == "area-centroid":
            return model.area_centroid
        return np.zeros(3)
    c = np.asarray(center, dtype=np.float64).reshape(-1)
    if c.shape != (3,) or not np.isfinite(c).all():
        raise ValueError("`center` must be a name or three finite coordinates (m); "
                         f"got {center!r}")
    return c


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
    if not isinstance(model, ShapeModel):
        if units is None:
            raise ValueError("`units` (km or m) is required when reading a shape model file")
        model = read_shape_model(model, units=units)
    magnitude = check_int("magnitude", magnitude, 1, 100_000)
    check_choice("crossings", crossings, ("error", "outermost", "innermost"))
    check_choice("smooth", smooth, ("butterfly", "loop", "linear", "none"))
    subdivisions = check_int("subdivisions", subdivisions, 0, 5)
    c = _centre(model, center)
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

    if isinstance(obj, Body | ShapeModel):
        return obj.to_pyvista()
    if isinstance(obj, pv.PolyData):
        return obj
    raise TypeError(f"expected a Body, ShapeModel or pyvista.PolyData; got {type(obj).__name__}")


def sample_surface(mesh, n: int, *, rng=None) -> np.ndarray:
    """``n`` points uniform on a triangle surface (Body, ShapeModel or PolyData), (n, 3)."""
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
