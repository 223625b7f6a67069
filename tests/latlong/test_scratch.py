"""Radii on disk (issue 18, bodies bigger than memory): a memory-mapped, unlinked scratch
file whose resident pages are dropped in the background; the build with it gives the
in-memory build's bytes."""

from __future__ import annotations

import hashlib
import os
import threading
import time

import numba
import numpy as np
import pytest

from latlong import BodySettings, FbmParams, Scene, build
from latlong.scratch import disk_radii, is_on_disk
from latlong.settings import SphereBase, check_memory


def test_disk_radii_hold_their_values_and_leave_no_file(tmp_path):
    a = disk_radii(100_000, tmp_path, trim_interval_s=0.001)
    assert is_on_disk(a) and is_on_disk(a[10:]) and not is_on_disk(np.zeros(3))
    assert a.flags.writeable and a.dtype == np.float64 and a.shape == (100_000,)
    assert os.listdir(tmp_path) == []  # unlinked as soon as mapped
    ref = np.random.default_rng(0).normal(size=100_000)
    stop = time.monotonic() + 0.3
    while time.monotonic() < stop:  # written while the trimmer drops the pages
        a[:] = ref
        a *= 2.0
        a /= 2.0
    time.sleep(0.05)
    np.testing.assert_array_equal(a, ref)


def _rss_file_kb() -> int:
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith("RssFile:"):
                return int(line.split()[1])
    raise LookupError


@pytest.mark.skipif(not os.path.exists("/proc/self/status"), reason="needs Linux /proc")
def test_resident_pages_are_dropped(tmp_path):
    try:
        _rss_file_kb()
    except LookupError:
        pytest.skip("no RssFile in /proc/self/status")
    n = 16 << 20  # 128 MiB
    a = disk_radii(n, tmp_path, trim_interval_s=3600.0)  # no trim: the pages stay mapped
    before = _rss_file_kb()
    a[:] = 1.0
    assert _rss_file_kb() - before > 100_000
    b = disk_radii(n, tmp_path, trim_interval_s=0.02)
    before = _rss_file_kb()
    b[:] = 1.0
    time.sleep(0.3)
    assert _rss_file_kb() - before < 20_000
    assert float(b.sum()) == n


def test_disk_radii_errors(tmp_path):
    with pytest.raises(ValueError, match="`scratch_dir`"):
        disk_radii(10, tmp_path / "missing")
    with pytest.raises(ValueError, match="`n_vertices`"):
        disk_radii(0, tmp_path)


def test_trimmer_stops_with_the_array(tmp_path):
    a = disk_radii(1000, tmp_path, trim_interval_s=0.01)
    names = {t.name for t in threading.enumerate()}
    assert "craterform-radii-trim" in names
    del a
    deadline = time.monotonic() + 10.0  # a loaded machine may run the thread late
    while (alive := [t for t in threading.enumerate() if t.name == "craterform-radii-trim"]) \
            and time.monotonic() < deadline:
        time.sleep(0.01)
    assert not alive


def _digest(body) -> str:
    h = hashlib.sha256(np.ascontiguousarray(body.radii_m).tobytes())
    for name in body.craters.dtype.names:
        h.update(np.ascontiguousarray(body.craters[name]).tobytes())
    return h.hexdigest()


@pytest.mark.parametrize("threads", [1, 2])
@pytest.mark.parametrize("preset", ["fbm-cratered", "sphere"])
def test_build_on_disk_gives_the_same_bytes(tmp_path, threads, preset):
    if threads > numba.config.NUMBA_NUM_THREADS:
        pytest.skip("fewer threads here")
    # craters from 3 m (~4 300 on this body): from the preset's 1 m, ~40 000 mostly below
    # the 5 m mesh took 31 s of CI per case
    craters = ["c=0.5,k=-2,d_min_m=3,d_max_m=15"]
    settings = {"preset": "fbm-cratered", "magnitude": 48, "seed": 4, "radius_m": 80.0,
                "craters": craters}
    if preset == "sphere":
        settings = {"base": "sphere", "magnitude": 48, "seed": 4, "radius_m": 80.0,
                    "craters": craters}
    old = numba.get_num_threads()
    numba.set_num_threads(threads)
    try:
        ref = build(Scene.from_settings({**settings, "radii_on_disk": "no"}))
        scene = Scene.from_settings({**settings, "radii_on_disk": "yes"})
        assert scene.radii_on_disk()
        disk = build(scene, scratch_dir=tmp_path)
    finally:
        numba.set_num_threads(old)
    assert is_on_disk(disk.radii_m) and not is_on_disk(ref.radii_m)
    assert len(ref.craters) > 50
    assert _digest(disk) == _digest(ref) and disk.metadata == ref.metadata
    assert os.listdir(tmp_path) == []


