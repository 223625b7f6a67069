"""A cratered closed triangle mesh: :class:`MeshSurface` and :func:`mesh_surface`.

The mesh path cratering real shape models of any topology (not star-shaped:
Itokawa's neck, a comet's two lobes): the model is moved so that its volume centroid
(the centre of mass at constant density) is the origin, refined to the requested
spacing (:func:`latlong.mesh.refine_mesh`), optionally given fBm detail along its
normals, then cratered (:func:`latlong.mesh.stamp_mesh_craters`) and strewn with boulders
(:func:`latlong.mesh.place_mesh_boulders`). Outputs are meshes (PLY, OBJ, STL, VTP, VTK, glTF
binary through the shared writers, boulders merged with a per-vertex ``boulder_id``),
catalogs and pictures; slopes through :func:`latlong.mesh_slopes`.
"""

from __future__ import annotations

import dataclasses
import json
import math

import numpy as np

from craters import validate_catalog
from craters._shared import check_finite, check_int, check_positive

from ..geometry.meshes import TriangleMeshSurface, centre_point
from ..meshio.boulders import BoulderMeshes, mesh_fields
from ..meshio.writers import MeshSource
from ..perlin import fbm3, random_rotation
from ..shapes import ShapeModel, as_shape_model
from .refine import refine_mesh
from .topology import mesh_checks

__all__ = ["MeshSurface", "lat_lon_deg", "mesh_surface"]


def lat_lon_deg(points) -> tuple[np.ndarray, np.ndarray]:
    """Latitude and longitude (degrees; east 0-360) of points seen from the origin."""
    p = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    r = np.linalg.norm(p, axis=1)
    lat = np.degrees(np.arcsin(np.clip(p[:, 2] / np.where(r > 0, r, 1.0), -1.0, 1.0)))
    lon = np.mod(np.degrees(np.arctan2(p[:, 1], p[:, 0])), 360.0)
    return lat, lon


def _frozen(a, dtype) -> np.ndarray:
    out = np.array(a, dtype=dtype, copy=True)
    out.setflags(write=False)
    return out


