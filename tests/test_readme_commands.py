"""Every ``bash`` and ``python`` block of the README and of the package docstrings runs.

Sources: ``README.md`` (its fenced ```bash and ```python blocks) and every package
``__init__.py`` of ``latlong``, ``dem`` and ``craters`` whose docstring holds a
``.. code-block:: bash`` or ``.. code-block:: python`` (read with ``ast``: nothing is
imported). Each source runs on its own, its blocks in order, in a scratch folder holding a
copy of the repository's tracked files (``git ls-files``, as in a fresh clone; without git:
README.md, examples/, tests/data/ and the packages' ``__init__.py``), so later commands read
what earlier ones wrote, as a user following the README or a docstring does. A command that
names a file the project does not ship, that fails, or that prints a Python warning fails
the test with its stderr.

Outputs: the README writes only into ``out/``, which git ignores, so a user who follows
the README and then runs the tests stays green; a package docstring writes only into
``out/<its last name>/`` (``out/sensors/`` for ``latlong.sensors``), so the README and the
docstrings can be followed in any order without one refusing to replace another's files.

Sizes are made small by the substitutions of :data:`SMALLER` (each with its reason), and
commands that need the network, services or the whole test suite are skipped by
:data:`SKIPPED` (each with its reason); every entry of both must apply to some command.
Every other command runs exactly as written: a plain ``latlong``/``dem``/``craters`` line (no
shell syntax: :func:`in_process_argv`) through the command's ``__main__.main`` in the test
process (``run_cli`` of conftest: what its console script runs, without the ~2 s of a new
process; with ``CRATERFORM_TEST_SUBPROCESS=1`` in a process of its own), any other line in bash;
Python blocks run exactly as written (with ``python -P``, so the packages under test are
imported, not the copy's sources).
"""

from __future__ import annotations

import ast
import os
import re
import shlex
import shutil
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / "README.md"
PACKAGES = ("latlong", "dem", "craters")

