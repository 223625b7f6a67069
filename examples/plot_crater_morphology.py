"""Crater morphology on the Moon and other bodies: fresh shapes by size, ageing by
diffusion, and the same crater on different targets.

Top row: fresh lunar craters stamped on flat ground - a simple bowl, a flat-floored
transitional crater, complex craters with central peaks and terraced walls, and a
peak-ring basin (Pike 1977; Baker et al. 2011) - with their roughness: irregular rims,
scalloped terraces that wander, merge and split, and central peaks broken into massifs.
Middle row: one 1 km crater at model ages from 0 to 3.8 Gyr, degraded by topographic
diffusion (Fassett & Thomson 2014).
Bottom: radial profiles with their depth/diameter, and the same 20 km crater on the
Moon, Mars, Mercury and Ceres (Pike 1977/1988, Garvin & Frawley 1998; 1/g scaling).
Writes ``crater_morphology.png``. Environment: ``CRATERFORM_EXAMPLE_OUT`` (default
``out``) and ``CRATERFORM_EXAMPLE_SMALL=1``.
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
n = 129 if small else 401
light = LightSource(azdeg=270, altdeg=25)


def single(diameter_m, *, age_gyr=0.0, degradation=0.0, target="moon", roughness=False):
    """One crater at the centre of flat ground 3.4 diameters across: heights, pixel."""
    pixel = 3.4 * diameter_m / (n - 1)
    c = (n - 1) / 2 * pixel
    cat = craters.make_catalog(x_m=[c], y_m=[c], diameter_m=[diameter_m], age_gyr=[age_gyr],
                               degradation=[degradation])
    h, stamped = craters.stamp_many(np.zeros((n, n)), pixel, cat, roughness=roughness,
                                    target=target, return_catalog=True, rng=1)
    return h, pixel, stamped[0]


def shade(ax, h, pixel, title):
    ax.imshow(light.hillshade(h, vert_exag=2.0, dx=pixel, dy=pixel), cmap="gray",
              origin="lower")
    ax.set_title(title, fontsize=9)
    ax.set_xticks([])
    ax.set_yticks([])


fresh_km = [2.0, 18.0, 45.0, 120.0, 330.0]
ages = [0.0, 0.1, 1.0, 2.0, 3.8]
fig = plt.figure(figsize=(15, 10.5))
grid = fig.add_gridspec(3, 5, height_ratios=[1, 1, 1.15])

x = np.linspace(0.0, 1.6, 801)
ax_fresh = fig.add_subplot(grid[2, 0:2])
for j, d_km in enumerate(fresh_km):
    h, pixel, row = single(d_km * 1000.0, roughness=True)
    m = craters.crater_morphometry(d_km * 1000.0)
    shade(fig.add_subplot(grid[0, j]), h, pixel,
          f"D = {d_km:g} km: {row['morphology']}\nd/D = {m['depth_diameter']:.3f}")
    ax_fresh.plot(x, craters.radial_profile(x, d_km * 1000.0) / (d_km * 1000.0),
                  label=f"{d_km:g} km ({row['morphology']})")
ax_fresh.set_xlabel("r / R")
ax_fresh.set_ylabel("height / D")
ax_fresh.set_title("fresh lunar profiles (Pike 1977 depth and rim laws)", fontsize=9)
ax_fresh.legend(fontsize=8)

ax_age = fig.add_subplot(grid[2, 2:4])
for j, age in enumerate(ages):
    h, pixel, row = single(1000.0, age_gyr=age, degradation=np.nan)
    m = craters.crater_morphometry(1000.0, age_gyr=age)
    shade(fig.add_subplot(grid[1, j]), h, pixel,
          f"1 km, {age:g} Gyr: d/D = {m['depth_diameter']:.3f}\n"
          f"degradation {row['degradation']:.2f}")
    ax_age.plot(x, craters.radial_profile(x, 1000.0, age_gyr=age),
                label=f"{age:g} Gyr")
ax_age.set_xlabel("r / R")
ax_age.set_ylabel("height (m)")
ax_age.set_title("a 1 km lunar crater ageing by diffusion (Fassett & Thomson 2014)",
                 fontsize=9)
ax_age.legend(fontsize=8)

ax_body = fig.add_subplot(grid[2, 4])
for body in ("moon", "mars", "mercury", "ceres"):
    m = craters.crater_morphometry(20_000.0, target=body)
    ax_body.plot(x, craters.radial_profile(x, 20_000.0, target=body) / 1000.0,
                 label=f"{body}: d/D {m['depth_diameter']:.3f}, {m['morphology']}")
ax_body.set_xlabel("r / R")
ax_body.set_ylabel("height (km)")
ax_body.set_title("a fresh 20 km crater on four bodies", fontsize=9)
ax_body.legend(fontsize=7)

fig.tight_layout()
fig.savefig(out / "crater_morphology.png", dpi=80)
print(f"wrote {out / 'crater_morphology.png'}")
