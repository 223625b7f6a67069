"""Batches on dask.distributed, measured: 64 variants of a cratered body at M = 100 (the
fbm-cratered preset: Perlin fBm, N_cum = 0.5 D^-2 craters of 1-15 m; a .npz and the crater
catalog per variant).

Runs, all through the ``latlong batch`` command:

A. the default local cluster (one single-threaded worker process per core);
B. a cluster of separate processes: ``dask scheduler`` + two ``dask worker --nthreads 1``
   on 127.0.0.1;
C. the same separate cluster, with one worker process killed (``kill -9``) mid-run: its
   nanny starts a new one and the scheduler reschedules the lost variants;
D. the local cluster, the whole batch (its process group) killed mid-run, then
   ``--resume``, which must build only the unfinished variants.

Then single ``latlong build --config SCENE --seed S`` runs (``--singles`` seeds, spread over
the range) to the same file names. Prints variants/hour of A and B, and whether every
output's sha256 agrees between A, B, C, D and the single builds.

    python tests/benchmarks/bench_batch.py [--variants 64] [--magnitude 100] [--singles 4]
"""

from __future__ import annotations

import argparse
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
DASK = str(Path(sys.executable).parent / "dask")  # the `dask` command of this environment


def _env(**extra) -> dict:
    env = {**os.environ, **extra}
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT), *filter(None, [env.get("PYTHONPATH")])])
    return env


def _rows(folder: Path) -> list[dict]:
    from latlong.parallel.batch import read_index

    index = folder / "index.csv"
    return read_index(index) if index.exists() else []


def _shas(folder: Path) -> dict:
    return {(r["variant"], f): s for r in _rows(folder) if r["status"] == "ok"
            for f, s in zip(r["files"].split(";"), r["sha256"].split(";"), strict=True)}


def _batch(scene, seeds, out, *extra, wait=True, **popen):
    cmd = [sys.executable, "-m", "latlong", "batch", str(scene), "--seeds", seeds, "-o",
           str(out), "-q", *extra]
    proc = subprocess.Popen(cmd, env=_env(), **popen)
    return proc.wait() if wait else proc


def _wait_rows(folder: Path, n: int, proc) -> int:
    while proc.poll() is None:
        rows = len(_rows(folder))
        if rows >= n:
            return rows
        time.sleep(0.2)
    raise RuntimeError(f"the batch ended (code {proc.returncode}) before {n} variants")


def _load() -> str:
    return "load " + " ".join(f"{x:.1f}" for x in os.getloadavg())


