"""The evenly spaced lat/long mesh: a pole seen from above, and edge-length statistics.

Martin et al. 2014 Fig. 2-3: ring L holds 6L vertices, so triangles stay nearly the same
size up to the poles (no thin polar fans). Writes ``mesh_structure.png`` with the north
pole of a magnitude-8 grid and the edge-length ratio against magnitude. Environment:
``CRATERFORM_EXAMPLE_MAGNITUDE`` (largest magnitude in the ratio plot, default 128) and
``CRATERFORM_EXAMPLE_OUT`` (default ``out``).
"""

import os
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.collections import LineCollection  # noqa: E402

from latlong import LatLongGrid  # noqa: E402

largest = int(os.environ.get("CRATERFORM_EXAMPLE_MAGNITUDE", "128"))
out = Path(os.environ.get("CRATERFORM_EXAMPLE_OUT", "out"))
out.mkdir(parents=True, exist_ok=True)

fig, (ax0, ax1) = plt.subplots(1, 2, figsize=(12, 5.5))
# left: the northern hemisphere of a magnitude-8 grid, azimuthal equidistant projection
g = LatLongGrid(8)
colat = np.pi / 2 - g.latitudes()
xy = np.stack([colat * np.cos(g.longitudes()), colat * np.sin(g.longitudes())], axis=1)
e = g.edges()
north = (g.vertex_rings()[e] <= g.magnitude).all(axis=1)
ax0.add_collection(LineCollection(xy[e[north]], linewidths=0.7, colors="0.3"))
keep = g.vertex_rings() <= g.magnitude
ax0.scatter(*xy[keep].T, s=8, c=g.vertex_rings()[keep], cmap="viridis", zorder=3)
ax0.set_aspect("equal")
ax0.set_title("magnitude 8, northern hemisphere from above\n(ring L holds 6L vertices)")
ax0.axis("off")

# right: longest / shortest edge against magnitude
mags = np.unique(np.geomspace(1, largest, 16).astype(int))
ratios = []
for m in mags:
    gm = LatLongGrid(int(m))
    u = gm.unit_vectors()
    em = gm.edges()
    length = np.linalg.norm(u[em[:, 0]] - u[em[:, 1]], axis=1)
    ratios.append(length.max() / length.min())
ax1.semilogx(mags, ratios, "o-")
ax1.axhline(2.5, color="r", ls="--", label="acceptance limit 2.5")
ax1.set_xlabel("magnitude M")
ax1.set_ylabel("longest / shortest edge")
ax1.set_ylim(1, 3)
ax1.legend()
ax1.grid(True, which="both", alpha=0.3)
ax1.set_title("edge-length ratio")
fig.tight_layout()
fig.savefig(out / "mesh_structure.png", dpi=80)
print(f"wrote {out / 'mesh_structure.png'}")
