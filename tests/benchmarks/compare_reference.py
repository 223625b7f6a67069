"""Benchmark against a reference commit in the same run (plain script).

Checks out ``--ref`` (default: 2f20b41, the last commit before the body-aware crater
morphology and diffusion degradation) into a temporary git worktree and runs the named
benchmark scripts alternately from that tree and from this one, ``--repeat`` times
each, each in a fresh interpreter with its own tree first on ``PYTHONPATH``. Every
script prints ``... = N craters/s`` on its first line; the report gives each run's
figure, the medians and the ratio current / reference (above 1: faster now).
Usage: ``python tests/benchmarks/compare_reference.py [--ref COMMIT] [--repeat N]
[--quick] [bench_craters.py bench_body_craters.py ...]``.
"""

from __future__ import annotations

import argparse
import os
import re
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
RATE = re.compile(r"=\s*([0-9.]+)\s*craters/s")


def run(tree: Path, script: str, quick: bool) -> tuple[float, str]:
    env = dict(os.environ, PYTHONPATH=str(tree))
    cmd = [sys.executable, str(tree / "tests" / "benchmarks" / script)]
    if quick:
        cmd.append("--quick")
    proc = subprocess.run(cmd, cwd=tree, env=env, capture_output=True, text=True, check=False)
    if proc.returncode:
        raise SystemExit(f"{script} failed in {tree}:\n{proc.stderr[-2000:]}")
    first = proc.stdout.splitlines()[0]
    m = RATE.search(first)
    if not m:
        raise SystemExit(f"{script}: no 'craters/s' on its first line: {first!r}")
    return float(m.group(1)), first


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("scripts", nargs="*",
                        default=["bench_craters.py", "bench_body_craters.py"])
    parser.add_argument("--ref", default="2f20b41", help="reference commit")
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--quick", action="store_true")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory(prefix="craterform-ref-") as tmp:
        ref = Path(tmp) / "ref"
        subprocess.run(["git", "-C", str(ROOT), "worktree", "add", "--detach", str(ref),
                        args.ref], check=True, capture_output=True)
        try:
            for script in args.scripts:
                rates: dict[str, list[float]] = {"reference": [], "current": []}
                for i in range(args.repeat):
                    for name, tree in (("reference", ref), ("current", ROOT)):
                        rate, line = run(tree, script, args.quick)
                        rates[name].append(rate)
                        print(f"{script} [{name} {i + 1}] {line}", flush=True)
                med = {k: statistics.median(v) for k, v in rates.items()}
                print(f"{script}: median {med['current']:.0f} craters/s now vs "
                      f"{med['reference']:.0f} at {args.ref}: ratio "
                      f"{med['current'] / med['reference']:.2f} (cost "
                      f"x{med['reference'] / med['current']:.2f})", flush=True)
        finally:
            subprocess.run(["git", "-C", str(ROOT), "worktree", "remove", "--force", str(ref)],
                           check=False, capture_output=True)


if __name__ == "__main__":
    main()
