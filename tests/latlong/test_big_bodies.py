"""Bodies far bigger than memory used to allow (issue 18): the build keeps one float64
radius per vertex plus bounded buffers, with the same bytes as the whole-grid code it
replaced; a build that would not fit is refused up front."""

from __future__ import annotations

import hashlib

import numba
import numpy as np
import pytest

import craters
import latlong.body as body_module
import latlong.cratering as cratering
import latlong.perlin as perlin
import latlong.surface as surface
from craters.exact import dot
from latlong import (
    Body,
    BodySettings,
    FbmParams,
    LatLongGrid,
    Scene,
    build,
    perlin_fbm,
    stamp_craters,
)
from latlong.cratering import WaveScheduleOutgrown
from latlong.grid import build_bytes_per_vertex
from latlong.settings import check_memory
from latlong.surface import band_areas


def _fbm_whole_grid(grid, frequency, octaves, persistence, lacunarity, amplitude_m, rng):
    """The fBm as computed before issue 18: every unit vector at once, then the kernel,
    then the amplitude (reference)."""
    from latlong._perlin_kernels import GRAD3, PERM, _fbm3_kernel

    rng = np.random.default_rng(rng)
    rot = perlin.random_rotation(rng)
    offset = rng.uniform(0.0, 256.0, size=3)
    u = grid.unit_vectors_range(0, grid.n_vertices)
    xs, ys, zs = (((u[:, 0] * rot[a, 0] + u[:, 1] * rot[a, 1] + u[:, 2] * rot[a, 2])
                   * frequency + offset[a]).astype(np.float32) for a in range(3))
    out = np.empty(grid.n_vertices)
    _fbm3_kernel(xs, ys, zs, octaves, np.float32(persistence), np.float32(lacunarity), 0,
                 PERM, GRAD3, out)
    out *= amplitude_m
    return out


@pytest.mark.parametrize("chunk", [1, 97, 1000, 1 << 20])
@pytest.mark.parametrize("magnitude", [7, 40])
def test_fbm_in_chunks_equals_the_whole_grid(monkeypatch, chunk, magnitude):
    grid = LatLongGrid(magnitude)
    args = (1.5, 6, 0.5, 1.75, 40.0)
    ref = _fbm_whole_grid(grid, *args, rng=3)
    monkeypatch.setattr(perlin, "_CHUNK", chunk)
    np.testing.assert_array_equal(perlin_fbm(grid, *args, rng=3), ref)
    out = np.full(grid.n_vertices, np.nan)
    assert perlin_fbm(grid, *args, rng=3, out=out) is out
    np.testing.assert_array_equal(out, ref)


@pytest.mark.parametrize("bad", [np.empty(10), np.empty(386, np.float32),
                                 np.empty((386, 2))[:, 0]])
def test_fbm_out_is_checked(bad):
    with pytest.raises(ValueError, match="`out`"):
        perlin_fbm(LatLongGrid(8), 1.5, 4, 0.5, 2.0, 1.0, rng=0, out=bad)


def test_body_takes_an_array_over_without_a_copy():
    grid = LatLongGrid(6)
    radii = np.linspace(1.0, 2.0, grid.n_vertices)
    kept = radii.copy()
    copied = Body(grid, radii)
    assert not np.shares_memory(copied.radii_m, radii) and radii.flags.writeable
    adopted = Body(grid, radii, copy=False)
    assert adopted.radii_m is radii and not radii.flags.writeable
    np.testing.assert_array_equal(adopted.radii_m, kept)
    assert adopted.radius_m == copied.radius_m
    # not float64 / not contiguous: converted (a copy whatever `copy` says)
    other = Body(grid, radii.astype(np.float32), copy=False)
    assert not np.shares_memory(other.radii_m, radii)
    assert not other.radii_m.flags.writeable


def test_replace_shares_unchanged_radii_and_copies_new_ones():
    grid = LatLongGrid(6)
    body = Body.sphere(grid, 3.0)
    assert body.replace(metadata={"a": 1}).radii_m is body.radii_m
    assert body.replace(stretch=(2, 1, 1)).radii_m is body.radii_m
    new = np.full(grid.n_vertices, 4.0)
    assert not np.shares_memory(body.replace(radii_m=new).radii_m, new)
    assert body.replace(radii_m=new, copy=False).radii_m is new
    with pytest.raises(ValueError, match="finite"):
        body.replace(radii_m=np.full(grid.n_vertices, np.nan))


