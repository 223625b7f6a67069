"""Real shape models as lat/long bodies: Itokawa upsampled from q = 8, Bennu with craters.

Top row: the Itokawa q = 8 model (386 vertices), the lat/long body made from it (ray
cast through a butterfly-subdivided surface), and the q = 32 model of the same body for
comparison, with the mean surface distance of each to q = 32. Bottom: the Bennu radar
model imported and given craters below its resolution. Writes ``shape_import.png``.
Environment: ``CRATERFORM_EXAMPLE_OUT`` (default ``out``), ``CRATERFORM_EXAMPLE_SMALL=1``.
"""

import os
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.image as mpimg  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from latlong import Body, Scene, build, from_shape_model, read_shape_model, render_preview  # noqa: E402, I001
from latlong.shapes import mean_surface_distance  # noqa: E402

small = os.environ.get("CRATERFORM_EXAMPLE_SMALL") == "1"
out = Path(os.environ.get("CRATERFORM_EXAMPLE_OUT", "out"))
out.mkdir(parents=True, exist_ok=True)
data = Path(__file__).parents[1] / "tests" / "data"
magnitude = 60 if small else 200
png = out / "_shape_panel.png"
rng = np.random.default_rng(0)


def distance(a, b):
    return mean_surface_distance(a, b, rng=rng)


q8 = read_shape_model(data / "itokawa_8.obj", units="km")
q32 = read_shape_model(data / "itokawa_32.obj", units="km")
centre = q32.volume_centroid
fine = q32.to_pyvista().translate(-centre)
body8 = from_shape_model(q8, magnitude, center=centre, crossings="outermost")


def as_body(model, smooth="linear"):
    """A shape model drawn with the same renderer (its radii on the grid)."""
    return from_shape_model(model, magnitude, center=centre, crossings="outermost",
                            smooth=smooth)


d_q8 = distance(q8.to_pyvista().translate(-centre), fine)
d_body = distance(body8.to_pyvista(), fine)
panels = [
    (f"Itokawa q = 8 ({len(q8.vertices)} vertices): {d_q8:.2f} m from q = 32", as_body(q8)),
    (f"lat/long body from q = 8, M = {magnitude}: {d_body:.2f} m from q = 32", body8),
    (f"Itokawa q = 32 ({len(q32.vertices)} vertices, drawn smoothed)",
     as_body(q32, "butterfly")),
]
bennu = build(Scene.from_settings({
    "base": f"shape:{data / 'bennu_radar_sbgat.obj'}", "shape_units": "km",
    "magnitude": 2 * magnitude, "craters": ["c=0.9,k=-3,d_min_m=4,d_max_m=40"], "amplitude_m": 0.5,
    "seed": 1}))
title = f"Bennu radar model + {len(bennu.craters):,} craters 4-40 m, M = {2 * magnitude}"
panels.append((title, bennu))

fig, axes = plt.subplots(2, 2, figsize=(12, 9))
for ax, (title, body) in zip(axes.ravel(), panels, strict=True):
    assert isinstance(body, Body)
    render_preview(body, png, sun_azimuth_deg=60, sun_elevation_deg=25, width_px=640,
                   height_px=480)
    ax.imshow(mpimg.imread(png))
    ax.set_title(title, fontsize=9)
    ax.axis("off")
png.unlink()
fig.tight_layout()
fig.savefig(out / "shape_import.png", dpi=80)
print(f"wrote {out / 'shape_import.png'}")
