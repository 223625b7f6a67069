"""Every ``bash`` block of the README runs, in order, at small sizes.

The blocks are read from ``README.md`` and run command by command with ``bash``, in one
scratch folder that holds a copy of the repository's tracked files (``git ls-files``, as
in a fresh clone; without git: README.md, examples/ and tests/data/), so later commands
read what earlier ones wrote, as a user following the README does. A command that names a
file the project does not ship, or that fails, fails the test with its stderr.

Sizes are made small by the substitutions of :data:`SMALLER` (each with its reason), and
commands that need the network, services or the whole test suite are skipped by
:data:`SKIPPED` (each with its reason); every other command runs exactly as written.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / "README.md"

#: (pattern, replacement, why): applied in order to every command line before it runs.
SMALLER: list[tuple[str, str, str]] = [
    (r"^pip install \. && ", "", "the package is installed already (this environment)"),
    (r"--magnitude \d+", "--magnitude 24", "bodies of 3458 vertices instead of ~1 M"),
    (r"--preset (eros|bennu) ", r"--preset \1 --magnitude 24 ",
     "the real-body presets default to large magnitudes"),
    (r"--preset bennu ", "--preset bennu --boulders c=0.238,k=-2.9,d_min_m=20,d_max_m=40 ",
     "the preset's 3300 boulders of 4-40 m make a 93 MB mesh; 30 of 20-40 m"),
    (r"--preset fbm-cratered ", ("--preset fbm-cratered --craters c=0.5,k=-2,d_min_m=4,"
                                 "d_max_m=15 "),
     "the preset's 68 000 craters of 1-15 m; 4000 of 4-15 m (scene.toml's)"),
    (r"c=0.05,k=-2,d_min_m=1,d_max_m=15", "c=0.05,k=-2,d_min_m=5,d_max_m=15",
     "Itokawa: 25 x fewer craters"),
    (r"c=0.1,k=-2,d_min_m=1,d_max_m=10", "c=0.1,k=-2,d_min_m=4,d_max_m=10",
     "the faulted body: 16 x fewer craters"),
    (r"c=0.05,k=-2,d_min_m=2,d_max_m=20", "c=0.05,k=-2,d_min_m=8,d_max_m=20",
     "Bennu: 16 x fewer craters"),
    (r"npf=gaspra,age_gyr=1.0,d_min_m=100,", "npf=gaspra,age_gyr=1.0,d_min_m=400,",
     "Gaspra: 315 craters of 0.4-2 km instead of 24 700 of 0.1-2 km"),
    (r"--radius-m 2000 ", "--radius-m 200 ", "a 100 x smaller sphere: 10 000 craters"),
    (r"--spacing-m 1 ", "--spacing-m 200 ", "Itokawa's mesh refined to its 2 levels only"),
    (r"--backend implicit ", "--backend implicit --polygons 5000 --packing-voxels 24 ",
     "a coarse implicit surface"),
    (r"--preview (\S+)", r"--preview \1 --width-px 96 --height-px 72", "small pictures"),
    (r"^latlong render (.*)$", r"latlong render \1 --width-px 96 --height-px 72",
     "small pictures"),
    (r"--patch-k 64", "--patch-k 4", "patches of a small body"),
    (r"--size 512x512", "--size 48x48", "small camera frames"),
    (r"--beams 128x96", "--beams 12x8", "few LIDAR beams"),
    (r"--seeds 1-\d+", "--seeds 1-1", "one variant per setting"),
    (r"--vary layers=9,11", "--vary layers=2,3", "short layer stacks"),
    (r"dem enhance --config examples/site.toml", ("dem enhance --config examples/site.toml "
                                                "--layers 4 --size 65"),
     "a short stack of small layers"),
    (r"--levels 2 (.*)--region 0,0,257", r"--levels 1 \1--region 0,0,129",
     "one doubling of a 129^2 corner"),
    (r"--area-m2 1e1[01]", "--area-m2 1e9", "a tenth or a hundredth of the area"),
]

#: (pattern, why): a command line matching ``pattern`` is not run.
SKIPPED: list[tuple[str, str]] = [
    (r"python -m pytest", "runs the test suite (this test among it)"),
    (r"^pip install \"\.\[gravity\]\"$", ("installs from the network; the test "
                                            "extra holds polyhedral-gravity already")),
    (r"^dask (scheduler|worker)|dask worker", "starts a dask scheduler or workers"),
    (r"--scheduler tcp://", "needs the dask scheduler of the lines above"),
    (r"^kill %", "stops that scheduler and its workers"),
]


def bash_blocks(text: str) -> list[str]:
    """The bodies of the ```bash blocks of ``text``, in order."""
    return re.findall(r"^```bash\n(.*?)^```", text, flags=re.MULTILINE | re.DOTALL)


def commands(block: str) -> list[str]:
    """The command lines of a block: continuations joined, comment-only lines dropped."""
    joined = re.sub(r"\\\n\s*", "", block)
    return [line.strip() for line in joined.splitlines()
            if line.strip() and not line.strip().startswith("#")]


def without_comment(line: str) -> str:
    """``line`` without a trailing ``# ...`` comment (outside quotes)."""
    quote = None
    for i, ch in enumerate(line):
        if ch in "'\"" and quote in (None, ch):
            quote = None if quote else ch
        elif ch == "#" and quote is None and (i == 0 or line[i - 1].isspace()):
            return line[:i].rstrip()
    return line


def smaller(line: str) -> str:
    """``line`` with :data:`SMALLER` applied."""
    for pattern, replacement, _ in SMALLER:
        line = re.sub(pattern, replacement, line)
    return line


def skipped(line: str) -> str | None:
    """Why ``line`` is not run (None: it is run)."""
    for pattern, why in SKIPPED:
        if re.search(pattern, line):
            return why
    return None


def _copy_repository(dest: Path) -> None:
    """The tracked files of the repository (working-tree contents), as a clone has them."""
    try:
        listed = subprocess.run(["git", "-C", str(ROOT), "ls-files", "-z"], check=True,
                                capture_output=True).stdout.decode().split("\0")
        files = [f for f in listed if f and (ROOT / f).is_file()]
    except (OSError, subprocess.CalledProcessError):
        files = ["README.md"] + [str(p.relative_to(ROOT)) for top in ("examples", "tests/data")
                                 for p in (ROOT / top).rglob("*") if p.is_file()]
    for f in files:
        (dest / f).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(ROOT / f, dest / f)


def test_readme_parsing():
    """The parser sees every block and the helpers do what the run relies on."""
    text = README.read_text(encoding="utf-8")
    assert len(bash_blocks(text)) == text.count("```bash") >= 10
    assert commands("a \\\n    b  # x\n# only a comment\nc\n") == ["a b  # x", "c"]
    assert without_comment('dem info x.tif   # a note') == "dem info x.tif"
    assert without_comment('--vary "craters=c=1;#x"') == '--vary "craters=c=1;#x"'
    assert smaller("latlong build --magnitude 400 -o a.npz") == \
        "latlong build --magnitude 24 -o a.npz"
    assert skipped("pip install \".[test]\" && python -m pytest")