#: (pattern, replacement, why): applied in order to every command line before it runs.
SMALLER: list[tuple[str, str, str]] = [
    (r"^pip install \. && ", "", "the package is installed already (this environment)"),
    (r"--magnitude \d+", "--magnitude 24", "bodies of 3458 vertices instead of ~1 M"),
    (r"--preset (eros|bennu) ", r"--preset \1 --magnitude 24 ",
     "the real-body presets default to large magnitudes"),
    (r"--preset eros ", "--preset eros --craters c=0.0377,k=-1.9,d_min_m=200,d_max_m=1180 ",
     "the preset's 44 000 craters of 20 m-1.2 km; 1 800 from 200 m"),
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
    (r"--size-px (512|256)", "--size-px 32", "small descent frames"),
    (r"--lidar-beams 64x64", "--lidar-beams 8x8", "few LIDAR beams"),
    (r"--size-m 1000 --pixel-m 1 ", "--size-m 1000 --pixel-m 25 ", "a 40 x 40 pixel window"),
    (r"--patches 8 --workers 2", "--patches 2", "two patches in this process"),
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


def readme_blocks(text: str) -> list[tuple[str, str]]:
    """The ``(language, body)`` of the ```bash and ```python blocks of ``text``, in order."""
    return re.findall(r"^```(bash|python)\n(.*?)^```", text, flags=re.MULTILINE | re.DOTALL)


def docstring_blocks(doc: str) -> list[tuple[str, str]]:
    """The ``(language, body)`` of the ``.. code-block:: bash|python`` blocks of ``doc``."""
    lines, blocks, i = doc.splitlines(), [], 0
    while i < len(lines):
        match = re.match(r"^( *)\.\. code-block:: (bash|python)\s*$", lines[i])
        i += 1
        if not match:
            continue
        indent, body = len(match.group(1)), []
        while i < len(lines) and (not lines[i].strip()
                                  or len(lines[i]) - len(lines[i].lstrip()) > indent):
            body.append(lines[i])
            i += 1
        blocks.append((match.group(2), textwrap.dedent("\n".join(body)).strip("\n") + "\n"))
    return blocks


def _init_docstring(package: str) -> str:
    path = ROOT.joinpath(*package.split("."), "__init__.py")
    return ast.get_docstring(ast.parse(path.read_text(encoding="utf-8"))) or ""


def _documented_packages() -> list[str]:
    """The packages whose ``__init__`` docstring holds runnable blocks, sorted."""
    names = [".".join(p.parent.relative_to(ROOT).parts) for top in PACKAGES
             for p in (ROOT / top).rglob("__init__.py")]
    return sorted(n for n in names if docstring_blocks(_init_docstring(n)))


#: README.md first, then the packages whose docstrings hold examples.
SOURCES: list[str] = ["README.md", *_documented_packages()]


def blocks_of(source: str) -> list[tuple[str, str]]:
    """The runnable blocks of a source (``README.md`` or a dotted package name)."""
    if source == "README.md":
        return readme_blocks(README.read_text(encoding="utf-8"))
    return docstring_blocks(_init_docstring(source))


def output_folder(source: str) -> str:
    """Where a source may write, relative to the repository's folder."""
    return "out/" if source == "README.md" else f"out/{source.rsplit('.', 1)[-1]}/"


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


def smaller(line: str, used: set[int] | None = None) -> str:
    """``line`` with :data:`SMALLER` applied (the indices that changed it added to ``used``)."""
    for index, (pattern, replacement, _) in enumerate(SMALLER):
        line, count = re.subn(pattern, replacement, line)
        if count and used is not None:
            used.add(index)
    return line


def skipped(line: str) -> str | None:
    """Why ``line`` is not run (None: it is run)."""
    for pattern, why in SKIPPED:
        if re.search(pattern, line):
            return why
    return None


#: Characters with a meaning to bash beyond splitting words and quoting: a line holding any
#: runs in bash.
SHELL_SYNTAX = re.compile(r"[&|;<>$`*?~(){}\[\]\\!#]")


def in_process_argv(line: str) -> list[str] | None:
    """The words of ``line`` if it is one of the three commands with no shell syntax (bash
    and ``shlex`` split it alike), else None (it runs in bash)."""
    if SHELL_SYNTAX.search(line):
        return None
    words = shlex.split(line)
    return words if words and words[0] in PACKAGES else None


def _bash_lines() -> list[str]:
    return [line for source in SOURCES for language, body in blocks_of(source)
            if language == "bash" for line in commands(body)]


def _copy_repository(dest: Path) -> None:
    """The tracked files of the repository (working-tree contents), as a clone has them."""
    try:
        listed = subprocess.run(["git", "-C", str(ROOT), "ls-files", "-z"], check=True,
                                capture_output=True).stdout.decode().split("\0")
        files = [f for f in listed if f and (ROOT / f).is_file()]
    except (OSError, subprocess.CalledProcessError):
        files = ["README.md"] + [str(p.relative_to(ROOT)) for top in ("examples", "tests/data")
                                 for p in (ROOT / top).rglob("*") if p.is_file()]
        files += [str(p.relative_to(ROOT)) for top in PACKAGES
                  for p in (ROOT / top).rglob("__init__.py")]
    for f in files:
        (dest / f).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(ROOT / f, dest / f)


def _files(folder: Path) -> set[str]:
    return {p.relative_to(folder).as_posix() for p in folder.rglob("*") if p.is_file()}


def test_parsing():
    """The parsers see every block and the helpers do what the runs rely on."""
    text = README.read_text(encoding="utf-8")
    assert len(readme_blocks(text)) == text.count("```bash") + text.count("```python") >= 8
    doc = "Text.\n\n.. code-block:: bash\n\n    a \\\n        b\n\n    c\n\nAfter.\n"
    assert docstring_blocks(doc) == [("bash", "a \\\n    b\n\nc\n")]
    assert commands("a \\\n    b  # x\n# only a comment\nc\n") == ["a b  # x", "c"]
    assert without_comment('dem info x.tif   # a note') == "dem info x.tif"
    assert without_comment('--vary "craters=c=1;#x"') == '--vary "craters=c=1;#x"'
    assert smaller("latlong build --magnitude 400 -o a.npz") == \
        "latlong build --magnitude 24 -o a.npz"
    assert skipped("pip install \".[test]\" && python -m pytest -q")
    assert in_process_argv("dem fill 'a b.tif' -o out/x.tif --seed=1") == [
        "dem", "fill", "a b.tif", "-o", "out/x.tif", "--seed=1"]
    for line in ("mkdir -p out && latlong info a.npz", "latlong info a.npz | head",
                 "craters profile > out/p.txt", "latlong info $HOME/a.npz", "ls out/",
                 "NUMBA_NUM_THREADS=1 latlong info a.npz", "latlong info out/*.npz"):
        assert in_process_argv(line) is None, line
    # the three packages document their commands; none of the 43 commands of the
    # reference README was dropped on the way into the docstrings
    assert {"latlong", "dem", "craters"} <= set(SOURCES)
    run = [line for line in _bash_lines()
           if re.search(r"(^|&& )(latlong|dem|craters) ", line) and not skipped(line)]
    assert len(run) >= 43


def test_quick_start_comes_first_and_ci_runs_its_test_command():
    """Install + demo, then install + tests, as the first two blocks; CI runs the latter."""
    first, second = (commands(body) for _, body in readme_blocks(
        README.read_text(encoding="utf-8"))[:2])
    assert len(first) == 1 and first[0].startswith("pip install . && ")
    assert "latlong build" in first[0]
    assert second == ['pip install ".[test]" && python -m pytest -q']
    ci = ROOT / ".ci" / "run"
    if not ci.exists():
        pytest.skip("no .ci/run in this copy (not a checkout)")
    assert second[0] in ci.read_text(encoding="utf-8").splitlines()


def test_the_readme_points_at_every_documented_package():
    readme = README.read_text(encoding="utf-8")
    missing = [name for name in SOURCES[1:] if f"`{name}`" not in readme]
    assert not missing, f"the README does not name these packages' docstrings: {missing}"


def test_every_substitution_and_skip_applies():
    used: set[int] = set()
    lines = [without_comment(line) for line in _bash_lines()]
    for line in lines:
        if not skipped(line):
            smaller(line, used)
    unused = [SMALLER[i][0] for i in range(len(SMALLER)) if i not in used]
    unused += [p for p, _ in SKIPPED if not any(re.search(p, line) for line in lines)]
    assert not unused, f"entries that apply to no command: {unused}"


def _run(command: list[str], cwd: Path, env: dict, what: str, **kw) -> None:
    start = time.perf_counter()
    _check(subprocess.run(command, cwd=cwd, env=env, capture_output=True, text=True,
                          timeout=300, **kw), what, start)


def _check(done: subprocess.CompletedProcess, what: str, start: float) -> None:
    """The command ran to exit code 0 and printed no Python warning."""
    assert done.returncode == 0, (
        f"{what}\nafter {time.perf_counter() - start:.1f} s, "
        f"exit {done.returncode}\n{done.stderr[-3000:]}")
    # no Python warning line (RuntimeWarning, ComplexWarning ...) reaches the user
    assert not re.search(r"\b\w*Warning\b", done.stderr), (
        f"{what}\nprinted a warning:\n{done.stderr[-3000:]}")


@pytest.mark.parametrize("source", SOURCES)
def test_blocks_run_in_order(source, tmp_path, run_cli):
    repo = tmp_path / "repo"
    repo.mkdir()
    _copy_repository(repo)
    before = _files(repo)
    env = dict(os.environ, MPLBACKEND="Agg")
    env["PATH"] = os.pathsep.join([str(Path(sys.executable).parent), env.get("PATH", "")])
    ran = 0
    for number, (language, body) in enumerate(blocks_of(source), 1):
        if language == "python":
            _run([sys.executable, "-P", "-"], repo, env,
                 f"{source} block {number} (python):\n{body}", input=body)
            ran += 1
            continue
        for line in commands(body):
            if skipped(line):
                continue
            command = smaller(without_comment(line))
            ran += 1
            what = f"{source} block {number}: {line!r}\nran as: {command!r}"
            argv = in_process_argv(command)
            if argv is not None:
                start = time.perf_counter()
                _check(run_cli(*argv, cwd=repo), what, start)
                continue
            _run(["bash", "-e", "-o", "pipefail", "-c", command], repo, env, what)
    assert ran
    stray = sorted(f for f in _files(repo) - before if not f.startswith(output_folder(source)))
    assert not stray, f"{source} wrote outside {output_folder(source)}: {stray[:20]}"


if __name__ == "__main__":
    for name in SOURCES:
        sys.stdout.write(f"== {name}\n")
        for language, body in blocks_of(name):
            if language == "python":
                sys.stdout.write(f"PY   {len(body.splitlines())} lines\n")
                continue
            for line in commands(body):
                why = skipped(line)
                sys.stdout.write(f"SKIP ({why}): {line}\n" if why else
                                 f"RUN  {smaller(without_comment(line))}\n")
