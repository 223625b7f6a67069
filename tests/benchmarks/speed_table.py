"""The speed table of the README (issue 35): each figure a ratio against a peer measured in
the same run, with the absolute times (plain script, not a test; ~3 minutes).

Runs the benchmarks that measure against the peers, each in a subprocess of its own, and
prints one Markdown table from what they print:

- ``bench_body_craters.py --moon``: stamping 2 001 lunar craters on an M = 330 body, two
  threads against one (best of ``--repeat``), alone and, with ``--hog``, beside a
  busy-loop process (a loaded machine);
- ``bench_latlong.py``'s fBm: ``latlong.fbm3`` (10 octaves, 6 M points) against
  ``noise.pnoise3`` called from a list comprehension (its fastest Python use; needs
  ``pip install ".[reference]"``);
- ``bench_sensors_peers.py``: a 1024^2 camera frame (direct light and cast shadows) of a
  12 M-triangle body against Mitsuba 3's ``scalar_rgb`` path tracer at 1 spp, and a
  512^2-beam LIDAR frame against raw ``embreex`` rays;
- ``bench_writers.py --magnitude 1400``: PLY and GLB exports of an 11.8 M-vertex body
  against ``dd`` writing to the same disk (``conv=fdatasync``; the disk's speed on a shared
  machine moves between runs: both dd figures are printed).

A benchmark whose peer is not installed gives a row saying so. Usage:
``python tests/benchmarks/speed_table.py [--repeat N] [--hog]``.
"""

from __future__ import annotations

import argparse
import datetime
import json
import os
import platform
import re
import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent


def run(args: list[str], hog: bool = False) -> str:
    """What ``python args...`` (in this folder) prints, beside a busy loop if ``hog``."""
    busy = subprocess.Popen([sys.executable, "-c", "while True: pass"]) if hog else None
    try:
        done = subprocess.run([sys.executable, *args], cwd=HERE, capture_output=True,
                              text=True, timeout=1800)
    finally:
        if busy is not None:
            busy.kill()
            busy.wait()
    return done.stdout + done.stderr


def _num(pattern: str, text: str) -> float | None:
    m = re.search(pattern, text)
    return float(m.group(1)) if m else None


def stamping_rows(repeat: int, hog: bool) -> list[tuple[str, str, str, str]]:
    rows = []
    for loaded in (False, True) if hog else (False,):
        out = run(["bench_body_craters.py", "--moon", "--repeat", str(repeat)], hog=loaded)
        one = _num(r"1 thread\(s\): ([0-9.]+) s", out)
        two = _num(r"2 thread\(s\): ([0-9.]+) s", out)
        ratio = _num(r"/ 1 thread: x([0-9.]+)", out)
        what = "stamping 2 001 lunar craters, M = 330" + (", beside a busy loop" if loaded
                                                          else "")
        rows.append((what, f"{two:.2f} s on 2 threads" if two else "failed",
                     f"{one:.2f} s on 1 thread" if one else "", f"x{ratio:.2f}" if ratio
                     else ""))
    return rows


def fbm_row() -> tuple[str, str, str, str]:
    out = run(["-c", "import bench_latlong as b; b.bench_fbm(False)"])
    if "No module named 'noise'" in out:
        return ("fBm, 10 octaves, 6 M points", "", "`noise` not installed", "")
    t = _num(r"points, 10 octaves\): ([0-9.]+) s", out)
    ref = _num(r"list comprehension ([0-9.]+) M points/s", out)
    ratio = _num(r"speed-up x([0-9.]+)", out)
    return ("fBm, 10 octaves, 6 M points (`latlong.fbm3`)", f"{t:.2f} s",
            f"`noise.pnoise3` {ref:.2f} M points/s", f"x{ratio:.1f}")


def sensor_rows(repeat: int) -> list[tuple[str, str, str, str]]:
    out = run(["bench_sensors_peers.py", "--repeat", str(repeat)])
    cam = _num(r"shadows: craterform ([0-9.]+) s", out)
    mi = _num(r"scalar_rgb direct 1 spp ([0-9.]+) s", out)
    lid = _num(r"lidar_frame ([0-9.]+) s", out)
    emb = _num(r"embreex run ([0-9.]+) s", out)
    rows = []
    if cam and mi:
        rows.append(("camera 1024^2, 12 M triangles, direct light + shadows", f"{cam:.3f} s",
                     f"Mitsuba 3 scalar_rgb {mi:.3f} s", f"x{mi / cam:.2f}"))
    else:
        rows.append(("camera 1024^2 against Mitsuba 3", "", "Mitsuba not installed or failed",
                     ""))
    if lid and emb:
        rows.append(("LIDAR 512^2 beams, same mesh", f"{lid:.3f} s", f"embreex {emb:.3f} s",
                     f"x{emb / lid:.2f}"))
    return rows


def writer_rows() -> list[tuple[str, str, str, str]]:
    out = run(["bench_writers.py", "--magnitude", "1400", "--repeat", "2"])
    line = [x for x in out.splitlines() if x.startswith("{")]
    if not line:
        return [("PLY / GLB export, M = 1400", "failed", "", "")]
    r = json.loads(line[-1])
    dd = f"dd {r['dd_MBps']} / {r['dd_after_MBps']} MB/s (before / after)"
    return [(f"{kind} export, M = 1400 (11.8 M vertices)", f"{r[key]} MB/s", dd,
             f"x{r[key] / r['dd_MBps']:.2f} / x{r[key] / r['dd_after_MBps']:.2f}")
            for kind, key in (("PLY", "ply_MBps"), ("GLB", "glb_MBps"))]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--hog", action="store_true",
                        help="also stamp beside a busy-loop process")
    args = parser.parse_args()
    rows = (stamping_rows(args.repeat, args.hog) + [fbm_row()] + sensor_rows(args.repeat)
            + writer_rows())
    print(f"{datetime.date.today()}, {platform.machine()}, {os.cpu_count()} cores "
          f"(ratio > 1: craterform faster)\n")
    print("| benchmark | craterform | peer, same run | ratio |")
    print("|---|---|---|---|")
    for row in rows:
        print("| " + " | ".join(row) + " |")


if __name__ == "__main__":
    main()
