"""Bad inputs found by fuzzing (issue 19, items 5 and 6): each one is refused with one
``error:`` line naming the flag (or the file) and the rule, exit code 2, no traceback,
nothing written and the inputs unchanged; a crash, hang or silent garbage before.

The commands run in-process through each CLI's ``main``; a subprocess only where a
segfault, a signal or the start-up of the console script is the point.
"""

from __future__ import annotations

import os
import signal
import struct
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

DATA = Path(__file__).parent / "data"
TETRA_V = [[1, 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1]]
TETRA_F = [[0, 1, 2], [0, 3, 1], [0, 2, 3], [1, 3, 2]]
PLY_HEAD = ("ply\nformat binary_little_endian 1.0\nelement vertex {nv}\nproperty float x\n"
            "property float y\nproperty float z\nelement face {nf}\n"
            "property list uchar int vertex_indices\nend_header\n")


# --------------------------------------------------------------------------- inputs
def huge_ply(tmp: Path) -> None:
    """A header declaring 99 999 999 vertices over 3 kB of data (a VTK segfault)."""
    (tmp / "huge.ply").write_bytes(PLY_HEAD.format(nv=99_999_999, nf=10).encode()
                                   + bytes(3000))


def bad_index_ply(tmp: Path) -> None:
    body = np.array(TETRA_V, np.float32).tobytes() + b"".join(
        struct.pack("<Biii", 3, *f) for f in [*TETRA_F[:3], [1, 3, 50]])
    (tmp / "badidx.ply").write_bytes(PLY_HEAD.format(nv=4, nf=4).encode() + body)


def big_index_obj(tmp: Path) -> None:
    lines = [f"v {x} {y} {z}" for x, y, z in TETRA_V]
    lines += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in TETRA_F[:3]] + ["f 2 4 " + "1" * 24]
    (tmp / "bigidx.obj").write_text("\n".join(lines) + "\n")


def overflow_plate(tmp: Path) -> None:
    lines = ["1e400 4"] + [f"{i + 1} {x} {y} {z}" for i, (x, y, z) in enumerate(TETRA_V)]
    lines += [f"{i + 1} {a + 1} {b + 1} {c + 1}" for i, (a, b, c) in enumerate(TETRA_F)]
    (tmp / "plate.tab").write_text("\n".join(lines) + "\n")


def tiny_obj(tmp: Path) -> None:
    """Coordinates of ~1e-300 m (a ZeroDivisionError before)."""
    lines = [f"v {x * 1e-300!r} {y * 1e-300!r} {z * 1e-300!r}" for x, y, z in TETRA_V]
    lines += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in TETRA_F]
    (tmp / "tiny.obj").write_text("\n".join(lines) + "\n")


def body_npz(tmp: Path, name: str, change) -> None:
    from latlong import Body, LatLongGrid

    Body.sphere(LatLongGrid(4), 10.0).save(tmp / "ok.npz")
    with np.load(tmp / "ok.npz") as z:
        fields = {k: z[k] for k in z.files}
    (tmp / "ok.npz").unlink()
    change(fields)
    np.savez(tmp / name, **fields)


def no_magnitude(tmp: Path) -> None:
    body_npz(tmp, "nomag.npz", lambda f: f.pop("magnitude"))


def complex_radii(tmp: Path) -> None:
    body_npz(tmp, "cplx.npz", lambda f: f.update(radii_m=f["radii_m"] * (1 + 1j)))


def pds(tmp: Path, projection: str, extra: str = "") -> None:
    (tmp / "X.IMG").write_bytes(bytes(18))
    (tmp / "x.lbl").write_text(
        'PDS_VERSION_ID = PDS3\nRECORD_TYPE = FIXED_LENGTH\nRECORD_BYTES = 6\n'
        f'^IMAGE = "X.IMG"\n{extra}OBJECT = IMAGE\n LINES = 3\n LINE_SAMPLES = 3\n'
        ' SAMPLE_TYPE = LSB_INTEGER\n SAMPLE_BITS = 16\nEND_OBJECT = IMAGE\n'
        'OBJECT = IMAGE_MAP_PROJECTION\n MAP_PROJECTION_TYPE = "SIMPLE CYLINDRICAL"\n'
        f' A_AXIS_RADIUS = 1737.4 <KM>\n{projection} CENTER_LATITUDE = 0.0\n'
        ' CENTER_LONGITUDE = 0.0\n MAXIMUM_LATITUDE = 1\n WESTERNMOST_LONGITUDE = 0\n'
        'END_OBJECT = IMAGE_MAP_PROJECTION\nEND\n')


