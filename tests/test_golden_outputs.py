"""Byte-identical outputs: every command of the project at small sizes, against sha256s
recorded before the structure change (issue 15) and kept since.

Each step runs one command line in-process through its console-script entry point, in
one shared folder (later steps read earlier outputs, as the README's commands do), and
the sha256 of every file it writes (and of the standard output of ``info`` commands) is
compared with ``tests/data/golden_outputs.json``. A change of bytes must be explained in
the commit that changes that file; regenerate it with::

    CRATERFORM_WRITE_GOLDEN=1 python -m pytest tests/test_golden_outputs.py

Bytes depend on the platform as well as on the code: numpy picks SIMD implementations of
``exp``, ``arcsin`` ... by the CPU's features (an AVX-512 machine and an AVX2 one differed
in 18 of the 29 steps; the commands and this suite now cap numpy's loops at AVX2,
:func:`craters.cli.start.cap_numpy_simd`, so the record names no CPU features), OpenBLAS
its kernels (the sums that decide bytes avoid it), and VTK, GDAL and numba their versions. The file
holds one record per platform the hashes were made on (``records``: the platform and the
steps' hashes); the comparison runs against this platform's record and is skipped with the
difference to the nearest record named where there is none (the determinism tests still
compare runs within one machine), unless ``CRATERFORM_GOLDEN_ANY_PLATFORM=1`` asks for the
comparison with the first record anyway.

``CRATERFORM_WRITE_GOLDEN=1`` (the code changed bytes) writes this platform's record and
drops the others, which that change made stale; ``CRATERFORM_WRITE_GOLDEN=add`` (the same
code on another machine) adds or replaces this platform's record and keeps the others.
"""

from __future__ import annotations

import contextlib
import hashlib
import io
import json
import os
import platform
import shlex
import subprocess
import sys
from importlib.metadata import entry_points, version
from pathlib import Path

import numpy as np
import pytest

# one worker runs every step (the steps share one folder and build on each other)
pytestmark = pytest.mark.xdist_group("golden")

DATA = Path(__file__).parent / "data"
GOLDEN = DATA / "golden_outputs.json"
WRITE = os.environ.get("CRATERFORM_WRITE_GOLDEN", "")
#: Compare on any platform (to find which steps' bytes depend on the CPU, e.g. with
#: NUMBA_CPU_NAME=generic and NPY_DISABLE_CPU_FEATURES naming the AVX-512 features)
ANY_PLATFORM = bool(os.environ.get("CRATERFORM_GOLDEN_ANY_PLATFORM"))