class SeparateCluster:
    """``dask scheduler`` and ``dask worker --nthreads 1`` processes on 127.0.0.1."""

    def __init__(self, work: Path, n_workers: int):
        self.work, self.n = work, n_workers
        self.procs: list[subprocess.Popen] = []

    def __enter__(self):
        info = self.work / "scheduler.json"
        env = _env(NUMBA_NUM_THREADS="1")
        quiet = {"stdout": subprocess.DEVNULL, "stderr": subprocess.DEVNULL}
        self.procs.append(subprocess.Popen(
            [DASK, "scheduler", "--host", "127.0.0.1", "--port", "0", "--no-dashboard",
             "--scheduler-file", str(info)], env=env, **quiet))
        while not info.exists():
            time.sleep(0.2)
        time.sleep(0.5)
        self.address = json.loads(info.read_text())["address"]
        for _ in range(self.n):
            self.procs.append(subprocess.Popen(
                [DASK, "worker", self.address, "--nthreads", "1", "--host", "127.0.0.1",
                 "--no-dashboard"], env=env, **quiet))
        from distributed import Client

        with Client(self.address, timeout=60) as client:
            client.wait_for_workers(self.n, timeout=120)
        return self

    def worker_pids(self) -> list[int]:
        from distributed import Client

        with Client(self.address, timeout=60) as client:
            return sorted(client.run(os.getpid).values())

    def __exit__(self, *exc):
        for p in reversed(self.procs):
            p.terminate()
        for p in reversed(self.procs):
            try:
                p.wait(timeout=60)
            except subprocess.TimeoutExpired:
                p.kill()
                p.wait()


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--variants", type=int, default=64)
    ap.add_argument("--magnitude", type=int, default=100)
    ap.add_argument("--singles", type=int, default=4, help="seeds built alone to compare")
    ap.add_argument("--work", help="working folder (default: a new temporary one)")
    ap.add_argument("--keep", action="store_true", help="keep every run's files")
    args = ap.parse_args()
    work = Path(args.work or tempfile.mkdtemp(prefix="bench_batch_"))
    work.mkdir(parents=True, exist_ok=True)
    scene = work / "scene.toml"
    scene.write_text(f'preset = "fbm-cratered"\nmagnitude = {args.magnitude}\n')
    seeds = f"1-{args.variants}"
    n = args.variants
    print(f"work folder {work}; {os.cpu_count()} cores; scene fbm-cratered at M = "
          f"{args.magnitude}; {n} variants")
    times, found = {}, {}

    # A: the default local cluster
    print(f"A local cluster ... ({_load()})", flush=True)
    t = time.perf_counter()
    code = _batch(scene, seeds, work / "A")
    times["A"] = time.perf_counter() - t
    found["A"] = _shas(work / "A")
    print(f"A exit {code}: {len(_rows(work / 'A'))} rows, {times['A']:.0f} s, "
          f"{3600 * n / times['A']:.0f} variants/hour ({_load()})", flush=True)

    with SeparateCluster(work, 2) as cluster:
        # B: separate processes
        print(f"B separate processes at {cluster.address} ... ({_load()})", flush=True)
        t = time.perf_counter()
        code = _batch(scene, seeds, work / "B", "--scheduler", cluster.address)
        times["B"] = time.perf_counter() - t
        found["B"] = _shas(work / "B")
        print(f"B exit {code}: {len(_rows(work / 'B'))} rows, {times['B']:.0f} s, "
              f"{3600 * n / times['B']:.0f} variants/hour ({_load()})", flush=True)
        if not args.keep:
            shutil.rmtree(work / "B")
        # C: kill -9 one worker process mid-run
        proc = _batch(scene, seeds, work / "C", "--scheduler", cluster.address, wait=False)
        at = _wait_rows(work / "C", n // 4, proc)
        victim = cluster.worker_pids()[0]
        os.kill(victim, signal.SIGKILL)
        print(f"C killed worker process {victim} after {at} variants", flush=True)
        code = proc.wait()
        rows = _rows(work / "C")
        found["C"] = _shas(work / "C")
        print(f"C exit {code}: {len(rows)} rows, {sum(r['status'] == 'ok' for r in rows)} ok, "
              f"workers now {cluster.worker_pids()}", flush=True)
        if not args.keep:
            shutil.rmtree(work / "C")

    # D: kill the whole batch mid-run, then --resume
    proc = _batch(scene, seeds, work / "D", wait=False, start_new_session=True)
    at = _wait_rows(work / "D", n // 2, proc)
    os.killpg(proc.pid, signal.SIGKILL)
    proc.wait()
    time.sleep(2)
    kept = len(_rows(work / "D"))
    print(f"D killed the batch (process group {proc.pid}) at {at} rows; the index holds "
          f"{kept}", flush=True)
    cmd = [sys.executable, "-m", "latlong", "batch", str(scene), "--seeds", seeds, "-o",
           str(work / "D"), "--resume"]
    out = subprocess.run(cmd, env=_env(), capture_output=True, text=True)
    print(f"D --resume exit {out.returncode}: {out.stdout.strip()}", flush=True)
    counts = re.search(r"(\d+) built, (\d+) kept", out.stdout)
    resumed = counts is not None and (int(counts[1]), int(counts[2])) == (n - kept, kept)
    found["D"] = _shas(work / "D")
    if not args.keep:
        shutil.rmtree(work / "D")

    # single builds of some seeds, to the same file names
    single = work / "single"
    single.mkdir(exist_ok=True)
    step = max(1, n // max(1, args.singles))
    picks = sorted({min(n, 1 + i * step) for i in range(args.singles)} | {n})[-args.singles:]
    agree_single = 0
    t = time.perf_counter()
    for s in picks:
        name = f"seed{s:04d}"
        files = [f"{name}.npz", f"{name}_craters.csv"]
        subprocess.run([sys.executable, "-m", "latlong", "build", "--config", str(scene),
                        "--seed", str(s), "-q", "--force", "-o", str(single / files[0]),
                        "--catalog", str(single / files[1])], env=_env(), check=True)
        from latlong.parallel.batch import sha256_file

        agree_single += all(sha256_file(single / f) == found["A"].get((name, f)) for f in files)
        if not args.keep:
            for f in files:
                (single / f).unlink()
    t_single = (time.perf_counter() - t) / len(picks)

    print("\nresults")
    print(f"  A local cluster       : {times['A']:.0f} s, {3600 * n / times['A']:.0f} "
          "variants/hour")
    print(f"  B separate processes  : {times['B']:.0f} s, {3600 * n / times['B']:.0f} "
          "variants/hour")
    print(f"  single build (alone)  : {t_single:.1f} s per seed ({3600 / t_single:.0f}/hour "
          "one after the other)")
    files = len(found["A"])
    for run in ("B", "C", "D"):
        print(f"  {run} sha256 equal to A  : {found[run] == found['A']} "
              f"({len(found[run])} of {files} files)")
    print(f"  single builds equal A  : {agree_single} of {len(picks)} seeds ({picks})")
    print(f"  D --resume built only the {n - kept} unfinished variants: {resumed}")
    ok = all(found[r] == found["A"] for r in "BCD") and agree_single == len(picks) and \
        len(found["A"]) == 2 * n and resumed
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
