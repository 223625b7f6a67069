"""Issue 34 items 1-3: a run's outputs are locked while it runs (a second writer fails fast
naming the first), the no-clobber check is repeated atomically at the rename, a run killed
with SIGKILL while it moves its outputs into place is taken back by the next run, and
work too large for the disk or the machine is refused before it starts.

Another run is played by a small helper process that takes the output's lock the way a
run does (``flock`` on ``.<name>.lock``) and waits: each command then runs in this
process and must exit 2 with one line naming that process and the lock, writing nothing.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

DATA = Path(__file__).parent / "data"


def _helpers():
    """The command runner and checks of test_output_safety.py (tests import by path)."""
    import importlib.util

    spec = importlib.util.spec_from_file_location(
        "_output_safety", Path(__file__).with_name("test_output_safety.py"))
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


_h = _helpers()
BUILD, ENHANCE, assert_refused, run, snapshot, tiny_tif = (
    _h.BUILD, _h.ENHANCE, _h.assert_refused, _h.run, _h.snapshot, _h.tiny_tif)

_HOLD = r"""
import fcntl, os, sys, time
fd = os.open(sys.argv[1], os.O_RDWR | os.O_CREAT, 0o666)
fcntl.flock(fd, fcntl.LOCK_EX)
os.pwrite(fd, f"craterform {os.getpid()}\n".encode(), 0)
print("locked", flush=True)
time.sleep(120)
"""


class Holder:
    """A process holding the lock of an output (as a run writing it would)."""

    def __init__(self, output: Path):
        lock = output.parent / f".{output.name}.lock"
        self.proc = subprocess.Popen([sys.executable, "-c", _HOLD, str(lock)],
                                     stdout=subprocess.PIPE, text=True)
        assert self.proc.stdout.readline().strip() == "locked"
        self.lock = lock

    def close(self):
        self.proc.kill()
        self.proc.wait()
        self.proc.stdout.close()
        self.lock.unlink(missing_ok=True)


def _cases(tmp: Path) -> dict[str, tuple[str, list, Path]]:
    """(program, arguments, the output the other run holds) per kind of output."""
    tif = tiny_tif(tmp / "in.tif")
    body = tmp / "in.npz"
    scene = tmp / "scene.toml"
    scene.write_text('base = "sphere"\nmagnitude = 8\noutput = "b.npz"\n')
    return {
        "npz": ("latlong", [*BUILD, "-o", tmp / "o.npz"], tmp / "o.npz"),
        "ply": ("latlong", [*BUILD, "-o", tmp / "o.ply"], tmp / "o.ply"),
        "glb": ("latlong", [*BUILD, "-o", tmp / "o.glb"], tmp / "o.glb"),
        "glb's json": ("latlong", [*BUILD, "-o", tmp / "o.glb"], tmp / "o.json"),
        "preview": ("latlong", [*BUILD, "-o", tmp / "o.npz", "--preview", tmp / "p.png"],
                    tmp / "p.png"),
        "tif": ("dem", ["convert", tif, "-o", tmp / "o.tif"], tmp / "o.tif"),
        "zarr": ("dem", ["convert", tif, "-o", tmp / "o.zarr"], tmp / "o.zarr"),
        "stack folder": ("dem", [*ENHANCE, tif, "-o", tmp / "site"], tmp / "site"),
        "camera folder": ("latlong", ["camera", body, "-o", tmp / "cam", "--size", "8x8",
                                      "--fov-deg", "30", "--sun-direction", "1,0,0",
                                      "--target-lat-lon", "0,0", "--range-m", "900,800"],
                          tmp / "cam"),
        "lidar folder": ("latlong", ["lidar", body, "-o", tmp / "scan", "--beams", "4x4",
                                     "--fov-deg", "10", "--target-lat-lon", "0,0",
                                     "--range-m", "900,800"], tmp / "scan"),
        "batch folder": ("latlong", ["batch", scene, "--seeds", "1-1", "-o", tmp / "batch"],
                         tmp / "batch"),
    }


KINDS = ["npz", "ply", "glb", "glb's json", "preview", "tif", "zarr", "stack folder",
         "camera folder", "lidar folder", "batch folder"]


@pytest.mark.parametrize("kind", KINDS)
def test_a_second_writer_fails_fast_naming_the_first(capsys, tmp_path, kind):
    code, _, err = run(capsys, "latlong", *BUILD, "-o", tmp_path / "in.npz")
    assert code == 0, err
    prog, argv, held = _cases(tmp_path)[kind]
    before = snapshot(tmp_path)
    other = Holder(held)
    try:
        start = time.perf_counter()
        code, _, err = run(capsys, prog, *argv)
        took = time.perf_counter() - start
        after = snapshot(tmp_path)
        after.pop(str(other.lock.relative_to(tmp_path)))  # the other run's
    finally:
        other.close()
    assert_refused(code, err, "being written by another run", f"process {other.proc.pid}",
                   other.lock.name)
    assert took < 5, took  # before any work
    assert after == before


@pytest.mark.parametrize("kind", ["npz", "tif", "zarr"])  # a file, a raster, a folder store
def test_a_second_writer_with_wait_waits_for_the_first_to_end(capsys, caplog, tmp_path,
                                                              kind):
    code, _, err = run(capsys, "latlong", *BUILD, "-o", tmp_path / "in.npz")
    assert code == 0, err
    prog, argv, held = _cases(tmp_path)[kind]
    other = Holder(held)
    ended = threading.Event()

    def end_the_other_run():  # once this run has found it and waits
        while "waiting for process" not in caplog.text:
            time.sleep(0.05)
        other.close()
        ended.set()

    helper = threading.Thread(target=end_the_other_run, daemon=True)
    helper.start()
    try:
        code, _, err = run(capsys, prog, *argv, "--wait")
    finally:
        helper.join(timeout=60)
        other.close()
    assert ended.is_set()
    assert code == 0, err
    assert f"waiting for process {other.proc.pid} to finish writing" in caplog.text
    assert held.exists()


def test_two_real_runs_at_once_one_succeeds(tmp_path):
    out = tmp_path / "o.ply"
    argv = [str(Path(sys.executable).parent / "latlong"), "build", "--preset", "fbm-cratered",
            "--magnitude", "40", "--seed", "1", "-q", "-o", str(out)]
    procs = [subprocess.Popen(argv, stderr=subprocess.PIPE, text=True) for _ in range(2)]
    results = [(p.returncode, p.communicate(timeout=300)[1]) for p in procs]
    results = [(p.returncode, err) for p, (_, err) in zip(procs, results, strict=True)]
    codes = sorted(c for c, _ in results)
    assert codes == [0, 2], results
    (err,) = [e for c, e in results if c == 2]
    # the later one found the lock, or - if the first had finished - the file
    assert "being written by another run" in err or "exists; use --force" in err, err
    assert [p.name for p in tmp_path.iterdir()] == ["o.ply"]


def test_a_file_that_appears_meanwhile_is_never_replaced(tmp_path):
    from craters._shared import atomic_path, check_output_path, output_group

    out = tmp_path / "o.txt"
    with pytest.raises(ValueError, match="appeared while this run wrote it"):
        with output_group():
            check_output_path(out, force=False)
            with atomic_path(out) as tmp:
                tmp.write_text("ours")
            out.write_text("someone else's")  # after the check, before the rename
    assert out.read_text() == "someone else's"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["o.txt"]


# the kill of test_output_safety's SIGTERM case, as a SIGKILL that leaves no chance to clean
_KILL_IN_COMMIT = _h._KILL_BETWEEN.replace("signal.SIGTERM", "signal.SIGKILL")
assert "SIGKILL" in _KILL_IN_COMMIT


def test_sigkill_between_the_renames_is_taken_back_by_the_next_run(capsys, tmp_path):
    old = {"o.glb": b"old glb", "o.json": b"old json"}
    for name, data in old.items():
        (tmp_path / name).write_bytes(data)
    proc = subprocess.run([sys.executable, "-c", _KILL_IN_COMMIT, *BUILD, "-o",
                           str(tmp_path / "o.glb"), "--force"], capture_output=True, timeout=300)
    assert proc.returncode == -signal.SIGKILL
    assert (tmp_path / "o.glb").read_bytes()[:4] == b"glTF"  # the mix a kill -9 leaves
    journals = [p for p in tmp_path.iterdir() if p.name.endswith(".journal")]
    assert len(journals) == 1 and json.loads(journals[0].read_text())["outputs"]
    # the next run into the folder reads the journal and puts the old pair back
    code, _, err = run(capsys, "latlong", *BUILD, "-o", tmp_path / "other.npz")
    assert code == 0, err
    assert {k: v for k, v in snapshot(tmp_path).items() if k in old} == old
    assert sorted(p.name for p in tmp_path.iterdir()) == ["o.glb", "o.json", "other.npz"]


def test_an_expansion_larger_than_the_disk_is_refused_up_front(capsys, tmp_path):
    start = time.perf_counter()
    code, _, err = run(capsys, "dem", "expand", DATA / "ldem4_crop.lbl", "-o",
                       tmp_path / "big.tif", "--levels", "12", "--seed", "1")
    assert_refused(code, err, "1048577 x 1048577", "TiB", "free", "fewer levels")
    assert time.perf_counter() - start < 5
    assert list(tmp_path.iterdir()) == []


def _free_bytes(monkeypatch, free: int) -> None:
    """The disk as the free-space checks see it: ``free`` bytes left."""
    import shutil

    import latlong.meshio.sizes

    real = shutil.disk_usage

    def usage(path):
        total, used, _ = real(path)
        return shutil._ntuple_diskusage(total, used, free)

    monkeypatch.setattr(latlong.meshio.sizes.shutil, "disk_usage", usage)


def test_a_build_larger_than_the_free_disk_is_refused_up_front(capsys, tmp_path, monkeypatch):
    # M = 40: 9 602 vertices, a .ply of ~400 kB and an .stl of ~960 kB on a 1 MB disk
    _free_bytes(monkeypatch, 1_000_000)
    argv = ("build", "--magnitude", "40", "--base", "sphere", "--radius-m", "100")
    code, _, err = run(capsys, "latlong", *argv, "-o", tmp_path / "a.ply",
                       "-o", tmp_path / "a.stl")
    assert_refused(code, err, "'", "a.ply", "a.stl", "needs about 1.3 MiB", "free",
                   "--magnitude")
    assert list(tmp_path.iterdir()) == []
    code, _, err = run(capsys, "latlong", *argv, "-o", tmp_path / "a.ply")  # fits
    assert code == 0, err
    real = (tmp_path / "a.ply").stat().st_size
    from latlong.meshio.sizes import mesh_file_bytes
    assert abs(mesh_file_bytes("a.ply", 6 * 40**2 + 2) - real) < 0.02 * real


def test_an_export_larger_than_the_free_disk_is_refused_up_front(capsys, tmp_path,
                                                                 monkeypatch):
    code, _, err = run(capsys, "latlong", "build", "--magnitude", "40", "--base", "sphere",
                       "--radius-m", "100", "-o", tmp_path / "b.npz", "-q")
    assert code == 0, err
    _free_bytes(monkeypatch, 100_000)
    code, _, err = run(capsys, "latlong", "export", tmp_path / "b.npz", "-o",
                       tmp_path / "b.glb", "--lod", "2")
    assert_refused(code, err, "b.glb", "needs about", "free", "--lod")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["b.npz"]


def test_a_stack_larger_than_the_free_disk_is_refused_up_front(capsys, tmp_path,
                                                               monkeypatch):
    tif = tiny_tif(tmp_path / "tiny.tif")
    _free_bytes(monkeypatch, 2_000)  # 2 layers of 17^2 pixels at 3.6 B: 2 081 B
    code, _, err = run(capsys, "dem", *ENHANCE, tif, "-o", tmp_path / "site")
    assert_refused(code, err, "site", "needs about 2.0 KiB", "2 layers of 17 x 17",
                   "fewer layers")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["tiny.tif"]


def test_frames_larger_than_the_free_disk_are_refused_up_front(capsys, tmp_path, monkeypatch):
    _free_bytes(monkeypatch, 100_000)  # 4 frames of 64^2 px at >= 28 B a pixel: 459 kB
    code, _, err = run(capsys, "latlong", "descent", "--preset", "fbm-cratered", "--lat-deg",
                       "0", "--lon-deg", "0", "--frames", "4", "--size-px", "64", "-o",
                       tmp_path / "d")
    assert_refused(code, err, "-o/--output", "needs about 448.0 KiB", "4 frames of 64x64",
                   "fewer frames")
    assert list(tmp_path.iterdir()) == []


def test_windows_and_descents_larger_than_the_memory_are_refused_up_front(capsys, tmp_path,
                                                                          monkeypatch):
    # a 16384^2 window (55 GB) was killed by the OOM killer on a 25 GB machine
    import latlong.ondemand.window

    monkeypatch.setattr(latlong.ondemand.window, "physical_memory_bytes", lambda: 2e9)
    code, _, err = run(capsys, "latlong", "tile", "--preset", "fbm-cratered", "--radius-m",
                       "100000", "--lat-deg", "0", "--lon-deg", "0", "--size-m", "409.6",
                       "--pixel-m", "0.1", "-o", tmp_path / "t.tif")
    assert_refused(code, err, "--size-m", "4096 x 4096 pixels", "3.5 GiB of memory",
                   "1.9 GiB", "larger pixels")
    code, _, err = run(capsys, "latlong", "descent", "--preset", "fbm-cratered", "--lat-deg",
                       "0", "--lon-deg", "0", "--frames", "2", "--size-px", "2048", "-o",
                       tmp_path / "d")
    assert_refused(code, err, "--size-px", "2048 px frames over 3277 px of terrain",
                   "a smaller frame")
    assert list(tmp_path.iterdir()) == []


def _sparse_tif(path: Path, side: int) -> Path:
    """A ``side``-square float32 GeoTIFF of which one block holds data (a few kB on disk)."""
    import numpy as np
    import rasterio
    from affine import Affine

    with rasterio.open(path, "w", driver="GTiff", width=side, height=side, count=1,
                       dtype="float32", crs="EPSG:32633", tiled=True, blockxsize=256,
                       blockysize=256, sparse_ok=True, nodata=np.nan,
                       transform=Affine(1.0, 0, 500000.0, 0, -1.0, 4000000.0)) as ds:
        ds.write(np.zeros((256, 256), np.float32), 1, window=((0, 256), (0, 256)))
    return path


def test_a_raster_larger_than_the_memory_is_refused_before_reading(capsys, tmp_path,
                                                                    monkeypatch):
    # was numpy's "Unable to allocate 149. GiB for an array with shape (1, 200000, 200000)"
    import dem.budget

    tif = _sparse_tif(tmp_path / "big.tif", 10000)
    monkeypatch.setattr(dem.budget, "physical_memory_bytes", lambda: 1e9)
    for argv in (("info", tif), ("slopes", tif, "--csv", tmp_path / "s.csv")):
        code, _, err = run(capsys, "dem", *argv)
        assert_refused(code, err, "big.tif", "10000 x 10000 pixels", "1.5 GiB of memory",
                       "crop it first")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["big.tif"]


def test_a_fill_larger_than_the_free_disk_is_refused_up_front(capsys, tmp_path, monkeypatch):
    tif = _sparse_tif(tmp_path / "big.tif", 10000)
    _free_bytes(monkeypatch, 100_000_000)  # the filled DEM: 10^8 float32 pixels
    code, _, err = run(capsys, "dem", "fill", tif, "-o", tmp_path / "f.tif", "--seed", "1")
    assert_refused(code, err, "f.tif", "needs about 381.5 MiB", "10000 x 10000 pixels")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["big.tif"]


def test_the_expansion_size_is_refused_before_numba_and_scipy_load(tmp_path):
    # what keeps the refusal under a second (issue 34): numba (~0.3 s) and scipy.ndimage
    # (~0.25 s) load where they run, after the output's size is checked
    code = ("import sys\nfrom dem.__main__ import main\ntry:\n    main()\nexcept SystemExit:\n"
            "    pass\nprint([m for m in ('numba', 'scipy.ndimage') if m in sys.modules])")
    proc = subprocess.run([sys.executable, "-c", code, "expand", str(DATA / "ldem4_crop.lbl"),
                           "-o", str(tmp_path / "big.tif"), "--levels", "12", "--seed", "1"],
                          capture_output=True, text=True, cwd=tmp_path)
    assert "1048577 x 1048577" in proc.stderr, proc.stderr
    assert proc.stdout.strip() == "[]", proc.stdout
    assert list(tmp_path.iterdir()) == []


_LAYER = "c=0.08,k=-2,d_min_m=1,d_max_m=1000"


@pytest.mark.parametrize("argv", [
    ("latlong", "tile", "--preset", "fbm-cratered", "--lat-deg", "0", "--lon-deg", "0",
     "--size-m", "16384", "--pixel-m", "1", "-o", "big.tif"),
    ("latlong", "descent", "--preset", "fbm-cratered", "--lat-deg", "0", "--lon-deg", "0",
     "--size-px", "6000", "-o", "frames"),
    ("dem", "tile", str(DATA / "ldem4_crop.lbl"), "--craters", _LAYER, "--lat-deg", "0",
     "--lon-deg", "0", "--size-m", "16384", "--pixel-m", "1", "-o", "big.tif"),
    ("dem", "descent", str(DATA / "ldem4_crop.lbl"), "--craters", _LAYER, "--lat-deg", "0",
     "--lon-deg", "0", "--size-px", "6000", "-o", "frames"),
], ids=["latlong-tile", "latlong-descent", "dem-tile", "dem-descent"])
def test_windows_and_descents_are_refused_before_numba_loads(tmp_path, argv):
    # what keeps these refusals under a second (issue 34; 1.3-1.6 s when the command
    # modules loaded the terrain's kernels first): numba loads where the terrain is made
    package, *args = argv
    code = (f"import sys\nfrom {package}.__main__ import main\ntry:\n    main()\n"
            "except SystemExit:\n    pass\nprint('numba' in sys.modules)")
    proc = subprocess.run([sys.executable, "-c", code, *args], capture_output=True, text=True,
                          cwd=tmp_path)
    assert "of memory; this machine has" in proc.stderr, proc.stderr
    assert proc.stdout.strip() == "False", proc.stdout
    assert list(tmp_path.iterdir()) == []


def test_more_workers_than_the_machine_holds_are_refused(capsys, tmp_path):
    from latlong.parallel.backends import max_workers

    scene = tmp_path / "scene.toml"
    scene.write_text('base = "sphere"\nmagnitude = 8\n')
    code, _, err = run(capsys, "latlong", "batch", scene, "--seeds", "1-2", "-o",
                       tmp_path / "b", "--workers", "100000")
    assert_refused(code, err, "--workers", f"[1, {max_workers()}]", "100000")
    assert [p.name for p in tmp_path.iterdir()] == ["scene.toml"]
    assert 1 <= max_workers() <= 4 * (os.cpu_count() or 1)


# --------------------------------------------------------------- bounded inputs (item 3)
_ASCII_PLY = ("ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
              "property float z\nelement face 1\nproperty list uchar int vertex_indices\n"
              "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 {last}\n")
SENSOR = ["--target-lat-lon", "10,30", "--range-m", "150,25", "--frames", "1", "--fov-deg",
          "20"]


@pytest.mark.parametrize("last", ["99999999", "-5", "x"])
@pytest.mark.parametrize("sensor", ["camera", "lidar"])
def test_an_ascii_ply_with_bad_indices_is_refused_not_a_crash(capsys, tmp_path, last, sensor):
    # VTK's reader dies with SIGSEGV on an index past the vertices: ASCII PLYs are read here
    ply = tmp_path / "bad.ply"
    ply.write_text(_ASCII_PLY.format(last=last))
    extra = ["--size", "8x8", "--sun-direction", "1,0,0"] if sensor == "camera" else \
        ["--beams", "4x4"]
    code, _, err = run(capsys, "latlong", sensor, ply, "-o", tmp_path / "o", *SENSOR, *extra)
    assert_refused(code, err, "bad.ply")
    assert not (tmp_path / "o").exists()


def test_an_ascii_ply_of_polygons_reads_as_triangles(tmp_path):
    from latlong.meshio.readers import read_mesh

    quad = tmp_path / "quad.ply"
    quad.write_text(_ASCII_PLY.replace("vertex 3", "vertex 4").replace(
        "3 0 1 {last}", "0 1 1\n4 0 1 2 3"))
    mesh = read_mesh(quad, units="m")
    assert mesh.faces.tolist() == [[0, 1, 2], [0, 2, 3]] and mesh.vertices.shape == (4, 3)


def test_a_csv_field_over_128_kib_is_one_line(capsys, tmp_path):
    poses = tmp_path / "poses.csv"
    poses.write_text("time_s,x_m\n1," + "x" * 200_000 + "\n")
    code, _, err = run(capsys, "latlong", *BUILD, "-o", tmp_path / "b.npz")
    assert code == 0, err
    code, _, err = run(capsys, "latlong", "camera", tmp_path / "b.npz", "-o", tmp_path / "c",
                       "--poses", poses, "--size", "8x8", "--fov-deg", "20",
                       "--sun-direction", "1,0,0")
    assert_refused(code, err, "poses.csv", "field larger than field limit")
    from craters.catalog import read_catalog

    with pytest.raises(ValueError, match="field larger than field limit"):
        read_catalog(poses)


def test_a_frame_larger_than_memory_and_a_camera_far_away_are_refused(capsys, tmp_path,
                                                                       monkeypatch):
    from latlong.sensors import camera_files

    monkeypatch.setattr(camera_files, "physical_memory_bytes", lambda: 24 * 2**30)
    code, _, err = run(capsys, "latlong", *BUILD, "-o", tmp_path / "b.npz")
    assert code == 0, err
    start = time.perf_counter()
    code, _, err = run(capsys, "latlong", "camera", tmp_path / "b.npz", "-o", tmp_path / "c",
                       *SENSOR, "--size", "16384x16384", "--sun-direction", "1,0,0")
    assert_refused(code, err, "--size 16384x16384", "of memory", "smaller frame")
    assert time.perf_counter() - start < 5
    code, _, err = run(capsys, "latlong", "camera", tmp_path / "b.npz", "-o", tmp_path / "c",
                       "--target-lat-lon", "10,30", "--range-m", "1e20,1e19", "--frames", "1",
                       "--fov-deg", "20", "--size", "8x8", "--sun-direction", "1,0,0")
    assert_refused(code, err, "--range-m", "1e+20 m from the model", "times its")
    assert not (tmp_path / "c").exists()


def test_a_silent_scheduler_fails_within_the_timeout(tmp_path):
    import socket

    import latlong

    scene = tmp_path / "scene.toml"
    scene.write_text('base = "sphere"\nmagnitude = 8\n')
    with socket.socket() as silent:  # accepts connections, never speaks
        silent.bind(("127.0.0.1", 0))
        silent.listen(4)
        address = f"tcp://127.0.0.1:{silent.getsockname()[1]}"
        start = time.perf_counter()
        with pytest.raises(ValueError, match="no dask scheduler answered within 1 s"):
            latlong.batch(scene, "1", out=tmp_path / "b", scheduler=address,
                          connect_timeout_s=1)
        assert time.perf_counter() - start < 5


def _silent_commands(tmp_path):
    """Every command that takes --scheduler, with its other arguments."""
    scene = tmp_path / "scene.toml"
    scene.write_text('base = "sphere"\nmagnitude = 8\n')
    tif = tiny_tif(tmp_path / "tiny.tif")
    config = tmp_path / "site.toml"
    config.write_text(f'input = "{tif}"\nlayers = 2\nsize = 17\n')
    return {
        "latlong build": ["latlong", *BUILD, "--on-demand", "-o", tmp_path / "b.npz"],
        "latlong batch": ["latlong", "batch", scene, "--seeds", "1", "-o", tmp_path / "lb"],
        "dem expand": ["dem", "expand", tif, "-o", tmp_path / "e.tif"],
        "dem batch": ["dem", "batch", config, "--seeds", "1", "-o", tmp_path / "db"],
    }


@pytest.mark.parametrize("command", ["latlong build", "latlong batch", "dem expand",
                                     "dem batch"])
def test_connect_timeout_bounds_every_command_with_a_scheduler(capsys, tmp_path, command):
    import socket

    argv = _silent_commands(tmp_path)[command]
    with socket.socket() as silent:  # accepts connections, never speaks
        silent.bind(("127.0.0.1", 0))
        silent.listen(4)
        address = f"tcp://127.0.0.1:{silent.getsockname()[1]}"
        code, _, err = run(capsys, *argv, "--scheduler", address, "--connect-timeout-s", "0.5")
    assert code == 2 and err.count("\n") == 1, err
    # the probe's socket timed out at the given 0.5 s (tests do not time wall clocks)
    assert "no dask scheduler answered within 0.5 s (no answer)" in err, err
    assert not [p for p in tmp_path.iterdir() if p.suffix not in (".toml", ".tif")]
    # out of range: refused before anything runs
    code, _, err = run(capsys, *argv, "--scheduler", address, "--connect-timeout-s", "0")
    assert code == 2 and "--connect-timeout-s" in err and "[0.1, 3600]" in err, err


def test_force_replaces_a_camera_run_whole_and_keeps_the_users_files(capsys, tmp_path):
    code, _, err = run(capsys, "latlong", *BUILD, "-o", tmp_path / "b.npz")
    assert code == 0, err
    cam = ["camera", tmp_path / "b.npz", "-o", tmp_path / "c", "--target-lat-lon", "10,30",
           "--fov-deg", "20", "--size", "8x8", "--sun-direction", "1,0,0"]
    code, _, err = run(capsys, "latlong", *cam, "--range-m", "900,800", "--frames", "3")
    assert code == 0, err
    (tmp_path / "c" / "notes.txt").write_text("mine")
    code, _, err = run(capsys, "latlong", *cam, "--range-m", "700,600", "--frames", "1",
                       "--force")
    assert code == 0, err
    names = sorted(p.name for p in (tmp_path / "c").iterdir())
    assert "notes.txt" in names and not [n for n in names if "_0001" in n or "_0002" in n]
    assert len(json.loads((tmp_path / "c" / "frames.json").read_text())["frames"]) == 1
    assert (tmp_path / "c" / "notes.txt").read_text() == "mine"
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]
