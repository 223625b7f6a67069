"""Stamping throughput against cratermaker, like for like, on one crater list (issue 20).

One list of 2000 craters on the Moon (R = 1737.4 km; positions uniform on the sphere;
diameters 25-250 km drawn from N_cum ~ D^-2; seed 1; fresh; oldest first in file order)
is written as a craterform catalog CSV that both tools read. Sizes: craterform's
magnitude-165 and -330 latitude/longitude spheres (163 352 and 653 402 vertices) against
cratermaker's icosphere surfaces of grid level 7 and 8 (163 842 and 655 362 faces: its
cells; each cell's elevation lives at the face centre, and its 327 680 / 1 310 720 nodes
carry elevations too). A crater's 1.5 D region covers ~20-1900 cells on the coarse mesh
and ~75-7600 on the fine one.

craterform (this interpreter, one subprocess per thread count with NUMBA_NUM_THREADS
set): ``latlong.stamp_craters(Body.sphere(LatLongGrid(M), R), catalog, rng=1)`` with its
defaults: region = ejecta edge at ``craters.DEFAULT_EJECTA_EDGE`` = 3 radii = 1.5 D,
irregular rims and the fractal roughness overlay on (``--no-roughness`` for ideal
craters), slope erosion checked (no crater is on ground steep enough to be eroded on a
sphere), profile tables computed inside the timed call, write-back of every vertex of
the region. Warm: compiled on a tiny body first; the body is built before the clock.

cratermaker (its own Python 3.12 virtual environment, ``pip install cratermaker`` pinned
to ``CRATERMAKER_PIN``; made in ``--venv``, default ``.venv-cratermaker`` in the current
folder, or reused): ``Simulation(target=Moon with radius 1737.4 km, surface="icosphere",
gridlevel=7|8, morphology="basicmoon", ejecta_truncation=3.0`` (crater radii: the region
ends at 1.5 D), ``dorays=False, do_counting=False, do_subpixel_degradation=False,
do_slope_collapse=False, conserve_volume=False)``, and the two diffusion steps that
``BasicMoonMorphology.compute_ejecta`` always runs on the ejecta region (burial
softening and the degradation function) removed by running the base
``Morphology.compute_ejecta`` instead (``--cratermaker-diffusion`` keeps them). What it
still does per crater: region extraction (ball tree, plus a buffer ring of cells),
overlap sets for its batch queue, reference-surface fit, crater profile on faces and
nodes, ejecta profile on the ejecta region, the excavated and ejecta volumes, the
elevation update. Timed: the ``sim.emplace(list)`` call (queue + forming); the
``Crater.maker`` calls that make the list (morphometry, Monte-Carlo projectile scaling)
are timed separately and reported as well. Warm: the first 20 craters are emplaced
before the clock (ball trees etc.); the elevation is reset to 0 before each run; the mesh
is generated once and kept in ``--workdir`` (default ``.cratermaker-bench``).

Medians of ``--repeats`` runs; other benchmarks may share the machine, which is why (the
1-minute load average before each measurement is printed and kept in the JSON: with the
second core busy, craterform's 2-thread figure drops below its 1-thread one).

    python tests/benchmarks/compare_cratermaker.py [--repeats 5] [--venv DIR]
        [--workdir DIR] [--sizes 165:7 330:8] [--threads 1 2] [--no-roughness]

Prints craters/s per size for craterform at each thread count and for cratermaker, the
ratios, and writes ``compare_cratermaker.json`` in the work folder.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

RADIUS_M = 1737.4e3
N_CRATERS = 2000
D_MIN_M, D_MAX_M = 25e3, 250e3
SEED = 1
SIZES = ((165, 7), (330, 8))  # craterform magnitude, cratermaker icosphere grid level
CRATERMAKER_PIN = "cratermaker==2026.10.3a0"   # the version issue 20 names and pip found
PYTHON_312 = "/root/.pyenv/versions/3.12.1/bin/python"
N_WARM = 20
RESULT = "RESULT "

# Runs in cratermaker's venv: argv = csv, gridlevel, repeats, simdir, radius_m, diffusion
CRATERMAKER_WORKER = r'''
import csv, json, statistics, sys, time
import numpy as np
import cratermaker as cm
from cratermaker.components.morphology import Morphology
from cratermaker.components.morphology.basicmoon import BasicMoonMorphology

path, level, repeats, simdir = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), sys.argv[4]
radius_m, diffusion = float(sys.argv[5]), sys.argv[6] == "1"
if not diffusion:  # no burial softening / degradation-function diffusion of the ejecta
    BasicMoonMorphology.compute_ejecta = Morphology.compute_ejecta
with open(path, newline="") as fh:
    rows = list(csv.DictReader(ln for ln in fh if not ln.startswith("#")))
lat = [float(r["lat_deg"]) for r in rows]
lon = [float(r["lon_deg"]) for r in rows]
diam = [float(r["diameter_m"]) for r in rows]
options = dict(surface="icosphere", gridlevel=level, morphology="basicmoon",
               ejecta_truncation=3.0, dorays=False, do_counting=False,
               do_subpixel_degradation=False, do_slope_collapse=False,
               conserve_volume=False)
t0 = time.perf_counter()
target = cm.Target.maker("Moon", target_radius=radius_m)
sim = cm.Simulation(target=target, simdir=simdir, ask_overwrite=False, reset=True,
                    rng_seed=1, save_actions=None, **options)
t_setup = time.perf_counter() - t0
surf = sim.surface


def make(idx):
    return [sim.Crater.maker(diameter=diam[i], location=(lon[i], lat[i])) for i in idx]


sim.emplace(make(range(N_WARM)))  # ball trees, caches
points = faces = 0
probe = make(range(len(diam)))
for c in probe:
    reg = c.ejecta_region if c.emplaceable else None
    if reg is not None:
        faces += reg.n_face
        points += reg.n_face + reg.n_node
n_emplaceable = sum(bool(c.emplaceable) for c in probe)
del probe
t_make, t_emplace = [], []
for _ in range(repeats):
    surf.update_elevation(0.0, overwrite=True)
    t0 = time.perf_counter()
    batch = make(range(len(diam)))
    t1 = time.perf_counter()
    done = sim.emplace(batch)
    t2 = time.perf_counter()
    t_make.append(t1 - t0)
    t_emplace.append(t2 - t1)
print("RESULT " + json.dumps({
    "version": cm.__version__, "gridlevel": level, "n_face": int(surf.n_face),
    "n_node": int(surf.n_node), "radius_m": float(surf.radius), "setup_s": t_setup,
    "options": {**options, "target": "Moon", "ejecta_diffusion": diffusion,
                "scaling": type(sim.scaling).__name__, "warm_craters": N_WARM},
    "n_craters": len(diam), "n_emplaceable": n_emplaceable, "n_emplaced": len(done),
    "region_faces": faces, "region_faces_plus_nodes": points,
    "face_elevation_range_m": [float(surf.face_elevation.min()),
                               float(surf.face_elevation.max())],
    "make_s": t_make, "emplace_s": t_emplace}))
'''


def crater_list(n: int = N_CRATERS, seed: int = SEED):
    """The shared crater list: uniform positions, N_cum ~ D^-2 in [D_MIN_M, D_MAX_M], fresh,
    ages falling with the row (oldest first, so both tools stamp in file order)."""
    import numpy as np

    import craters

    rng = np.random.default_rng(seed)
    v = rng.normal(size=(n, 3))
    v /= np.linalg.norm(v, axis=1, keepdims=True)
    lat = np.degrees(np.arcsin(np.clip(v[:, 2], -1.0, 1.0)))
    lon = np.degrees(np.arctan2(v[:, 1], v[:, 0]))
    # inverse CDF of the truncated power law p(D) ~ D^-3 (N_cum ~ D^-2)
    u = rng.uniform(size=n)
    lo, hi = D_MIN_M**-2.0, D_MAX_M**-2.0
    diam = (lo - u * (lo - hi)) ** -0.5
    age = np.linspace(3.5, 0.0, n, endpoint=False)
    return craters.make_catalog(lat_deg=lat, lon_deg=lon, diameter_m=diam, age_gyr=age,
                                degradation=np.zeros(n))


def craterform_worker(csv_path: str, magnitude: int, repeats: int, roughness: bool) -> dict:
    """Time ``latlong.stamp_craters`` of the list on a magnitude-M sphere (this process)."""
    import numba
    import numpy as np

    import craters
    from latlong import Body, LatLongGrid, stamp_craters

    cat = craters.read_catalog(csv_path)
    kw = {"roughness": roughness, "ejecta_edge": craters.DEFAULT_EJECTA_EDGE}
    stamp_craters(Body.sphere(LatLongGrid(8), RADIUS_M), cat[:2], rng=1, **kw)  # compile
    body = Body.sphere(LatLongGrid(magnitude), RADIUS_M)
    times, out = [], None
    for _ in range(repeats):
        t0 = time.perf_counter()
        out = stamp_craters(body, cat, rng=1, **kw)
        times.append(time.perf_counter() - t0)
    return {"magnitude": magnitude, "n_vertices": body.grid.n_vertices,
            "threads": numba.get_num_threads(), "n_craters": len(cat),
            "n_stamped": len(out.craters),
            "vertex_updates": int(np.sum(out.craters["n_vertices"])), "times_s": times,
            "height_range_m": [float((out.radii_m - RADIUS_M).min()),
                               float((out.radii_m - RADIUS_M).max())],
            "options": {**kw, "rng": 1, "slope_erosion": True, "irregularity": 0.02}}


def run_craterform(csv_path: Path, magnitude: int, threads: int, repeats: int,
                   roughness: bool) -> dict:
    env = {**os.environ, "NUMBA_NUM_THREADS": str(threads)}
    cmd = [sys.executable, __file__, "--worker", str(csv_path), "--magnitude", str(magnitude),
           "--repeats", str(repeats)] + ([] if roughness else ["--no-roughness"])
    proc = subprocess.run(cmd, env=env, capture_output=True, text=True)
    return _result(proc, cmd)


def cratermaker_venv(folder: Path) -> Path:
    """A Python 3.12 virtual environment with cratermaker in ``folder``; its python."""
    python = folder / "bin" / "python"
    if not python.exists():
        base = PYTHON_312 if Path(PYTHON_312).exists() else "python3.12"
        subprocess.run([base, "-m", "venv", str(folder)], check=True)
    ok = subprocess.run([str(python), "-c", "import cratermaker"], capture_output=True)
    if ok.returncode != 0:
        subprocess.run([str(python), "-m", "pip", "install", "-q", CRATERMAKER_PIN],
                       check=True)
    return python


def run_cratermaker(python: Path, csv_path: Path, level: int, repeats: int, workdir: Path,
                    diffusion: bool) -> dict:
    with tempfile.NamedTemporaryFile("w", suffix=".py", dir=workdir, delete=False) as fh:
        fh.write(f"N_WARM = {N_WARM}\n" + CRATERMAKER_WORKER)
    try:
        cmd = [str(python), fh.name, str(csv_path), str(level), str(repeats),
               str(workdir / f"sim-level{level}"), repr(RADIUS_M), "1" if diffusion else "0"]
        env = {**os.environ, "TQDM_DISABLE": "1"}
        proc = subprocess.run(cmd, env=env, capture_output=True, text=True, cwd=workdir)
        return _result(proc, cmd)
    finally:
        os.unlink(fh.name)


def _result(proc, cmd) -> dict:
    lines = [ln for ln in proc.stdout.splitlines() if ln.startswith(RESULT)]
    if proc.returncode != 0 or not lines:
        raise RuntimeError(f"failed: {' '.join(cmd)}\n{proc.stdout[-3000:]}"
                           f"{proc.stderr[-3000:]}")
    return json.loads(lines[-1][len(RESULT):])


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--venv", type=Path, default=Path(".venv-cratermaker"),
                        help="cratermaker's virtual environment (made if missing)")
    parser.add_argument("--workdir", type=Path, default=Path(".cratermaker-bench"),
                        help="crater list, cratermaker meshes, the JSON of the results")
    parser.add_argument("--sizes", nargs="+", default=[f"{m}:{g}" for m, g in SIZES],
                        help="craterform magnitude : cratermaker icosphere grid level")
    parser.add_argument("--threads", type=int, nargs="+", default=[1, 2])
    parser.add_argument("--no-roughness", action="store_true")
    parser.add_argument("--cratermaker-diffusion", action="store_true",
                        help="keep the diffusion cratermaker's basicmoon applies to ejecta")
    parser.add_argument("--skip-cratermaker", action="store_true")
    parser.add_argument("--worker", help=argparse.SUPPRESS)
    parser.add_argument("--magnitude", type=int, help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    roughness = not args.no_roughness
    if args.worker:
        res = craterform_worker(args.worker, args.magnitude, args.repeats, roughness)
        print(RESULT + json.dumps(res))
        return 0

    import craters

    workdir = args.workdir.resolve()
    workdir.mkdir(parents=True, exist_ok=True)
    csv_path = workdir / "craters.csv"
    craters.write_catalog(crater_list(), csv_path)
    python = None if args.skip_cratermaker else cratermaker_venv(args.venv.resolve())
    sizes = [tuple(int(x) for x in s.split(":")) for s in args.sizes]
    print(f"{N_CRATERS} craters, D {D_MIN_M / 1e3:g}-{D_MAX_M / 1e3:g} km (N_cum ~ D^-2), "
          f"Moon R = {RADIUS_M / 1e3:g} km; medians of {args.repeats} runs; "
          f"{os.cpu_count()} cores (other jobs may share them)")
    results = {"machine": {"cpus": os.cpu_count(), "platform": platform.platform()},
               "crater_list": {"n": N_CRATERS, "d_min_m": D_MIN_M, "d_max_m": D_MAX_M,
                               "k_cum": -2.0, "seed": SEED, "radius_m": RADIUS_M,
                               "csv": str(csv_path)},
               "repeats": args.repeats, "sizes": []}
    for magnitude, level in sizes:
        row = {"magnitude": magnitude, "gridlevel": level, "craterform": {}}
        for t in args.threads:
            load = os.getloadavg()[0]
            r = run_craterform(csv_path, magnitude, t, args.repeats, roughness)
            r["load_1min_before"] = load
            med = statistics.median(r["times_s"])
            r.update(median_s=med, craters_per_s=r["n_craters"] / med,
                     vertex_updates_per_s=r["vertex_updates"] / med)
            row["craterform"][str(t)] = r
            print(f"craterform M={magnitude} ({r['n_vertices']:,} vertices), "
                  f"{r['threads']} thread(s): {med:.3f} s = {r['craters_per_s']:,.0f} "
                  f"craters/s, {r['vertex_updates_per_s'] / 1e6:.2f} M vertex-updates/s "
                  f"({r['vertex_updates'] / r['n_craters']:.0f} vertices/crater; load "
                  f"{load:.1f}; runs "
                  + ", ".join(f"{x:.3f}" for x in r["times_s"]) + " s)")
        if python is not None:
            load = os.getloadavg()[0]
            c = run_cratermaker(python, csv_path, level, args.repeats, workdir,
                                args.cratermaker_diffusion)
            c["load_1min_before"] = load
            med = statistics.median(c["emplace_s"])
            med_make = statistics.median(c["make_s"])
            c.update(median_emplace_s=med, median_make_s=med_make,
                     craters_per_s=c["n_emplaced"] / med,
                     craters_per_s_with_make=c["n_emplaced"] / (med + med_make),
                     point_updates_per_s=c["region_faces_plus_nodes"] / med)
            row["cratermaker"] = c
            print(f"cratermaker {c['version']} icosphere level {level} ({c['n_face']:,} "
                  f"faces, {c['n_node']:,} nodes): emplace {med:.2f} s = "
                  f"{c['craters_per_s']:,.1f} craters/s ({c['n_emplaced']} emplaced; "
                  f"{c['region_faces'] / c['n_emplaced']:.0f} faces + "
                  f"{(c['region_faces_plus_nodes'] - c['region_faces']) / c['n_emplaced']:.0f}"
                  f" nodes per crater region, load {load:.1f}, "
                  f"{c['point_updates_per_s'] / 1e6:.2f} M "
                  f"face+node updates/s); Crater.maker for the list {med_make:.2f} s more, "
                  f"make + emplace {c['craters_per_s_with_make']:,.1f} craters/s; runs "
                  + ", ".join(f"{x:.2f}" for x in c["emplace_s"]) + " s")
            ratios = {t: r["craters_per_s"] / c["craters_per_s"]
                      for t, r in row["craterform"].items()}
            row["ratio_craterform_to_cratermaker"] = ratios
            print("  ratio craterform / cratermaker (emplace only): "
                  + ", ".join(f"{t} thread(s) x{v:.0f}" for t, v in ratios.items()))
        results["sizes"].append(row)
    if python is not None:
        first = results["sizes"][0]["cratermaker"]
        print(f"cratermaker {first['version']} options: {json.dumps(first['options'])}")
    out = workdir / "compare_cratermaker.json"
    out.write_text(json.dumps(results, indent=1), encoding="utf-8")
    print(f"results: {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
