"""The implicit backend (Li et al. 2020, 2022): an Eros-like body from the 1708-plate model.

Top row: the LCSN crater kernels of Li 2022 Fig. 6 (normalised), and kernel_3 fitted to
Fassett & Thomson's degradation of a 1 km crater over 0-3 Gyr (Table A.1). Middle: the
constraint (NEAR MSI plate model), its non-uniform sphere packing, the bare metaball
surface fitted to it (``constraint_weight=0``: one dome per ball) and the coarse surface
the body is built on (the default ``constraint_weight=1``: the constraint's own signed
distance, smooth where the constraint is smooth), each with its mean distance to the
constraint and the KS distance of its slope-against-a-5 %-smoothed-copy distribution from
the constraint's (:func:`latlong.implicit.shape_fidelity`). Bottom: three LCSN crater
layers on the multi-level grid (3 km fresh craters on 4 km cells, 1 km fresh on 2 km
cells, simple bowls on 1 km cells) and Gabor micro-detail fitted by example to the LOLA
LDEM_4 crop in ``tests/data`` (its 7.6 km pixels read as 100 m, 12 m rms), from two sides.
Writes ``implicit_asteroid.png``. Environment: ``CRATERFORM_EXAMPLE_OUT`` (default ``out``),
``CRATERFORM_EXAMPLE_SMALL=1``.
"""

import os
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.image as mpimg  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import craters  # noqa: E402
import dem  # noqa: E402
from latlong import render_preview  # noqa: E402
from latlong.implicit import (  # noqa: E402
    LcsnLayer,
    fit_gabor,
    implicit_surface,
    shape_fidelity,
)
from latlong.shapes import ShapeModel, read_shape_model  # noqa: E402

small = os.environ.get("CRATERFORM_EXAMPLE_SMALL") == "1"
out = Path(os.environ.get("CRATERFORM_EXAMPLE_OUT", "out"))
out.mkdir(parents=True, exist_ok=True)
data = Path(__file__).parents[1] / "tests" / "data"
polygons = 40_000 if small else 400_000
png = out / "_implicit_panel.png"

fig = plt.figure(figsize=(13, 13))
grid = fig.add_gridspec(3, 2, height_ratios=[0.8, 1, 1])

# kernels: Fig. 6 and Table A.1
ax = fig.add_subplot(grid[0, 0])
r = np.linspace(0.0, 3.0, 601)
for kind, label in ((1, "simple 1"), (2, "simple 2"), (3, "fresh"), (4, "complex")):
    p = craters.LCSN_PRESETS[f"fig6-kernel{kind}"]
    ax.plot(np.concatenate([-r[::-1], r]), np.concatenate(
        [craters.lcsn_kernel(kind, r[::-1], **p.raw), craters.lcsn_kernel(kind, r, **p.raw)]),
        label=f"kernel_{kind} ({label})")
ax.set(title="Li 2022 Fig. 6 kernels (normalised)", xlabel="r", ylabel="height")
ax.legend(fontsize=8)
ax = fig.add_subplot(grid[0, 1])
r = np.linspace(0.0, 1200.0, 601)
for age in range(4):
    p = craters.LCSN_PRESETS[f"table-a1-1km-{age}gyr"]
    m = p.morphometry("numeric")
    rim = f"rim {m['H_rim']:.1f} m" if np.isfinite(m["H_rim"]) else "no rim"
    ax.plot(np.concatenate([-r[::-1], r]), np.concatenate(
        [craters.lcsn_kernel(3, r[::-1], **p.raw), craters.lcsn_kernel(3, r, **p.raw)]),
        label=f"{age} Gyr: depth {m['H_t']:.0f} m, {rim}")
ax.set(title="kernel_3, Table A.1: a 1 km crater over 3 Gyr", xlabel="r (m)",
       ylabel="height (m)")
ax.legend(fontsize=8)

# the body
model = read_shape_model(data / "eros001708.tab", units="km")
moved = ShapeModel(model.vertices - model.volume_centroid, model.faces)
layers = [LcsnLayer("table-a1-3km-0gyr", 2000, 4000, exponent=3.0, probability=0.6),
          LcsnLayer("table-a1-1km-0gyr", 1000, 2000, exponent=3.0, probability=0.6),
          LcsnLayer("fig6-kernel1", 500, 1000, exponent=3.0, probability=0.5,
                    depth_ratio=(0.1, 0.2))]
gabor = fit_gabor(dem.read(data / "ldem4_crop.lbl").heights, 100.0, amplitude_m=12.0)
surf = implicit_surface(model, layers, gabor=gabor, target_polygons=polygons, rng=2022)
coarse = ShapeModel(surf.base_vertices, surf.base_faces)
bare = implicit_surface(model, target_polygons=polygons, constraint_weight=0.0, rng=2022)
bare = ShapeModel(bare.base_vertices, bare.base_faces)
# (small: 4 000 query points; the slope measure's cost grows as their square)
fits = [shape_fidelity(m, moved, fine=0.02 if small else 0.01,
                       n_points=4000 if small else 20000) for m in (bare, coarse)]
import pyvista as pv  # noqa: E402

balls = pv.merge([pv.Sphere(radius=float(rad), center=tuple(c), theta_resolution=16,
                            phi_resolution=16)
                  for c, rad in zip(surf.packing.centers, surf.packing.radii, strict=True)])
pk = surf.metadata["packing"]
sub = grid[1, :].subgridspec(1, 4)
panels = [
    (sub[0], moved.to_pyvista(), f"constraint: NEAR MSI plates, {len(model.faces)} facets"),
    (sub[1], balls, f"sphere packing: {pk['spheres']} balls, coverage {pk['coverage']:.0%}"),
]
for spec, mesh, label, f in ((sub[2], bare, f"bare metaballs (blend {surf.metaballs.blend:g})",
                              fits[0]), (sub[3], coarse, "coarse surface (weight 1)", fits[1])):
    panels.append((spec, mesh.to_pyvista(), (f"{label}\n{100 * f.mean_fraction:.2f} % of the "
                   f"axis off, slope KS {f.slope_ks:.2f}")))
bottom = grid[2, :].subgridspec(1, 2)
n_by_layer = [int((surf.catalog["layer"] == i).sum()) for i in range(3)]
title = (f"{len(surf.faces):,} triangles, {len(surf.catalog)} craters "
         f"({' + '.join(map(str, n_by_layer))} on 4 / 2 / 1 km cells), Gabor by example")
panels += [(bottom[0], surf.to_pyvista(), title), (bottom[1], surf.to_pyvista(),
                                                   "the same body from +y, sun low")]
for k, (spec, mesh, label) in enumerate(panels):
    view = (0.0, 90.0, 60.0, 20.0) if k == 4 else (20.0, -90.0, 60.0, 25.0)
    render_preview(mesh, png, view_lat_deg=view[0], view_lon_deg=view[1],
                   sun_azimuth_deg=view[2], sun_elevation_deg=view[3], width_px=900,
                   height_px=520)
    ax = fig.add_subplot(spec)
    ax.imshow(mpimg.imread(png))
    ax.set_title(label, fontsize=9)
    ax.axis("off")
png.unlink()
fig.tight_layout()
fig.savefig(out / "implicit_asteroid.png", dpi=80)
print(f"wrote {out / 'implicit_asteroid.png'}")