def map_scale_zero(tmp: Path) -> None:
    pds(tmp, " MAP_SCALE = 0 <KM/PIXEL>\n")


def nested_objects(tmp: Path) -> None:
    pds(tmp, " MAP_RESOLUTION = 1 <PIX/DEG>\n", "OBJECT = A\n" * 5000 + "END_OBJECT = A\n" * 5000)


def nested_parentheses(tmp: Path) -> None:
    pds(tmp, " MAP_RESOLUTION = 1 <PIX/DEG>\n", "X = " + "(" * 5000 + ")" * 5000 + "\n")


def fifo(tmp: Path) -> None:
    os.mkfifo(tmp / "scene.toml")


def big_toml(tmp: Path) -> None:
    with open(tmp / "scene.toml", "wb") as fh:
        fh.truncate(17 << 20)


def gappy_tif(tmp: Path) -> None:
    import dem

    d = dem.read(DATA / "ldem4_crop.lbl")
    z = d.heights.copy()
    z[100:110, 100:110] = np.nan
    dem.write(dem.Dem(z, d.transform, d.crs, body_radius_m=d.body_radius_m),
              tmp / "gappy.tif")


def complex_tif(tmp: Path) -> None:
    import rasterio
    from affine import Affine

    z = (np.arange(81.0).reshape(9, 9) * (1 + 1j)).astype(np.complex64)
    with rasterio.open(tmp / "cplx.tif", "w", driver="GTiff", width=9, height=9, count=1,
                       dtype="complex64", crs="EPSG:32633",
                       transform=Affine(10.0, 0, 5e5, 0, -10.0, 4e6)) as ds:
        ds.write(z, 1)


def nothing(tmp: Path) -> None:
    pass


LDEM = str(DATA / "ldem4_crop.lbl")
OUT = ["-q", "-o", "out.npz"]
# (id, setup, command, argv, texts the error line must hold)
CASES = [
    ("ply-face-index", bad_index_ply, "latlong",
     ["build", "--magnitude", "8", "--base", "shape:badidx.ply", "--shape-units", "km", *OUT],
     ["--base", "badidx.ply", "out of range [0, 50] for 4 vertices"]),
    ("obj-face-index-1e23", big_index_obj, "latlong",
     ["build", "--magnitude", "8", "--base", "shape:bigidx.obj", "--shape-units", "km", *OUT],
     ["--base", "bigidx.obj", "below 2**63"]),
    ("plate-header-1e400", overflow_plate, "latlong",
     ["build", "--magnitude", "8", "--base", "shape:plate.tab", "--shape-units", "km", *OUT],
     ["--base", "plate.tab", "below 2**63"]),
    ("shape-coordinates-1e-300", tiny_obj, "latlong",
     ["build", "--magnitude", "8", "--base", "shape:tiny.obj", "--shape-units", "m", *OUT],
     ["--base", "tiny.obj", "allowed 0.001 m to 1e+09 m"]),
    ("implicit-coordinates-1e-300", tiny_obj, "latlong",
     ["build", "--backend", "implicit", "--shape", "tiny.obj", "--shape-units", "m", *OUT],
     ["--shape", "tiny.obj", "allowed 0.001 m to 1e+09 m"]),
    ("lacunarity-1e300", nothing, "latlong",
     ["build", "--magnitude", "8", "--base", "fbm", "--lacunarity", "1e300", *OUT],
     ["--lacunarity", "--octaves", "below 2**31"]),
    ("radius-1e308", nothing, "latlong",
     ["build", "--magnitude", "8", "--radius-m", "1e308", *OUT],
     ["--radius-m", "[0.001, 1e+09]"]),
    ("smooth-width-1e9", nothing, "latlong",
     ["build", "--magnitude", "8", "--base", "faulting", "--smooth-width-m", "1e9", *OUT],
     ["--smooth-width-m", "must be in [0,"]),
    ("crater-memory", nothing, "latlong",
     ["build", "--magnitude", "100", "--craters", "c=0.5,k=-2,d_min_m=0.042,d_max_m=15",
      "--max-memory-gb", "8", *OUT],
     ["--craters", "8.9e+06 craters", "GB of memory", "--max-memory-gb = 8 GB"]),
    ("boulder-memory", nothing, "latlong",
     ["build", "--magnitude", "16", "--base", "sphere", "--boulders",
      "c=0.05,k=-2,d_min_m=0.02,d_max_m=2", "--max-memory-gb", "1", *OUT],
     ["--boulders", "boulders need about", "--max-memory-gb = 1 GB"]),
    ("duplicated-spec-key", nothing, "latlong",
     ["build", "--magnitude", "8", "--craters", "c=0.1,c=0.2,k=-2,d_min_m=1,d_max_m=5", *OUT],
     ["--craters", "c is given twice"]),
    ("npz-without-magnitude", no_magnitude, "latlong", ["info", "nomag.npz"],
     ["nomag.npz", "no magnitude"]),
    ("npz-complex-radii", complex_radii, "latlong", ["info", "cplx.npz"],
     ["cplx.npz", "radii_m must hold real numbers"]),
    ("config-fifo", fifo, "latlong", ["build", "--config", "scene.toml", *OUT],
     ["scene.toml", "not a regular file"]),
    ("config-dev-zero", nothing, "latlong", ["build", "--config", "/dev/zero", *OUT],
     ["/dev/zero", "not a regular file"]),
    ("config-17-MiB", big_toml, "dem", ["fill", "--config", "scene.toml", "-o", "x.tif"],
     ["scene.toml", "at most 16777216"]),
    ("dem-config-fifo", fifo, "dem", ["fill", "--config", "scene.toml", "-o", "x.tif"],
     ["scene.toml", "not a regular file"]),
    ("body-radius-1e-300", nothing, "dem", ["info", LDEM, "--body-radius-m", "1e-300"],
     ["--body-radius-m", "[0.001, 1e+09]"]),
    ("pds-map-scale-0", map_scale_zero, "dem", ["info", "x.lbl"],
     ["x.lbl", "MAP_SCALE must be finite and > 0"]),
    ("pds-5000-objects", nested_objects, "dem", ["info", "x.lbl"],
     ["x.lbl", "nested deeper than 64"]),
    ("pds-5000-parentheses", nested_parentheses, "dem", ["info", "x.lbl"],
     ["x.lbl", "nested deeper than 64"]),
    ("roughness-1e300", gappy_tif, "dem",
     ["fill", "gappy.tif", "--roughness", "1e300", "--seed", "1", "-q", "-o", "x.tif"],
     ["--roughness", "[0, 1000]"]),
    ("complex-geotiff", complex_tif, "dem", ["info", "cplx.tif"],
     ["cplx.tif", "complex numbers"]),
    ("profile-diameter-1e-320", nothing, "craters", ["profile", "--diameter-m", "1e-320"],
     ["--diameter-m", "[0.001, 1e+07]"]),
    ("profile-diameter-1e308", nothing, "craters", ["profile", "--diameter-m", "1e308"],
     ["--diameter-m", "[0.001, 1e+07]"]),
]


