"""A crater-saturated synthetic lunar terrain (like Fig. 4 of the lunar paper).

A fractal base surface (spectral synthesis, fractal dimension 2.2) receives a lunar
mare crater population, N_cum = c D^-1.8, stamped oldest first with degradation from
age, irregular rims and roughness. Writes ``crater_terrain.png`` (shaded relief and a
profile across it) and ``crater_terrain.csv`` (the ground-truth catalog). Environment:
``CRATERFORM_EXAMPLE_OUT`` (default ``out``) and ``CRATERFORM_EXAMPLE_SMALL=1``.
"""

import os
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.colors import LightSource  # noqa: E402

import craters  # noqa: E402

small = os.environ.get("CRATERFORM_EXAMPLE_SMALL") == "1"
out = Path(os.environ.get("CRATERFORM_EXAMPLE_OUT", "out"))
out.mkdir(parents=True, exist_ok=True)
n = 257 if small else 1025
pixel_m = 1.0
rng = np.random.default_rng(4)

# fractal base: power spectrum ~ f^-(2H+2) with H = 3 - F = 0.8
f = np.hypot(*np.meshgrid(np.fft.fftfreq(n), np.fft.fftfreq(n)))
f[0, 0] = 1.0
spectrum = f ** -(0.8 + 1.0) * np.exp(2j * np.pi * rng.random((n, n)))
spectrum[0, 0] = 0.0
base = np.fft.ifft2(spectrum).real
base *= 2.0 / base.std()  # metres

side = (n - 1) * pixel_m
layer = craters.CraterLayer(c=0.05, k=-1.8, d_min_m=3.0, d_max_m=side / 3, age_max_gyr=3.8)
cat = craters.population([layer], x_range_m=(0, side), y_range_m=(0, side), rng=rng)
heights, stamped = craters.stamp_many(base, pixel_m, cat, rng=rng, return_catalog=True)
craters.write_catalog(stamped, out / "crater_terrain.csv")

fig, (ax0, ax1) = plt.subplots(1, 2, figsize=(14, 6.5), gridspec_kw={"width_ratios": [1, 1.2]})
ls = LightSource(azdeg=270, altdeg=20)
ax0.imshow(ls.hillshade(heights, vert_exag=1.0, dx=pixel_m, dy=pixel_m), cmap="gray",
           origin="lower", extent=(0, side, 0, side))
ax0.set_title(f"{len(stamped)} craters, N_cum = 0.05 D^-1.8, D 3-{side / 3:.0f} m")
ax0.set_xlabel("x (m)")
ax0.set_ylabel("y (m)")
row = n // 2
ax0.axhline(row * pixel_m, color="r", lw=0.8)
ax1.plot(np.arange(n) * pixel_m, base[row], color="0.6", lw=1, label="base terrain")
ax1.plot(np.arange(n) * pixel_m, heights[row], "k", lw=1, label="with craters")
ax1.set_xlabel("x (m)")
ax1.set_ylabel("height (m)")
ax1.set_title("profile along the red line")
ax1.legend()
fig.tight_layout()
fig.savefig(out / "crater_terrain.png", dpi=80)
print(f"wrote {out / 'crater_terrain.png'} and {out / 'crater_terrain.csv'}")
