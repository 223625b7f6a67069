"""Issue 16 acceptance: the body presets' catalogs against the published counts (script).

Builds each body preset (``eros``, ``itokawa``, ``bennu``) for the seeds given (default
1-3, at the preset's own resolution unless ``--quick``), pools the crater and boulder
catalogs and prints, per layer, the maximum-likelihood cumulative exponent and the density
at the published reference diameter against the cited ranges (in ``PUBLISHED``, each with
its source; the same sources as the presets' descriptions). Usage, from the top folder:
``python tests/benchmarks/measure_presets.py [--quick] [SEED ...]``.
"""

import argparse

import numpy as np

import craters
import latlong

# (what, column, d_lo_m, d_hi_m (the exponent's fit range), exponent range, reference D m,
#  range of N(>= reference D) per km^2 over all sizes, source)
PUBLISHED = {
    "eros": [
        ("craters >= 0.2 km", "craters", 200.0, 1180.0, (-2.0, -1.83), 200.0, (1.38, 1.99),
         ("near saturation: Hartmann 1984 to Trask 1966 equilibrium (Veverka 2000, Chapman "
         "2002)")),
        ("craters 0.1-0.2 km", "craters", 100.0, 200.0, (-2.3, -1.7), 100.0, (3.0, 5.0),
         "R = 0.08 (0.06-0.10) below 0.2 km (Berthoud et al. 2001)"),
        ("craters 50-100 m", "craters", 50.0, 100.0, (-2.3, -1.7), 50.0, (10.7, 24.0),
         "R = 0.08 down to 50 m (Berthoud et al. 2001): 16 per km^2 >= 50 m, x/1.5 .. x1.5"),
        ("craters 20-50 m", "craters", 20.0, 50.0, (-1.3, -0.7), 20.0, (26.7, 60.0),
         "~40 per km^2 >= 20 m, not ~400 (NEAR MSI, NEAR team; Chapman 2002), x/1.5 .. x1.5"),
        ("boulders", "boulders", 40.0, 100.0, (-3.39, -3.11), 40.0, (0.21, 0.29),
         ("6760 >= 15 m on 1125 km^2 (Thomas 2001), b = -3.25 +- 0.14 (Michikami & "
         "Hagermann 2021), extrapolated to 40 m")),
    ],
    "itokawa": [
        ("craters", "craters", 6.0, 19.0, None, 6.0, (0.0, None),
         "few; >= 15 per km^2 >= 20 m (named craters, lower bound): no published SFD here"),
        ("boulders", "boulders", 5.0, 20.0, (-3.2, -3.0), 5.0, (900.0, 1000.0),
         "373 >= 5 m on 0.393 km^2 (~950 +- 50), b = -3.1 +- 0.1 (Michikami et al. 2008)"),
    ],
    "bennu": [
        ("craters", "craters", 10.0, 50.0, None, 10.0, (138.0, None),
         ">= 108 craters >= 10 m on 0.785 km^2 (Daly et al. 2020; lower bound)"),
        ("boulders", "boulders", 10.0, 40.0, (-3.2, -2.6), 10.0, (255.0, None),
         "> 200 >= 10 m on 0.785 km^2, b = -2.9 +- 0.3 (DellaGiustina et al. 2019)"),
    ],
}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("seeds", nargs="*", type=int, default=[1, 2, 3])
    parser.add_argument("--quick", action="store_true", help="coarse grids (same catalogs "
                        "up to the area's resolution)")
    args = parser.parse_args()
    for name, rows in PUBLISHED.items():
        coarse = {"eros": {"magnitude": 120}, "bennu": {"magnitude": 120},
                  "itokawa": {"spacing_m": 6.0}}[name] if args.quick else {}
        pooled = {"craters": [], "boulders": []}
        areas = []
        for seed in args.seeds:
            body = latlong.build(latlong.Scene.from_settings(
                {"preset": name, "seed": seed, **coarse}))
            pooled["craters"].append(np.asarray(body.craters["diameter_m"]))
            pooled["boulders"].append(np.asarray(body.boulders["diameter_m"]))
            areas.append(body_area_km2(body))
        area = float(np.sum(areas))
        print(f"{name}: {len(args.seeds)} seeds, total area {area:.4g} km^2")
        for what, col, lo, hi, b_rng, d_ref, n_rng, src in rows:
            d = np.concatenate(pooled[col])
            d = d[(d >= lo) & (d <= hi)]
            b = craters.fit_power_law_exponent(d, lo, hi) if len(d) > 5 else float("nan")
            dens = np.count_nonzero(np.concatenate(pooled[col]) >= d_ref) / area
            ok_b = b_rng is None or b_rng[0] <= b <= b_rng[1]
            ok_n = dens >= n_rng[0] * (1 - 1e-9) and (n_rng[1] is None or dens <= n_rng[1])
            rng_txt = "no published exponent" if b_rng is None else \
                f"published {b_rng[0]:g}..{b_rng[1]:g}"
            hi_txt = "" if n_rng[1] is None else f"..{n_rng[1]:g}"
            print(f"  {what}: n = {len(d)}, exponent {b:+.2f} ({rng_txt}) "
                  f"{'ok' if ok_b else 'OUT'}; N(>= {d_ref:g} m) = {dens:.3g} per km^2 "
                  f"(published {n_rng[0]:g}{hi_txt or ' or more'}) {'ok' if ok_n else 'OUT'}"
                  f"\n      source: {src}")


def body_area_km2(body) -> float:
    """Surface area of the body without its boulders, km^2."""
    try:
        mesh = body.to_pyvista(boulders=False)
    except TypeError:
        mesh = body.to_pyvista()
    return float(mesh.compute_cell_sizes().cell_data["Area"].sum()) / 1e6


if __name__ == "__main__":
    main()
