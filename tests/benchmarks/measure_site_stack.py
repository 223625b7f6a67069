"""Issue 21 acceptance figures for the README's site stack on the LOLA crop (plain script).

Builds ``examples/site.toml`` for each seed given (default 2014) and prints the height
range of all layers, layer 0's median Horn slope against the LOLA input on the same window,
every layer's median slope, the same-footprint comparison (layer k over the window layer
k + 1 covers, then layer k + 1), the share of each layer steeper than 30 degrees and
(issue 36) how many craters of all layers are older than a larger crater whose rim holds
their centre (brute force over the catalogues in the stack's frame; acceptance: 0).
Usage, from the repository's top folder: ``python tests/benchmarks/measure_site_stack.py
[SEED ...]``.
"""

import sys
import tomllib

import numpy as np
from scipy.spatial import cKDTree

import dem


def older_inside(stack) -> tuple[int, int]:
    """(craters older than a larger crater whose rim holds their centre, all craters)."""
    cats = [c for c in stack.catalogs if c is not None and len(c)]
    x, y, d, age = (np.concatenate([c[k] for c in cats])
                    for k in ("x_m", "y_m", "diameter_m", "age_gyr"))
    tree = cKDTree(np.c_[x, y])
    bad = {i for j in range(len(d)) for i in tree.query_ball_point([x[j], y[j]], d[j] / 2)
           if d[i] < d[j] and age[i] > age[j]}
    return len(bad), len(d)


def main() -> None:
    seeds = [int(s) for s in sys.argv[1:]] or [2014]
    with open("examples/site.toml", "rb") as f:
        site = tomllib.load(f)
    base = dem.read(site.pop("input"))
    site.pop("output")
    for seed in seeds:
        st = dem.enhance({**site, "seed": seed}, dem=base)
        l0 = st.layers[0]
        col0 = round((l0.transform.c - base.transform.c) / base.transform.a)
        row0 = round((l0.transform.f - base.transform.f) / base.transform.e)
        window = dem.slope(base)[row0:row0 + l0.shape[0], col0:col0 + l0.shape[1]]
        lola = float(np.nanmedian(window))
        med = [float(np.nanmedian(dem.slope(d))) for d in st.layers]
        same = []
        for k in range(len(st) - 1):
            r, c, w = st.windows[k]
            s = dem.slope(st.layers[k])[r:r + w, c:c + w]
            same.append((float(np.nanmedian(s)), med[k + 1]))
        lo = min(float(d.heights.min()) for d in st.layers)
        hi = max(float(d.heights.max()) for d in st.layers)
        steep = [float(np.nanmean(dem.slope(d) > 30)) * 100 for d in st.layers]
        print(f"seed {seed}: heights {lo / 1e3:.2f} .. {hi / 1e3:.2f} km; layer-0 median slope "
              f"{med[0]:.2f} deg vs LOLA {lola:.2f} ({100 * (med[0] / lola - 1):+.0f} %)")
        print("  per-layer median slope:", " ".join(f"{m:.2f}" for m in med))
        print("  same footprint (coarse -> fine):",
              " ".join(f"{a:.2f}->{b:.2f}" for a, b in same))
        print("  % > 30 deg:", " ".join(f"{s:.2f}" for s in steep))
        bad, n = older_inside(st)
        print(f"  craters older than a larger one whose rim holds them: {bad} of {n}")


if __name__ == "__main__":
    main()