def test_auto_goes_on_disk_only_when_memory_is_short():
    small = Scene(BodySettings(magnitude=2000, max_memory_gb=0.8), FbmParams())
    assert small.radii_on_disk()  # 24 M vertices: 0.86 GB in memory, 0.67 GB on disk
    assert not Scene(BodySettings(magnitude=2000, max_memory_gb=100.0),
                     FbmParams()).radii_on_disk()
    assert Scene(BodySettings(magnitude=16, radii_on_disk="yes"), SphereBase()).radii_on_disk()
    with pytest.raises(ValueError, match="`magnitude` 2000 needs about .* GB of memory \\("):
        check_memory(2000, 0.8, radii_on_disk="no")
    with pytest.raises(ValueError, match="`magnitude` 2000 needs about .* GB of memory \\("):
        check_memory(2000, 0.8, radii_on_disk="auto", disk_ok=False)
    assert check_memory(2000, 0.8, radii_on_disk="auto")
    with pytest.raises(ValueError, match="with the radii on disk"):
        check_memory(20_000, 1.0)
    with pytest.raises(ValueError, match="`radii_on_disk` = yes needs a sphere or fbm base"):
        check_memory(16, radii_on_disk="yes", disk_ok=False)
    with pytest.raises(ValueError, match="`radii_on_disk`"):
        BodySettings(magnitude=16, radii_on_disk="maybe")
    # faulting and shape bases make their own arrays: refused, never put on disk
    with pytest.raises(ValueError, match="`magnitude` 2000 needs about"):
        Scene.from_settings({"preset": "paper", "magnitude": 2000, "max_memory_gb": 0.8})
    with pytest.raises(ValueError, match="`radii_on_disk` = yes needs"):
        Scene.from_settings({"preset": "paper", "magnitude": 20, "radii_on_disk": "yes"})


def test_cli_builds_on_disk_with_the_same_bytes(run_cli, tmp_path, one_line_error):
    common = ("latlong", "build", "--preset", "fbm-cratered", "--magnitude", "40", "--seed",
              "2", "-q")
    for mode in ("no", "yes"):
        d = tmp_path / mode
        d.mkdir()
        proc = run_cli(*common, "--radii-on-disk", mode, "-o", str(d / "b.ply"),
                       "-o", str(d / "b.glb"))
        assert proc.returncode == 0, proc.stderr
        assert sorted(os.listdir(d)) == ["b.glb", "b.json", "b.ply"]
    for name in ("b.ply", "b.glb"):
        assert (tmp_path / "no" / name).read_bytes() == (tmp_path / "yes" / name).read_bytes()
    proc = run_cli(*common, "--radii-on-disk", "maybe", "-o", str(tmp_path / "c.ply"))
    one_line_error(proc, "--radii-on-disk", "auto", "yes", "no")
    assert not (tmp_path / "c.ply").exists()


def test_dropping_pages_keeps_the_values():
    from latlong.scratch import disk_radii, drop_pages

    a = disk_radii(300_000, trim_interval_s=3600.0)
    a[:] = np.arange(300_000) * 0.5
    drop_pages(a, 1000, 250_000)  # pages leave memory, the file keeps the data
    drop_pages(a, 5, 5)  # an empty range: nothing
    assert np.array_equal(a, np.arange(300_000) * 0.5)
    b = np.ones(10)
    drop_pages(b, 0, 10)  # not on disk: untouched
    assert (b == 1).all()
