"""Batches on dask.distributed (``latlong batch``, ``dem batch``, ``latlong.batch``,
``dem.batch``): the index, byte identity with single builds, resume, failures, errors,
and a cluster of separate processes. Every test starts and stops its own cluster on
127.0.0.1 (one LocalCluster of two single-threaded worker processes for the module)."""

from __future__ import annotations

import contextlib
import json
import logging
import os
import re
import subprocess
import sys
import time
from pathlib import Path

import pytest

import dem
import latlong
from dem.cli import main as dem_main
from latlong.cli import main as latlong_main
from latlong.parallel.backends import choose_backend, open_backend, run_task
from latlong.parallel.batch import parse_seeds, read_index, sha256_file, variants
from latlong.parallel.batch_tasks import run_variant

pytestmark = pytest.mark.xdist_group("batch")

ROOT = Path(__file__).resolve().parents[1]
LOLA = ROOT / "tests" / "data" / "ldem4_crop.lbl"
# a cratered fBm body at M = 16 (1538 vertices): a build takes a fraction of a second
SCENE = """preset = "fbm-cratered"
magnitude = 16
craters = ["c=0.5,k=-2,d_min_m=8,d_max_m=15"]
"""
# a layer stack of three 17-pixel layers on the LOLA crop (input relative to ROOT)
STACK = """input = "tests/data/ldem4_crop.lbl"
output = "site"
layers = 3
size = 17
craters = ["c=0.05,k=-2,d_min_m=20000,d_max_m=60000"]
"""
# a body made on demand (a fraction of a second)
_ON_DEMAND = {"preset": "fbm-cratered", "seed": 5, "on_demand": True, "magnitude": 40,
              "craters": ["c=0.5,k=-2,d_min_m=4,d_max_m=15"]}
# a crater layer the scene accepts but the build refuses (about 1e15 craters)
TOO_MANY = "c=1e6,k=-2,d_min_m=0.01,d_max_m=1"


@pytest.fixture(scope="module")
def scheduler():
    """A LocalCluster of two single-threaded worker processes on 127.0.0.1."""
    from distributed import LocalCluster

    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                      dashboard_address=None, silence_logs=logging.ERROR,
                      scheduler_kwargs={"dashboard_address": "127.0.0.1:0"}) as cluster:
        yield cluster.scheduler_address


@pytest.fixture
def scene(tmp_path) -> Path:
    path = tmp_path / "scene.toml"
    path.write_text(SCENE)
    return path


def _shas(folder: Path, names) -> dict:
    return {n: sha256_file(folder / n) for n in names}


def test_seeds_and_variant_names():
    assert parse_seeds("1-3,7") == (1, 2, 3, 7)
    assert parse_seeds([5, 1]) == (5, 1)
    specs = [["c=1,k=-2,d_min_m=1,d_max_m=2"], ["c=2,k=-2,d_min_m=1,d_max_m=2"]]
    names = [v.name for v in variants("9-10", {"magnitude": [16, 20], "craters": specs})]
    assert names[:3] == ["seed0009_magnitude=16_craters=v1", "seed0009_magnitude=16_craters=v2",
                         "seed0009_magnitude=20_craters=v1"] and len(names) == 8
    for bad in ("", "1-x", "3-1", "1,1", "-2", "1-2000000"):
        with pytest.raises(ValueError, match="seeds"):
            parse_seeds(bad)
    with pytest.raises(ValueError, match="given twice"):
        variants("1", {"radius_m": [100.0, 100]})


