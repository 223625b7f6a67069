"""Issue 19 item 4 (and item 9's PDS pointer): no command clobbers or modifies an input,
writes a file it did not check, leaves half a run behind or temporaries of a killed run.

Each case: exit 2 with one ``error:`` line naming the flag, nothing written (the folder
unchanged), inputs byte-identical, no temporaries left.
"""

from __future__ import annotations

import errno
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
import rasterio
from affine import Affine

DATA = Path(__file__).parent / "data"


def snapshot(folder: Path) -> dict:
    """Every file below ``folder`` (hidden ones included) -> its bytes (links: target)."""
    out = {}
    for p in sorted(folder.rglob("*")):
        rel = str(p.relative_to(folder))
        if p.is_symlink():
            out[rel] = ("link", os.readlink(p))
        elif p.is_file():
            out[rel] = p.read_bytes()
        else:
            out[rel] = "dir"
    return out


def run(capsys, prog: str, *argv):
    """``prog``'s ``main(argv)`` in this process: (exit code, stdout, stderr)."""
    if prog == "latlong":
        from latlong.cli import main
    elif prog == "dem":
        from dem.cli import main
    else:
        from craters.cli import main
    try:
        code = main([str(a) for a in argv])
    except SystemExit as exc:
        code = exc.code
    out, err = capsys.readouterr()
    return code, out, err


def assert_refused(code, err, *needles):
    assert code == 2, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error:"), err
    assert "Traceback" not in err
    for needle in needles:
        assert needle in lines[0], lines[0]


def temporaries(folder: Path) -> list[str]:
    return [p.name for p in folder.rglob(".*")]


def small_obj(path: Path) -> Path:
    """An octahedron of radius 500 m as OBJ."""
    v = [(500, 0, 0), (-500, 0, 0), (0, 500, 0), (0, -500, 0), (0, 0, 500), (0, 0, -500)]
    f = [(1, 3, 5), (3, 2, 5), (2, 4, 5), (4, 1, 5), (3, 1, 6), (2, 3, 6), (4, 2, 6), (1, 4, 6)]
    path.write_text("".join(f"v {a} {b} {c}\n" for a, b, c in v)
                    + "".join(f"f {a} {b} {c}\n" for a, b, c in f))
    return path


def tiny_tif(path: Path) -> Path:
    z = np.add.outer(np.arange(33.0), 2 * np.arange(33.0)).astype(np.float32)
    with rasterio.open(path, "w", driver="GTiff", width=33, height=33, count=1,
                       dtype="float32", crs="EPSG:32633",
                       transform=Affine(10.0, 0, 500000.0, 0, -10.0, 4000000.0)) as ds:
        ds.write(z, 1)
    return path


BUILD = ["build", "--magnitude", "8", "--seed", "1", "-q", "--base", "sphere"]


# --------------------------------------------------------------- companions, inputs
@pytest.mark.parametrize("companion", ["o.json", "o.lod0.bin"])
@pytest.mark.parametrize("kind", ["file", "symlink"])
def test_glb_companion_is_checked_up_front(capsys, tmp_path, companion, kind):
    mine = tmp_path / "mine.txt"
    mine.write_text("MINE\n")
    if kind == "file":
        shutil.copy(mine, tmp_path / companion)
    else:
        (tmp_path / companion).symlink_to(mine)
    before = snapshot(tmp_path)
    code, _, err = run(capsys, "latlong", *BUILD, "-o", tmp_path / "o.glb")
    assert_refused(code, err, "--output", companion, "--force")
    assert snapshot(tmp_path) == before


@pytest.mark.parametrize("kind", ["file", "symlink"])
def test_glb_companion_replaced_with_force(capsys, tmp_path, kind):
    """With --force the companion is replaced; a symlink is replaced, never followed."""
    mine = tmp_path / "mine.txt"
    mine.write_text("MINE\n")
    if kind == "file":
        shutil.copy(mine, tmp_path / "o.json")
    else:
        (tmp_path / "o.json").symlink_to(mine)
    code, _, err = run(capsys, "latlong", *BUILD, "-o", tmp_path / "o.glb", "--force")
    assert code == 0, err
    assert not (tmp_path / "o.json").is_symlink()
    assert (tmp_path / "o.json").read_text().startswith("{")
    assert mine.read_text() == "MINE\n"
    assert temporaries(tmp_path) == []


