"""Terrain on demand against the sequential stamp over a lunar DEM (issue 37, "Faithful to
the sequential model ... and a lunar DEM stack"): the same base raster, the same counter-
based catalogue, two surfaces compared, layer by layer of a stack.

The DEM is the LOLA crop of ``tests/data`` (LDEM_4, 7.6 km pixels; ``tests/data/README.md``)
around (5 N, 180 E). A stack is three layers, each a 1024^2 window of pixel ``p`` = 240, 60
and 15 m (a factor of 4 between layers), each holding the craters of its own scale, 3 to
64 pixels across (N_cum = 0.08 D^-2 per m^2, about the lunar equilibrium density: Gault
1970, Radio Sci. 5, 273), with ages up to 3.5, 1 and 0.1 Gyr (so each size is seen near its
equilibrium, as ``measure_ondemand.py``'s scene); the layer above and the DEM hold the
larger relief. For each layer and seed:

* **on demand**: the window of ``dem.ondemand.dem_tile`` (the DEM as the base, craters
  >= 3 pixels);
* **sequential**: ``craters.stamp_many`` of the field's catalogue (oldest first, the
  field's ejecta edge, roughness and slope erosion, ``rng=seed``) on the same window of
  the base alone (``DemBase`` at the window's pixel centres), the catalogue's centres in
  the window's gnomonic plane.

Compared on the central 512^2 pixels (a crater of the layer reaches at most 96 pixels,
so every crater reaching them lies wholly inside the window for both stamps):

* per-pixel |dh| (median, 95th percentile, metres);
* Horn slopes: medians and the two-sample Kolmogorov-Smirnov statistic;
* visible craters per octave of diameter in pixels: stamped (not erased by slope erosion)
  with the centre inside the compared area and not within D/2 of a younger stamped
  crater's centre;
* depth/diameter measured on each raster for its visible craters >= 6 pixels across
  (as ``ondemand_faithfulness.py``: plane fitted to the 0.7-1.3 radius annulus, rim crest
  the median of 8 sectors' highest detrended height there, floor the lowest within 0.5
  radii): medians and the median paired ratio;
* power in octave bands of spatial frequency (``dem.analysis.band_power``): on-demand /
  sequential.

Acceptance (issue 37): slope KS <= 0.05, visible craters per bin within 10 %, d/D median
within 5 %. Run by hand (about 4 s per layer and seed on two cores):

    python tests/benchmarks/ondemand_faithfulness_dem.py --seeds 1-20 --json out.json \
        --png-dir out/
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np
from scipy.spatial import cKDTree

sys.path.insert(0, str(Path(__file__).resolve().parent))
from ondemand_faithfulness import weighted_ks  # noqa: E402  (the body harness's KS)

LOLA = Path(__file__).resolve().parents[1] / "data" / "ldem4_crop.lbl"
SITE = (5.0, 180.0)
LAYERS = ((240.0, 3.5), (60.0, 1.0), (15.0, 0.1))  # pixel m, oldest crater Gyr
SIZE = 1024
CORE = slice(256, 768)
BANDS = [(2.0 ** -k, 2.0 ** (1 - k)) for k in range(8, 0, -1)]  # cycles per pixel


def scene_of(radius_m: float, pixel_m: float, age_max: float, seed: int):
    from latlong import Scene

    layer = (f"c=0.08,k=-2,d_min_m={3 * pixel_m:g},d_max_m={64 * pixel_m:g},"
             f"age_max_gyr={age_max:g}")
    return Scene.from_settings({"base": "sphere", "radius_m": radius_m, "body": "moon",
                                "seed": seed, "on_demand": True, "craters": [layer]})


def tile_xy(units: np.ndarray, lat: float, lon: float, radius: float, pixel: float):
    """Grid-frame metres (x along columns, y along rows) of directions in the window's
    gnomonic plane (``latlong.ondemand.tile.tile_units`` inverted)."""
    from latlong.ondemand import units_of
    from latlong.ondemand.base import tangent_frame

    c = units_of([lat], [lon])
    e, n = tangent_frame(c)
    d = units @ c[0]
    xt = radius * (units @ e[0]) / d
    yt = radius * (units @ n[0]) / d
    col = xt / pixel + 0.5 * SIZE - 0.5
    row = -yt / pixel + 0.5 * SIZE - 0.5
    return col * pixel, row * pixel


def visible(x_px, y_px, d_px, age, ids, stamped_ids) -> np.ndarray:
    """Indices of visible craters (module notes), centres in the compared area."""
    st = np.isin(ids, stamped_ids)
    inside = (x_px >= CORE.start) & (x_px < CORE.stop) & (y_px >= CORE.start) & (y_px < CORE.stop)
    idx = np.flatnonzero(st)
    tree = cKDTree(np.c_[x_px[idx], y_px[idx]])
    out = []
    for k in np.flatnonzero(st & inside):
        near = idx[tree.query_ball_point([x_px[k], y_px[k]], 0.5 * d_px.max())]
        younger = near[(age[near] < age[k]) | ((age[near] == age[k]) & (ids[near] > ids[k]))]
        dist = np.hypot(x_px[younger] - x_px[k], y_px[younger] - y_px[k])
        if not np.any(dist < 0.5 * d_px[younger]):
            out.append(k)
    return np.array(out, dtype=np.int64)


def depth_ratio(h: np.ndarray, x_px: float, y_px: float, d_px: float,
                pixel: float) -> float:
    r = 0.5 * d_px
    i0, i1 = int(max(0, np.floor(y_px - 1.3 * r))), int(min(SIZE, np.ceil(y_px + 1.3 * r) + 1))
    j0, j1 = int(max(0, np.floor(x_px - 1.3 * r))), int(min(SIZE, np.ceil(x_px + 1.3 * r) + 1))
    yy, xx = np.mgrid[i0:i1, j0:j1]
    dx, dy = xx - x_px, yy - y_px
    rho = np.hypot(dx, dy) / r
    z = h[i0:i1, j0:j1]
    ann = (rho >= 0.7) & (rho <= 1.3)
    a = np.c_[np.ones(ann.sum()), dx[ann], dy[ann]]
    coef = np.linalg.lstsq(a, z[ann], rcond=None)[0]
    zd = z - (coef[0] + coef[1] * dx + coef[2] * dy)
    sector = (np.floor((np.arctan2(dy, dx) + np.pi) / (np.pi / 4)).astype(int)) % 8
    crest = np.median([zd[ann & (sector == s)].max() for s in range(8)
                       if (ann & (sector == s)).any()])
    floor = zd[rho <= 0.5].min()
    return float((crest - floor) / (d_px * pixel))


def save_picture(path: Path, od: np.ndarray, seq: np.ndarray, pixel: float) -> None:
    """Hillshades (sun 20 deg above the west) of the compared area: on demand | sequential."""
    from PIL import Image

    from latlong.ondemand.tile import hillshade

    pics = [(255 * hillshade(h[CORE, CORE], pixel)).astype(np.uint8) for h in (od, seq)]
    gap = np.zeros((pics[0].shape[0], 8), np.uint8)
    Image.fromarray(np.concatenate([pics[0], gap, pics[1]], axis=1)).save(path)


def run_layer(lola, pixel: float, age_max: float, seed: int, png_dir: Path | None = None
              ) -> dict:
    from craters import stamp_many
    from dem.analysis import band_power
    from dem.core import Dem
    from dem.ondemand import DemBase
    from dem.terrain import slope
    from latlong.ondemand import units_of
    from latlong.ondemand.field import CraterField
    from latlong.ondemand.tile import tile_of_field, tile_units

    t0 = time.perf_counter()
    sc = scene_of(lola.body_radius_m, pixel, age_max, seed)
    field = CraterField(sc, DemBase(lola, seed=seed))  # what dem_tile makes
    t = tile_of_field(field, *SITE, SIZE, pixel, 3.0)
    cat = field.last_catalog()  # oldest first
    base = field.base.radius(
        tile_units(*SITE, SIZE, pixel, t.radius_m).reshape(-1, 3)).reshape(SIZE, SIZE)
    base -= t.radius_m
    x_m, y_m = tile_xy(units_of(cat["lat_deg"], cat["lon_deg"]), *SITE, t.radius_m, pixel)
    names = [n for n in ("diameter_m", "age_gyr", "id") if n in cat.dtype.names]
    from craters.catalog import make_catalog
    seq_cat = make_catalog(x_m=x_m, y_m=y_m, degradation=np.full(len(cat), np.nan),
                           **{n: cat[n] for n in names})
    seq, stamped = stamp_many(base, pixel, seq_cat, ejecta_edge=field.xe,
                              irregularity=field.irregularity, rng=seed, return_catalog=True)
    od = t.heights_m
    if png_dir is not None:
        save_picture(png_dir / f"dem_faithfulness_{pixel:g}m_seed{seed}.png", od, seq, pixel)
    core_od, core_seq = od[CORE, CORE], seq[CORE, CORE]
    dh = np.abs(core_od - core_seq)
    s_od = slope(Dem(core_od, pixel_size_m=pixel))
    s_sq = slope(Dem(core_seq, pixel_size_m=pixel))
    s_od, s_sq = s_od[np.isfinite(s_od)], s_sq[np.isfinite(s_sq)]
    # visible craters on each surface (the same rule; stamped sets differ by slope erosion)
    xp, yp, dp = x_m / pixel, y_m / pixel, cat["diameter_m"] / pixel
    vis_od = visible(xp, yp, dp, cat["age_gyr"], cat["id"], cat["id"][cat["slope_factor"] > 0])
    vis_sq = visible(xp, yp, dp, cat["age_gyr"], cat["id"], stamped["id"])
    bins = np.arange(1, 7)  # [2^b, 2^(b+1)) pixels, 2-128 px
    count = {}
    for b in bins:
        lo, hi = 2.0 ** b, 2.0 ** (b + 1)
        count[f"{lo:g}-{hi:g} px"] = [int(np.sum((dp[vis_od] >= lo) & (dp[vis_od] < hi))),
                                      int(np.sum((dp[vis_sq] >= lo) & (dp[vis_sq] < hi)))]
    both = np.intersect1d(vis_od, vis_sq)
    big = lambda v: v[dp[v] >= 6.0]  # noqa: E731
    dd_od = [depth_ratio(od, xp[k], yp[k], dp[k], pixel) for k in big(vis_od)]
    dd_sq = [depth_ratio(seq, xp[k], yp[k], dp[k], pixel) for k in big(vis_sq)]
    paired = [depth_ratio(od, xp[k], yp[k], dp[k], pixel)
              / depth_ratio(seq, xp[k], yp[k], dp[k], pixel) for k in big(both)]
    power = [band_power(Dem(core_od, pixel_size_m=pixel), lo, hi)
             / band_power(Dem(core_seq, pixel_size_m=pixel), lo, hi) for lo, hi in BANDS]
    return {"pixel_m": pixel, "seed": seed, "craters": len(cat), "stamped_seq": len(stamped),
            "stamped_od": int(np.sum(cat["slope_factor"] > 0)),
            "dh_median_m": float(np.median(dh)), "dh_p95_m": float(np.percentile(dh, 95)),
            "slope_median_deg": [float(np.median(s_od)), float(np.median(s_sq))],
            "slope_ks": weighted_ks(s_od, np.ones(len(s_od)), s_sq, np.ones(len(s_sq))),
            "visible_per_bin": count,
            "dd_median": [float(np.median(dd_od)) if dd_od else float("nan"),
                          float(np.median(dd_sq)) if dd_sq else float("nan")],
            "dd_n": [len(dd_od), len(dd_sq)], "dd_od": dd_od, "dd_seq": dd_sq,
            "dd_paired_ratio_median": float(np.median(paired)) if paired else float("nan"),
            "power_ratio_by_band": power, "seconds": time.perf_counter() - t0}


def summary(rows: list[dict]) -> dict:
    out = {}
    for pixel, _ in LAYERS:
        rs = [r for r in rows if r["pixel_m"] == pixel]
        if not rs:
            continue
        vis = {k: np.sum([r["visible_per_bin"][k] for r in rs], axis=0).tolist()
               for k in rs[0]["visible_per_bin"]}
        dd_od = np.concatenate([r["dd_od"] for r in rs])
        dd_sq = np.concatenate([r["dd_seq"] for r in rs])
        pw = np.array([r["power_ratio_by_band"] for r in rs])
        out[f"{pixel:g} m"] = {
            "seeds": len(rs), "slope_ks_max": max(r["slope_ks"] for r in rs),
            "slope_ks_median": float(np.median([r["slope_ks"] for r in rs])),
            "visible_per_bin_od_seq": vis,
            "visible_ratio_per_bin": {k: (v[0] / v[1] if v[1] else float("nan"))
                                      for k, v in vis.items()},
            "dd_pooled_median": [float(np.median(dd_od)), float(np.median(dd_sq))],
            "dd_pooled_ratio": float(np.median(dd_od) / np.median(dd_sq)),
            "dd_per_seed_ratio": [r["dd_median"][0] / r["dd_median"][1] for r in rs],
            "power_ratio_min_max_by_band": [[float(pw[:, i].min()), float(pw[:, i].max())]
                                            for i in range(pw.shape[1])],
            "dh_median_m": float(np.median([r["dh_median_m"] for r in rs]))}
    return out


def main() -> int:
    import dem

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", default="1-3", help="e.g. 1-20 or 1,4,7 (default: 1-3)")
    ap.add_argument("--json", type=Path)
    ap.add_argument("--png-dir", type=Path, help="hillshades of the first seed's layers: on "
                    "demand | sequential")
    args = ap.parse_args()
    if "-" in args.seeds:
        a, b = (int(x) for x in args.seeds.split("-"))
        seeds = list(range(a, b + 1))
    else:
        seeds = [int(x) for x in args.seeds.split(",")]
    lola = dem.read(LOLA)
    rows = []
    for seed in seeds:
        for pixel, age in LAYERS:
            r = run_layer(lola, pixel, age, seed, args.png_dir if seed == seeds[0] else None)
            rows.append(r)
            print(f"seed {seed} {pixel:g} m: {r['craters']} craters, |dh| median "
                  f"{r['dh_median_m']:.3g} m p95 {r['dh_p95_m']:.3g} m; slope KS "
                  f"{r['slope_ks']:.4f} (medians {r['slope_median_deg'][0]:.2f} / "
                  f"{r['slope_median_deg'][1]:.2f} deg); d/D {r['dd_median'][0]:.4f} / "
                  f"{r['dd_median'][1]:.4f} (n {r['dd_n'][0]}/{r['dd_n'][1]}, paired "
                  f"{r['dd_paired_ratio_median']:.3f}); visible "
                  f"{ {k: v for k, v in r['visible_per_bin'].items()} }; "
                  f"{r['seconds']:.1f} s", flush=True)
    summ = summary(rows)
    print(json.dumps(summ, indent=1))
    if args.json:
        args.json.write_text(json.dumps({"layers": rows, "summary": summ}, indent=1) + "\n")
        print(f"wrote {args.json}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
