"""``latlong build --backend implicit`` through the real entry point."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import craters
from latlong import load
from latlong.shapes import read_shape_model

DATA = Path(__file__).parents[1] / "data"
ITOKAWA = ["--backend", "implicit", "--shape", str(DATA / "itokawa_8.obj"), "--shape-units",
           "km", "--polygons", "20000"]
BENNU = ["--backend", "implicit", "--shape", str(DATA / "bennu_radar_sbgat.obj"),
         "--shape-units", "km", "--polygons", "20000"]
LAYERS = ["--lcsn", "kernel=table-a1-300m-0gyr,d_min_m=40,d_max_m=80",
          "--lcsn", "kernel=fig6-kernel1,d_min_m=20,d_max_m=40,depth_ratio=0.1:0.2,probability=0.7"]


def assert_one_line_error(proc, *needles):
    assert proc.returncode == 2, proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error:"), proc.stderr
    for needle in needles:
        assert needle in lines[0], lines[0]


def test_build_meshes_catalog_preview(run_cli, tmp_path):
    outs = [tmp_path / f"a{s}" for s in (".ply", ".obj", ".stl", ".vtp")]
    proc = run_cli("latlong", "build", *ITOKAWA, *LAYERS, "--seed", "4",
                   *sum((["-o", str(p)] for p in outs), []), "--catalog",
                   str(tmp_path / "a.csv"), "--preview", str(tmp_path / "a.png"),
                   "--gabor", "frequency=0.1,bandwidth=0.05,amplitude_m=0.3")
    assert proc.returncode == 0, proc.stderr
    assert "implicit body:" in proc.stdout and proc.stdout.count("wrote") == 6
    meshes = [read_shape_model(p, units="m") for p in outs]
    assert len({len(m.faces) for m in meshes}) == 1
    assert meshes[0].volume_m3 == pytest.approx(meshes[1].volume_m3, rel=1e-5)
    cat = craters.read_catalog(tmp_path / "a.csv")
    assert set(cat["kind"]) == {"fresh", "simple"} and set(cat["level"]) == {0, 1}
    assert (tmp_path / "a.png").stat().st_size > 10_000


def test_npz_projection_and_crossings(run_cli, tmp_path):
    proc = run_cli("latlong", "build", *BENNU, "--magnitude", "40", "--seed", "1",
                   "-o", str(tmp_path / "b.npz"))
    assert proc.returncode == 0, proc.stderr
    body = load(tmp_path / "b.npz")
    assert body.magnitude == 40 and body.metadata["implicit"]["seed"] == 1
    # Itokawa is not star-shaped: refused, nothing written ...
    proc = run_cli("latlong", "build", *ITOKAWA, "--seed", "1", "-o", str(tmp_path / "i.ply"),
                   "-o", str(tmp_path / "i.npz"), "--catalog", str(tmp_path / "i.csv"),
                   *LAYERS)
    assert_one_line_error(proc, ".npz", "not star-shaped")
    assert not list(tmp_path.glob("i.*"))
    # ... unless a crossing is chosen
    proc = run_cli("latlong", "build", *ITOKAWA, "--seed", "1", "-o", str(tmp_path / "i.npz"),
                   "--shape-crossings", "outermost", "--magnitude", "30", *LAYERS)
    assert proc.returncode == 0, proc.stderr
    assert len(load(tmp_path / "i.npz").craters) > 0


def test_same_seed_same_bytes_any_thread_count(run_cli, tmp_path):
    names = ("m.ply", "m.obj", "m.stl", "m.vtp", "m.npz", "m.csv")
    files = {}
    for tag, threads in (("one", "1"), ("two", "2")):
        d = tmp_path / tag
        d.mkdir()
        outs = [d / n for n in names]
        proc = run_cli("latlong", "build", *BENNU, *LAYERS, "--seed", "9", "-q",
                       "--shape-crossings", "outermost", "--magnitude", "30",
                       "--gabor", "frequency=0.05,bandwidth=0.025,amplitude_m=0.4",
                       *sum((["-o", str(p)] for p in outs[:-1]), []), "--catalog", str(outs[-1]),
                       env={"NUMBA_NUM_THREADS": threads})
        assert proc.returncode == 0, proc.stderr
        assert proc.stdout == ""
        files[tag] = [p.read_bytes() for p in outs]
    assert files["one"] == files["two"]


def test_config_file(run_cli, tmp_path):
    cfg = tmp_path / "scene.toml"
    cfg.write_text(f'backend = "implicit"\nshape = "{DATA / "bennu_radar_sbgat.obj"}"\n'
                   'shape_units = "km"\npolygons = 20000\nseed = 3\n'
                   'lcsn = ["kernel=fig6-kernel2,d_min_m=20,d_max_m=40,depth_ratio=0.1:0.1"]\n'
                   f'output = ["{tmp_path / "c.ply"}"]\ncatalog = "{tmp_path / "c.csv"}"\n')
    proc = run_cli("latlong", "build", "--config", str(cfg), "-q")
    assert proc.returncode == 0, proc.stderr
    cat = craters.read_catalog(tmp_path / "c.csv")
    assert set(cat["kind"]) == {"flat-floored"}
    np.testing.assert_allclose(cat["depth_m"] / cat["diameter_m"], 0.1)


@pytest.mark.parametrize("args,needles", [
    (["--backend", "implicit"], ["--shape"]),
    (["--backend", "voxels"], ["--backend", "latlong, implicit"]),
    (["--shape", "x.obj"], ["--shape", "--backend implicit"]),
    ([*BENNU[:4]], ["--shape-units"]),
    ([*BENNU, "--radius-m", "100"], ["--radius-m", "does not apply"]),
    ([*BENNU, "--craters", "c=0.5,k=-2,d_min_m=2,d_max_m=5"], ["--craters", "does not apply"]),
    (["--backend", "implicit", "--shape", "missing.obj", "--shape-units", "km"],
     ["--shape", "does not exist"]),
    ([*BENNU, "--lcsn", "kernel=nope,d_min_m=1,d_max_m=2"], ["--lcsn", "`kernel`"]),
    ([*BENNU, "--lcsn", "kernel=fig6-kernel1,d_min_m=5,d_max_m=2"], ["--lcsn", "d_min_m"]),
    ([*BENNU, "--lcsn", "kernel=fig6-kernel1,d_min_m=5,d_max_m=20,probability=0"],
     ["--lcsn", "probability"]),
    ([*BENNU, "--lcsn", "kernel=fig6-kernel1,d_min_m=5,d_max_m=20", "--cell-m", "10"],
     ["--cell-m"]),
    ([*BENNU, "--polygons", "5"], ["--polygons"]),
    ([*BENNU, "--voxel-m", "-1"], ["--voxel-m"]),
    ([*BENNU, "--packing-voxels", "3"], ["--packing-voxels"]),
    ([*BENNU, "--constraint-weight", "1.5"], ["--constraint-weight", "[0, 1]"]),
    ([*BENNU, "--packing-voxels", "1024"], ["--packing-voxels = 1024", "GiB"]),
    ([*BENNU, "--lcsn", "kernel=fig6-kernel1,d_min_m=10,d_max_m=20,exponent=-300"],
     ["--lcsn", "exponent"]),
    ([*BENNU, "--lcsn", "kernel=fig6-kernel1,dmin=10,d_max_m=20"], ["--lcsn", "now d_min_m="]),
    ([*BENNU, "--gabor", "frequency=1,bandwidth=1"], ["--gabor", "missing amplitude_m"]),
    ([*BENNU, "--gabor-example", "x.npy"], ["--gabor-pixel-m"]),
    ([*BENNU, "--gabor-pixel-m", "2"], ["--gabor-pixel-m", "--gabor-example"]),
    ([*BENNU, "--shape-crossings", "all"], ["--shape-crossings"]),
    ([*BENNU, "--magnitude", "0", "-o", "x.npz"], ["--magnitude"]),
])
def test_bad_input_one_line_nothing_written(run_cli, tmp_path, args, needles):
    out = tmp_path / "x.ply"
    extra = [] if any(a.startswith("-o") for a in args) else ["-o", str(out)]
    proc = run_cli("latlong", "build", *args, *extra, cwd=tmp_path)
    assert_one_line_error(proc, *needles)
    assert not list(tmp_path.iterdir())


def test_bad_outputs(run_cli, tmp_path):
    proc = run_cli("latlong", "build", *BENNU, "-o", str(tmp_path / "x.xyz"))
    assert_one_line_error(proc, "unknown format", ".npz", ".glb")
    proc = run_cli("latlong", "build", *BENNU)
    assert_one_line_error(proc, "nothing to write")
    (tmp_path / "y.ply").write_text("keep")
    proc = run_cli("latlong", "build", *BENNU, "-o", str(tmp_path / "y.ply"))
    assert_one_line_error(proc, "exists", "--force")
    assert (tmp_path / "y.ply").read_text() == "keep"


def test_gabor_example(run_cli, tmp_path):
    z = np.random.default_rng(0).normal(size=(64, 64))
    np.save(tmp_path / "ex.npy", z)
    proc = run_cli("latlong", "build", *BENNU, "--gabor-example", str(tmp_path / "ex.npy"),
                   "--gabor-pixel-m", "4", "--gabor-amplitude-m", "0.5", "-o",
                   str(tmp_path / "g.ply"), "-q")
    assert proc.returncode == 0, proc.stderr
    from PIL import Image

    Image.fromarray((np.clip(z + 3, 0, 6) * 40).astype(np.uint8)).save(tmp_path / "ex.png")
    proc = run_cli("latlong", "build", *BENNU, "--gabor-example", str(tmp_path / "ex.png"),
                   "--gabor-pixel-m", "4", "-o", str(tmp_path / "h.ply"))
    assert_one_line_error(proc, "--gabor-amplitude-m")
    assert not (tmp_path / "h.ply").exists()