def _shape_argv(tmp_path, how):
    model = tmp_path / "m.obj"
    given = {"plain": model, "dotdot": tmp_path / "sub" / ".." / "m.obj",
             "symlink": tmp_path / "link.obj"}[how]
    if how == "dotdot":
        (tmp_path / "sub").mkdir()
    if how == "symlink":
        given.symlink_to(model)
    return given


@pytest.mark.parametrize("how", ["plain", "dotdot", "symlink"])
@pytest.mark.parametrize("backend", ["shape", "implicit"])
def test_build_never_overwrites_its_shape_model(capsys, tmp_path, how, backend):
    small_obj(tmp_path / "m.obj")
    given = _shape_argv(tmp_path, how)
    if backend == "shape":
        argv = ["build", "--magnitude", "8", "--seed", "1", "-q", "--base", f"shape:{given}",
                "--shape-units", "m"]
    else:
        argv = ["build", "--backend", "implicit", "--shape", given, "--shape-units", "m",
                "--seed", "1", "-q"]
    before = snapshot(tmp_path)
    code, _, err = run(capsys, "latlong", *argv, "-o", tmp_path / "m.obj", "--force")
    assert_refused(code, err, "--output", "input")
    assert snapshot(tmp_path) == before


@pytest.mark.parametrize("command", ["slopes", "spectrum"])
def test_dem_report_never_overwrites_its_input(capsys, tmp_path, command):
    """A GeoTIFF named .csv (GDAL reads by content) given as the input and as --csv."""
    (tmp_path / "sub").mkdir()
    tif = tiny_tif(tmp_path / "in.csv")
    before = snapshot(tmp_path)
    code, _, err = run(capsys, "dem", command, tif, "--csv", tmp_path / "sub" / ".." / "in.csv",
                       "--force", "-q")
    assert_refused(code, err, "--csv", "input")
    assert snapshot(tmp_path) == before


@pytest.mark.parametrize("how", ["plain", "symlink"])
def test_dem_fill_refuses_output_equal_input(capsys, tmp_path, how):
    tif = tiny_tif(tmp_path / "in.tif")
    out = tif
    if how == "symlink":
        out = tmp_path / "link.tif"
        out.symlink_to(tif)
    before = snapshot(tmp_path)
    code, _, err = run(capsys, "dem", "fill", tif, "-o", out, "--force", "-q")
    assert_refused(code, err, "-o/--output", "input")
    assert snapshot(tmp_path) == before


# --------------------------------------------------------------- stack folders
ENHANCE = ["enhance", "--layers", "2", "--size", "17", "--seed", "1", "-q"]


@pytest.fixture
def site(capsys, tmp_path):
    tif = tiny_tif(tmp_path / "tiny.tif")
    code, _, err = run(capsys, "dem", *ENHANCE, tif, "-o", tmp_path / "site")
    assert code == 0, err
    return tmp_path / "site"


def test_enhance_refuses_an_input_inside_the_replaced_folder(capsys, tmp_path, site):
    before = snapshot(tmp_path)
    code, _, err = run(capsys, "dem", *ENHANCE, site / "layer_00.tif", "-o", site, "--force")
    assert_refused(code, err, "-o/--output", "layer_00.tif")
    assert snapshot(tmp_path) == before


def test_enhance_refuses_a_config_inside_the_replaced_folder(capsys, tmp_path, site):
    shutil.copy(site / "manifest.json", tmp_path / "keep.json")
    scene = tmp_path / "scene.toml"
    scene.write_text(f'input = "{tmp_path / "tiny.tif"}"\n')
    moved = site / "scene.toml"
    shutil.move(scene, moved)
    before = snapshot(tmp_path)
    code, _, err = run(capsys, "dem", *ENHANCE, "--config", moved, "-o", site, "--force")
    assert_refused(code, err, "-o/--output")
    assert snapshot(tmp_path) == before


@pytest.mark.parametrize("name", ["notes.txt", "layer_00.tif.bak", "sub"])
def test_enhance_refuses_to_replace_files_a_stack_did_not_write(capsys, tmp_path, site, name):
    if name == "sub":
        (site / name).mkdir()
    else:
        (site / name).write_text("mine\n")
    before = snapshot(tmp_path)
    code, _, err = run(capsys, "dem", *ENHANCE, tmp_path / "tiny.tif", "-o", site, "--force")
    assert_refused(code, err, "-o/--output", name)
    assert snapshot(tmp_path) == before