class Hang(BaseException):
    """A command still running after two minutes."""


def snapshot(folder: Path) -> dict:
    return {p.name: (p.read_bytes() if p.is_file() else None) for p in folder.iterdir()}


def main_of(command: str):
    if command == "latlong":
        from latlong.cli import main
    elif command == "dem":
        from dem.cli import main
    else:
        from craters.cli import main
    return main


def assert_refused(rc: int, err: str, texts, before: dict, folder: Path) -> None:
    assert rc == 2, err
    assert "Traceback" not in err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), err
    for text in texts:
        assert text in lines[0], lines[0]
    assert snapshot(folder) == before  # nothing written, inputs unchanged, no temporaries


@pytest.mark.parametrize("setup,command,argv,texts",
                         [c[1:] for c in CASES], ids=[c[0] for c in CASES])
def test_refused_in_one_line(tmp_path, monkeypatch, capsys, setup, command, argv, texts):
    setup(tmp_path)
    monkeypatch.chdir(tmp_path)
    monkeypatch.delenv("CRATERFORM_DEBUG", raising=False)
    before = snapshot(tmp_path)

    def hang(signum, frame):  # not an Exception: the CLI must not report it as an error
        raise Hang(f"{command} {' '.join(argv)} hangs")

    previous = signal.signal(signal.SIGALRM, hang)  # a FIFO read used to block for ever
    signal.alarm(120)
    try:
        rc = main_of(command)(list(argv))
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, previous)
    captured = capsys.readouterr()
    assert_refused(rc, captured.err, texts, before, tmp_path)


# --------------------------------------------------------------------------- subprocesses
def run(argv, cwd, env=None, timeout=300):
    full = {k: v for k, v in os.environ.items() if k != "CRATERFORM_DEBUG"}
    full.update(env or {})
    return subprocess.run([sys.executable, *argv], capture_output=True, text=True, cwd=cwd,
                          env=full, timeout=timeout)


