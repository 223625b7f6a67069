"""Cratering directly on any closed triangle mesh (shapes that are not star-shaped).

::

    shape model -> mesh_surface (centred on its volume centroid, refine_mesh: butterfly
                   levels then n-section to the spacing) -> MeshSurface
                -> mesh_crater_population -> stamp_mesh_craters (local height grids over
                   geodesic neighbourhoods; the body path's profiles and kernels)
                -> mesh_boulder_population -> place_mesh_boulders
                -> MeshSurface.save (PLY/OBJ/STL/VTP/VTK/glb), catalogs, slopes, pictures

``latlong build --surface mesh --base shape:PATH`` and ``ShapeBase(..., surface="mesh")``
in a :class:`latlong.Scene` run these steps.
"""

from .boulders import mesh_boulder_population, place_mesh_boulders
from .cratering import mesh_crater_population, sample_mesh_points, stamp_mesh_craters
from .refine import refine_mesh, refinement_plan
from .surface import MeshSurface, lat_lon_deg, mesh_surface, with_detail
from .topology import TriangleGrid, adjacency, mesh_checks

__all__ = ["MeshSurface", "TriangleGrid", "adjacency", "lat_lon_deg", "mesh_boulder_population",
           "mesh_checks", "mesh_crater_population", "mesh_surface", "place_mesh_boulders",
           "refine_mesh", "refinement_plan", "sample_mesh_points", "stamp_mesh_craters",
           "with_detail"]
