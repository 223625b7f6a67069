"""What the sensors see: one triangle mesh in the surface's frame (metres) with its boulder
ids and the catalogs that label it, made from any surface.

A surface is anything with the members of :class:`latlong.geometry.surface.Surface` the
sensors use: ``mesh_source()``, ``craters``, ``boulders`` and ``metadata`` -- a lat/long
:class:`latlong.Body`, a ``latlong.mesh.MeshSurface``, a mesh file read by
:func:`latlong.load_surface`, a DEM site of ``dem`` (``dem.DemSurface``). Its mesh is
taken as the mesh writers take it (:meth:`Surface.mesh_source`): the surface, then its
placed boulders as their own closed meshes with a per-vertex ``boulder_id`` (boulder
catalog row, -1 on the surface). Its crater catalog labels the frames: a catalog as
stamped (``centre_x_m, centre_y_m, centre_z_m``, ...) as it is; a map catalog (``x_m,
y_m`` in a local frame with z up: a DEM site's, or ``dem enhance``'s for a ``dem mesh``
file) placed on the surface straight below each centre (:func:`drape_catalog`). The
sensors read nothing else of a surface: they never ask which kind they hold.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

import craters
from craters._shared import ParameterError
from craters.catalog import add_columns

from ..geometry.meshes import TriangleMeshSurface
from ..meshio.writers import MeshSource, array_source
from .engine import RayMesh

if TYPE_CHECKING:
    from ..geometry.surface import Surface

__all__ = ["SceneGeometry", "craters_catalog", "drape_catalog", "ray_scene",
           "scene_geometry", "scene_mesh", "traced_model"]

#: The members of a surface the sensors use.
SURFACE_MEMBERS = ("mesh_source", "craters", "boulders", "metadata")


@dataclass(frozen=True, slots=True)
class SceneGeometry(TriangleMeshSurface):
    """A triangle mesh in the surface's frame and the ground truth that labels it: a
    :class:`~latlong.geometry.surface.Surface` (normals, frames, measures and ``save``:
    :class:`~latlong.geometry.meshes.TriangleMeshSurface`)."""

    vertices: np.ndarray
    """(n, 3) float64 positions, metres, the surface's frame."""
    faces: np.ndarray
    """(m, 3) int64 vertex indices."""
    face_boulder_id: np.ndarray
    """(m,) int32 boulder catalog row of each triangle, -1 on the surface."""
    craters: np.ndarray | None = None
    """The crater catalog as stamped (rows in stamping order, oldest first) or None."""
    boulders: np.ndarray | None = None
    """The boulder catalog as placed or None."""
    source: str = ""
    """Where it came from."""
    crs_wkt: str = ""
    """The CRS of the vertices as OGC WKT when the surface says it (a DEM site's local
    frame), else "" (a body's frame: :func:`~latlong.sensors.lidar_files.las_crs_wkt`)."""

    @property
    def metadata(self) -> dict:
        """``{"source": source}`` and, when known, ``{"crs_wkt": crs_wkt}``."""
        return {"source": self.source, **({"crs_wkt": self.crs_wkt} if self.crs_wkt else {})}

    def mesh(self) -> tuple[np.ndarray, np.ndarray]:
        """The vertices and the surface's faces (the boulders' left out)."""
        return self.vertices, self.faces[self.face_boulder_id < 0]

    def mesh_source(self) -> MeshSource:
        """The whole scene (boulders with their ``boulder_id``) for the mesh writers."""
        ids = np.full(len(self.vertices), -1, dtype=np.int32)
        ids[self.faces] = self.face_boulder_id[:, None]
        return array_source(self.vertices, self.faces, "craterform scene, metres",
                            boulder_id=ids)


def _is_surface(model) -> bool:
    """``model`` has the members of a surface the sensors use."""
    return all(hasattr(model, k) for k in SURFACE_MEMBERS)


def _of_surface(model: Surface) -> SceneGeometry:
    """The mesh and the surface's own catalogs (map catalogs not placed yet); a
    SceneGeometry, a surface too, gives an equal copy of itself."""
    if not _is_surface(model):
        raise TypeError("`model` must be a surface (latlong.geometry.Surface: a Body, a "
                        "mesh surface, a mesh file from latlong.load_surface, a dem "
                        f"DemSurface) or a SceneGeometry; got {type(model).__name__}")
    verts, ids = [], []
    src = model.mesh_source()
    for xyz, values in src.vertex_chunks():
        verts.append(np.asarray(xyz, dtype=np.float64))
        ids.append(np.asarray(values.get("boulder_id", np.full(len(xyz), -1)), np.int32))
    faces = np.concatenate([np.asarray(f, dtype=np.int64) for f in src.faces()])
    vid = np.concatenate(ids)
    source = str(model.metadata.get("source") or "") or repr(model)
    return SceneGeometry(np.concatenate(verts), faces, vid[faces[:, 0]], model.craters,
                         model.boulders, source, str(model.metadata.get("crs_wkt") or ""))


def scene_geometry(model, *, craters=None, mesh: RayMesh | None = None) -> SceneGeometry:
    """The mesh and catalogs of ``model`` (module notes).

    Parameters
    ----------
    model : Surface or SceneGeometry
        A surface (module notes; :func:`latlong.load_surface` reads one from a file), or
        a geometry made already (an equal copy, ``craters`` applied).
    craters : structured array or path, optional
        A crater catalog (CSV or array with ``centre_x_m, centre_y_m, centre_z_m`` and
        ``rim_radius_m`` or ``diameter_m``) to use instead of the surface's own; a map
        catalog (``x_m, y_m``, z up) is placed on the surface (:func:`drape_catalog`).
    mesh : RayMesh, optional
        The model's ray mesh if built already (places a map catalog; else one is built).
    """
    return _labelled(_of_surface(model), craters, mesh)