@dataclasses.dataclass(frozen=True, eq=False)
class MeshSurface(TriangleMeshSurface):
    """A closed triangle mesh in metres (origin = the model's volume centroid), what was
    added to it and how it was made. Immutable: operations return new surfaces. A
    :class:`~latlong.geometry.surface.Surface` (normals, frames and measures:
    :class:`~latlong.geometry.meshes.TriangleMeshSurface`)."""

    vertices: np.ndarray
    """(V, 3) float64 positions, metres, read-only."""
    faces: np.ndarray
    """(F, 3) int64 vertex indices, counter-clockwise seen from outside, read-only."""
    heights_m: np.ndarray
    """(V,) metres each vertex moved along the local up axes since the refined model
    (fBm detail, craters), read-only."""
    craters: np.ndarray | None = None
    """The crater catalog as stamped (:func:`latlong.mesh.stamp_mesh_craters`) or None."""
    boulders: np.ndarray | None = None
    """The boulders as placed (:func:`latlong.mesh.place_mesh_boulders`) or None."""
    metadata: dict = dataclasses.field(default_factory=dict)
    """JSON-serialisable description: source, centre, refinement, seed, parameters."""

    def __post_init__(self):
        v = _frozen(self.vertices, np.float64)
        f = _frozen(self.faces, np.int64)
        if v.ndim != 2 or v.shape[1:] != (3,) or f.ndim != 2 or f.shape[1:] != (3,):
            raise ValueError(f"`vertices` and `faces` must be (n, 3); got {v.shape}, {f.shape}")
        if not np.isfinite(v).all():
            raise ValueError("`vertices` must be finite")
        h = _frozen(self.heights_m, np.float64)
        if h.shape != (len(v),):
            raise ValueError(f"`heights_m` must have shape ({len(v)},); got {h.shape}")
        object.__setattr__(self, "vertices", v)
        object.__setattr__(self, "faces", f)
        object.__setattr__(self, "heights_m", h)
        for name in ("craters", "boulders"):
            cat = getattr(self, name)
            if cat is not None:
                cat = np.array(validate_catalog(cat), copy=True)
                cat.setflags(write=False)
                object.__setattr__(self, name, cat)
        try:
            meta = json.loads(json.dumps(self.metadata))
        except TypeError as exc:
            raise TypeError(f"`metadata` must be JSON-serialisable: {exc}") from None
        object.__setattr__(self, "metadata", meta)

    def replace(self, **changes) -> MeshSurface:
        """A new surface with some fields replaced (nothing recomputed; a moved surface
        with boulders needs them placed again, or ``boulders=None``)."""
        if ("vertices" in changes and "boulders" not in changes and self.boulders is not None
                and len(self.boulders)):
            raise ValueError("the surface moves but it has placed boulders: pass `boulders` "
                             "too (None, or placed again with latlong.mesh.place_mesh_boulders)")
        return dataclasses.replace(self, **changes)

    # ------------------------------------------------------------------ measures
    @property
    def n_vertices(self) -> int:
        return len(self.vertices)

    def shape_model(self) -> ShapeModel:
        """The surface as a :class:`~latlong.ShapeModel` (without boulders)."""
        return ShapeModel(self.vertices, self.faces, self.metadata.get("source", ""))

    @property
    def mean_edge_m(self) -> float:
        """Mean length of the faces' edges (each edge once per face), metres."""
        e = self.vertices[self.faces[:, [1, 2, 0]]] - self.vertices[self.faces]
        return float(np.linalg.norm(e, axis=2).mean())

    def checks(self) -> dict:
        """Closed 2-manifold and topology figures (:func:`latlong.mesh.mesh_checks`)."""
        return mesh_checks(self.vertices, self.faces)

    def slopes(self, radius_deg: float = 3.0, *, weighted: bool = True):
        """Per-vertex slopes and vertex areas as for bodies (:func:`latlong.mesh_slopes`:
        cap-averaged normals against the radial direction from the origin)."""
        from ..slopes import mesh_slopes

        return mesh_slopes(self.shape_model(), radius_deg, weighted=weighted, center="origin")

    # ------------------------------------------------------------------ outputs
    def mesh_source(self) -> MeshSource:
        """The surface, boulders merged at their finest level after it (``boulder_id``
        per vertex: -1 on the surface, else the catalog row;
        :class:`~latlong.meshio.boulders.BoulderMeshes`), for the mesh writers."""
        n = len(self.vertices)
        rocks = BoulderMeshes.of(self.boulders, n)
        cat = self.boulders

        def rock_heights(s0, world):  # height above the ground under each rock
            k = world.shape[0]
            centre = np.stack([cat["centre_x_m"], cat["centre_y_m"], cat["centre_z_m"]], 1)
            up = np.stack([cat["normal_x"], cat["normal_y"], cat["normal_z"]], 1)
            h = np.einsum("kvi,ki->kv", world - centre[s0:s0 + k, None, :], up[s0:s0 + k])
            return h - (h.min(axis=1, keepdims=True) + cat["burial_m"][s0:s0 + k, None])

        def vertex_chunks():
            values = {"height_m": self.heights_m}
            if rocks is not None:
                values["boulder_id"] = np.full(n, -1, dtype=np.int32)
            yield self.vertices, values
            if rocks is not None:
                yield from rocks.vertex_chunks(rock_heights)

        def face_groups():
            if rocks is None:
                yield None, [self.faces]
            else:
                yield "body", [self.faces]
                yield "boulders", rocks.face_chunks()

        def facet_chunks():
            yield self.vertices[self.faces]
            if rocks is not None:
                yield from rocks.facet_chunks()

        comments = (f"{n} surface vertices",) + (
            (rocks.comment("the surface"),) if rocks is not None else ())
        extra_v, extra_f = (0, 0) if rocks is None else (rocks.n_vertices, rocks.n_faces)
        return MeshSource(n + extra_v, len(self.faces) + extra_f, vertex_chunks, face_groups,
                          facet_chunks, mesh_fields(rocks), "craterform mesh surface, metres",
                          comments)

    def to_pyvista(self, *, boulders: bool = True):
        """A ``pyvista.PolyData`` with point array ``height_m`` (boulders merged)."""
        import pyvista as pv

        mesh = pv.PolyData(np.array(self.vertices),
                           np.hstack([np.full((len(self.faces), 1), 3), self.faces]).ravel())
        mesh.point_data["height_m"] = np.array(self.heights_m)
        if boulders and self.boulders is not None and len(self.boulders):
            from craters.boulders import boulder_world_meshes

            bv, bf = boulder_world_meshes(self.boulders)
            rocks = pv.PolyData(bv, np.hstack([np.full((len(bf), 1), 3), bf]).ravel())
            rocks.point_data["height_m"] = np.zeros(len(bv))
            mesh = mesh.merge(rocks)
        return mesh


