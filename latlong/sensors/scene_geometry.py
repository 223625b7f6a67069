"""What the sensors see: one triangle mesh in the body frame (metres) with its boulder ids
and the catalogs that label it.

A model is a :class:`latlong.Body` or its ``.npz``, a ``latlong.mesh.MeshSurface``
(``--surface mesh``), or any mesh file pyvista reads (PLY, OBJ, STL, VTP, VTK, GLB:
``dem mesh`` outputs, shape models). The body's placed boulders are part of the mesh
(as the exports write them: boulders after the surface, ``boulder_id`` = catalog row);
a mesh file's ``boulder_id`` point array is kept when it has one.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

import craters
from craters._shared import ParameterError, check_choice
from craters._shared.files import check_regular_file

from ..body import load
from ..export import body_mesh_source
from ..geometry.meshes import TriangleMeshSurface
from ..geometry.surface import Surface
from ..meshio.readers import read_mesh
from ..meshio.writers import MeshSource, array_source

__all__ = ["MESH_SUFFIXES", "SceneGeometry", "scene_geometry"]

#: Mesh files read through pyvista.
MESH_SUFFIXES = (".ply", ".obj", ".stl", ".vtp", ".vtk", ".glb", ".gltf")
_UNITS = {"m": 1.0, "km": 1000.0}


@dataclass(frozen=True, slots=True)
class SceneGeometry(TriangleMeshSurface):
    """A triangle mesh in the body frame and the ground truth that labels it: a
    :class:`~latlong.geometry.surface.Surface`."""

    vertices: np.ndarray
    """(n, 3) float64 positions, metres, body frame."""
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

    @property
    def metadata(self) -> dict:
        """``{"source": source}``."""
        return {"source": self.source}

    def mesh(self) -> tuple[np.ndarray, np.ndarray]:
        """The vertices and the surface's faces (the boulders' left out)."""
        return self.vertices, self.faces[self.face_boulder_id < 0]

    def mesh_source(self) -> MeshSource:
        """The whole scene (boulders with their ``boulder_id``) for the mesh writers."""
        ids = np.full(len(self.vertices), -1, dtype=np.int32)
        ids[self.faces] = self.face_boulder_id[:, None]
        return array_source(self.vertices, self.faces, "craterform scene, metres",
                            boulder_id=ids)


def _from_source(src, craters_, boulders, source) -> SceneGeometry:
    verts, ids = [], []
    for xyz, values in src.vertex_chunks():
        verts.append(np.asarray(xyz, dtype=np.float64))
        ids.append(np.asarray(values.get("boulder_id", np.full(len(xyz), -1)), np.int32))
    faces = np.concatenate([np.asarray(f, dtype=np.int64) for f in src.faces()])
    vid = np.concatenate(ids)
    return SceneGeometry(np.concatenate(verts), faces, vid[faces[:, 0]], craters_, boulders,
                         source)


def _read_mesh(path: Path, units: str) -> SceneGeometry:
    mesh = read_mesh(path, units=units)  # the mesh-reader registry (latlong.meshio)
    return _mesh_geometry(mesh.vertices, mesh.faces, mesh.fields, path)


def _mesh_geometry(verts, faces, fields, path) -> SceneGeometry:
    if not len(faces):
        raise ValueError(f"cannot read mesh {str(path)!r}: no triangles in it")
    if not np.isfinite(verts).all():
        raise ValueError(f"mesh {str(path)!r} has non-finite vertices")
    if "boulder_id" in fields:
        fid = np.asarray(fields["boulder_id"]).astype(np.int32)[faces[:, 0]]
    else:
        fid = np.full(len(faces), -1, dtype=np.int32)
    return SceneGeometry(verts, faces, fid, None, None, str(path))


def scene_geometry(model, *, units: str = "m", craters=None, mesh=None) -> SceneGeometry:
    """The mesh and catalogs of ``model`` (module notes).

    Parameters
    ----------
    model : Body, MeshSurface, SceneGeometry, or path
        A body, a ``--surface mesh`` surface, or a file: ``.npz`` (a body) or a mesh
        (``MESH_SUFFIXES``).
    units : {"m", "km"}
        Units of a mesh file's coordinates (bodies are in metres).
    craters : structured array or path, optional
        A crater catalog (CSV or array with ``centre_x_m, centre_y_m, centre_z_m`` and
        ``rim_radius_m`` or ``diameter_m``) to use instead of the model's own; a map
        catalog (``x_m, y_m``, as ``dem enhance`` writes it for a ``dem mesh`` in the same
        local frame, z up) is placed on the surface straight below each centre (off the
        mesh: no label).
    mesh : RayMesh, optional
        The model's ray mesh if already built (places a map catalog; else one is built).
    """
    check_choice("units", units, tuple(_UNITS))
    if isinstance(model, SceneGeometry):
        geo = model
    elif hasattr(model, "mesh_source") and hasattr(model, "faces"):
        geo = _from_source(model.mesh_source(), model.craters, model.boulders, "mesh surface")
    elif isinstance(model, Surface):  # a body (and its boulders)
        geo = _from_source(model.mesh_source(), model.craters, model.boulders, repr(model))
    elif isinstance(model, str | Path):
        path = Path(model)
        check_regular_file(path, "model file")
        suffix = path.suffix.lower()
        if suffix == ".npz":
            body = load(path)
            geo = _from_source(body_mesh_source(body), body.craters, body.boulders, str(path))
        elif suffix in MESH_SUFFIXES:
            geo = _read_mesh(path, units)
        else:
            raise ParameterError("model", f"must be a body .npz or a mesh file "
                                 f"({' '.join(MESH_SUFFIXES)}); got {str(path)!r}")
    else:
        raise TypeError(f"`model` must be a Body, a mesh surface or a path; got "
                        f"{type(model).__name__}")
    if craters is not None:
        if isinstance(craters, str | Path):
            craters = craters_catalog(craters)
        craters = np.asarray(craters)
        names = craters.dtype.names or ()
        if "centre_x_m" not in names and {"x_m", "y_m"} <= set(names):
            craters = _placed_on_surface(craters, geo, mesh)
        geo = SceneGeometry(geo.vertices, geo.faces, geo.face_boulder_id, craters,
                            geo.boulders, geo.source)
    return geo


def _placed_on_surface(catalog, geo: SceneGeometry, mesh=None) -> np.ndarray:
    """A map catalog (``x_m, y_m``: a ``dem`` catalog in the mesh's local frame, z up) with
    ``centre_*`` on the surface straight below the highest point and ``normal_*`` = +z;
    every row kept (ids are rows), ``centre_z_m`` NaN where the vertical misses the mesh."""
    import numpy.lib.recfunctions as rfn

    from .engine import RayMesh

    x = np.asarray(catalog["x_m"], dtype=np.float64)
    y = np.asarray(catalog["y_m"], dtype=np.float64)
    top = float(geo.vertices[:, 2].max()) + 1.0
    mesh = RayMesh(geo.vertices, geo.faces) if mesh is None else mesh
    hits = mesh.intersect(np.stack([x, y, np.full(len(x), top)], 1),
                          np.tile([0.0, 0.0, -1.0], (len(x), 1)))
    z = np.where(hits.hit, top - hits.t_m, np.nan)
    zero = np.zeros(len(x))
    return np.asarray(rfn.append_fields(
        catalog, ["centre_x_m", "centre_y_m", "centre_z_m", "normal_x", "normal_y",
                  "normal_z"], [x, y, z, zero, zero, zero + 1.0], usemask=False))


def craters_catalog(path) -> np.ndarray:
    """A crater catalog CSV (as ``latlong build --catalog`` writes it)."""
    try:
        return craters.read_catalog(path)
    except FileNotFoundError:
        raise
    except (OSError, KeyError) as exc:
        raise ValueError(f"cannot read crater catalog {str(path)!r}: {exc}") from None