def test_index_and_single_builds(tmp_path, scene, scheduler):
    out = tmp_path / "batch"
    rows = []
    result = latlong.batch(scene, "1-2", vary={"radius_m": [100.0, 150.0]}, out=out,
                           scheduler=scheduler, on_done=rows.append)
    assert (result.done, result.skipped, result.failed) == (4, 0, 0)
    index = read_index(out / "index.csv")
    assert [r["variant"] for r in index] == ["seed0001_radius-m=100", "seed0001_radius-m=150",
                                             "seed0002_radius-m=100", "seed0002_radius-m=150"]
    assert sorted(r["variant"] for r in rows) == sorted(r["variant"] for r in index)
    for r in index:
        files = r["files"].split(";")
        assert files == [f"{r['variant']}.npz", f"{r['variant']}_craters.csv"]
        assert r["sha256"].split(";") == [sha256_file(out / f) for f in files]
        assert r["status"] == "ok" and not r["error"] and r["radius_m"] in ("100", "150")
        assert float(r["seconds"]) > 0 and float(r["peak_mb"]) > 10
    assert not [p for p in out.iterdir() if p.name.startswith(".")]  # no temporary left
    # the same bytes as `latlong build --config SCENE --seed S` to the same file names
    single = tmp_path / "single"
    single.mkdir()
    for seed, radius in ((1, "150"), (2, "100")):
        name = f"seed000{seed}_radius-m={radius}"
        assert latlong_main(["build", "--config", str(scene), "--seed", str(seed),
                                 "--radius-m", radius, "-q", "-o", str(single / f"{name}.npz"),
                                 "--catalog", str(single / f"{name}_craters.csv")]) == 0
        files = [f"{name}.npz", f"{name}_craters.csv"]
        assert _shas(single, files) == _shas(out, files)


def test_default_local_cluster(tmp_path, scene):
    """Without a scheduler the batch starts (and stops) its own cluster on 127.0.0.1."""
    out = tmp_path / "batch"
    result = latlong.batch(scene, "4", out=out, workers=1)
    assert (result.done, result.failed) == (1, 0)
    single = tmp_path / "single"
    single.mkdir()
    files = ["seed0004.npz", "seed0004_craters.csv"]
    assert latlong_main(["build", "--config", str(scene), "--seed", "4", "-q", "-o",
                         str(single / files[0]), "--catalog", str(single / files[1])]) == 0
    assert _shas(single, files) == _shas(out, files)


def _probe_task(payload, folder, name):
    import numba

    (folder / f"{name}.txt").write_text(f"{payload} {numba.get_num_threads()}")
    if payload == "bad":
        raise ValueError("`x` must be good")


def test_a_variant_in_the_worker(tmp_path):
    """The task writes under a temporary folder, its files are hashed and renamed into
    place; ``threads`` limits numba in a dask task (:func:`run_task`); a bad variant
    leaves nothing behind."""
    import numba

    try:
        rec = run_task(lambda _, payload: run_variant(_probe_task, payload, str(tmp_path), "v1"),
                       None, "fine", 1)
        assert rec["status"] == "ok" and rec["files"] == ["v1.txt"]
        assert (tmp_path / "v1.txt").read_text() == "fine 1"
        assert rec["sha256"] == [sha256_file(tmp_path / "v1.txt")] and rec["peak_mb"] > 1
        rec = run_variant(_probe_task, "bad", str(tmp_path), "v2")
        assert rec["status"] == "failed" and rec["error"] == "`x` must be good"
        assert sorted(p.name for p in tmp_path.iterdir()) == ["v1.txt"]
    finally:
        numba.set_num_threads(numba.config.NUMBA_NUM_THREADS)


def test_named_outputs_keep_their_bytes(tmp_path, scheduler):
    """Outputs that name themselves (a .glb and its .json manifest) equal a single build
    written to the same names; the scene's names get the variant's prefix."""
    scene = tmp_path / "named.toml"
    scene.write_text(SCENE + 'output = ["meshes/body.glb", "body.ply"]\ncatalog = "c.scc"\n')
    out = tmp_path / "batch"
    latlong.batch(scene, [3], out=out, scheduler=scheduler)
    files = ["seed0003_body.glb", "seed0003_body.json", "seed0003_body.ply", "seed0003_c.scc"]
    assert read_index(out / "index.csv")[0]["files"].split(";") == files
    assert json.loads((out / "seed0003_body.json").read_text())["glb"] == "seed0003_body.glb"
    single = tmp_path / "single"
    single.mkdir()
    assert latlong_main(["build", "--config", str(scene), "--seed", "3", "-q",
                             "-o", str(single / files[0]), "-o", str(single / files[2]),
                             "--catalog", str(single / files[3])]) == 0
    assert _shas(single, files) == _shas(out, files)