# (step name, command line, hash its standard output too)
STEPS: list[tuple[str, str, bool]] = [
    ("build_faulting",
     ("latlong build --magnitude 24 --base faulting --seed 3 --faults-1 200 --faults-2 300 "
     "-o fa.npz -o fa.ply -o fa.obj -o fa.stl -o fa.vtp -o fa.vtk "
     "--preview fa.png --width-px 160 --height-px 120 -q"), False),
    ("build_fbm", ("latlong build --magnitude 30 --base fbm --seed 1 --octaves 6 "
     "--amplitude-m 4 -o fb.npz -o fb.ply -q"), False),
    ("build_sphere_craters",
     ("latlong build --magnitude 40 --base sphere --radius-m 100 --seed 4 "
     "--craters c=0.5,k=-2,d_min_m=4,d_max_m=20 "
     "--craters c=0.05,k=-2,d_min_m=20,d_max_m=30,age_min_gyr=1,age_max_gyr=3 "
     "--no-crater-roughness "
     "--catalog sc.csv -o sc.npz -q"), False),
    ("build_preset_cratered", ("latlong build --preset fbm-cratered --magnitude 48 --seed 1 "
     "-o pc.npz --catalog pc.csv -q"), False),
    ("build_preset_faulted", ("latlong build --preset faulted-cratered --magnitude 32 --seed 2 "
     "--faults-1 100 --faults-2 100 -o pf.npz -q"), False),
    ("build_preset_bennu", ("latlong build --preset bennu --magnitude 40 --seed 2 "
     "-o bn.npz -q"), False),
    ("build_boulders", ("latlong build --preset fbm-cratered --magnitude 48 --seed 1 "
     "--boulders c=0.002,k=-3,d_min_m=1,d_max_m=8,burial_max=0.5,near=0.3 "
     "-o rk.npz -o rk.ply -o rk.obj -o rk.vtp -o rk.glb --boulder-catalog rk.csv -q"), False),
    ("build_shape", ("latlong build --base shape:eros001708.tab --shape-units km "
     "--magnitude 40 --craters c=0.05,k=-2,d_min_m=300,d_max_m=1200 --seed 1 "
     "-o sh.npz -o sh.stl -q"), False),
    ("build_config", "latlong build --config scene.toml -q", False),
    ("build_implicit", ("latlong build --backend implicit --shape eros001708.tab "
     "--shape-units km --lcsn kernel=table-a1-1km-0gyr,d_min_m=1000,d_max_m=2000 "
     "--lcsn kernel=fig6-kernel1,d_min_m=500,d_max_m=1000,depth_ratio=0.1:0.2 "
     "--gabor frequency=0.0025,bandwidth=0.00125,amplitude_m=10 --polygons 20000 "
     "--packing-voxels 32 --seed 1 "
     "-o im.ply -o im.obj -o im.npz --magnitude 20 --shape-crossings outermost "
     "--catalog im.csv -q"), False),
    ("export_glb", "latlong export pc.npz -o pc.glb --patch-k 8 --lod 2 -q", False),
    ("export_vtp", "latlong export pc.npz -o pcs.vtp -q", False),
    ("render", "latlong render pc.npz -o pcv.png --views 6 --width-px 96 --height-px 72 -q",
     False),
    ("latlong_slopes", ("latlong slopes pc.npz --compare eros001708.tab --shape-units km "
     "--csv sl.csv -q"), False),
    ("latlong_spectrum", "latlong spectrum pc.npz --csv sp.csv -q", False),
    ("latlong_info", "latlong info sh.npz", True),
    ("craters_profile", "craters profile --diameter-m 1000 --age-gyr 3 --csv prof.csv -q",
     False),
    ("craters_population", ("craters population --craters c=0.5,k=-2,d_min_m=50,d_max_m=800 "
     "--radius-m 2000 --seed 1 -o pop.csv -q"), False),
    ("craters_population_model_age", ("craters population --craters npf=moon,age_gyr=3.8,"
     "d_min_m=100,d_max_m=20000,equilibrium=trask --area-m2 1e9 --seed 1 -o popm.scc -q"),
     False),
    ("craters_population_robbins", ("craters population --craters npf=mars,age_gyr=3.5,"
     "d_min_m=1000,d_max_m=20000 --area-m2 1e10 --seed 1 -o popr.csv --columns robbins -q"),
     False),
    ("build_model_age_scc", ("latlong build --magnitude 24 --base sphere --radius-m 20000 "
     "--craters npf=moon,age_gyr=3.8,d_min_m=300,d_max_m=3000 --seed 2 --catalog bn.scc -q"),
     False),
    ("dem_info", "dem info ldem4_crop.lbl", True),
    ("dem_fill", "dem fill gappy.tif -o filled.tif --seed 1 -q", False),
    ("dem_expand", ("dem expand filled.tif -o fine.tif --levels 2 --seed 1 "
     "--region 0,0,33 -q"), False),
    ("dem_enhance", "dem enhance --config site.toml --seed 5 -q", False),
    ("dem_mesh_stack", "dem mesh site/manifest.json -o site.ply -q", False),
    ("dem_mesh_one", "dem mesh fine.tif -o fine.vtp -q", False),
    ("dem_slopes", "dem slopes site/manifest.json --csv dsl.csv -q", False),
    ("dem_spectrum", "dem spectrum fine.tif --csv dsp.csv -q", False),
]