# --------------------------------------------------------------------------- building
def fbm_detail(vertices, faces, frequency: float, octaves: int, persistence: float,
               lacunarity: float, amplitude_m: float, *, scale_m: float, rng) -> np.ndarray:
    """Heights (metres) of 3-D Perlin fBm at the vertex positions / ``scale_m``
    (randomly rotated and shifted as :func:`latlong.perlin_fbm` does on the unit sphere),
    for detail along the normals; points on both sides of a thin part get their own."""
    rot = random_rotation(rng)
    offset = rng.uniform(0.0, 256.0, size=3)
    p = np.asarray(vertices, dtype=np.float64) / scale_m
    xyz = [(p[:, 0] * rot[a, 0] + p[:, 1] * rot[a, 1] + p[:, 2] * rot[a, 2]) * frequency
           + offset[a] for a in range(3)]
    return amplitude_m * fbm3(xyz[0], xyz[1], xyz[2], octaves=octaves, persistence=persistence,
                              lacunarity=lacunarity)


def mesh_surface(model, spacing_m: float, *, units: str | None = None,
                 center="volume-centroid", smooth: str = "butterfly",
                 metadata: dict | None = None) -> MeshSurface:
    """A :class:`MeshSurface` from a closed shape model refined to ``spacing_m``.

    Parameters
    ----------
    model : ShapeModel, str or Path
        The model (a path is read with :func:`latlong.read_shape_model`, which needs
        ``units``). Any closed, oriented 2-manifold: it need not be star-shaped.
    spacing_m : float
        Mean edge of the refined mesh, metres (:func:`latlong.mesh.refine_mesh`).
    center : "volume-centroid", "area-centroid", "origin" or (x, y, z) metres
        The point that becomes the origin (catalog latitudes and longitudes are seen
        from it): by default the centre of mass at constant density.
    smooth : {"butterfly", "linear"}
        Interpolating subdivision before the n-section, or the facets kept exactly.

    Examples
    --------
    >>> s = mesh_surface("tests/data/itokawa_8.obj", 20.0, units="km")
    >>> s.checks()["euler_characteristic"], s.metadata["refinement"]["butterfly_levels"]
    (2, 1)
    """
    model = as_shape_model(model, units=units)
    c = centre_point(model, center)
    moved = ShapeModel(model.vertices - c, model.faces, model.source)
    fine = refine_mesh(moved, spacing_m, smooth=smooth)
    from .refine import refinement_plan

    levels, n = refinement_plan(model.mean_edge_m, spacing_m, smooth)
    meta = {"source": model.source, "center_m": [float(x) for x in c],
            "model_resolution_m": model.mean_edge_m, "model_volume_m3": model.volume_m3,
            "spacing_m": spacing_m, "smooth": smooth,
            "refinement": {"butterfly_levels": levels, "nsection": n,
                           "vertices": len(fine.vertices), "faces": len(fine.faces)},
            **(metadata or {})}
    surf = MeshSurface(fine.vertices, fine.faces, np.zeros(len(fine.vertices)), metadata=meta)
    object.__setattr__(surf, "metadata", {**surf.metadata, "mean_edge_m": surf.mean_edge_m})
    return surf


def with_detail(surface: MeshSurface, frequency: float, octaves: int, persistence: float,
                lacunarity: float, amplitude_m: float, *, rng) -> MeshSurface:
    """``surface`` with fBm detail (:func:`fbm_detail` at the volume-equivalent radius)
    added along its vertex normals."""
    amplitude_m = check_finite("amplitude_m", amplitude_m)
    frequency = check_positive("frequency", frequency)
    octaves = check_int("octaves", octaves, 1, 30)
    scale = (3.0 * abs(surface.volume_m3) / (4.0 * math.pi)) ** (1.0 / 3.0)
    h = fbm_detail(surface.vertices, surface.faces, frequency, octaves, persistence,
                   lacunarity, amplitude_m, scale_m=scale, rng=rng)
    v = surface.vertices + h[:, None] * surface.vertex_normals("area")
    return surface.replace(vertices=v, heights_m=surface.heights_m + h)
