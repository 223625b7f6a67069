"""``dem fill`` bigger than memory (issue 18, deliver 3): the tiled fill from a file gives
the bytes of the whole-raster fill; its pieces (holes across tile edges, the streamed
fractal dimension, the sums) against the whole-raster references; the memory refusal."""

from __future__ import annotations

import hashlib
import os

import numpy as np
import pytest

from dem import Dem, fill_gaps, read, write
from dem.fractal import fractal_fit, fractal_fit_rows
from dem.holes import holes_of_file
from dem.streamsum import PairwiseSum
from dem.tiledfill import fill_to_file


def _sha(path) -> str:
    with open(path, "rb") as fh:
        return hashlib.sha256(fh.read()).hexdigest()


def _holey(rng, shape=(150, 130)) -> np.ndarray:
    """fBm-like terrain with holes: a large one, one around an island holding another (the
    boxes overlap), a long thin one, scattered pixels; many cross tile edges."""
    z = rng.standard_normal(shape).cumsum(0).cumsum(1) * 0.5
    z[10:60, 15:75] = np.nan
    z[80:130, 20:70] = np.nan
    z[95:115, 35:55] = 1.0  # an island in it
    z[100:110, 40:50] = np.nan  # with a hole of its own
    z[5:shape[0] - 5, min(100, shape[1] - 5)] = np.nan  # a long thin hole
    z[rng.random(shape) < 0.01] = np.nan
    return z


@pytest.fixture
def holey_tif(tmp_path):
    z = _holey(np.random.default_rng(7))
    return write(Dem(z, pixel_size_m=10.0), tmp_path / "in.tif")


@pytest.mark.parametrize("tile_px", [16, 23, 64, 4096])
@pytest.mark.parametrize("kw", [
    {"rng": 3},
    {"rng": 4, "roughness": 0.05, "fractal_dimension": 2.3, "craters": None},
    {"rng": 5, "craters": "c=0.05,k=-2,d_min_m=40,d_max_m=600"},
])
def test_tiled_fill_is_the_whole_fill(holey_tif, tmp_path, tile_px, kw):
    whole = write(fill_gaps(read(holey_tif), **kw), tmp_path / "whole.tif")
    made = fill_to_file(holey_tif, tmp_path / "tiled.tif", tile_px=tile_px, **kw)
    assert _sha(made.path) == _sha(whole)
    assert made.parameters["holes"] > 100
    if "craters" in kw and kw["craters"]:
        assert made.parameters["craters"] > 0  # the stamped craters are the same too
    left = sorted(p.name for p in tmp_path.iterdir())
    assert left == ["in.tif", "tiled.tif", "whole.tif"]  # no scratch or temporaries


def test_tiled_fill_of_a_geographic_pds_dem(lola_crop, tmp_path):
    """A PDS3 input with a geographic CRS: the pixel size is the whole DEM's (centre
    latitude), not a tile's."""
    src = tmp_path / "lola.tif"
    z = np.array(lola_crop.heights)
    z[100:140, 60:200] = np.nan
    write(lola_crop.replace(heights=z), src)
    whole = write(fill_gaps(read(src), rng=9), tmp_path / "whole.tif")
    made = fill_to_file(src, tmp_path / "tiled.tif", rng=9, tile_px=48)
    assert _sha(made.path) == _sha(whole)


def test_tiled_fill_reads_a_pds_product(tmp_path):
    """A PDS3 .lbl input (its size from the label): the same bytes as the whole fill."""
    lbl = os.path.join(os.path.dirname(__file__), "..", "data", "ldem4_crop.lbl")
    whole = write(fill_gaps(read(lbl), rng=2), tmp_path / "whole.tif")
    made = fill_to_file(lbl, tmp_path / "tiled.tif", rng=2, tile_px=100)
    assert made.shape == (257, 257) and made.tiles == 9
    assert _sha(made.path) == _sha(whole)


def test_holes_across_tiles_are_scipys_labels(rng):
    from scipy import ndimage

    z = np.where(rng.random((97, 83)) < 0.45, np.nan, 1.0)  # many components, long ones
    labels, n = ndimage.label(np.isnan(z), structure=np.ones((3, 3), dtype=bool))
    objs = ndimage.find_objects(labels)
    want = np.array([[s[0].start, s[0].stop, s[1].start, s[1].stop] for s in objs])
    counts = np.bincount(labels.ravel())[1:]
    for tile in (1, 2, 7, 16, 100):
        holes = holes_of_file(lambda r, c, h, w: z[r:r + h, c:c + w], z.shape, tile)
        assert len(holes.box) == n
        np.testing.assert_array_equal(holes.box, want)
        np.testing.assert_array_equal(holes.pixels, counts)
        assert holes.known == int(np.isfinite(z).sum())


@pytest.mark.parametrize("strip_rows", [1, 5, 64, 1000])
def test_streamed_fractal_fit_is_the_whole_fit(rng, strip_rows):
    z = _holey(rng, (120, 90))
    d = Dem(z, pixel_size_m=(2.0, 3.0))
    got = fractal_fit_rows(lambda a, b: z[a:b], z.shape, d.pixel_size_m, d.resolution_m,
                           strip_rows=strip_rows)
    assert got == fractal_fit(d)


@pytest.mark.parametrize("n", [1, 8, 129, 5000, 300_001])
def test_pairwise_sum_is_numpys_sum(rng, n):
    x = rng.standard_normal(n) * 10.0 ** rng.uniform(-4, 4, n)
    total = PairwiseSum(n)
    a = 0
    while a < n:
        b = min(n, a + int(rng.integers(0, 5000)))
        total.push(x[a:b])
        a = b
    assert total.total == float(np.sum(x))


def test_a_hole_too_large_for_the_memory_is_refused(holey_tif, tmp_path):
    from craters._shared import ParameterError

    with pytest.raises(ParameterError, match=r"`max_memory_gb` is too small for the hole at "
                                             r"rows \d+\.\.\d+, cols .* GB"):
        fill_to_file(holey_tif, tmp_path / "t.tif", rng=1, craters=None, max_memory_gb=0.001)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["in.tif"]


def _cli(*argv):
    from dem.cli import main

    try:
        return main(list(argv))
    except SystemExit as exc:
        return exc.code


def test_cli_fills_in_tiles_over_max_memory(holey_tif, tmp_path, capsys):
    """``--max-memory-gb`` below the whole-raster fill's need: the tiled path, same bytes."""
    assert _cli("fill", str(holey_tif), "-o", str(tmp_path / "w.tif"), "--seed", "2",
                "--craters", "none", "-q") == 0
    assert _cli("fill", str(holey_tif), "-o", str(tmp_path / "t.tif"), "--seed", "2",
                "--craters", "none", "--max-memory-gb", "0.0025") == 0
    out = capsys.readouterr().out
    assert "dem fill: 150 x 130 -> 150 x 130 pixels, seed 2" in out
    assert _sha(tmp_path / "t.tif") == _sha(tmp_path / "w.tif")


def test_cli_refuses_a_hole_over_max_memory(holey_tif, tmp_path, capsys):
    before = holey_tif.read_bytes()
    code = _cli("fill", str(holey_tif), "-o", str(tmp_path / "t.tif"), "--seed", "2",
                "--max-memory-gb", "0.0005")
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2
    assert len(err) == 1 and err[0].startswith("error: --max-memory-gb is too small for the "
                                               "hole at rows "), err
    assert sorted(os.listdir(tmp_path)) == ["in.tif"]
    assert holey_tif.read_bytes() == before


if __name__ == "__main__":  # pragma: no cover
    pytest.main([__file__, "-q"])