@pytest.mark.xdist_group("readme")
def test_readme_bash_blocks_run_in_order(tmp_path):
    _copy_repository(tmp_path)
    env = dict(os.environ, MPLBACKEND="Agg")
    env["PATH"] = os.pathsep.join([str(Path(sys.executable).parent), env.get("PATH", "")])
    ran, times = 0, []
    for number, block in enumerate(bash_blocks(README.read_text(encoding="utf-8")), 1):
        for line in commands(block):
            if skipped(line):
                continue
            command = smaller(without_comment(line))
            start = time.perf_counter()
            done = subprocess.run(["bash", "-e", "-o", "pipefail", "-c", command],
                                  cwd=tmp_path, env=env, capture_output=True, text=True,
                                  timeout=300)
            times.append((time.perf_counter() - start, command))
            assert done.returncode == 0, (
                f"README bash block {number}: {line!r}\nran as: {command!r}\n"
                f"after {times[-1][0]:.1f} s, "
                f"exit {done.returncode}\n{done.stderr[-3000:]}")
            # no Python warning line (RuntimeWarning, ComplexWarning ...) reaches the user
            assert not re.search(r"\b\w*Warning\b", done.stderr), (
                f"README bash block {number}: {command!r} printed a warning:\n"
                f"{done.stderr[-3000:]}")
            ran += 1
    assert ran >= 40


if __name__ == "__main__":
    for block in bash_blocks(README.read_text(encoding="utf-8")):
        for line in commands(block):
            why = skipped(line)
            sys.stdout.write(f"SKIP ({why}): {line}\n" if why else
                             f"RUN  {smaller(without_comment(line))}\n")
