"""A gallery of crater-saturated asteroids built from the scene presets.

Top row: an Eros-like body with a young (sparse, fresh) and an old (saturated,
degraded) crater population, in the spirit of Li et al. 2022 Figs. A.1/A.2. Bottom row:
Martin et al. 2014 Fig. 8's comparison of base shapes under the same kind of craters:
Perlin fBm (``fbm-cratered``) and two-phase faulting (``faulted-cratered``). Writes
``asteroid_gallery.png``. Environment: ``CRATERFORM_EXAMPLE_OUT`` (default ``out``) and
``CRATERFORM_EXAMPLE_SMALL=1`` (small meshes, quick).
"""

import os
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.image as mpimg  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402

from latlong import Scene, build, render_preview  # noqa: E402

small = os.environ.get("CRATERFORM_EXAMPLE_SMALL") == "1"
out = Path(os.environ.get("CRATERFORM_EXAMPLE_OUT", "out"))
out.mkdir(parents=True, exist_ok=True)
png = out / "_gallery_panel.png"
m_eros, m_small = (80, 60) if small else (700, 500)

scenes = [
    ("Eros-like, young surface: N_cum = 0.03 D^-2, ages < 0.5 Gyr",
     {"preset": "eros-like", "magnitude": m_eros,
      "craters": ["c=0.03,k=-2,d_min_m=40,d_max_m=1500,age_max_gyr=0.5"]}),
    ("Eros-like, old surface: N_cum = 0.15 D^-2, ages < 3.5 Gyr",
     {"preset": "eros-like", "magnitude": m_eros,
      "craters": ["c=0.15,k=-2,d_min_m=40,d_max_m=1500,age_max_gyr=3.5"]}),
    ("Perlin base + N_cum = 0.5 D^-2 (fbm-cratered)",
     {"preset": "fbm-cratered", "magnitude": m_small}),
    ("two-phase faulting + N_cum = 0.1 D^-2 (faulted-cratered)",
     {"preset": "faulted-cratered", "magnitude": m_small}),
]
fig, axes = plt.subplots(2, 2, figsize=(13, 9.5))
for ax, (title, given) in zip(axes.ravel(), scenes, strict=True):
    body = build(Scene.from_settings({**given, "seed": 2014}))
    render_preview(body, png, sun_azimuth_deg=60, sun_elevation_deg=25, width_px=800,
                   height_px=560)
    ax.imshow(mpimg.imread(png))
    ax.set_title(f"{title}\n{len(body.craters):,} craters, magnitude {body.magnitude}",
                 fontsize=10)
    ax.axis("off")
png.unlink()
fig.tight_layout()
fig.savefig(out / "asteroid_gallery.png", dpi=80)
print(f"wrote {out / 'asteroid_gallery.png'}")