SCENE_TOML = """\
magnitude = 36
base = "faulting"
radius_m = 80.0
faults_1 = 150
faults_2 = 150
seed = 11
output = ["cf.npz", "cf.ply"]
catalog = "cf.csv"
[[craters]]
c = 0.3
k = -2.0
d_min_m = 3.0
d_max_m = 12.0
age_max_gyr = 2.0
"""

SITE_TOML = """\
input = "lola.tif"
output = "site"
target = [180.0, -0.5]
layers = 3
size = 65
body_radius_m = 1737400.0
craters = ["c=0.05,k=-2,d_min_m=200,d_max_m=100000",
           "c=0.005,k=-1.8,d_min_m=20000,d_max_m=200000,age_min_gyr=3,age_max_gyr=3.8,kind=old"]
boulders = ["c=0.00001,k=-3,d_min_m=300,d_max_m=2000,burial_max=0.3"]
"""


def _inputs(folder: Path) -> None:
    """The input files the steps read: shape model, LOLA crop, a gappy GeoTIFF, scenes."""
    import rasterio
    from affine import Affine

    import dem

    for name in ("eros001708.tab", "ldem4_crop.lbl", "ldem4_crop.img"):
        (folder / name).write_bytes((DATA / name).read_bytes())
    lola = dem.read(DATA / "ldem4_crop.lbl")
    with rasterio.open(folder / "lola.tif", "w", driver="GTiff", width=257, height=257,
                       count=1, dtype="float32", crs=lola.crs, transform=lola.transform) as ds:
        ds.write(lola.heights.astype(np.float32), 1)
    z = lola.heights[:65, :65].astype(np.float32).copy()
    z[20:31, 25:40] = np.nan
    z[50:53, 5:9] = np.nan
    with rasterio.open(folder / "gappy.tif", "w", driver="GTiff", width=65, height=65,
                       count=1, dtype="float32", nodata=np.nan, crs="EPSG:32633",
                       transform=Affine(100.0, 0, 500000.0, 0, -100.0, 4000000.0)) as ds:
        ds.write(z, 1)
    (folder / "scene.toml").write_text(SCENE_TOML)
    (folder / "site.toml").write_text(SITE_TOML)


def platform_fingerprint() -> dict:
    """What the bytes depend on besides the code: machine, CPU features numpy dispatches
    on, and the versions of the libraries that compute or write them."""
    from numpy._core._multiarray_umath import __cpu_features__

    from craters.cli.start import NUMPY_SIMD_CAP

    simd: str | list[str] = sorted(k for k, v in __cpu_features__.items()
                                   if v and k.startswith(("AVX", "FMA")))
    if os.environ.get("NPY_DISABLE_CPU_FEATURES") in NUMPY_SIMD_CAP.values():
        # numpy capped at AVX2 before it loaded (conftest, as the commands): the loops of
        # any x86-64 CPU give these bytes (AVX2 and SSE alike, tested), so no CPU list
        simd = "numpy dispatch capped at X86_V3 (craters.cli.start.cap_numpy_simd)"
    return {"machine": platform.machine(), "simd": simd,
            **{lib: version(lib) for lib in ("numpy", "numba", "scipy", "vtk", "rasterio",
                                              "matplotlib", "pillow")}}


def _entry_point(name: str):
    (ep,) = [e for e in entry_points(group="console_scripts") if e.name == name]
    return ep.load()