def test_serial_backend_gives_the_dask_bytes(tmp_path, scene, scheduler, monkeypatch):
    """The serial backend builds the variants in this process (no cluster): the same
    files and index as dask's workers; a variant that fails is recorded, the others
    built."""
    vary = {"radius_m": [100.0, 150.0]}
    there = latlong.batch(scene, "1-2", vary=vary, out=tmp_path / "dask", scheduler=scheduler)
    here = latlong.batch(scene, "1-2", vary=vary, out=tmp_path / "serial", backend="serial")
    assert (here.done, here.failed) == (4, 0)
    assert [(r["files"], r["sha256"]) for r in here.rows] == \
        [(r["files"], r["sha256"]) for r in there.rows]
    monkeypatch.chdir(ROOT)  # the config's input is relative to the working folder
    config = tmp_path / "stack.toml"
    config.write_text(STACK)
    rows = [dem.batch(config, "5", out=tmp_path / name, **how).rows[0]
            for name, how in (("dem_dask", {"scheduler": scheduler}),
                              ("dem_serial", {"backend": "serial"}))]
    assert rows[0]["sha256"] == rows[1]["sha256"] and "manifest.json" in rows[0]["files"]
    scene.write_text(SCENE + "max_memory_gb = 1e12\n")
    mixed = latlong.batch(scene, "1", out=tmp_path / "mixed", backend="serial",
                          vary={"craters": [["c=0.5,k=-2,d_min_m=8,d_max_m=15"], [TOO_MANY]]})
    assert [r["status"] for r in mixed.rows] == ["ok", "failed"]
    assert "asks for about" in mixed.rows[1]["error"]


@pytest.mark.parametrize(("how", "message"), [
    ({"backend": "threads"}, "`backend` must be one of serial, dask; got 'threads'"),
    ({"backend": "serial", "workers": 2}, "`workers` applies to the dask backend"),
    ({"backend": "serial", "scheduler": "tcp://127.0.0.1:9"},
     "`scheduler` applies to the dask backend"),
    ({"workers": 0}, "`workers` must be an integer in [1, "),
])
def test_backend_choice_errors_before_any_work(tmp_path, scene, how, message):
    with pytest.raises(ValueError, match=re.escape(message)):
        latlong.batch(scene, "1", out=tmp_path / "batch", **how)
    assert not (tmp_path / "batch").exists()


def test_the_backends_map_alike(scheduler):
    """Both backends yield every result once; ``errors="return"`` hands a failure back
    in place of its result, ``"raise"`` raises it."""
    import operator

    assert (choose_backend(), choose_backend(scheduler=scheduler),
            choose_backend(default="dask")) == ("serial", "dask", "dask")
    for how in ({"backend": "serial"}, {"scheduler": scheduler}):
        with open_backend(**how) as backend:
            got = dict(backend.map(operator.truediv, [1.0, 2.0, 0.0, 4.0], shared=8.0,
                                   retries=0, errors="return"))
            assert [got[i] for i in (0, 1, 3)] == [8.0, 4.0, 2.0]
            assert isinstance(got[2], ZeroDivisionError)
            with pytest.raises(ZeroDivisionError):
                list(backend.map(operator.truediv, [0.0], shared=1.0, retries=0))


