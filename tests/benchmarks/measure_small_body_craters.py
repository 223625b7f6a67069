"""Issue 36 acceptance: the small-body presets' craters as stamped on the mesh (script).

Builds the ``bennu`` preset for the seeds given and measures each crater's depth/diameter
on the built mesh, not the catalogue: around the crater's centre the vertices within 1.3
radii in the local tangent frame, a plane fitted to the annulus 0.7-1.3 radii removes the
regional tilt, rim crest = the median over 8 azimuth sectors of each sector's highest
point in the annulus, floor = the lowest point within 0.5 radii
(``ondemand_faithfulness.depth_ratios``). Only craters at least ``MIN_SPACINGS`` mesh
spacings across are measured (fewer vertices do not resolve a bowl). Medians for D >= 10
m and D < 10 m against Daly et al. (2020, GRL 47, e2020GL089672: 0.10 +- 0.03 for 108
craters >= 10 m; the craters < 10 m of the same OSIRIS-REx altimetry: 0.13 +- 0.04).
Acceptance: each median within 20 %. Usage, from the top folder with
``PYTHONPATH=tests/benchmarks``: ``python tests/benchmarks/measure_small_body_craters.py
[SEED ...]``.
"""

import sys
import time

import numpy as np
from ondemand_faithfulness import depth_ratios
from scipy.spatial import cKDTree

import latlong

DALY = {"large": (10.0, np.inf, 0.10), "small": (0.0, 10.0, 0.13)}
MIN_SPACINGS = 6.0


def measure(seed: int, preset: str = "bennu", **overrides) -> tuple[np.ndarray, np.ndarray,
                                                                     float]:
    """Diameters (m), as-stamped d/D (NaN where not measurable) and the mesh spacing of the
    preset built with ``seed`` (and settings ``overrides``)."""
    body = latlong.build(latlong.Scene.from_settings({"preset": preset, "seed": seed,
                                                      **overrides}))
    cat = body.craters
    centres = np.stack([cat["centre_x_m"], cat["centre_y_m"], cat["centre_z_m"]], axis=1)
    rho = np.linalg.norm(centres, axis=1)
    tree = cKDTree(body.grid.unit_vectors())
    dd = depth_ratios(body, tree, centres / rho[:, None], rho, cat["diameter_m"],
                      (1.0, 1.0, 1.0))
    spacing = float(np.median(cat["spacing_m"]))
    dd[cat["diameter_m"] < MIN_SPACINGS * spacing] = np.nan
    return cat["diameter_m"], dd, spacing


def main(seeds, **overrides) -> int:
    t0 = time.time()
    ds, dds = [], []
    for seed in seeds:
        d, dd, spacing = measure(seed, **overrides)
        ds.append(d)
        dds.append(dd)
        print(f"seed {seed}: {len(d)} craters, mesh spacing {spacing:.2f} m, "
              f"{np.isfinite(dd).sum()} measurable (>= {MIN_SPACINGS:g} spacings across)")
    d, dd = np.concatenate(ds), np.concatenate(dds)
    ok = True
    for _name, (lo, hi, ref) in DALY.items():
        sel = (d >= lo) & (d < hi) & np.isfinite(dd)
        med = float(np.median(dd[sel])) if sel.any() else float("nan")
        good = abs(med / ref - 1.0) <= 0.2
        ok &= good
        print(f"bennu D {lo:g}-{hi:g} m: median as-stamped d/D {med:.4f} over {sel.sum()} "
              f"craters (Daly {ref}: {100 * (med / ref - 1):+.1f} %, within 20 %: {good})")
    print(f"{time.time() - t0:.0f} s")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main([int(s) for s in sys.argv[1:]] or [1, 2, 3]))
