"""Slope distributions of synthetic asteroids against Eros (Martin et al. 2014 Fig. 9).

Two-phase faulting and the three Perlin parameter sets of Fig. 5, each with craters
N_cum = 0.5 D^-2, compared with the NEAR Eros plate model: 3-degree averaged per-vertex
slopes (angle between the local normal and the radial direction), slope-area histograms
in 3-degree bins and the cumulative share of steeper ground. Writes ``slope_study.png``
and ``slope_study.csv``. Environment: ``CRATERFORM_EXAMPLE_OUT`` (default ``out``) and
``CRATERFORM_EXAMPLE_SMALL=1``.
"""

import os
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from latlong import (  # noqa: E402
    Scene,
    build,
    mesh_slopes,
    read_shape_model,
    slope_summary,
    slopes_and_areas,
)

small = os.environ.get("CRATERFORM_EXAMPLE_SMALL") == "1"
out = Path(os.environ.get("CRATERFORM_EXAMPLE_OUT", "out"))
out.mkdir(parents=True, exist_ok=True)
magnitude = 40 if small else 300
radius_m = 100.0
d_min = 2.5 * np.pi * radius_m / (2 * magnitude)  # craters from 2.5 vertex spacings
craters = [f"c=0.5,k=-2,d_min_m={d_min:.3f},d_max_m=15"]

cases = [("two-phase faulting", {"preset": "paper"})]
cases += [(f"Perlin {name}", {"preset": name}) for name in ("fig5a", "fig5b", "fig5c")]
results = []
for label, given in cases:
    body = build(Scene.from_settings({**given, "magnitude": magnitude, "radius_m": radius_m,
                                      "craters": craters, "seed": 9}))
    slope_deg, area = slopes_and_areas(body, 3.0)
    results.append((f"{label} + craters", slope_summary(slope_deg, area)))
data = Path(__file__).parents[1] / "tests" / "data"
eros_files = [data / "eros001708.tab", Path("../shared/data/asteroids/eros007790.tab")]
for path in eros_files:
    if path.is_file():
        eros = read_shape_model(path, units="km")
        results.append((f"Eros plate model ({len(eros.faces)} facets)",
                        slope_summary(*mesh_slopes(eros, 3.0))))

fig, (ax0, ax1) = plt.subplots(1, 2, figsize=(13, 5))
eros_styles = iter(["k-", "k--"])
for label, r in results:
    edges, frac = r["edges_deg"], r["area_fraction"]
    centres = 0.5 * (edges[:-1] + edges[1:])[:30]
    style = next(eros_styles) if "Eros" in label else "-"
    above = r["above_percent"][:30]
    ax0.plot(centres, 100 * frac[:30], style, marker="o", ms=3, label=label)
    ax1.semilogy(edges[:30], np.where(above > 1e-6, above, np.nan), style, marker="o", ms=3,
                 label=label)
ax0.set_xlabel("slope (deg), 3 deg bins")
ax0.set_ylabel("share of the surface area (%)")
ax0.set_title("slope-area distribution (3 deg averaged normals)")
ax1.set_xlabel("slope (deg)")
ax1.set_ylabel("area steeper than the slope (%)")
ax1.set_title("cumulative slope-frequency")
for ax in (ax0, ax1):
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_xlim(0, 90)
fig.suptitle(f"Synthetic asteroids (magnitude {magnitude}, radius {radius_m:g} m, "
             "N_cum = 0.5 D^-2 craters) against Eros")
fig.tight_layout()
fig.savefig(out / "slope_study.png", dpi=80)
with open(out / "slope_study.csv", "w", encoding="utf-8") as fh:
    fh.write("input,median_slope_deg,percent_above_10deg,percent_above_20deg,"
             "percent_above_30deg\n")
    for label, r in results:
        pa = r["percent_above"]
        fh.write(f"{label},{r['median_deg']:.3f},{pa[10]:.3f},{pa[20]:.3f},{pa[30]:.3f}\n")
(out / "_tmp.npz").unlink(missing_ok=True)
print(f"wrote {out / 'slope_study.png'} and {out / 'slope_study.csv'}")
