"""Boulders (Martin 2014, V.C): multi-resolution procedural shapes and size populations.

Pure functions over numpy; placing boulders on a body is ``latlong.boulders``, on a DEM
``dem.boulders``.

* :mod:`~craters.boulders.meshes`: the shapes (icosahedron refined by random midpoint
  displacement, exact subsets level to level), :class:`BoulderShape`,
  :class:`BoulderNode`, the meshes of placed catalogs, :func:`boulder_faces`
* :mod:`~craters.boulders.abundance`: Golombek & Rapp's (1997) rock-abundance model as
  boulder layers (:func:`golombek_layers`)
* :mod:`~craters.boulders.placement`: :class:`BoulderLayer` populations (N_cum = c D^k),
  their draw, orientations and resting on the ground, the placed catalog columns
"""

from .abundance import (
    golombek_cumulative_area,
    golombek_cumulative_number,
    golombek_layers,
    golombek_q,
    parse_boulder_specs,
    parse_golombek_spec,
)
from .meshes import (
    BoulderNode,
    BoulderShape,
    boulder,
    boulder_faces,
    boulder_meshes,
    boulder_world_meshes,
    catalog_shape,
    iter_boulder_meshes,
    mesh_chunk,
)
from .placement import (
    MIN_BURIAL,
    BoulderLayer,
    draw_boulder_layer,
    near_crater_draws,
    orientations,
    parse_boulder_spec,
    placed_columns,
    quaternions,
    rest_on_ground,
)

__all__ = ["MIN_BURIAL", "BoulderLayer", "BoulderNode", "BoulderShape", "boulder",
           "boulder_faces", "boulder_meshes", "boulder_world_meshes",
           "catalog_shape", "draw_boulder_layer", "golombek_cumulative_area",
           "golombek_cumulative_number", "golombek_layers", "golombek_q",
           "iter_boulder_meshes", "mesh_chunk", "parse_boulder_specs", "parse_golombek_spec",
           "near_crater_draws",
           "orientations", "parse_boulder_spec", "placed_columns", "quaternions",
           "rest_on_ground"]
