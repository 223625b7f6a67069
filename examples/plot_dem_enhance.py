"""Enhancing a real DEM around a site: nested layers, each 2x finer, with craters per layer.

The 257 x 257 crop of LOLA LDEM_4 in ``tests/data`` (7.6 km/px, centred on the equator
at 180 E) is the base of ``dem.enhance``: layers of 129 x 129 pixels around the target
(0 N, 180 E), each the random-midpoint-displacement expansion of the central half of
the previous one, with craters from one population (N_cum = 0.05 D^-2 per m^2 plus an
older, shallower-sloped family) put into the finest layer that contains them. The
montage shows the hillshade of every layer with the footprint of the next one outlined;
the titles give the pixel size and the craters stamped in that layer. The layers match
exactly where they overlap (asserted). Writes ``dem_enhance.png``. Environment:
``CRATERFORM_EXAMPLE_OUT`` (output folder, default ``out``),
``CRATERFORM_EXAMPLE_SMALL=1`` (4 layers of 65 x 65, faster).
"""

import math
import os
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.colors import LightSource  # noqa: E402
from matplotlib.patches import Rectangle  # noqa: E402

import dem  # noqa: E402

small = os.environ.get("CRATERFORM_EXAMPLE_SMALL") == "1"
out = Path(os.environ.get("CRATERFORM_EXAMPLE_OUT", "out"))
out.mkdir(parents=True, exist_ok=True)
data = Path(__file__).resolve().parents[1] / "tests" / "data" / "ldem4_crop.lbl"

base = dem.read(data)  # heights in metres, geographic CRS on a 1737.4 km sphere
scene = {
    "layers": 4 if small else 6,
    "size": 65 if small else 129,
    "target": [180.0, 0.0],  # lon, lat in degrees (the CRS's units)
    "seed": 2014,
    "craters": ["c=0.05,k=-2,d_min_m=20,d_max_m=150000",
                "c=0.005,k=-1.8,d_min_m=20000,d_max_m=300000,age_min_gyr=3,age_max_gyr=3.9,kind=old"],
}
stack = dem.enhance(scene, dem=base)
assert stack.is_consistent()  # finer even pixels == coarser footprint, every pair

sizes = stack.pixel_sizes_m()
stamped = stack.info["craters"]["stamped"]
n = len(stack)
cols = math.ceil(n / 2)
light = LightSource(azdeg=300, altdeg=30)
fig, axes = plt.subplots(2, cols, figsize=(4.6 * cols, 9.4))
for k, ax in enumerate(axes.flat):
    if k >= n:
        ax.axis("off")
        continue
    layer = stack.layers[k]
    shade = light.hillshade(layer.heights, vert_exag=2, dx=sizes[k], dy=sizes[k])
    ax.imshow(shade, cmap="gray", vmin=0, vmax=1, interpolation="nearest")
    if k + 1 < n:
        r0, c0, w = stack.windows[k]
        ax.add_patch(Rectangle((c0 - 0.5, r0 - 0.5), w, w, fill=False, ec="tab:red", lw=1.5))
    unit, scale = ("km", 1e-3) if sizes[k] >= 1000 else ("m", 1.0)
    ax.set_title(f"layer {k}: {sizes[k] * scale:.3g} {unit}/px, {stamped[k]} craters",
                 fontsize=10)
    ax.axis("off")
c = stack.info["craters"]
fig.suptitle(f"dem.enhance of LOLA LDEM_4 around 0 N 180 E: {n} layers of "
             f"{scene['size']}^2, {sum(stamped)} craters stamped, {c['rejected']:.3g} of "
             f"{c['drawn']:.3g} drawn rejected (too small for the layers containing them)",
             fontsize=11)
fig.tight_layout()
fig.savefig(out / "dem_enhance.png", dpi=80)
print(f"wrote {out / 'dem_enhance.png'}")