def test_enhance_replaces_its_own_stack_with_force(capsys, tmp_path, site):
    code, _, err = run(capsys, "dem", *ENHANCE, tmp_path / "tiny.tif", "-o", site, "--force",
                       "--seed", "2")
    assert code == 0, err
    assert temporaries(tmp_path) == []


@pytest.mark.parametrize("command", ["camera", "lidar"])
@pytest.mark.parametrize("which", ["model", "poses"])
def test_sensor_output_folder_never_holds_an_input(capsys, tmp_path, command, which):
    out = tmp_path / "out"
    out.mkdir()
    model = (out if which == "model" else tmp_path) / "m.npz"
    model.write_bytes(b"model")
    poses = (out if which == "poses" else tmp_path) / "poses.csv"
    poses.write_text("mine\n")
    argv = [command, model, "-o", out, "--force", "--poses", poses]
    if command == "camera":
        argv += ["--size", "8x8", "--sun-direction", "1,0,0"]
    before = snapshot(tmp_path)
    code, _, err = run(capsys, "latlong", *argv)
    assert_refused(code, err, "-o/--output", which)
    assert snapshot(tmp_path) == before


# --------------------------------------------------------------- a failed run writes nothing
def _enospc(*args, **kwargs):
    raise OSError(errno.ENOSPC, "No space left on device")


@pytest.mark.parametrize("later", ["second -o", "--preview", "--catalog"])
@pytest.mark.parametrize("existing", [False, True])
def test_a_failed_later_output_takes_back_the_earlier_ones(capsys, tmp_path, monkeypatch,
                                                           later, existing):
    import craters
    import latlong.outputs

    argv = ["build", "--magnitude", "8", "--seed", "1", "-q", "--craters",
            "c=0.05,k=-2,d_min_m=5,d_max_m=10", "-o", tmp_path / "a.npz", "-o", tmp_path / "a.glb"]
    if later == "second -o":
        import latlong.gltf
        monkeypatch.setattr(latlong.gltf, "_finish", _enospc)
    elif later == "--preview":
        argv += ["--preview", tmp_path / "a.png"]
        monkeypatch.setattr(latlong.outputs, "render_preview", _enospc)
    else:
        argv += ["--catalog", tmp_path / "a.csv"]
        monkeypatch.setattr(craters, "write_catalog", _enospc)
    if existing:  # an earlier run's outputs, replaced with --force: restored on failure
        for name in ("a.npz", "a.glb", "a.json"):
            (tmp_path / name).write_text(f"old {name}\n")
        argv.append("--force")
    before = snapshot(tmp_path)
    code, _, err = run(capsys, "latlong", *argv)
    assert_refused(code, err, "No space left")
    assert snapshot(tmp_path) == before


@pytest.mark.parametrize("prog", ["dem", "latlong"])
def test_a_failed_plot_takes_back_the_csv(capsys, tmp_path, monkeypatch, prog):
    """A --plot that cannot be written (disk full): the --csv of the same run is taken
    back."""
    import matplotlib.figure

    if prog == "dem":
        tif = tiny_tif(tmp_path / "in.tif")
    else:
        code, _, err = run(capsys, "latlong", *BUILD, "-o", tmp_path / "in.npz")
        assert code == 0, err
        tif = tmp_path / "in.npz"
    before = snapshot(tmp_path)
    monkeypatch.setattr(matplotlib.figure.Figure, "savefig", _enospc)
    code, _, err = run(capsys, prog, "slopes", tif, "--csv", tmp_path / "s.csv", "--plot",
                       tmp_path / "s.png", "-q")
    assert_refused(code, err, "No space left")
    assert snapshot(tmp_path) == before