def _digest(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def _snapshot(folder: Path) -> dict[str, tuple[int, int]]:
    return {str(p.relative_to(folder)): (p.stat().st_mtime_ns, p.stat().st_size)
            for p in folder.rglob("*") if p.is_file()}


@pytest.fixture(scope="module")
def outputs(tmp_path_factory):
    """Run every step once in one folder; {step: {file or '<stdout>': sha256}}."""
    folder = tmp_path_factory.mktemp("golden")
    _inputs(folder)
    result = {}
    cwd = os.getcwd()
    os.chdir(folder)
    try:
        for name, command, with_stdout in STEPS:
            before = _snapshot(folder)
            argv = shlex.split(command)
            out, err = io.StringIO(), io.StringIO()
            with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
                try:
                    code = _entry_point(argv[0])(argv[1:])
                except SystemExit as exc:
                    code = exc.code
            after = _snapshot(folder)
            files = sorted(k for k, v in after.items() if before.get(k) != v)
            hashes = {f: _digest(folder / f) for f in files}
            if with_stdout:
                hashes["<stdout>"] = hashlib.sha256(out.getvalue().encode()).hexdigest()
            result[name] = {"exit": code, "files": hashes, "stderr": err.getvalue()}
    finally:
        os.chdir(cwd)
    if WRITE:
        here = platform_fingerprint()
        steps = {k: {"exit": v["exit"], "files": v["files"]} for k, v in result.items()}
        kept = [r for r in _records() if r["platform"] != here] if WRITE == "add" else []
        GOLDEN.write_text(json.dumps({"records": [{"platform": here, "steps": steps}, *kept]},
                                     indent=1, sort_keys=True) + "\n")
    return result


def _records() -> list[dict]:
    return json.loads(GOLDEN.read_text())["records"] if GOLDEN.exists() else []


@pytest.fixture(scope="module")
def golden():
    """The hashes recorded on this platform."""
    records, here = _records(), platform_fingerprint()
    for record in records:
        if record["platform"] == here:
            return record["steps"]
    if WRITE or ANY_PLATFORM:  # regenerating records this platform
        return records[0]["steps"]

    def differ(made_on):
        return {k: (made_on.get(k), v) for k, v in here.items() if made_on.get(k) != v}

    nearest = min((differ(r["platform"]) for r in records), key=len)
    pytest.skip(f"no golden hashes were made on this platform ({len(records)} records; "
                f"CRATERFORM_WRITE_GOLDEN=add records it); the nearest differs in {nearest}")


@pytest.mark.parametrize("step", [s[0] for s in STEPS])
def test_same_bytes_as_recorded(golden, outputs, step):
    got = outputs[step]
    assert got["exit"] == 0, got["stderr"]
    assert got["files"], f"{step} wrote nothing"
    want = golden[step]
    assert sorted(got["files"]) == sorted(want["files"])
    differ = [f for f in want["files"] if got["files"][f] != want["files"][f]]
    assert not differ, f"{step}: different bytes in {differ}"


#: A golden step run again with numba compiling for a generic x86-64 CPU (no AVX, no FMA),
#: with fewer outputs than the step writes (the same bytes for those): the fBm base's
#: kernels, ~8 s of compiling in CI; the whole set takes minutes (issue 34's "goldens with
#: a generic CPU name", every step by hand: the closing notes)
GENERIC_CPU_STEPS = {
    "build_fbm": ("latlong build --magnitude 30 --base fbm --seed 1 --octaves 6 "
                  "--amplitude-m 4 -o fb.npz -o fb.ply -q"),
}


@pytest.mark.parametrize("step", sorted(GENERIC_CPU_STEPS))
def test_numba_for_a_generic_cpu_gives_the_recorded_bytes(golden, tmp_path, step):
    # numba compiles each kernel for the CPU it runs on; without fast-math no contraction
    # or reordering may differ between targets, so another x86-64 CPU makes these bytes
    argv = shlex.split(GENERIC_CPU_STEPS[step])
    (command,) = [c for name, c, _ in STEPS if name == step]
    assert set(argv) <= set(shlex.split(command))  # the step's own options
    env = {**os.environ, "NUMBA_CPU_NAME": "generic",
           "NUMBA_CACHE_DIR": str(tmp_path / "numba-cache")}  # compiled here, not reused
    proc = subprocess.run([sys.executable, "-m", *argv], cwd=tmp_path, env=env,
                          capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    names = [argv[i + 1] for i, a in enumerate(argv) if a == "-o"]
    assert {f: _digest(tmp_path / f) for f in names} == \
        {f: golden[step]["files"][f] for f in names}


def test_enough_commands_are_recorded():
    records = _records()
    assert records and len(STEPS) >= 15
    assert all(set(r["steps"]) == {s[0] for s in STEPS} for r in records)
    assert len({json.dumps(r["platform"], sort_keys=True) for r in records}) == len(records)