@pytest.mark.parametrize("chunk", [5, 1 << 20])
def test_radii_checks_in_chunks(monkeypatch, chunk):
    monkeypatch.setattr(body_module, "_CHECK_CHUNK", chunk)
    grid = LatLongGrid(6)
    radii = np.full(grid.n_vertices, 2.0)
    radii[[3, 50, 200]] = [-1.0, 0.0, -2.5]
    with pytest.raises(ValueError, match=r"3 vertices have radius <= 0 \(min -2\.5 m\)"):
        Body(grid, radii)
    radii[:] = 2.0
    radii[-1] = np.inf
    with pytest.raises(ValueError, match="must be finite"):
        Body(grid, radii, copy=False)


@pytest.mark.parametrize("magnitude", [1, 5, 40, 41, 150])
def test_mean_radius_from_ring_areas(magnitude):
    """The reference radius of a body made without one: the area-weighted mean, the same
    bits as ``dot(vertex_areas, radii) / sum`` summed in index order (craters.exact.dot:
    BLAS's ddot differs in its last bits from one CPU to another) up to 10 000 vertices
    (M <= 40, one block), within 1e-15 beyond."""
    grid = LatLongGrid(magnitude)
    radii = 100.0 + np.random.default_rng(magnitude).standard_normal(grid.n_vertices)
    w = grid.vertex_areas()
    ref = dot(w, radii) / float(w.sum())
    got = Body(grid, radii).radius_m
    if grid.n_vertices <= 10_000:
        assert got == ref
    else:
        assert abs(got - ref) <= 1e-15 * ref
    w_sorted = np.sort(w)  # a different order of the same sum: agrees to rounding
    assert abs(got - float(np.sum(w * radii) / w_sorted.sum())) <= 1e-14 * ref


def test_ring_areas_give_the_vertex_areas():
    grid = LatLongGrid(9)
    np.testing.assert_array_equal(
        grid.vertex_areas(), grid.ring_areas()[np.repeat(np.arange(grid.n_rings),
                                                         grid.ring_sizes())])
    assert abs(grid.vertex_areas().sum() - 4 * np.pi) < 1e-12


@pytest.mark.parametrize("step", [1, 50, 1000])
def test_band_areas_do_not_depend_on_the_step(monkeypatch, step):
    body = Body(LatLongGrid(30), 10.0 + np.random.default_rng(1).random(5402),
                stretch=(1.5, 1.0, 0.8))
    ref = band_areas(body)
    monkeypatch.setattr(surface, "_TRIANGLES_PER_STEP", step)
    np.testing.assert_array_equal(band_areas(body), ref)


def _cratered_inputs():
    radius = 500.0
    body = Body.sphere(LatLongGrid(60), radius)
    area = 4 * np.pi * radius**2
    cat = craters.power_law_population(radius=radius, c=300 / (area * (10.0**-2 - 150.0**-2)),
                                       k=-2.0, d_min=10.0, d_max=150.0, rng=5)
    return body, cat


def _digest(body):
    h = hashlib.sha256(body.radii_m.tobytes())
    for name in body.craters.dtype.names:
        h.update(np.ascontiguousarray(body.craters[name]).tobytes())
    return h.hexdigest()


def test_stamping_into_the_body_gives_the_same_bytes():
    body, cat = _cratered_inputs()
    ref = _digest(stamp_craters(body, cat, rng=2))
    assert body.radii_m.min() == body.radii_m.max() == 500.0  # untouched by default
    mine = body.radii_m
    out = stamp_craters(body, cat, rng=2, overwrite_body=True)
    assert out.radii_m is mine and not mine.flags.writeable
    assert _digest(out) == ref


def test_stamping_into_a_read_only_buffer_falls_back_to_a_copy():
    body, cat = _cratered_inputs()
    ref = _digest(stamp_craters(body, cat, rng=2))
    buf = np.frombuffer(body.radii_m.tobytes(), dtype=np.float64)  # cannot be made writeable
    frozen = Body(body.grid, buf, radius_m=body.radius_m, copy=False)
    out = stamp_craters(frozen, cat, rng=2, overwrite_body=True)
    assert _digest(out) == ref and frozen.radii_m.max() == 500.0


