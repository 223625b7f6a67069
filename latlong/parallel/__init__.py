"""Parallel execution: batches of variants and independent tiles on a backend.

:mod:`.backends` is the seam: a backend maps a function over independent items, serial
(in this process) or dask (a local cluster or an existing scheduler), chosen in one
place (:func:`.backends.choose_backend`). :mod:`.batch` runs one task per variant
(``latlong batch``, ``dem batch``; default dask); :mod:`.tiles` maps a function over
independent tiles (``dem expand``; default serial, ``--workers`` / ``--scheduler`` dask);
:mod:`.batch_tasks` is what a variant's task runs. ``dem`` uses it too (``dem ->
latlong``, never the reverse).
"""
