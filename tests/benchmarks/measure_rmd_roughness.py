"""Issue 36 acceptance: RMD detail independent of the large-scale slope (plain script).

Builds the README's site stack (``examples/site.toml``; with ``--no-craters`` its RMD
layers alone) and, for every layer k >= 1, takes the fine-scale residual at its
(odd, odd) pixels: the height minus the mean of the four diagonal pixels of layer k - 1
(exactly the square phase's prediction, so in a crater-free stack the residual is the
RMD displacement itself). Pixels are classed by the Horn slope of layer k - 1 at the
nearest of those four (the large-scale slope) and the RMS residual on slopes > 20 degrees
is compared with the RMS on slopes < 5 degrees (acceptance: ratio <= 1.5). Usage, from the
top folder: ``python tests/benchmarks/measure_rmd_roughness.py [--no-craters] [SEED ...]``.
"""

import argparse
import tomllib

import numpy as np

import dem

FLAT_DEG, STEEP_DEG = 5.0, 20.0


def residuals(stack):
    """Per layer k >= 1: (residual at the (odd, odd) pixels, parent slope there, degrees)."""
    out = []
    for k in range(1, len(stack)):
        r, c, w = stack.windows[k - 1]
        parent = stack.layers[k - 1].heights[r:r + w, c:c + w]
        slope = dem.slope(stack.layers[k - 1])[r:r + w, c:c + w]
        fine = stack.layers[k].heights
        n = (w - 1) * 2 + 1
        if fine.shape[0] != n:
            raise RuntimeError(f"layer {k}: {fine.shape} is not 2 x {w} - 1")
        pred = 0.25 * (parent[:-1, :-1] + parent[1:, :-1] + parent[:-1, 1:] + parent[1:, 1:])
        res = fine[1::2, 1::2] - pred
        s = np.maximum.reduce([slope[:-1, :-1], slope[1:, :-1], slope[:-1, 1:], slope[1:, 1:]])
        out.append((res, s))
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--no-craters", action="store_true")
    ap.add_argument("seeds", type=int, nargs="*", default=[2014])
    args = ap.parse_args()
    with open("examples/site.toml", "rb") as f:
        site = tomllib.load(f)
    base = dem.read(site.pop("input"))
    site.pop("output")
    if args.no_craters:
        site.pop("craters")
    pooled = {"flat": [], "steep": []}
    for seed in args.seeds:
        st = dem.enhance({**site, "seed": seed}, dem=base)
        print(f"seed {seed}{' (no craters)' if args.no_craters else ''}: layer, pixel m, "
              "RMS residual m on < 5 deg (n) / > 20 deg (n), ratio")
        for k, (res, s) in enumerate(residuals(st), start=1):
            flat, steep = res[s < FLAT_DEG], res[s > STEEP_DEG]
            pooled["flat"].append(flat / st.layers[k].resolution_m)
            pooled["steep"].append(steep / st.layers[k].resolution_m)
            if steep.size < 20 or flat.size < 20:
                continue
            a, b = np.sqrt(np.mean(flat**2)), np.sqrt(np.mean(steep**2))
            print(f"  {k:2d} {st.layers[k].resolution_m:8.1f}  {a:9.4f} ({flat.size:5d}) / "
                  f"{b:9.4f} ({steep.size:5d})  {b / a:5.2f}")
    f, s = np.concatenate(pooled["flat"]), np.concatenate(pooled["steep"])
    ratio = np.sqrt(np.mean(s**2)) / np.sqrt(np.mean(f**2))
    print(f"all layers (residual / pixel size): steep / flat RMS = {ratio:.2f} "
          f"(n = {s.size} / {f.size}; acceptance <= 1.5)")


if __name__ == "__main__":
    main()
