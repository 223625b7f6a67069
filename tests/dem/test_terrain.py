"""Slopes, slope distributions and power spectra of DEMs."""

from __future__ import annotations

import math

import numpy as np
import pytest
from affine import Affine
from scipy import ndimage

import dem
from dem import Dem

SLOPE_TOL_DEG = 0.01
BETA_TOL = 0.15


def test_tilted_plane_30_degrees():
    z = np.add.outer(np.zeros(40), np.arange(60.0)) * 2.0 * math.tan(math.radians(30))
    d = Dem(z, pixel_size_m=2.0)
    s = dem.slope(d)
    assert np.abs(s[1:-1, 1:-1] - 30.0).max() <= SLOPE_TOL_DEG
    assert np.isnan(s[0]).all() and np.isnan(s[:, -1]).all()
    assert np.abs(dem.slope(d, "central")[1:-1, 1:-1] - 30.0).max() <= SLOPE_TOL_DEG


def horn_reference(z, dx, dy):
    """Independent Horn: correlation with the two 3 x 3 kernels."""
    kx = np.array([[-1, 0, 1], [-2, 0, 2], [-1, 0, 1]]) / (8 * dx)
    ky = np.array([[-1, -2, -1], [0, 0, 0], [1, 2, 1]]) / (8 * dy)
    gx = ndimage.correlate(z, kx, mode="nearest")
    gy = ndimage.correlate(z, ky, mode="nearest")
    out = np.degrees(np.arctan(np.hypot(gx, gy)))
    out[0], out[-1], out[:, 0], out[:, -1] = np.nan, np.nan, np.nan, np.nan
    return out


def test_horn_equals_reference(rng):
    z = rng.standard_normal((50, 70)).cumsum(axis=0).cumsum(axis=1)
    d = Dem(z, pixel_size_m=(3.0, 2.0))
    got, want = dem.slope(d), horn_reference(z, 3.0, 2.0)
    inner = np.s_[1:-1, 1:-1]
    assert np.abs(got[inner] - want[inner]).max() <= 1e-9


def test_nan_next_to_unknown_pixels(rng):
    z = rng.standard_normal((30, 30))
    z[10, 12] = np.nan
    s = dem.slope(Dem(z, pixel_size_m=1.0))
    near = np.zeros_like(z, dtype=bool)
    near[9:12, 11:14] = True
    assert np.isnan(s[near]).all()
    assert np.isfinite(s[1:-1, 1:-1][~near[1:-1, 1:-1]]).all()


def test_geographic_rows_use_their_own_width():
    radius = 1_737_400.0
    rows, cols = 60, 40
    t = Affine(0.01, 0, 10.0, 0, -0.5, 50.0)  # rows from 50 N down to 20 N
    lat = np.radians(50.0 - 0.5 * (np.arange(rows) + 0.5))
    x_m = radius * np.radians(0.01) * np.cos(lat)[:, None] * np.arange(cols)[None, :]
    d = Dem(x_m * math.tan(math.radians(20)), t, "+proj=longlat +R=1737400 +no_defs",
            body_radius_m=radius)
    s = dem.slope(d)
    assert np.abs(s[1:-1, 1:-1] - 20.0).max() < 0.05  # width shrinks with cos(lat) per row
    width, dy = dem.pixel_sizes_by_row(d)
    assert width[0] < width[-1] and dy == pytest.approx(radius * np.radians(0.5))


def test_slope_distribution():
    z = np.add.outer(np.zeros(20), np.arange(20.0)) * math.tan(math.radians(25))
    out = dem.slope_distribution(Dem(z, pixel_size_m=1.0))
    assert out["median_deg"] == pytest.approx(25.0)
    assert out["percent_above"][20] == pytest.approx(100.0)
    assert out["percent_above"][30] == 0.0
    assert out["area_fraction"].sum() == pytest.approx(1.0)
    assert out["area_fraction"][8] == pytest.approx(1.0)  # the 24-27 deg bin


@pytest.mark.parametrize("beta", [2.0, 2.6, 3.2, 3.8])
def test_power_spectrum_recovers_beta(beta, rng, fbm_surface):
    d = Dem(fbm_surface(512, (8.0 - beta) / 2.0, rng) * 50.0, pixel_size_m=5.0)
    wl, psd = dem.power_spectrum(d)
    assert wl[0] > wl[-1] >= 10.0
    assert abs(dem.spectral_exponent(wl, psd) - beta) <= BETA_TOL


def test_power_spectrum_integrates_to_the_variance(rng):
    z = rng.standard_normal((128, 128))
    d = Dem(z, pixel_size_m=1.0)
    wl, psd = dem.power_spectrum(d, n_bins=40)
    # white noise: flat density equal to variance / (bandwidth^2) = 1 / (1 cycle/m)^2
    assert np.median(psd) == pytest.approx(1.0, rel=0.15)
    with pytest.raises(ValueError, match="unknown"):
        dem.power_spectrum(Dem(np.where(z > 2, np.nan, z), pixel_size_m=1.0))


def test_roughness_is_the_fractal_fit(lola_crop):
    fit = dem.roughness(lola_crop)
    assert 2.0 <= fit.fractal_dimension <= 3.0


def test_cli_slopes_and_spectrum(run_cli, tmp_path):
    from pathlib import Path

    crop = Path(__file__).parents[1] / "data" / "ldem4_crop.lbl"
    csv, png = tmp_path / "s.csv", tmp_path / "s.png"
    proc = run_cli("dem", "slopes", str(crop), "--compare", str(crop), "--label", "a", "b",
                   "--csv", str(csv), "--plot", str(png))
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.splitlines()[1].startswith("a")
    assert csv.read_text().startswith("# dem slopes") and png.stat().st_size > 10_000
    out = tmp_path / "p.csv"
    proc = run_cli("dem", "spectrum", str(crop), "--csv", str(out), "-q")
    assert proc.returncode == 0, proc.stderr
    assert "wavelength_m" in out.read_text().splitlines()[1]
    proc = run_cli("dem", "slopes", str(crop), "--bin-deg", "0", "--csv", str(tmp_path / "x.csv"))
    assert proc.returncode == 2 and "--bin-deg" in proc.stderr
    assert not (tmp_path / "x.csv").exists()
    proc = run_cli("dem", "spectrum", str(crop), "-q")  # nothing to write, nothing to print
    assert proc.returncode == 2 and "nothing to do" in proc.stderr
