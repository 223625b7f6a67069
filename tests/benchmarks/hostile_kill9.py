"""Issue 34: kill -9 at random moments of a run that replaces an existing output, and check
that what a reader finds is the complete old output or the complete new one.

Each case first writes the old output (seed 1) and the new one (seed 2, into a side
folder: the reference bytes), then per trial restores the old output, starts the run with
``--force`` and sends SIGKILL after a uniform random delay in [0, its full duration]. The
folder is classified straight after the kill (old / new / mixed / missing) and again after
the next run's sweep (:func:`craters._shared.sweep_temporaries`, which every command runs
on its output folder: it takes back a run killed between its renames). Left temporaries
and lock files are counted too.

    python tests/benchmarks/hostile_kill9.py --trials 100            # ~10 min on 2 cores

Prints one line per case with the counts; exits 1 if any trial ends mixed after the sweep.
"""

from __future__ import annotations

import argparse
import hashlib
import random
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

BIN = Path(sys.executable).parent
BUILD = ["build", "--preset", "fbm-cratered", "--magnitude", "60", "-q"]
CASES = {
    # a .glb with its .json manifest: one output group
    "glb+json": (["latlong", *BUILD, "-o", "{out}/o.glb"], ["o.glb", "o.json"]),
    # three outputs of one build: .npz, .ply and the crater catalog
    "npz+ply+csv": (["latlong", *BUILD, "-o", "{out}/o.npz", "-o", "{out}/o.ply",
                     "--catalog", "{out}/o.csv"], ["o.npz", "o.ply", "o.csv"]),
}


def digest(folder: Path) -> dict[str, str]:
    return {p.name: hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(folder.iterdir()) if p.is_file() and not p.name.startswith(".")}


def run(argv: list[str], out: Path, seed: int, force: bool = True) -> subprocess.Popen:
    cmd = [str(BIN / argv[0]), *(a.format(out=out) for a in argv[1:]), "--seed", str(seed)]
    return subprocess.Popen(cmd + (["--force"] if force else []), stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL)


def classify(state: dict, old: dict, new: dict) -> str:
    if state == old:
        return "old"
    if state == new:
        return "new"
    return "missing" if set(state) < set(old) else "mixed"


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--trials", type=int, default=100)
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args()
    rng = random.Random(args.seed)
    bad = 0
    from craters._shared import sweep_temporaries

    for name, (argv, _files) in CASES.items():
        with tempfile.TemporaryDirectory() as d:
            base, ref, work = Path(d) / "old", Path(d) / "new", Path(d) / "work"
            for folder in (base, ref, work):
                folder.mkdir()
            assert run(argv, base, 1, force=False).wait() == 0
            start = time.perf_counter()
            assert run(argv, ref, 2, force=False).wait() == 0
            full = time.perf_counter() - start
            old, new = digest(base), digest(ref)
            counts: dict[str, int] = {}
            left = 0
            for _ in range(args.trials):
                shutil.rmtree(work)
                shutil.copytree(base, work)
                proc = run(argv, work, 2)
                time.sleep(rng.uniform(0, full))
                proc.send_signal(signal.SIGKILL)
                proc.wait()
                now = classify(digest(work), old, new)
                sweep_temporaries(work, now=time.time())  # as the next run's first sweep
                after = classify(digest(work), old, new)
                left += len([p for p in work.iterdir() if p.name.startswith(".")])
                key = f"{now}->{after}"
                counts[key] = counts.get(key, 0) + 1
                bad += after not in ("old", "new")
            print(f"{name}: {args.trials} kills in a {full:.1f} s run: "
                  f"{dict(sorted(counts.items()))}; hidden files left after the sweep: {left}",
                  flush=True)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
