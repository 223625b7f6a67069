"""The README's landing-site stack (``examples/site.toml``) on the Moon, with the checks a
lunar scientist would make.

The 257 x 257 crop of LOLA LDEM_4 in ``tests/data`` (7.6 km/px, centred on the equator
at 180 E) is the base of ``dem.enhance``: layers of 129 x 129 pixels around the target,
each the random-midpoint-displacement expansion of the central half of the previous
one, with a 3.9 Gyr lunar crater population (Neukum et al. 2001 production function and
chronology, Trask equilibrium) below what the LOLA DEM resolves (4 source pixels), each
crater put into the finest layer that contains it. The montage shows the hillshade of
every layer with the footprint of the next one outlined; the titles give the pixel
size, the craters stamped, the height range (the Moon's: about -9.1 ... +10.8 km) and
the median Horn slope (LOLA's own at layer 0's pixel size for comparison; real lunar
slopes steepen at shorter baselines). The layers match exactly where they overlap
(asserted). Writes ``dem_enhance.png``. Environment: ``CRATERFORM_EXAMPLE_OUT``
(output folder, default ``out``), ``CRATERFORM_EXAMPLE_SMALL=1`` (5 layers of 65 x 65).
"""

import math
import os
import tomllib
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.colors import LightSource  # noqa: E402
from matplotlib.patches import Rectangle  # noqa: E402

import dem  # noqa: E402

small = os.environ.get("CRATERFORM_EXAMPLE_SMALL") == "1"
out = Path(os.environ.get("CRATERFORM_EXAMPLE_OUT", "out"))
out.mkdir(parents=True, exist_ok=True)
root = Path(__file__).resolve().parents[1]
with open(root / "examples" / "site.toml", "rb") as f:
    site = tomllib.load(f)
base = dem.read(root / site.pop("input"))  # heights in metres, geographic CRS (Moon)
site.pop("output")
scene = {**site, "seed": 2014}
if small:
    scene.update(layers=5, size=65)
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
    z = layer.heights
    slope = float(np.nanmedian(dem.slope(layer)))
    ax.set_title(f"layer {k}: {sizes[k] * scale:.3g} {unit}/px, {stamped[k]} craters\n"
                 f"{z.min() / 1e3:.1f} ... {z.max() / 1e3:.1f} km, median slope {slope:.1f} deg",
                 fontsize=10)
    ax.axis("off")
# LOLA's own slopes over layer 0's footprint (layer 0 is the source's grid there)
l0 = stack.layers[0]
col0 = round((l0.transform.c - base.transform.c) / base.transform.a)
row0 = round((l0.transform.f - base.transform.f) / base.transform.e)
win = dem.slope(base)[row0:row0 + l0.shape[0], col0:col0 + l0.shape[1]]
fig.suptitle(f"examples/site.toml: dem.enhance of LOLA LDEM_4 around 0 N 180 E, {n} layers "
             f"of {scene['size']}^2, {sum(stamped)} craters stamped; LOLA's own median "
             f"slope over layer 0's window: {np.nanmedian(win):.1f} deg", fontsize=11)
fig.tight_layout()
fig.savefig(out / "dem_enhance.png", dpi=80)
print(f"wrote {out / 'dem_enhance.png'}")