@pytest.mark.parametrize("what", ["file", "folder"])
@pytest.mark.parametrize("existing", [False, True])
def test_output_group_takes_back_files_and_folders(tmp_path, what, existing):
    from craters._shared import output_group, replace_output, temp_file, temp_folder

    target = tmp_path / "out"
    if existing:
        if what == "file":
            target.write_text("old")
        else:
            target.mkdir()
            (target / "a").write_text("old")
    before = snapshot(tmp_path)
    with pytest.raises(KeyboardInterrupt), output_group():
        with output_group():  # nested: handed to the outer group on success
            if what == "file":
                tmp = temp_file(target)
                tmp.write_text("new")
            else:
                tmp = temp_folder(target)
                (tmp / "b").write_text("new")
            replace_output(tmp, target)
        # staged: nothing moves before the outermost group (the run) ends
        assert snapshot(tmp_path).keys() - before.keys() and all(
            snapshot(tmp_path)[k] == v for k, v in before.items())
        raise KeyboardInterrupt
    assert snapshot(tmp_path) == before
    with output_group():  # success: the new output stays, no backup left
        tmp = temp_file(tmp_path / "x")
        replace_output(tmp, target if what == "file" else tmp_path / "x")
    assert temporaries(tmp_path) == []


# --------------------------------------------------------------- temporaries of killed runs
def test_temporaries_of_a_killed_run_are_swept(capsys, tmp_path):
    from craters._shared import temp_file

    # a dead process's temporaries (its pid is free), a live one's, and look-alikes
    dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"],
                          capture_output=True, text=True, check=True)
    pid = int(dead.stdout)
    stale = [tmp_path / f".o.glb.{pid}.abcd_123.tmp.glb",
             tmp_path / f".o.glb.{pid}.zz99zz99.tmp.lod0.bin"]
    for p in stale:
        p.write_bytes(b"x" * 100)
    (tmp_path / f".site.{pid}.qwertyui.tmp").mkdir()
    (tmp_path / f".site.{pid}.qwertyui.tmp" / "layer_00.tif").write_bytes(b"x")
    live = temp_file(tmp_path / "other.glb", ".glb")  # this process's: kept
    old_live = tmp_path / f".x.{os.getppid()}.abcdefgh.tmp"  # a live process: kept
    old_live.write_bytes(b"x")
    user = [tmp_path / ".o.glb.1234.tmp", tmp_path / "notes.tmp", tmp_path / ".hidden",
            tmp_path / f"o.glb.{pid}.abcdefgh.tmp"]
    for p in user:
        p.write_bytes(b"mine")
    code, _, err = run(capsys, "latlong", *BUILD, "-o", tmp_path / "o.npz")
    assert code == 0, err
    left = sorted(p.name for p in tmp_path.iterdir())
    assert sorted([live.name, old_live.name, "o.npz", *(p.name for p in user)]) == left


def test_sweep_removes_week_old_temporaries_of_live_pids(tmp_path):
    from craters._shared import sweep_temporaries

    p = tmp_path / f".x.{os.getppid()}.abcdefgh.tmp.npz"
    p.write_bytes(b"x")
    old = time.time() - 8 * 24 * 3600
    os.utime(p, (old, old))
    assert sweep_temporaries(tmp_path, now=time.time()) == [p]


# --------------------------------------------------------------- kills
_SLOW_EXPORT = r"""
import signal, sys, time
# Python keeps SIGINT ignored when its parent ignored it (a pytest-xdist worker may):
# take Ctrl-C as a user's shell delivers it
signal.signal(signal.SIGINT, signal.default_int_handler)
import latlong.gltf as g
real = g._write_level_data
def slow(*a, **k):
    print("writing", flush=True)
    time.sleep(60)
    return real(*a, **k)
g._write_level_data = slow
from latlong.cli import main
sys.exit(main(sys.argv[1:]))
"""

_KILL_BETWEEN = r"""
import os, signal, sys
real = os.replace
def replace(src, dst):
    real(src, dst)
    if str(dst).endswith(".glb"):  # the .glb is in place, its .json not yet
        os.kill(os.getpid(), signal.SIGTERM)
os.replace = replace
from latlong.cli import main
sys.exit(main(sys.argv[1:]))
"""


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGINT])
def test_a_signal_cleans_temporaries_and_keeps_the_old_pair(tmp_path, sig):
    old = {"o.glb": b"old glb", "o.json": b"old json"}
    for name, data in old.items():
        (tmp_path / name).write_bytes(data)
    proc = subprocess.Popen([sys.executable, "-c", _SLOW_EXPORT, *BUILD, "-o",
                             str(tmp_path / "o.glb"), "--force"], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)
    assert proc.stdout.readline().strip() == "writing"
    proc.send_signal(sig)
    out, err = proc.communicate(timeout=60)
    assert proc.returncode == (143 if sig == signal.SIGTERM else 130), err
    assert len(err.strip().splitlines()) == 1 and err.startswith("error:"), err
    assert snapshot(tmp_path) == old


