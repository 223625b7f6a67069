"""Mesh files: the writers of every mesh format (:mod:`.writers`), checks of mesh files
before they are read (:mod:`.checks`) and chunked, overlapped writing (:mod:`.chunks`).
``dem`` writes its meshes through it too (``dem -> latlong``, never the reverse)."""