def _labelled(geo: SceneGeometry, craters, mesh: RayMesh | None) -> SceneGeometry:
    """``geo`` with the catalog ``craters`` instead of its own (if given), a map catalog
    draped on its surface (on ``mesh`` if built)."""
    catalog = geo.craters
    if craters is not None:
        catalog = np.asarray(craters_catalog(craters) if isinstance(craters, str | Path)
                             else craters)
    if catalog is not None and _is_map_catalog(catalog):
        catalog = drape_catalog(catalog, RayMesh(geo.vertices, geo.faces) if mesh is None
                                else mesh)
    return geo if catalog is geo.craters else dataclasses.replace(geo, craters=catalog)


def ray_scene(model, *, craters=None, mesh: RayMesh | None = None,
              build_quality: str = "medium") -> tuple[SceneGeometry, RayMesh]:
    """:func:`scene_geometry` and the :class:`RayMesh` of ``model``, its BVH built once
    (unless ``mesh`` is given) and used to place a map catalog: what every frame of a run
    shares."""
    geo = _of_surface(model)
    if mesh is None:
        mesh = RayMesh(geo.vertices, geo.faces, build_quality=build_quality)
    return _labelled(geo, craters, mesh), mesh


def scene_mesh(model, *, build_quality: str = "medium") -> RayMesh:
    """A :class:`RayMesh` of a RayMesh (returned as is), a surface or a
    :class:`SceneGeometry` (its mesh with the boulders), or a ``(vertices, faces)``
    pair."""
    if isinstance(model, RayMesh):
        return model
    if isinstance(model, tuple) and len(model) == 2:
        return RayMesh(*model, build_quality=build_quality)
    if not _is_surface(model):
        raise TypeError("`model` must be a RayMesh, a surface, a SceneGeometry or "
                        f"(vertices, faces); got {type(model).__name__}")
    geo = _of_surface(model)
    return RayMesh(geo.vertices, geo.faces, build_quality=build_quality)


def traced_model(model, ground_truth: SceneGeometry | None = None
                 ) -> tuple[RayMesh, SceneGeometry | None]:
    """The ray mesh a frame is traced in and the geometry that labels it (the first
    argument of :func:`~latlong.sensors.render.render` and
    :func:`~latlong.sensors.lidar.lidar_frame`): ``model`` a RayMesh or ``(vertices,
    faces)``, labelled by ``ground_truth`` if given; or a surface or SceneGeometry, its
    BVH built for the frame and labelled by its own catalogs unless ``ground_truth`` is
    given (its mesh must be the same triangles)."""
    if ground_truth is not None and not isinstance(ground_truth, SceneGeometry):
        raise TypeError("`ground_truth` must be a SceneGeometry; got "
                        f"{type(ground_truth).__name__}")
    if _is_surface(model):
        geo, mesh = ray_scene(model)
        ground_truth = geo if ground_truth is None else ground_truth
    else:  # a traced mesh: labelled by ground_truth only
        mesh = scene_mesh(model)
    if ground_truth is not None and len(ground_truth.faces) != len(mesh.faces):
        raise ParameterError("ground_truth", f"must describe the traced mesh: "
                             f"{len(ground_truth.faces)} triangles, not {len(mesh.faces)}")
    return mesh, ground_truth


def _is_map_catalog(catalog) -> bool:
    names = catalog.dtype.names or ()
    return "centre_x_m" not in names and {"x_m", "y_m"} <= set(names)


def drape_catalog(catalog, mesh: RayMesh) -> np.ndarray:
    """A map catalog (``x_m, y_m``: a ``dem`` catalog in the mesh's local frame, z up) with
    ``centre_*`` on the surface straight below the highest point and ``normal_*`` = +z;
    every row kept (ids are rows), ``centre_z_m`` NaN where the vertical misses the mesh.

    Examples
    --------
    >>> import craters
    >>> plane = RayMesh([[-9, -9, 2], [9, -9, 2], [0, 9, 2]], [[0, 1, 2]])
    >>> cat = craters.make_catalog(x_m=[0.0, 50.0], y_m=[0.0, 0.0], diameter_m=[2.0, 2.0])
    >>> drape_catalog(cat, plane)["centre_z_m"].tolist()
    [2.0, nan]
    """
    x = np.asarray(catalog["x_m"], dtype=np.float64)
    y = np.asarray(catalog["y_m"], dtype=np.float64)
    top = float(mesh.vertices[:, 2].max()) + 1.0
    hits = mesh.intersect(np.stack([x, y, np.full(len(x), top)], 1),
                          np.tile([0.0, 0.0, -1.0], (len(x), 1)))
    z = np.where(hits.hit, top - hits.t_m, np.nan)
    zero = np.zeros(len(x))
    return add_columns(catalog, ["centre_x_m", "centre_y_m", "centre_z_m", "normal_x",
                                 "normal_y", "normal_z"], [x, y, z, zero, zero, zero + 1.0])


def craters_catalog(path) -> np.ndarray:
    """A crater catalog CSV (as ``latlong build --catalog`` writes it)."""
    try:
        return craters.read_catalog(path)
    except FileNotFoundError:
        raise
    except (OSError, KeyError) as exc:
        raise ValueError(f"cannot read crater catalog {str(path)!r}: {exc}") from None
