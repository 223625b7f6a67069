"""Geometry shared by every kind of surface: the :class:`~.surface.Surface` protocol that
lat/long bodies, meshes, implicit bodies and DEM sites implement (:mod:`.surface`) and
area-weighted slope statistics (:mod:`.stats`)."""
