"""Boulders (Martin et al. 2014, V.C): the nested levels, a boulder field on an
asteroid, and boulders stamped into a DEM.

Writes ``boulder_levels.png`` (one boulder at its four levels and a few shape
settings), ``boulder_body.png`` (a rendered close-up of a cratered body with N_cum =
0.004 D^-3 boulders, 30 % around crater rims), ``boulder_dem.png`` (a 0.25 m DEM before
and after stamping, hill-shaded, and the catalog's size-frequency distribution against
the requested law). Environment: ``CRATERFORM_EXAMPLE_OUT`` (default ``out``) and
``CRATERFORM_EXAMPLE_SMALL=1``.
"""

import os
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import craters  # noqa: E402
import dem  # noqa: E402
from latlong import Scene, build, render_preview  # noqa: E402

small = os.environ.get("CRATERFORM_EXAMPLE_SMALL") == "1"
out = Path(os.environ.get("CRATERFORM_EXAMPLE_OUT", "out"))
out.mkdir(parents=True, exist_ok=True)



def equal_axes(ax):
    """Same scale on x, y, z (the meshes have a unit longest extent)."""
    for setter in (ax.set_xlim, ax.set_ylim, ax.set_zlim):
        setter(-0.5, 0.5)
    ax.set_box_aspect((1, 1, 1))
    ax.view_init(elev=20, azim=-60)
    ax.set_axis_off()


# 1. one boulder, four levels; then the shape parameters
fig = plt.figure(figsize=(13, 6))
node = craters.boulder(rng=5)
for i, (v, f) in enumerate(node.meshes()):
    ax = fig.add_subplot(2, 4, i + 1, projection="3d")
    ax.plot_trisurf(v[:, 0], v[:, 1], v[:, 2], triangles=f, color="0.7", edgecolor="0.3",
                    linewidth=0.2)
    ax.set_title(f"level {node.level + i}: {len(v)} vertices")
    equal_axes(ax)
for i, (label, shape) in enumerate([
        ("default", craters.BoulderShape()),
        ("flat slab", craters.BoulderShape(flatten=0.3, elongation=1.8)),
        ("rounded", craters.BoulderShape(roughness=0.08, flatten=0.8, elongation=1.1)),
        ("jagged", craters.BoulderShape(roughness=0.5))]):
    v, faces = craters.boulder_meshes([11], shape)
    ax = fig.add_subplot(2, 4, 5 + i, projection="3d")
    ax.plot_trisurf(v[0, :, 0], v[0, :, 1], v[0, :, 2], triangles=faces[3], color="0.6",
                    linewidth=0)
    ax.set_title(label)
    equal_axes(ax)
fig.tight_layout()
fig.savefig(out / "boulder_levels.png", dpi=90)
plt.close(fig)

# 2. a boulder field on a small cratered asteroid, seen from close by
body = build(Scene.from_settings({
    "preset": "fig5a", "magnitude": 60 if small else 500, "radius_m": 250.0,
    "craters": ["c=0.1,k=-2,d_min_m=4,d_max_m=60"],
    "boulders": ["c=0.02,k=-3,d_min_m=1.5,d_max_m=25,near=0.3"], "seed": 3}))
print(f"body: M = {body.magnitude}, {len(body.craters)} craters, {len(body.boulders)} "
      f"boulders")
render_preview(body, out / "boulder_body.png", sun_elevation_deg=12.0,
               camera_distance_m=1.6 * 250.0, width_px=640 if small else 1280,
               height_px=480 if small else 960)

# 3. boulders stamped into a 0.25 m DEM
rng = np.random.default_rng(2)
seed_dem = dem.Dem(rng.normal(0, 1.0, (17, 17)), pixel_size_m=4.0)
terrain = dem.expand(seed_dem, 4, fractal_dimension=2.3, roughness=0.03, rng=1)
layer = craters.BoulderLayer(c=0.02, k=-3.0, d_min_m=0.5, d_max_m=8.0)
rocks = dem.boulder_population(terrain, layer, rng=3)
stamped, placed = dem.stamp_boulders(terrain, rocks, return_catalog=True)


def hillshade(z, p, az=300.0, el=25.0):
    gy, gx = np.gradient(z, p)
    n = np.dstack([-gx, gy, np.ones_like(z)])
    n /= np.linalg.norm(n, axis=2, keepdims=True)
    a, e = np.radians(az), np.radians(el)
    return np.clip(n @ [np.cos(e) * np.sin(a), np.cos(e) * np.cos(a), np.sin(e)], 0, 1)


fig, ax = plt.subplots(1, 3, figsize=(16, 5.2))
p = terrain.pixel_size_m[0]
ext = [0, terrain.shape[1] * p, terrain.shape[0] * p, 0]
ax[0].imshow(hillshade(terrain.heights, p), cmap="gray", extent=ext)
ax[0].set_title(f"terrain, {p:g} m pixels")
ax[1].imshow(hillshade(stamped.heights, p), cmap="gray", extent=ext)
ax[1].set_title(f"{len(placed)} boulders stamped (heightfield maximum)")
for a in ax[:2]:
    a.set_xlabel("x (m)")
    a.set_ylabel("y (m)")
area = (terrain.shape[0] - 1) * (terrain.shape[1] - 1) * p * p
for cat, style, what in ((rocks, "b.", "drawn"), (placed, "k.", "stamped")):
    d = np.sort(cat["diameter_m"])[::-1]
    k_fit = craters.fit_power_law_exponent(d, layer.d_min_m, layer.d_max_m)
    ax[2].loglog(d, np.arange(1, len(d) + 1) / area, style, ms=3,
                 label=f"{what}: {len(d)}, fitted k = {k_fit:.2f}")
dd = np.geomspace(layer.d_min_m, layer.d_max_m, 50)
ax[2].loglog(dd, layer.c * (dd**layer.k - layer.d_max_m**layer.k), "r-",
             label=f"requested N = {layer.c:g} D^{layer.k:g}")
ax[2].set_title("size-frequency (stamped: boulders crossing the\nraster's border are left "
                "out, more often the large ones)", fontsize=10)
ax[2].set_xlabel("diameter D (m)")
ax[2].set_ylabel("cumulative number per m$^2$ (>= D)")
ax[2].legend()
fig.tight_layout()
fig.savefig(out / "boulder_dem.png", dpi=90)
plt.close(fig)
print(f"wrote {out / 'boulder_levels.png'}, {out / 'boulder_body.png'}, "
      f"{out / 'boulder_dem.png'}")
