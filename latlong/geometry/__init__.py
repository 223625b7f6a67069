"""Geometry shared by every kind of surface: the :class:`~.surface.Surface` protocol that
lat/long bodies, meshes, implicit bodies and DEM sites implement (:mod:`.surface`), face
and vertex normals with named weightings (:mod:`.normals`), the measures and surface
members of meshes held as arrays (:mod:`.meshes`) and area-weighted slope statistics
(:mod:`.stats`)."""
