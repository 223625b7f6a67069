"""Parallel execution: batches of variants and independent tiles as dask tasks.

:mod:`.batch` runs one task per variant (``latlong batch``, ``dem batch``) on a local
cluster or an existing scheduler; :mod:`.tiles` maps a function over independent tiles
(``dem expand --workers``); :mod:`.batch_tasks` is what runs on a worker. ``dem`` uses it
too (``dem -> latlong``, never the reverse).
"""