@pytest.fixture
def two_threads():
    if numba.config.NUMBA_NUM_THREADS < 2:
        pytest.skip("one thread: no parallel waves")
    old = numba.get_num_threads()
    numba.set_num_threads(2)
    yield
    numba.set_num_threads(old)


def test_outgrown_waves_in_place_raise(monkeypatch, two_threads):
    body, cat = _cratered_inputs()
    monkeypatch.setattr(cratering, "WAVE_RADIUS_SHARE", 4.0)  # a schedule far too tight
    with pytest.raises(WaveScheduleOutgrown):
        stamp_craters(body, cat, rng=2, overwrite_body=True)


def _scene(**body):
    return Scene.from_settings({"preset": "fbm-cratered", "magnitude": 40, "seed": 1,
                                "radius_m": 60.0, **body})


def test_build_redoes_an_outgrown_schedule_with_a_copy(monkeypatch, two_threads, caplog):
    ref = build(_scene())
    monkeypatch.setattr(cratering, "WAVE_RADIUS_SHARE", 4.0)
    with caplog.at_level("INFO", logger="latlong.build"):
        again = build(_scene())
    assert "building again" in caplog.text
    assert _digest(again) == _digest(ref) and again.metadata == ref.metadata


def test_memory_estimate_and_limit():
    # issue 18 on its 2-core machine: M = 8192 within 8 GB, M = 13 000 within 16 GB
    two = build_bytes_per_vertex(2)
    assert two == 11.0 and build_bytes_per_vertex(1) < two < build_bytes_per_vertex(8)
    assert LatLongGrid.estimate_bytes(100, two) < LatLongGrid.estimate_bytes(8192, two) < 8e9
    assert LatLongGrid.estimate_bytes(13_000, two) < 16e9
    assert LatLongGrid.estimate_bytes(13_000) == LatLongGrid.estimate_bytes(
        13_000, build_bytes_per_vertex(numba.get_num_threads()))
    check_memory(13_000, max_memory_gb=1000.0)
    with pytest.raises(ValueError, match=r"`magnitude` 13000 needs about .* GB .* more than "
                                         r"`max_memory_gb` = 1 GB"):
        check_memory(13_000, max_memory_gb=1.0)
    # a scene is only described, never allocated: a large one is accepted when allowed
    assert Scene(BodySettings(magnitude=20_000, max_memory_gb=1e4),
                 FbmParams()).body.magnitude == 20_000
    with pytest.raises(ValueError, match="`max_memory_gb`"):
        BodySettings(magnitude=10, max_memory_gb=0.0)


def test_cli_refuses_a_build_over_max_memory(run_cli, tmp_path, one_line_error):
    out = tmp_path / "b.npz"
    proc = run_cli("latlong", "build", "--preset", "fbm-cratered", "--magnitude", "3000",
                   "--max-memory-gb", "1", "--radii-on-disk", "no", "-o", str(out), "-q")
    one_line_error(proc, "--magnitude 3000 needs about", "GB", "--max-memory-gb = 1 GB")
    proc = run_cli("latlong", "build", "--preset", "fbm-cratered", "--magnitude", "3000",
                   "--max-memory-gb", "1", "-o", str(out), "-q")  # radii on disk, craters not
    one_line_error(proc, "--craters: about", "besides the 0.762 GB of magnitude 3000",
                   "--max-memory-gb = 1 GB")
    assert not out.exists()
    (tmp_path / "scene.toml").write_text('preset = "fbm-cratered"\nmagnitude = 3000\n'
                                         'max_memory_gb = 1.0\nradii_on_disk = "no"\n')
    proc = run_cli("latlong", "build", "--config", str(tmp_path / "scene.toml"),
                   "-o", str(out), "-q")
    one_line_error(proc, "magnitude", "'max_memory_gb' = 1 GB")
    proc = run_cli("latlong", "build", "--preset", "fbm-cratered", "--magnitude", "12",
                   "--max-memory-gb", "1", "--seed", "1", "-o", str(out), "-q")
    assert proc.returncode == 0, proc.stderr
