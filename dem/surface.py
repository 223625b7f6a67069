"""DEM sites as surfaces: :class:`DemSurface`, one DEM or a layer stack seen as a
:class:`latlong.geometry.surface.Surface`, so that what takes a surface (the camera and
the LIDAR of :mod:`latlong.sensors`, the mesh writers) takes a site as it takes a body.

Frame: the stack's local metric frame (:mod:`dem.frame`: x east, y north, metres from
the target pixel; z = height, metres, up); one DEM in its own local frame (origin at its
centre pixel), as :func:`dem.to_mesh` meshes it. Mesh: :mod:`dem.mesh`'s crack-free
multi-resolution triangulation (counter-clockwise seen from above), the stack's boulders
after it as their own closed meshes (``boulder_id`` = the boulder's ``index`` in the
stack catalogs, -1 on the terrain). Catalogs: every layer's craters, coarsest layer first
(the stamping order), as the stack keeps them: map catalogs (``x_m, y_m`` in the frame),
which the sensors drape on the surface; every layer's boulders as placed.

Examples
--------
>>> import numpy as np, dem
>>> site = DemSurface(dem.Dem(np.zeros((3, 4)), pixel_size_m=2.0))
>>> v, f = site.mesh()
>>> v.shape, f.shape, site.local_frames([[0.0, 0.0, 0.0]])[0].tolist()
((12, 3), (12, 3), [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from latlong.meshio.writers import MeshSource

from .core import crs_label
from .io import read
from .mesh import as_stack, mesh_arrays, mesh_source, to_mesh
from .stack import MANIFEST, Stack, read_stack

__all__ = ["DemSurface"]


def _joined(catalogs) -> np.ndarray | None:
    """The rows of every catalog, in order, with the columns they all have (None: no
    rows)."""
    cats = [c for c in catalogs if c is not None and len(c)]
    if not cats:
        return None
    names = [n for n in cats[0].dtype.names if all(n in c.dtype.names for c in cats)]
    cols = {n: np.concatenate([np.asarray(c[n]) for c in cats]) for n in names}
    out = np.empty(sum(len(c) for c in cats), dtype=[(n, a.dtype) for n, a in cols.items()])
    for n, a in cols.items():
        out[n] = a
    out.setflags(write=False)
    return out


class DemSurface:
    """A DEM or a layer stack as a surface (module notes).

    Parameters
    ----------
    source : Stack or Dem
        The site (a DEM is one layer in its own local frame; it must have no NaN).
    source_name : str
        Where it came from (the ``source`` of :attr:`metadata`).
    """

    __slots__ = ("_stack", "_name", "_mesh")

    def __init__(self, source, *, source_name: str = ""):
        self._stack = as_stack(source)
        self._name = str(source_name)
        self._mesh: tuple[np.ndarray, np.ndarray] | None = None

    @classmethod
    def read(cls, path, *, progress: bool = False) -> DemSurface:
        """The site in ``path``: a stack (its folder or ``manifest.json``, as ``dem
        enhance`` writes it) or a DEM file (GeoTIFF, PDS, Zarr: :func:`dem.read`)."""
        p = Path(path)
        is_stack = p.suffix.lower() == ".json" or (p.is_dir() and (p / MANIFEST).is_file())
        return cls(read_stack(p, progress=progress) if is_stack else read(p),
                   source_name=str(path))

    def __repr__(self) -> str:
        return f"DemSurface({self._name or self._stack!r})"

    @property
    def stack(self) -> Stack:
        """The layers, their catalogs and their frame."""
        return self._stack

    @property
    def craters(self) -> np.ndarray | None:
        """Every layer's crater catalog, coarsest layer first (map catalogs: ``x_m, y_m``
        in the site's frame), or None."""
        return _joined(self._stack.catalogs)

    @property
    def boulders(self) -> np.ndarray | None:
        """Every layer's boulders as placed, coarsest layer first, or None."""
        return _joined(self._stack.boulders)

    @property
    def metadata(self) -> dict:
        """``source``, the ``frame`` (:meth:`dem.LocalFrame.to_dict`), the ``pixel_sizes_m``
        of the layers, the stack's ``info`` (seed, parameters, crater counts) and
        ``crs_wkt``: the site's local frame as an OGC WKT engineering CRS naming the DEM's
        CRS and the origin (what the sensors' point clouds are in)."""
        return {"source": self._name, "frame": self._stack.frame.to_dict(),
                "pixel_sizes_m": self._stack.pixel_sizes_m(), "info": self._stack.info,
                "crs_wkt": self._local_wkt()}

    def _local_wkt(self) -> str:
        f = self._stack.frame
        crs = self._stack.layers[0].crs
        of = "no CRS" if crs is None else crs_label(crs)
        name = (f"site frame: metres east, north, up from ({f.origin_x!r}, {f.origin_y!r}) "
                f"of {of}").replace('"', "'")
        return (f'LOCAL_CS["{name}",LOCAL_DATUM["site",0],UNIT["metre",1],'
                'AXIS["X",EAST],AXIS["Y",NORTH],AXIS["Z",UP]]')

    def mesh(self) -> tuple[np.ndarray, np.ndarray]:
        """``(vertices, faces)`` of the terrain (boulders not included): (V, 3) float64
        metres in the site's frame, (F, 3) int64 counter-clockwise seen from above."""
        if self._mesh is None:
            verts, faces, _ = mesh_arrays(self._stack)
            verts.setflags(write=False)
            faces.setflags(write=False)
            self._mesh = verts, faces
        return self._mesh

    def vertex_normals(self, weighting: str = "area") -> np.ndarray:
        """(V, 3) unit vertex normals of :meth:`mesh` with a named weighting
        (:data:`latlong.geometry.normals.WEIGHTINGS`)."""
        from latlong.geometry.normals import vertex_normals

        return vertex_normals(*self.mesh(), weighting)

    def local_frames(self, points) -> np.ndarray:
        """(n, 3, 3) frames at ``points``: rows east, north, up = the site's x, y, z."""
        n = len(np.asarray(points, dtype=np.float64).reshape(-1, 3))
        return np.repeat(np.eye(3)[None], n, axis=0)

    def mesh_source(self) -> MeshSource:
        """The terrain, then the boulders, for the mesh writers (:func:`dem.mesh.mesh_source`)."""
        return mesh_source(self._stack)

    def save(self, path, *, progress: bool = False) -> Path:
        """Write the mesh to a file chosen by suffix, atomically (:func:`dem.to_mesh`)."""
        return to_mesh(self._stack, path, progress=progress)