def test_resume_redoes_only_missing_and_corrupt(tmp_path, scene, scheduler):
    out = tmp_path / "batch"
    first = latlong.batch(scene, "1-3", out=out, scheduler=scheduler)
    before = {r["variant"]: r["sha256"] for r in first.rows}
    (out / "seed0001.npz").unlink()  # missing
    with open(out / "seed0002_craters.csv", "r+b") as fh:  # corrupt
        fh.write(b"x")
    again = latlong.batch(scene, "1-3", out=out, scheduler=scheduler, resume=True)
    assert (again.done, again.skipped, again.failed) == (2, 1, 0)
    index = read_index(out / "index.csv")
    assert {r["variant"]: r["sha256"] for r in index} == before
    assert all(r["sha256"].split(";") == [sha256_file(out / f) for f in r["files"].split(";")]
               for r in index)
    # nothing left to do: no cluster is started (no scheduler at this address)
    done = latlong.batch(scene, "1-3", out=out, scheduler="tcp://127.0.0.1:9", resume=True)
    assert (done.done, done.skipped) == (0, 3)
    # a changed scene is not the batch the index describes: every variant is redone
    scene.write_text(SCENE.replace("d_min_m=8", "d_min_m=9"))
    changed = latlong.batch(scene, "1-3", out=out, scheduler=scheduler, resume=True)
    assert (changed.done, changed.skipped) == (3, 0)


def test_failed_variant_is_recorded_and_the_others_kept(tmp_path, scene, scheduler, run_module):
    # a memory allowance far above the up-front estimate of TOO_MANY (4e9 GB), so the
    # variant is accepted and fails while it runs (the population's count limit)
    scene.write_text(SCENE + "max_memory_gb = 1e12\n")
    out = tmp_path / "batch"
    proc = run_module("latlong", "batch", str(scene), "--seeds", "1-2", "--scheduler",
                      scheduler, "--vary", f"craters=c=0.5,k=-2,d_min_m=8,d_max_m=15;{TOO_MANY}",
                      "-o", str(out))
    assert proc.returncode == 1, proc.stderr
    last = proc.stderr.strip().splitlines()[-1]
    assert last.startswith("error: batch: 4 variants: 2 built, 0 kept, 2 failed")
    rows = {r["variant"]: r for r in read_index(out / "index.csv")}
    assert [rows[f"seed000{s}_craters=v2"]["status"] for s in (1, 2)] == ["failed"] * 2
    assert "asks for about" in rows["seed0001_craters=v2"]["error"]
    assert not rows["seed0001_craters=v2"]["files"]
    assert [rows[f"seed000{s}_craters=v1"]["status"] for s in (1, 2)] == ["ok"] * 2
    assert sorted(p.name for p in out.iterdir()) == [
        "index.csv", "seed0001_craters=v1.npz", "seed0001_craters=v1_craters.csv",
        "seed0002_craters=v1.npz", "seed0002_craters=v1_craters.csv"]
    # one line per finished variant on stderr when it is not a terminal
    assert sum(line.startswith(("ok ", "failed ")) for line in proc.stderr.splitlines()) == 4


@pytest.mark.parametrize(("args", "message"), [
    (["--seeds", "1-x"], "--seeds must be seeds like '1-1000'"),
    (["--seeds", "4-2"], "--seeds range '4-2' runs backwards"),
    (["--seeds", "1", "--vary", "colour=1,2"], "--vary 'colour=1,2': unknown key 'colour'"),
    (["--seeds", "1", "--vary", "seed=1,2"], "--vary seed: give the seeds with --seeds"),
    (["--seeds", "1", "--vary", "magnitude=16,x"], "--vary magnitude=x:"),
    (["--seeds", "1", "--vary", "radius-m=100,-5"],
     "--vary radius_m=-5: `radius_m` must be in [0.001, 1e+09]"),
    (["--seeds", "1", "--vary", "radius_m=100,100.0"], "--vary radius_m: value '100' is given"),
    (["--seeds", "1", "--scheduler", "nowhere"], "--scheduler must be a dask scheduler"),
    (["--seeds", "1", "--scheduler", "tcp://127.0.0.1:9", "--workers", "2"],
     "--workers applies to the local cluster"),
])
def test_bad_options_are_one_line_errors(tmp_path, scene, capsys, args, message):
    out = tmp_path / "batch"
    code = latlong_main(["batch", str(scene), "-o", str(out), *args])
    err = capsys.readouterr().err
    assert code == 2 and err.startswith("error: ") and message in err, err
    assert err.count("\n") == 1 and not out.exists()


