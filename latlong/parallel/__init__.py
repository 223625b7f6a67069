r"""Parallel execution: batches of variants and independent tiles on a backend.

:mod:`.backends` is the seam: a backend maps a function over independent items, serial
(in this process) or dask (a local cluster or an existing scheduler), chosen in one
place (:func:`.backends.choose_backend`). :mod:`.batch` runs one task per variant
(``latlong batch``, ``dem batch``; default dask); :mod:`.tiles` maps a function over
independent tiles (``dem expand``; default serial, ``--workers`` / ``--scheduler`` dask);
:mod:`.batch_tasks` is what a variant's task runs. ``dem`` uses it too (``dem ->
latlong``, never the reverse).

Batches: ``latlong batch`` and ``dem batch``
--------------------------------------------
Many terrains from one scene file: every seed of ``--seeds``, times every combination of
the ``--vary`` values, one `dask.distributed <https://distributed.dask.org>`_ task per
variant. The commands run as written from the repository's folder, into
``out/parallel/`` (``tests/test_readme_commands.py`` runs them with one seed each); with
two cores:

.. code-block:: bash

    mkdir -p out/parallel
    # 8 small cratered bodies, < 1 min
    latlong batch examples/scene.toml --seeds 1-8 -o out/parallel/batch/
    head -3 out/parallel/batch/index.csv                     # one row per variant

(The first run after installing also compiles the numba kernels in each worker: a minute
or two more.)

``examples/scene.toml`` is what ``latlong build --config`` reads (a Perlin fBm body of
100 m under N_cum = 0.5 D^-2 craters of 4-15 m, M = 60); each variant gets the outputs the
scene names, under its own name (``seed0001_body.npz``, ``seed0001_craters.csv``; a scene
that names none gets ``seed0001.npz`` and, with craters, ``seed0001_craters.csv``), byte
for byte what ``latlong build --config examples/scene.toml --seed 1`` writes to those
names. ``index.csv`` lists each variant: ``variant, seed``, the varied values, ``files``,
the ``sha256`` of each, ``seconds``, ``peak_mb`` (the worker's peak resident memory
during the task), ``status`` (``ok`` / ``failed``), ``error``, and ``settings_sha256``
(of the scene, file names and craterform version). Rows are written as variants finish;
a variant that fails is recorded with its error and the others go on (exit code 1,
one-line summary); a killed batch run again with ``--resume`` builds only the variants
that are not done (a done variant: its row says ok for the same settings, and its files
are there with their sha256). ``--vary KEY=V1,V2`` takes any key of the scene file
(dashes or underscores); several make a cartesian product, and values holding commas
(crater specs, ``X,Y,Z``) are separated by ``;``. Seeds, keys and values are all checked
before anything runs:

.. code-block:: bash

    # 2 radii x 2 crater populations x 4 seeds = 16 variants
    # (seed0003_radius-m=200_craters=v2_body.npz ...)
    latlong batch examples/scene.toml --seeds 1-4 --vary radius-m=100,200 \
        --vary "craters=c=0.5,k=-2,d_min_m=4,d_max_m=15;c=0.1,k=-2,d_min_m=4,d_max_m=15" \
        -o out/parallel/sweep/
    # layer stacks: one dem enhance config, each variant's stack in its own folder
    # (out/parallel/stacks/seed0001_layers=9/ ...)
    dem batch examples/site.toml --seeds 1-2 --vary layers=9,11 -o out/parallel/stacks/

By default a batch starts a local cluster (one single-threaded worker process per core,
each variant on one numba thread so variants do not oversubscribe the cores, on
127.0.0.1 only, no dashboard) and stops it at the end. To use an existing cluster
instead, start a scheduler and workers (here on this machine; on a cluster the workers
must see the batch folder and the scene's input files at the same paths) and add
``--scheduler``:

.. code-block:: bash

    dask scheduler --host 127.0.0.1 --port 8786 &
    NUMBA_NUM_THREADS=1 dask worker tcp://127.0.0.1:8786 --nthreads 1 --nworkers 2 &
    latlong batch examples/scene.toml --seeds 1-8 -o out/parallel/batch2/ \
        --scheduler tcp://127.0.0.1:8786
    kill %2 %1; wait                                  # stop the workers and the scheduler

Tasks are retried on other workers when a worker dies (``kill -9`` of a worker mid-run
loses no variant) or raises something other than a bad-input error. In Python:
``latlong.batch("examples/scene.toml", "1-8", out="out/parallel/batch3",
vary={"radius_m": [100.0, 200.0]})`` and ``dem.batch(...)`` return the counts and the
index rows (a script that starts the local cluster needs the ``if __name__ ==
"__main__":`` guard: its workers are new processes).

Tiles: ``dem expand --workers N`` (a local cluster) or ``--scheduler ADDRESS`` runs the
tiles of an expansion as tasks, with the same bytes as tile after tile in this process
(:mod:`dem`).
"""