@pytest.mark.parametrize("argv,texts", [
    (["build", "--magnitude", "8", "--base", "shape:huge.ply", "--shape-units", "km", *OUT],
     ["--base", "huge.ply", "header declares"]),
    (["build", "--backend", "implicit", "--shape", "huge.ply", "--shape-units", "km", *OUT],
     ["--shape", "huge.ply", "header declares"]),
    (["spectrum", "huge.ply", "--shape-units", "km"], ["huge.ply", "header declares"]),
], ids=["base-shape", "implicit-shape", "spectrum"])
def test_ply_header_beyond_the_file_is_refused_before_vtk(tmp_path, argv, texts):
    """A VTK segmentation fault (exit 139) before: a subprocess, so it cannot kill pytest."""
    huge_ply(tmp_path)
    before = snapshot(tmp_path)
    proc = run(["-m", "latlong", *argv], tmp_path)
    assert_refused(proc.returncode, proc.stderr, texts, before, tmp_path)


def console_script(name: str, launcher: str = "script") -> list[str]:
    """The command ``name`` as its console script or as ``python -m name``."""
    if launcher == "-m":
        return [sys.executable, "-m", name]
    path = Path(sys.executable).parent / name
    if not path.exists():
        pytest.skip(f"the {name} console script is not installed beside {sys.executable}")
    return [str(path)]


@pytest.mark.parametrize("command,argv", [
    ("latlong", ["build", "--magnitude", "8", *OUT]),
    ("dem", ["info", LDEM]),
    ("craters", ["profile", "--diameter-m", "100"]),
])
@pytest.mark.parametrize("value", ["0", "two"])
@pytest.mark.parametrize("launcher", ["script", "-m"])
def test_bad_numba_num_threads(tmp_path, command, argv, value, launcher):
    proc = subprocess.run([*console_script(command, launcher), *argv], capture_output=True,
                          text=True, cwd=tmp_path,
                          env={**os.environ, "NUMBA_NUM_THREADS": value}, timeout=300)
    assert_refused(proc.returncode, proc.stderr, ["NUMBA_NUM_THREADS", ">= 1", repr(value)],
                   {}, tmp_path)


@pytest.mark.parametrize("delay_s", [0.3, 1.0])
@pytest.mark.parametrize("launcher", ["script", "-m"])
def test_ctrl_c_during_start_up(tmp_path, delay_s, launcher):
    """One line and exit code 130, as a Ctrl-C later in a run (run_cli). A body of 6 M
    vertices (~3 s) so that the later signal lands inside the run."""
    # SIGINT as at a terminal: a test run started in the background (CI under nohup, `&`)
    # hands its children SIGINT ignored, and Python then never raises KeyboardInterrupt
    proc = subprocess.Popen([*console_script("latlong", launcher), "build", "--magnitude",
                             "1000", *OUT],
                            cwd=tmp_path, stderr=subprocess.PIPE, text=True,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    time.sleep(delay_s)
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=300)
    if proc.returncode == 0:  # the build finished before the signal: nothing to check
        pytest.skip("the run ended before the Ctrl-C")
    assert proc.returncode == 130, err
    assert err == "error: interrupted\n"
    assert list(tmp_path.iterdir()) == []


def test_closed_pipe_is_no_error(tmp_path):
    """``latlong info body.npz | head``: no "Broken pipe" error when the reader leaves."""
    from latlong import Body, LatLongGrid

    Body.sphere(LatLongGrid(4), 10.0).save(tmp_path / "b.npz")
    proc = subprocess.Popen([sys.executable, "-m", "latlong", "info", "b.npz"], cwd=tmp_path,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    proc.stdout.close()  # the reader is gone before the first line
    with proc.stderr:
        err = proc.stderr.read()
    assert proc.wait(timeout=300) == 141 and err == "", err


def test_noise_is_not_a_dependency():
    """``pip install .`` needs no compiler: ``noise`` (an sdist) is an extra."""
    import tomllib

    project = tomllib.loads((Path(__file__).parents[1] / "pyproject.toml").read_text())
    deps = [d.split(">")[0].split("=")[0].strip().lower()
            for d in project["project"]["dependencies"]]
    assert "noise" not in deps and {"matplotlib", "pillow"} <= set(deps)
    assert any(d.startswith("noise") for d in project["project"]["optional-dependencies"]
               ["reference"])


if __name__ == "__main__":
    sys.exit(pytest.main([__file__, "-q"]))