def test_unreachable_scheduler_writes_nothing(tmp_path, scene, capsys):
    out = tmp_path / "batch"
    code = latlong_main(["batch", str(scene), "--seeds", "1", "-o", str(out), "--scheduler",
                         "tcp://127.0.0.1:9", "--connect-timeout-s", "2"])
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1, err
    assert "--scheduler tcp://127.0.0.1:9: no dask scheduler answered within 2 s" in err
    assert not out.exists()


def test_errors_through_the_entry_point(tmp_path, scene, run_module):
    out = tmp_path / "batch"
    out.mkdir()
    (out / "index.csv").write_text("variant\n")
    proc = run_module("latlong", "batch", str(scene), "--seeds", "1", "-o", str(out))
    assert proc.returncode == 2 and proc.stderr.count("\n") == 1
    assert "holds a batch (index.csv): give --resume to finish it or --force" in proc.stderr
    proc = run_module("dem", "batch", str(scene), "--seeds", "1", "-o", str(tmp_path / "d"))
    assert proc.returncode == 2 and proc.stderr.count("\n") == 1
    assert "unknown config key(s) 'magnitude', 'preset'" in proc.stderr
    stack = tmp_path / "stack.toml"
    stack.write_text(STACK)
    proc = run_module("dem", "batch", str(stack), "--seeds", "1", "--vary", "size=17,100",
                      "-o", str(tmp_path / "d"), cwd=ROOT)
    assert proc.returncode == 2 and proc.stderr.count("\n") == 1
    assert "--vary size=100: `size` must be 2^n + 1" in proc.stderr


def test_dem_batch_equals_dem_enhance(tmp_path, scheduler, monkeypatch):
    monkeypatch.chdir(ROOT)  # the config's input is relative to the working folder
    config = tmp_path / "stack.toml"
    config.write_text(STACK)
    out = tmp_path / "batch"
    result = dem.batch(config, "5", vary={"layers": [2, 3]}, out=out, scheduler=scheduler)
    assert (result.done, result.failed) == (2, 0)
    name = "seed0005_layers=3"
    rows = {r["variant"]: r for r in read_index(out / "index.csv")}
    files = rows[name]["files"].split(";")
    assert f"{name}/manifest.json" in files and f"{name}/layer_02.tif" in files
    manifest = json.loads((out / name / "manifest.json").read_text())
    assert manifest["info"]["parameters"]["input"] == "tests/data/ldem4_crop.lbl"
    single = tmp_path / "single"
    single.mkdir()
    assert dem_main(["enhance", "--config", str(config), "--seed", "5", "--layers", "3",
                         "-q", "-o", str(single / name)]) == 0
    assert _shas(single, files) == _shas(out, files)


