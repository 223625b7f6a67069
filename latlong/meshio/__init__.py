"""Mesh files: one registry per direction, by suffix (trimesh's ``exchange`` as the model).

* :mod:`.readers`: :data:`~.readers.MESH_READERS` (suffix -> reader) and
  :func:`~.readers.read_mesh` (a file in metres as a :class:`~.readers.MeshData`, which
  is a :class:`~latlong.geometry.surface.Surface`); shape models
  (:func:`latlong.read_shape_model`) and the sensors read through it.
* :mod:`.writers`: :data:`~.writers.MESH_WRITERS` (suffix -> writer) and
  :func:`~.writers.write_mesh` of a streamed :class:`~.writers.MeshSource`: every
  surface's ``save``/``export``, and ``dem``'s meshes (``dem -> latlong``, never the
  reverse); a source may bring its own writer for a suffix (a lat/long body's ``.glb``).
* :mod:`.boulders`: placed boulders merged after a surface's mesh; :mod:`.checks`:
  checks of mesh files before VTK reads them; :mod:`.chunks`: chunked, overlapped
  writing; :mod:`.sizes`: the size of a body's file by suffix and the free-space check
  every writer of large outputs makes before any work.
"""
