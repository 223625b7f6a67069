"""A gallery of the body presets beside the real shape models they are built from.

Top row: the ``eros``, ``itokawa`` and ``bennu`` presets (bundled shape models, crater and
boulder populations from the published counts; ``latlong presets`` lists the sources).
Bottom row: the bundled shape models themselves, seen from the same direction, so the
outlines can be compared. Writes ``asteroid_gallery.png``. Environment:
``CRATERFORM_EXAMPLE_OUT`` (default ``out``) and ``CRATERFORM_EXAMPLE_SMALL=1`` (coarse,
quick).
"""

import os
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.image as mpimg  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pyvista as pv  # noqa: E402

from latlong import Scene, build, read_shape_model, render_preview  # noqa: E402
from latlong.presets import PRESETS  # noqa: E402

small = os.environ.get("CRATERFORM_EXAMPLE_SMALL") == "1"
out = Path(os.environ.get("CRATERFORM_EXAMPLE_OUT", "out"))
out.mkdir(parents=True, exist_ok=True)
png = out / "_gallery_panel.png"
coarse = {"eros": {"magnitude": 80}, "itokawa": {"spacing_m": 10.0},
          "bennu": {"magnitude": 50}}
view = {"sun_azimuth_deg": 60, "sun_elevation_deg": 25, "width_px": 700, "height_px": 500}

fig, axes = plt.subplots(2, 3, figsize=(16, 9))
for col, name in enumerate(("eros", "itokawa", "bennu")):
    body = build(Scene.from_settings({"preset": name, "seed": 2014,
                                      **(coarse[name] if small else {})}))
    target = body if hasattr(body, "radii_m") else body.to_pyvista()
    render_preview(target, png, **view)
    axes[0, col].imshow(mpimg.imread(png))
    axes[0, col].set_title(f"preset '{name}': {len(body.craters):,} craters, "
                           f"{len(body.boulders):,} boulders", fontsize=10)
    model = read_shape_model(PRESETS[name].model_path, units="km")
    faces = np.hstack([np.full((len(model.faces), 1), 3), model.faces]).ravel()
    real = pv.PolyData(np.asarray(model.vertices) - np.asarray(model.vertices).mean(0), faces)
    render_preview(real, png, **view)
    axes[1, col].imshow(mpimg.imread(png))
    axes[1, col].set_title(f"shape model {PRESETS[name].model} "
                           f"({len(model.faces):,} facets)", fontsize=10)
for ax in axes.ravel():
    ax.axis("off")
png.unlink()
fig.tight_layout()
fig.savefig(out / "asteroid_gallery.png", dpi=80)
print(f"wrote {out / 'asteroid_gallery.png'}")
