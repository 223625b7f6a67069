"""Issue 18: memory of a lat/long build, stage by stage (script).

``stages M``: the steps of ``latlong.build`` for ``--preset fbm-cratered --magnitude M
--seed 1`` (base, body, crater population, stamping into the body's radii, .npz), with
the process's resident set and its running maximum after each (bytes per vertex beside).
``caps M``: how much the stamping kernels add per thread: eight far-apart 15 m craters
(fbm-cratered's largest) stamped on a 100 m sphere; the growth of the peak resident set
(run it with ``NUMBA_NUM_THREADS=1`` and ``2``; the build estimate's
``BUILD_BYTES_PER_VERTEX_THREAD`` comes from it). Whole runs are measured with
``/usr/bin/time -v python -m latlong build ...`` (maximum resident set size). Usage, from
the top folder: ``PYTHONPATH=. python tests/benchmarks/measure_build_memory.py stages 1024``.
"""

import argparse
import resource
import time

import numba
import numpy as np

import craters
import latlong


def _max_rss() -> int:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024


def _rss() -> int:
    with open("/proc/self/status") as fh:
        for line in fh:
            if line.startswith("VmRSS"):
                return int(line.split()[1]) * 1024
    return 0


def stages(magnitude: int, out: str) -> None:
    from latlong.build import _base_heights  # the build's own steps, in its order

    scene = latlong.Scene.from_settings({"preset": "fbm-cratered", "magnitude": magnitude,
                                         "seed": 1})
    grid = latlong.LatLongGrid(magnitude)
    n = grid.n_vertices
    t0 = time.perf_counter()

    def stage(name):
        nonlocal t0
        rss, peak = _rss(), _max_rss()
        print(f"{name:24s} resident {rss / 1e6:8.1f} MB ({rss / n:6.1f} B/v)  peak "
              f"{peak / 1e6:8.1f} MB ({peak / n:6.1f} B/v)  {time.perf_counter() - t0:6.1f} s",
              flush=True)
        t0 = time.perf_counter()

    print(f"M = {magnitude}: {n} vertices, {numba.get_num_threads()} threads")
    stage("start")
    rng = np.random.default_rng(scene.seed)
    heights, radius_m, _ = _base_heights(scene, grid, rng, False)
    heights += radius_m
    body = latlong.Body(grid, heights, radius_m=radius_m, copy=False)
    del heights
    stage("base and body")
    cat = latlong.body_population(body, scene.craters.layers, rng=rng)
    stage(f"population ({len(cat)})")
    body = latlong.stamp_craters(body, cat, roughness=scene.craters.roughness, rng=rng,
                                 target=scene.target(), too_large="skip", overwrite_body=True)
    stage("stamp")
    body.save(out)
    stage(".npz")


def caps(magnitude: int) -> None:
    target = craters.small_body(100.0)
    lat = np.array([60, 60, 0, 0, -60, -60, 20, -20.0])
    lon = np.array([0, 180, 90, 270, 45, 225, 0, 180.0])
    cat = craters.make_catalog(lat_deg=lat, lon_deg=lon, diameter_m=np.full(8, 15.0),
                               age_gyr=np.linspace(1, 0.1, 8))
    warm = craters.make_catalog(lat_deg=lat[:2], lon_deg=lon[:2], diameter_m=np.ones(2),
                                age_gyr=np.array([1.0, 0.5]))
    latlong.stamp_craters(latlong.Body.sphere(latlong.LatLongGrid(64), 100.0), warm, rng=1,
                          target=target)  # compiled before measuring
    body = latlong.Body.sphere(latlong.LatLongGrid(magnitude), 100.0)
    before = _max_rss()
    out = latlong.stamp_craters(body, cat, rng=1, target=target, overwrite_body=True)
    grow = _max_rss() - before
    print(f"M = {magnitude}, {numba.get_num_threads()} threads: peak +{grow / 1e6:.0f} MB = "
          f"{grow / out.n_vertices:.2f} B per body vertex (largest cap "
          f"{out.craters['n_vertices'].max()} vertices)")


if __name__ == "__main__":
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("what", choices=("stages", "caps"))
    p.add_argument("magnitude", type=int)
    p.add_argument("--out", default="measure_build_memory.npz", help="the .npz of `stages`")
    a = p.parse_args()
    stages(a.magnitude, a.out) if a.what == "stages" else caps(a.magnitude)