def test_a_kill_between_the_renames_keeps_the_old_pair(tmp_path):
    old = {"o.glb": b"old glb", "o.json": b"old json"}
    for name, data in old.items():
        (tmp_path / name).write_bytes(data)
    proc = subprocess.run([sys.executable, "-c", _KILL_BETWEEN, *BUILD, "-o",
                           str(tmp_path / "o.glb"), "--force"], capture_output=True, text=True,
                          timeout=300)
    assert proc.returncode == 143, proc.stderr
    assert snapshot(tmp_path) == old


def test_the_new_pair_is_complete(capsys, tmp_path):
    for name in ("o.glb", "o.json"):
        (tmp_path / name).write_bytes(b"old")
    code, _, err = run(capsys, "latlong", *BUILD, "-o", tmp_path / "o.glb", "--force")
    assert code == 0, err
    import json

    man = json.loads((tmp_path / "o.json").read_text())
    assert man["glb"] == "o.glb" and (tmp_path / "o.glb").read_bytes()[:4] == b"glTF"
    assert temporaries(tmp_path) == []


# --------------------------------------------------------------- PDS ^IMAGE pointer
@pytest.mark.parametrize("pointer", ['"../secret.img"', '"/etc/passwd"', '("../secret.img", 1)',
                                     '"sub/../../secret.img"', '"LINK.IMG"'])
def test_pds_pointer_outside_the_label_folder_is_refused(capsys, tmp_path, pointer):
    folder = tmp_path / "pds"
    folder.mkdir()
    shutil.copy(DATA / "ldem4_crop.img", tmp_path / "secret.img")
    (folder / "sub").mkdir()
    (folder / "LINK.IMG").symlink_to(tmp_path / "secret.img")
    text = (DATA / "ldem4_crop.lbl").read_text(encoding="latin-1")
    label = folder / "x.lbl"
    label.write_text(text.replace('"LDEM4_CROP.IMG"', pointer), encoding="latin-1")
    before = snapshot(tmp_path)
    code, out, err = run(capsys, "dem", "info", label)
    assert_refused(code, err, "pointer", "x.lbl")
    assert snapshot(tmp_path) == before


def test_pds_pointer_below_the_label_folder_is_read(tmp_path):
    import dem

    folder = tmp_path / "pds"
    (folder / "data").mkdir(parents=True)
    shutil.copy(DATA / "ldem4_crop.img", folder / "data" / "LDEM4_CROP.IMG")
    text = (DATA / "ldem4_crop.lbl").read_text(encoding="latin-1")
    label = folder / "x.lbl"
    label.write_text(text.replace('"LDEM4_CROP.IMG"', '"data/LDEM4_CROP.IMG"'),
                     encoding="latin-1")
    assert np.array_equal(dem.read(label).heights, dem.read(DATA / "ldem4_crop.lbl").heights,
                          equal_nan=True)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(pytest.main([__file__, "-q"]))


@pytest.mark.parametrize("umask, file_mode, folder_mode", [(0o022, 0o644, 0o755),
                                                           (0o027, 0o640, 0o750),
                                                           (0o002, 0o664, 0o775)])
def test_outputs_take_the_umasks_modes(tmp_path, umask, file_mode, folder_mode):
    """Outputs get the modes open/mkdir would give them under the umask (a web server or a
    colleague reads them as the user's other files), not the temporaries' private 0600."""
    code = (f"import os, stat; os.umask({umask}); "
            "from craters._shared import atomic_path, temp_folder; "
            f"p = {str(tmp_path / 'a.txt')!r}\n"
            "with atomic_path(p) as t: t.write_text('x')\n"
            f"f = temp_folder({str(tmp_path / 'run')!r})\n"
            "print(oct(stat.S_IMODE(os.stat(p).st_mode)), oct(stat.S_IMODE(os.stat(f).st_mode)))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout.split()
    assert out == [oct(file_mode), oct(folder_mode)]
