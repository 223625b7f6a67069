r"""Cratering directly on any closed triangle mesh (shapes that are not star-shaped).

::

    shape model -> mesh_surface (centred on its volume centroid, refine_mesh: butterfly
                   levels then n-section to the spacing) -> MeshSurface
                -> mesh_crater_population -> stamp_mesh_craters (local height grids over
                   geodesic neighbourhoods; the body path's profiles and kernels)
                -> mesh_boulder_population -> place_mesh_boulders
                -> MeshSurface.save (PLY/OBJ/STL/VTP/VTK/glb), catalogs, slopes, pictures

``latlong build --surface mesh --base shape:PATH`` and ``ShapeBase(..., surface="mesh")``
in a :class:`latlong.Scene` run these steps.

From the command line
---------------------
The commands run as written from the repository's folder, into ``out/mesh/``
(``tests/test_readme_commands.py`` runs them at small sizes):

.. code-block:: bash

    mkdir -p out/mesh
    # Itokawa (not star-shaped: its neck) cratered on its own mesh, refined to ~1 m
    # (butterfly levels then n-section of the bundled 9.65 m model: 1.2 m edges, 786 k
    # triangles), craters below the model's resolution and younger than 10 Myr (older
    # ones of 1-15 m are erased by topographic diffusion on a small body), a few boulders
    latlong build --base shape:tests/data/itokawa_32.obj --shape-units km --surface mesh \
        --spacing-m 1 --craters c=0.05,k=-2,d_min_m=1,d_max_m=15,age_max_gyr=0.01 \
        --boulders c=0.002,k=-3,d_min_m=1,d_max_m=8,near=0.3 --seed 1 \
        -o out/mesh/itokawa.ply --catalog out/mesh/itokawa.csv --preview out/mesh/itokawa.png
    latlong slopes out/mesh/itokawa.ply --shape-units m --plot out/mesh/itokawa_slopes.png

``--surface mesh`` works on any closed model (or step by step with the functions above).
The model is moved to its volume centroid and refined to ``--spacing-m`` (default: the
lat/long spacing at ``--magnitude``) by interpolating (butterfly) subdivision, at least
two levels as the lat/long import, then an exact n-section; each crater is stamped
through a local height grid over the vertices within its geodesic reach (never across a
neck or a thin part), in a frame whose up axis is the surface normal over the crater,
with slope erosion against the body's self-gravity rather than the radial direction. A
crater whose region folds more than 75° from its plane is left out and counted. Outputs
are meshes (``.ply .obj .stl .vtp .vtk .glb``, boulders merged) and the catalogs;
``latlong slopes`` measures them. Star-shaped models can instead be ray-cast onto the
lat/long mesh (the default ``--surface latlong``, :mod:`latlong`).
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
