"""Base asteroid shapes: the three stages of two-phase faulting and the Fig. 5 fBm sets.

Reproduces the idea of Martin et al. 2014 Fig. 4 (middle row: rough phase-1 body,
smoothed, phase-2 roughness) and Fig. 5 (three Perlin parameter sets) and writes one
montage, ``base_shapes.png``. Environment: ``CRATERFORM_EXAMPLE_MAGNITUDE`` (default
200) and ``CRATERFORM_EXAMPLE_OUT`` (output folder, default ``out``).
"""

import os
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.image as mpimg  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from latlong import (  # noqa: E402
    FAULTING_PRESETS,
    FBM_PRESETS,
    Body,
    LatLongGrid,
    perlin_fbm,
    poisson_faulting,
    render_preview,  # noqa: E402
    smooth,
)

magnitude = int(os.environ.get("CRATERFORM_EXAMPLE_MAGNITUDE", "200"))
out = Path(os.environ.get("CRATERFORM_EXAMPLE_OUT", "out"))
out.mkdir(parents=True, exist_ok=True)
grid = LatLongGrid(magnitude)
radius_m = 100.0
rng = np.random.default_rng(2014)

# two-phase faulting, Fig. 4: 1000 faults <= 5 m, 3 x 20 m smoothing, 500 faults <= 0.5 m
p = FAULTING_PRESETS["fig4"]
stretch = p.stretch
stage1 = poisson_faulting(grid, p.n_faults_1, p.max_fault_1_m, rng=rng)
stage2 = smooth(grid, stage1, p.smooth_width_m, radius_m=radius_m, passes=p.smooth_passes)
stage3 = stage2 + poisson_faulting(grid, p.n_faults_2, p.max_fault_2_m, rng=rng)
panels = [("phase 1: 1000 faults <= 5 m", stage1, stretch),
          ("smoothed: 3 x 20 m", stage2, stretch),
          ("phase 2: 500 faults <= 0.5 m", stage3, stretch)]
# Perlin fBm, Fig. 5 (10 octaves)
for name, fp in FBM_PRESETS.items():
    h = perlin_fbm(grid, fp.frequency, fp.octaves, fp.persistence, fp.lacunarity,
                   fp.amplitude * radius_m, rng=rng)
    panels.append((f"fBm {name}: f={fp.frequency}, p={fp.persistence}, l={fp.lacunarity}", h,
                   (1.0, 1.0, 1.0)))

fig, axes = plt.subplots(2, 3, figsize=(15, 8.5))
for ax, (title, heights, st) in zip(axes.ravel(), panels, strict=True):
    body = Body.from_heights(grid, radius_m, heights, stretch=st)
    png = out / "_panel.png"
    render_preview(body, png, sun_azimuth_deg=70, sun_elevation_deg=25, width_px=640,
                   height_px=480)
    ax.imshow(mpimg.imread(png))
    ax.set_title(title, fontsize=10)
    ax.axis("off")
    png.unlink()
fig.suptitle(f"Base shapes on the lat/long mesh, magnitude {magnitude} "
             f"({grid.n_vertices:,} vertices), radius {radius_m:g} m")
fig.tight_layout()
fig.savefig(out / "base_shapes.png", dpi=80)
print(f"wrote {out / 'base_shapes.png'}")
