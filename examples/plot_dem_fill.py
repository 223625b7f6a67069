"""Filling large gaps in a real DEM with fractal terrain that meets their rims.

A 257 x 257 crop of LOLA LDEM_4 (7.6 km/px, from ``tests/data``) and a synthetic fBm
surface (F = 2.3) each lose a disc of 160 pixels and a square of 60 pixels;
``dem.fill_gaps`` fills them (fBm noise of the terrain's own fractal dimension and local
relief, plus the harmonic interpolation of the mismatch on the rims) and, in the LOLA
crop, stamps craters at the density the crater detector measures around them. The
hillshades (light from the north-west, where a grid-aligned crosshatch would show) are
the original, the DEM with its gaps, and the filled DEM; the titles give the fill's
diagonal-to-axis power at the Nyquist corner and its power at 6-12 px wavelengths,
each relative to the original terrain under the disc (1 = the same spectrum). Writes
``dem_fill.png``. Environment: ``CRATERFORM_EXAMPLE_OUT`` (output folder, default
``out``), ``CRATERFORM_EXAMPLE_SMALL=1`` (a 129 x 129 crop, faster).
"""

import os
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.colors import LightSource  # noqa: E402
from rasterio.windows import Window  # noqa: E402

import dem  # noqa: E402

small = os.environ.get("CRATERFORM_EXAMPLE_SMALL") == "1"
out = Path(os.environ.get("CRATERFORM_EXAMPLE_OUT", "out"))
out.mkdir(parents=True, exist_ok=True)
data = Path(__file__).resolve().parents[1] / "tests" / "data" / "ldem4_crop.lbl"

lola = dem.read(data)  # heights in metres, geographic CRS
if small:
    lola = lola.crop(Window(64, 64, 129, 129))
n = lola.shape[0]

# an fBm surface by spectral synthesis: amplitude f^(-beta/2), beta = 8 - 2F
f = np.hypot(*np.meshgrid(np.fft.fftfreq(n), np.fft.fftfreq(n), indexing="ij"))
f[0, 0] = 1.0
amp = f ** (-(8.0 - 2 * 2.3) / 2.0)
amp[0, 0] = 0.0
phase = np.exp(2j * np.pi * np.random.default_rng(0).random((n, n)))
fbm = dem.Dem(np.fft.ifft2(amp * phase).real * 300.0, pixel_size_m=100.0)

yy, xx = np.mgrid[0:n, 0:n]
radius = 0.31 * n
disc = (yy - n / 2) ** 2 + (xx - n / 2) ** 2 < radius**2
square = np.zeros((n, n), bool)
s0, s1 = int(0.04 * n), int(0.27 * n)
square[s0:s1, s0:s1] = True
gap = disc | square


def spectrum_ratios(filled, truth):
    """Diagonal-to-axis Nyquist power and mid-band power, fill over truth."""
    def zones(p):
        k = p.shape[0]
        a = np.column_stack([np.ones(k * k), np.tile(np.arange(k), k), np.repeat(np.arange(k), k)])
        p = p - (a @ np.linalg.lstsq(a, p.ravel(), rcond=None)[0]).reshape(k, k)
        s = np.abs(np.fft.fft2(p * np.outer(np.hanning(k), np.hanning(k)))) ** 2
        fy, fx = np.abs(np.fft.fftfreq(k))[:, None], np.abs(np.fft.fftfreq(k))[None, :]
        corner = (fx > 0.35) & (fy > 0.35)
        edge = ((fx > 0.4) & (fy < 0.1)) | ((fy > 0.4) & (fx < 0.1))
        mid = (np.hypot(fx, fy) > 0.08) & (np.hypot(fx, fy) < 0.16)
        return s[corner].mean() / s[edge].mean(), s[mid].mean()

    (hf, mf), (ht, mt) = zones(filled), zones(truth)
    return hf / ht, mf / mt


light = LightSource(azdeg=315, altdeg=40)
fig, axes = plt.subplots(2, 3, figsize=(13, 9))
inner = int(radius / np.sqrt(2))
patch = np.s_[n // 2 - inner:n // 2 + inner, n // 2 - inner:n // 2 + inner]
for row, (name, d) in enumerate((("LOLA LDEM_4 crop", lola), ("fBm, F = 2.3", fbm))):
    gappy = d.replace(heights=np.where(gap, np.nan, d.heights))
    filled = dem.fill_gaps(gappy, rng=1)
    step = filled.history[-1]["parameters"]
    hatch, mid = spectrum_ratios(filled.heights[patch], d.heights[patch])
    exaggeration = 3.0 / np.std(np.diff(d.heights, axis=1))
    for col, (title, z) in enumerate((("original", d.heights),
                                      ("gaps", np.where(gap, np.nanmean(d.heights),
                                                        d.heights)),
                                      ("filled", filled.heights))):
        ax = axes[row, col]
        ax.imshow(light.hillshade(z, vert_exag=exaggeration), cmap="gray",
                  interpolation="nearest")
        if col == 1:
            ax.contour(gap, levels=[0.5], colors="red", linewidths=0.8)
        ax.set_title(f"{name}: {title}", fontsize=9)
        ax.set_xticks([])
        ax.set_yticks([])
    axes[row, 2].set_title(
        f"{name}: filled, F = {step['fractal_dimension']:.2f}, "
        f"{step.get('craters', 0)} craters\nNyquist diagonal/axis x{hatch:.2f}, "
        f"6-12 px power x{mid:.2f} (1 = the original's)", fontsize=9)
fig.tight_layout()
path = out / "dem_fill.png"
fig.savefig(path, dpi=90)
print(f"wrote {path}")