@contextlib.contextmanager
def _separate_cluster(tmp_path: Path, n_workers: int = 2):
    """``dask scheduler`` and ``dask worker --nthreads 1`` processes on 127.0.0.1, the
    workers in another working folder than the client's."""
    env = {**os.environ, "NUMBA_NUM_THREADS": "1"}  # PYTHONPATH: set by conftest
    info = tmp_path / "scheduler.json"
    where = tmp_path / "workers"
    where.mkdir()
    procs = []
    try:
        procs.append(subprocess.Popen(
            [sys.executable, "-m", "distributed.cli.dask_scheduler", "--host", "127.0.0.1",
             "--port", "0", "--no-dashboard", "--scheduler-file", str(info)], env=env,
            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
        deadline = time.monotonic() + 60
        while not info.exists() and time.monotonic() < deadline:
            time.sleep(0.2)
        time.sleep(0.5)  # the file is written whole before the scheduler listens
        address = json.loads(info.read_text())["address"]
        for _ in range(n_workers):
            procs.append(subprocess.Popen(
                [sys.executable, "-m", "distributed.cli.dask_worker", address, "--nthreads",
                 "1", "--host", "127.0.0.1", "--no-dashboard", "--death-timeout", "60"],
                env=env, cwd=where, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
        yield address
    finally:
        for p in reversed(procs):
            p.terminate()
        for p in reversed(procs):
            try:
                p.wait(timeout=30)
            except subprocess.TimeoutExpired:
                p.kill()
                p.wait(timeout=30)


@pytest.mark.slow
def test_separate_processes_give_the_same_bytes(tmp_path, scene, scheduler, monkeypatch,
                                                 run_module):
    local = tmp_path / "local"
    latlong.batch(scene, "1-2", vary={"magnitude": [16, 18]}, out=local, scheduler=scheduler)
    config = tmp_path / "stack.toml"
    config.write_text(STACK)
    monkeypatch.chdir(ROOT)  # the config's input is relative to the working folder
    dem.batch(config, "1", out=tmp_path / "dem_local", scheduler=scheduler)
    expand = ("dem", "expand", str(LOLA), "--levels", "2", "--seed", "4", "-q")
    proc = run_module(*expand, "-o", str(tmp_path / "here.tif"))
    assert proc.returncode == 0, proc.stderr
    from latlong.ondemand.patches import build_patches

    on_demand = latlong.Scene.from_settings(_ON_DEMAND)
    here = build_patches(on_demand, patches=3)
    with _separate_cluster(tmp_path) as address:
        # a body made on demand in 16 patches on the separate workers: the same bytes
        there = build_patches(on_demand, patches=16, scheduler=address)
        assert there.radii_m.tobytes() == here.radii_m.tobytes()
        assert there.craters.tobytes() == here.craters.tobytes()
        # the tiles of one DEM as tasks on the separate workers: the same bytes
        proc = run_module(*expand, "--scheduler", address, "-o", str(tmp_path / "there.tif"))
        assert proc.returncode == 0, proc.stderr
        assert sha256_file(tmp_path / "here.tif") == sha256_file(tmp_path / "there.tif")
        proc = run_module("latlong", "batch", str(scene), "--seeds", "1-2", "--vary",
                          "magnitude=16,18", "--scheduler", address, "-o",
                          str(tmp_path / "remote"))
        assert proc.returncode == 0, proc.stderr
        # the workers run in another folder: the input is read where the client sees it
        proc = run_module("dem", "batch", str(config), "--seeds", "1", "--scheduler",
                          address, "-o", str(tmp_path / "dem_remote"), cwd=ROOT)
        assert proc.returncode == 0, proc.stderr
    for a, b in (("local", "remote"), ("dem_local", "dem_remote")):
        rows_a = read_index(tmp_path / a / "index.csv")
        rows_b = read_index(tmp_path / b / "index.csv")
        assert [(r["files"], r["sha256"]) for r in rows_a] == \
            [(r["files"], r["sha256"]) for r in rows_b]
    assert len(rows_a) == 1 and "manifest.json" in rows_a[0]["files"]


# --------------------------------------------------------------------------- DEM tiles
def test_expand_tiles_as_tasks_give_the_same_bytes(tmp_path, scheduler):
    """``dem.expand_to_file`` with its tiles as dask tasks (this module's cluster, and a
    local cluster of its own through ``dem expand --workers``) = tile after tile here."""
    from dem.expandfile import expand_to_file

    base = dem.read(LOLA)
    here = expand_to_file(base, tmp_path / "here.tif", 3, rng=9, tile_px=513)
    assert here.tiles == 16
    there = expand_to_file(base, tmp_path / "there.tif", 3, rng=9, tile_px=513,
                           scheduler=scheduler)
    assert there.tiles == 16
    assert sha256_file(here.path) == sha256_file(there.path)
    assert dem_main(["expand", str(LOLA), "--levels", "3", "--seed", "9", "--workers", "2",
                     "--tile-px", "513",
                     "-q", "-o", str(tmp_path / "cli.tif")]) == 0
    assert dem.read(tmp_path / "cli.tif").heights.tobytes() == \
        dem.read(here.path).heights.tobytes()


@pytest.mark.parametrize("args, message", [
    (["--workers", "0"], "--workers must be an integer in [1, "),
    (["--scheduler", "nowhere"], "--scheduler must be a dask scheduler address"),
    (["--scheduler", "tcp://127.0.0.1:9", "--workers", "2"], "--workers applies to the local"),
])
def test_expand_task_options_are_one_line_errors(tmp_path, capsys, args, message):
    out = tmp_path / "x.tif"
    assert dem_main(["expand", str(LOLA), "-o", str(out), *args]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("error: ") and message in err, err
    assert not out.exists() and list(tmp_path.iterdir()) == []


def test_expand_checks_its_backend_before_any_work(tmp_path):
    from dem.expandfile import expand_to_file

    for how, message in (({"backend": "serial", "workers": 2}, "`workers` applies to the dask"),
                         ({"backend": "spark"}, "`backend` must be one of serial, dask")):
        with pytest.raises(ValueError, match=message):
            expand_to_file(dem.read(LOLA), tmp_path / "x.tif", 1, rng=1, **how)
    assert list(tmp_path.iterdir()) == []


def test_map_tiles_on_dask_yields_every_result_and_raises_a_failure(scheduler):
    import operator

    from latlong.parallel.tiles import map_tiles

    got = sorted(map_tiles(operator.mul, 3, list(range(10)), scheduler=scheduler, window=3))
    assert got == [(i, 3 * i) for i in range(10)]
    with pytest.raises(ZeroDivisionError):
        list(map_tiles(operator.truediv, 1.0, [1.0, 2.0, 0.0, 4.0], scheduler=scheduler,
                       retries=0))


# --------------------------------------------------------------------------- on demand


def test_on_demand_patches_give_the_same_bytes_on_any_backend(scheduler):
    """A body built on demand in 1 patch here = 2 and 16 patches as dask tasks."""
    from latlong.ondemand.patches import build_patches

    scene = latlong.Scene.from_settings(_ON_DEMAND)
    one = build_patches(scene)
    for patches in (2, 16):
        got = build_patches(scene, patches=patches, scheduler=scheduler)
        assert got.radii_m.tobytes() == one.radii_m.tobytes()
        assert got.craters.tobytes() == one.craters.tobytes()
    assert len(one.craters) > 100


def test_workers_that_cap_numpy_otherwise_are_named(scheduler, caplog, monkeypatch):
    """An existing cluster's workers whose numpy is not capped as this process's is
    (``NPY_DISABLE_CPU_FEATURES``, :func:`craters.cli.start.cap_numpy_simd`) are named in
    one warning: on an AVX-512 CPU their last bits may differ."""

    def warned() -> list[str]:
        caplog.clear()
        with caplog.at_level(logging.WARNING, logger="latlong.parallel.backends"), \
                open_backend(scheduler=scheduler):
            pass
        return [r.getMessage() for r in caplog.records
                if "NPY_DISABLE_CPU_FEATURES" in r.getMessage()]

    assert warned() == []  # the workers inherited this process's environment
    monkeypatch.setenv("NPY_DISABLE_CPU_FEATURES", "X86_V3")
    (message,) = warned()
    assert message.startswith("2 of the workers of tcp://127.0.0.1:")
