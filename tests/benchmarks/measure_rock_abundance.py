"""Issue 36 acceptance: rocks of Golombek & Rapp's (1997) model in a rendered tile (script).

Rocks ``golombek,k=K,d_min_m=0.1,d_max_m=2`` (:func:`craters.golombek_layers`) are drawn
over flat 1025 x 1025 DEM tiles of 2 cm pixels (20.5 m a side) and stamped as the DEM
path stamps them (:func:`dem.stamp_boulders`: faceted, elongated, partly buried rocks as
a heightfield maximum). The rendered tile is then measured as a rock count measures an
image: every connected patch standing more than 1 mm above the ground is one rock, its
diameter its longest extent (the largest of 36 projected widths), its area the circle of
that diameter (the convention of the model's size-frequency: a rock of diameter D covers
pi D^2 / 4). The cumulative fractional area of rocks >= D is compared with the model
``F_k(D) - F_k(d_max)`` (the drawn range ends at 2 m); acceptance: within 20 %. The
catalogue's own fractional area is printed beside it. Usage, from the top folder:
``python tests/benchmarks/measure_rock_abundance.py [K] [TILES]``.
"""

import sys

import numpy as np
from scipy import ndimage

import dem
from craters.boulders.abundance import golombek_cumulative_area

D_MIN_M, D_MAX_M, PIXEL_M, SIDE_PX = 0.1, 2.0, 0.02, 1025
SIZES_M = np.array([0.1, 0.15, 0.2, 0.3, 0.5, 0.7, 1.0])
_DIRS = np.stack([np.cos(a := np.linspace(0, np.pi, 36, endpoint=False)), np.sin(a)])


def rock_diameters_m(heights: np.ndarray, pixel_m: float) -> np.ndarray:
    """Longest extent (m) of every patch standing > 1 mm above a flat ground."""
    lab, n = ndimage.label(heights > 1e-3)
    out = np.zeros(n)
    for i, sl in enumerate(ndimage.find_objects(lab)):
        rr, cc = np.nonzero(lab[sl] == i + 1)
        p = np.stack([rr, cc]).T @ _DIRS
        out[i] = ((p.max(0) - p.min(0)).max() + 1.0) * pixel_m
    return out


def main() -> None:
    k = float(sys.argv[1]) if len(sys.argv) > 1 else 0.1
    tiles = int(sys.argv[2]) if len(sys.argv) > 2 else 8
    rendered, listed, area = np.zeros(len(SIZES_M)), np.zeros(len(SIZES_M)), 0.0
    flat = dem.Dem(np.zeros((SIDE_PX, SIDE_PX)), pixel_size_m=PIXEL_M)
    spec = f"golombek,k={k},d_min_m={D_MIN_M},d_max_m={D_MAX_M}"
    for seed in range(tiles):
        cat = dem.boulder_population(flat, spec, rng=seed)
        d = rock_diameters_m(dem.stamp_boulders(flat, cat).heights, PIXEL_M)
        for i, s in enumerate(SIZES_M):
            rendered[i] += (np.pi / 4 * d[d >= s] ** 2).sum()
            listed[i] += (np.pi / 4 * cat["diameter_m"][cat["diameter_m"] >= s] ** 2).sum()
        area += (SIDE_PX * PIXEL_M) ** 2
    model = golombek_cumulative_area(SIZES_M, k) - golombek_cumulative_area(D_MAX_M, k)
    print(f"{spec}: {tiles} tiles of {SIDE_PX} px at {PIXEL_M} m ({area:.0f} m^2)")
    print("  D >= m   rendered   catalogue   model     rendered/model")
    for s, r, c, m in zip(SIZES_M, rendered / area, listed / area, model, strict=True):
        print(f"  {s:5.2f}   {r:8.4f}   {c:8.4f}   {m:8.4f}   {r / m:5.2f}")


if __name__ == "__main__":
    main()
