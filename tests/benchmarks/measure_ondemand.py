"""Measure terrain on demand (issue 37): tile times at every scale, a descent from orbit to
touchdown, and how consistent its frames are.

Scene: a lunar mare at 3.5 Gyr, the Moon's radius and crater morphology. Below 163.84 m
the surface is saturated: power-law craters N_cum = 0.08 D^-2 per m^2 (about the lunar
equilibrium density: Gault 1970, Radio Sci. 5, 273, finds N_cum ~ 10^-1.1 D^-2 for
steady-state small craters) from 2.5 mm, one layer per octave of diameter, each layer's
ages uniform up to the age at which diffusion has removed 90 % of its largest crater's
fresh depth (``lifetime_gyr``: the project's diffusion model, Fassett & Thomson
2014/2015's D-dependent diffusivity; ~10 Myr at 1 m, ~1.5 Gyr at 100 m), so that every
size shows the same mix of fresh and worn craters, as a steady state does (with one
layer per decade the mix jumped at each decade and so did the pictures' fine detail).
From 163.84 m to 20 km the craters are in production: Neukum's lunar production
function at 3.5 Gyr, ages from the chronology's flux (``npf=moon,age_gyr=3.5``; it meets
Trask's equilibrium at 179 m, ``craters.chronology.saturation_diameter_m``, and 163.84 m
is the octave edge nearest). Until stop 53 the equilibrium law ran up to 20 km: 25 x the
km-sized craters of a 3.5 Gyr mare, whose deep fresh bowls held the 10 km frames' power
at their largest scales (top-octave share 0.018 against 0.03-0.08 closer in). Rocks of
5 mm to 5 m (N_cum = 7e-4 D^-2.11 per m^2, examples/moon_site.toml). Below 2 cm the
craters stand for the regolith's texture (the equilibrium law carried on: with craters
ending at 2 cm the frames below 2 m lost their fine detail, 0.24 of the 10 km share).
1. Tiles: a 1024^2 window (``latlong.ondemand.tile.tile``) at 100 m, 10 m, 1 m, 10 cm and
   1 cm pixels, the second of two runs (compiled; the field's kept crater parameters
   cleared, so every crater's base is fitted again), seconds and nanoseconds per pixel,
   and the craters that made it.
2. Descent: ``--frames`` frames (default 100) from 100 km to 1 m above the site, square
   pictures ``--size`` wide (default 1024), the total time; per frame the share of the
   picture's power (8-bit display picture exposed on its own lit pixels, 2-D FFT, DC
   removed) in the top octave of spatial frequencies (|k| between N/4 and N/2 cycles per
   picture) and its ratio to the frame nearest 10 km; OpenCV tracking between
   consecutive frames (Shi-Tomasi + LK + USAC essential matrix,
   ``measure_feature_tracking``'s tracker) against the true
   relative poses: rotation error (degrees) and translation-direction error (degrees;
   a translation error relative to its length of e radians is a share e of it). Two
   numbers separate the terrain from the estimator: (a) the tracks' own geometry, a zoom
   about the principal point plus a shift fitted per pair (``zoom_fit``): zoom against
   the altitude ratio, the shift in pixels and the residual of the tracks (their noise);
   (b) a control, the same estimator on a perfectly consistent flat scene seen with the
   same camera, motion, number of tracks and track noise (``control_errors``): the
   error floor of the 5-point essential matrix for a nadir camera moving along its axis
   over near-planar ground, whatever the terrain. (c) The relative pose with its
   length, from the same tracks and frame a's depth (``pnp_pose``: OpenCV's USAC with
   MAGSAC++ and a least-squares polish; beside it EPnP in plain RANSAC and a
   Levenberg-Marquardt polish; the navigation filter's map or LIDAR): rotation error and
   |t_est - t_true| / |t_true|. Terrain that changed between the frames' resolutions
   would move the 3-D points away from where frame b sees them.
3. A 6-frame strip (100 km, 10 km, 1 km, 100 m, 10 m, 1 m) for the README.

Usage: ``python tests/benchmarks/measure_ondemand.py [--frames 100] [--size 1024]
[--strip examples/images/descent_ondemand.png] [--json out/ondemand.json]``. The README's
strip: ``--frames 6 --skip-tiles --site 0.01,0.01 --strip ...`` (at the default site,
(0, 0), a crater's shadow fills the frames from 100 m down at the 25 deg sun).
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))



def lifetime_gyr(diameter_m: float, worn: float = 0.9) -> float:
    """Age (Gyr) at which diffusion has removed ``worn`` of a fresh lunar crater's depth."""
    from craters.diffusion import kappa_m2_yr, tau_from_degradation

    tau = float(np.ravel(tau_from_degradation([diameter_m], [worn]))[0])
    return tau * (0.5 * diameter_m) ** 2 / float(np.ravel(kappa_m2_yr([diameter_m]))[0]) / 1e9


def octave_layers(d_lo_m: float = 0.02, d_hi_m: float = 20000.0) -> list[str]:
    """One crater layer per octave of diameter, ages up to the octave's top's lifetime."""
    out, a = [], d_lo_m
    while a < d_hi_m:
        b = min(2.0 * a, d_hi_m)
        out.append(f"c=0.08,k=-2,d_min_m={a:.6g},d_max_m={b:.6g},"
                   f"age_max_gyr={min(3.5, lifetime_gyr(b)):.4g}")
        a = b
    return out


#: Where the mare's craters leave equilibrium for production (module notes).
SATURATED_BELOW_M = 163.84
# the texture layers below 2 cm last: a layer's index is part of its craters' counter key,
# so the layers above keep theirs (and their craters)
LAYERS = (octave_layers(0.02, SATURATED_BELOW_M)
          + [f"npf=moon,age_gyr=3.5,d_min_m={SATURATED_BELOW_M:g},d_max_m=20000"]
          + octave_layers(0.0025, 0.02))
ROCKS = ["c=7e-4,k=-2.11,d_min_m=0.005,d_max_m=5,burial_max=0.5"]
SITE = [0.0, 0.0]
SUN_ELEVATION_DEG = [25.0]


def scene():
    from latlong import Scene

    return Scene.from_settings({"base": "sphere", "radius_m": 1737400.0, "body": "moon",
                                "seed": 1, "on_demand": True, "craters": LAYERS,
                                "boulders": ROCKS})


def tiles(sc, runs: int = 7) -> list[dict]:
    """1024^2 tiles from 100 m to 1 cm a pixel at SITE after a warm-up call: the median
    and largest of ``runs`` timings, each with every crater's parameters computed again."""
    from latlong.ondemand.field import crater_field
    from latlong.ondemand.tile import tile

    rows = []
    for pixel in (100.0, 10.0, 1.0, 0.1, 0.01):
        tile(sc, *SITE, size_m=1024 * pixel, pixel_m=pixel)
        times = []
        for _ in range(runs):
            crater_field(sc)._params.clear()  # timed with every crater's parameters computed
            t0 = time.perf_counter()
            t = tile(sc, *SITE, size_m=1024 * pixel, pixel_m=pixel)
            times.append(time.perf_counter() - t0)
        dt = float(np.median(times))
        rows.append({"pixel_m": pixel, "seconds": dt, "max_seconds": max(times),
                     "ns_per_pixel": 1e9 * dt / 1024**2, "craters": t.n_craters})
        print(f"tile 1024^2 at {pixel:g} m: median {dt:.3f} s, max {max(times):.3f} s of "
              f"{runs} ({1e9 * dt / 1024**2:.0f} ns/pixel), {t.n_craters} craters", flush=True)
    return rows


def top_octave_share(img: np.ndarray) -> float:
    """Share of the picture's power (DC removed) at |k| in [N/4, N/2] cycles/picture."""
    a = img.astype(np.float64)
    p = np.abs(np.fft.fft2(a - a.mean())) ** 2
    n = a.shape[0]
    k = np.fft.fftfreq(n) * n
    kk = np.hypot(*np.meshgrid(k, k))
    total = p[kk > 0].sum()
    return float(p[(kk >= n / 4) & (kk <= n / 2)].sum() / total) if total > 0 else 0.0


def descent_run(sc, frames: int, size: int):
    from latlong.ondemand.descent import descent, descent_altitudes, display

    alts = descent_altitudes(1e5, 1.0, frames)
    out = []
    t0 = time.perf_counter()
    for f in descent(sc, *SITE, alts, width_px=size, sun_elevation_deg=SUN_ELEVATION_DEG[0]):
        r = f.frame.reflectance
        # each frame exposed on its own lit pixels, as a descent camera's auto-exposure
        scale = float(np.percentile(r[r > 0], 99.5)) if (r > 0).any() else 1.0
        out.append((f, display(r, scale)))
    return out, time.perf_counter() - t0


def zoom_fit(p0: np.ndarray, p1: np.ndarray, c: np.ndarray) -> tuple[float, np.ndarray, float]:
    """(zoom, shift in px, median |residual| px) of p1 - c = zoom (p0 - c) + shift."""
    a = np.zeros((2 * len(p0), 3))
    a[0::2, 0] = p0[:, 0] - c[0]
    a[1::2, 0] = p0[:, 1] - c[1]
    a[0::2, 1] = 1.0
    a[1::2, 2] = 1.0
    rhs = (p1 - c).ravel()
    sol = np.linalg.lstsq(a, rhs, rcond=None)[0]
    return float(sol[0]), sol[1:], float(np.median(np.abs(rhs - a @ sol)))


def control_errors(k: np.ndarray, ratio: float, n: int, noise_px: float, size: int,
                   seed: int) -> tuple[float, float]:
    """(rotation, translation-direction) errors in degrees of ``relative_pose`` on ``n``
    points of a flat ground seen straight down by camera ``k`` before and after moving
    towards it by the altitude ratio ``ratio``, each track displaced by Gaussian noise of
    ``noise_px`` per axis (the median |residual| of a Gaussian is 0.674 sigma)."""
    import measure_feature_tracking as mft

    rng = np.random.default_rng(seed)
    u = rng.uniform(0.0, size - 1.0, (n, 2))
    f, c = k[0, 0], k[:2, 2]
    ub = c + (u - c) * ratio
    keep = np.all((ub >= 0) & (ub <= size - 1), axis=1)
    sigma = noise_px / 0.674
    p0 = u[keep] + sigma * rng.standard_normal((keep.sum(), 2))
    p1 = ub[keep] + sigma * rng.standard_normal((keep.sum(), 2))
    if len(p0) < 8 or not np.isfinite(f):
        return float("nan"), float("nan")
    r, t, _ = mft.relative_pose(p0, p1, k)
    return (mft.rotation_angle_deg(r),
            float(np.degrees(np.arccos(min(1.0, abs(float(t[2])))))))


def pnp_pose(p0: np.ndarray, p1: np.ndarray, depth_a: np.ndarray, k: np.ndarray,
             method: str = "USAC"):
    """(R, t, inliers) with x_b = R x_a + t from tracks ``p0`` (frame a, pixels with
    centres at integers) -> ``p1`` (frame b): p0 back-projected through frame a's depth
    (camera z, bilinear; what a LIDAR or the previous frame's map gives a navigation
    filter), then PnP. Unlike the essential matrix it gives the translation with its
    length, and it is well posed for a near-planar scene seen along the direction of
    motion, but poorly conditioned there: a small rotation and a lateral translation of
    altitude times it move a narrow nadir view's points alike, so a bias of the tracks
    leaks into both. ``"USAC"`` (default): OpenCV's USAC framework (MAGSAC++ scoring,
    sigma-consensus local optimisation, a least-squares polish over the inliers; as the
    essential matrix of ``measure_feature_tracking``); ``"RANSAC"``: EPnP in plain RANSAC
    (1 px) and a Levenberg-Marquardt polish over its inliers."""
    import cv2
    from scipy.ndimage import map_coordinates

    z = map_coordinates(depth_a, [p0[:, 1], p0[:, 0]], order=1, mode="nearest", cval=np.nan)
    ok = np.isfinite(z) & (z > 0)
    if ok.sum() < 8:
        return None
    ray = np.linalg.solve(k, np.vstack([p0[ok].T, np.ones(ok.sum())]))
    xa = (ray * z[ok]).T
    pb = p1[ok].astype(np.float64)
    if method == "USAC":
        prm = cv2.UsacParams()
        prm.threshold, prm.confidence, prm.maxIterations = 1.0, 0.99999, 2000
        prm.sampler, prm.score = cv2.SAMPLING_UNIFORM, cv2.SCORE_METHOD_MAGSAC
        prm.loMethod, prm.loIterations, prm.loSampleSize = cv2.LOCAL_OPTIM_SIGMA, 10, 20
        prm.final_polisher, prm.final_polisher_iterations = cv2.LSQ_POLISHER, 10
        found, _, rvec, tvec, inl = cv2.solvePnPRansac(xa, pb, k, np.zeros(5), params=prm)
    else:
        found, rvec, tvec, inl = cv2.solvePnPRansac(
            xa, pb, k, None, flags=cv2.SOLVEPNP_EPNP, reprojectionError=1.0,
            confidence=0.99999, iterationsCount=2000)
    if not found or inl is None or len(inl) < 8:
        return None
    inl = inl.ravel()
    if method != "USAC":
        rvec, tvec = cv2.solvePnPRefineLM(xa[inl], pb[inl], k, None, rvec, tvec)
    return cv2.Rodrigues(rvec)[0], np.ravel(tvec), len(inl)


def tracking(run) -> list[dict]:
    import measure_feature_tracking as mft

    rows = []
    for (fa, a), (fb, b) in zip(run[:-1], run[1:], strict=True):
        cam = fa.frame.camera
        k = np.array([[cam.fx, 0, cam.cx - 0.5], [0, cam.fy, cam.cy - 0.5], [0, 0, 1.0]])
        p0, p1, _ = mft.track_pair(a, b)
        row = {"altitude_m": fa.altitude_m, "tracks": len(p0)}
        if len(p0) >= 8:
            r_est, t_est, _ = mft.relative_pose(p0, p1, k)
            ra, pa = fa.frame.pose.rotation, fa.frame.pose.position_m
            rb, pb = fb.frame.pose.rotation, fb.frame.pose.position_m
            r_true = rb.T @ ra
            t_full = rb.T @ (pa - pb)
            t_true = t_full / np.linalg.norm(t_full)
            for tag, method in (("pnp", "USAC"), ("pnp_ransac", "RANSAC")):
                pnp = pnp_pose(p0, p1, fa.frame.depth_m, k, method)
                if pnp is not None:
                    row[f"{tag}_rotation_err_deg"] = mft.rotation_angle_deg(pnp[0] @ r_true.T)
                    row[f"{tag}_translation_rel_err"] = float(
                        np.linalg.norm(pnp[1] - t_full) / np.linalg.norm(t_full))
                    row[f"{tag}_inliers"] = pnp[2]
            t_est = np.ravel(t_est) / np.linalg.norm(t_est)
            row["rotation_err_deg"] = mft.rotation_angle_deg(r_est @ r_true.T)
            row["translation_err_deg"] = float(np.degrees(np.arccos(np.clip(
                abs(t_est @ t_true), -1.0, 1.0))))
            ratio = fa.altitude_m / fb.altitude_m
            zoom, shift, resid = zoom_fit(p0, p1, k[:2, 2])
            row["zoom_error"] = zoom / ratio - 1.0
            row["shift_px"] = float(np.hypot(*shift))
            row["track_noise_px"] = resid
            row["control_rotation_err_deg"], row["control_translation_err_deg"] = \
                control_errors(k, ratio, len(p0), resid, a.shape[0], len(rows))
        rows.append(row)
    return rows


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--frames", type=int, default=100, help="0: tiles only")
    ap.add_argument("--size", type=int, default=1024)
    ap.add_argument("--strip", default=None)
    ap.add_argument("--json", default=None)
    ap.add_argument("--skip-tiles", action="store_true")
    ap.add_argument("--tile-runs", type=int, default=7, help="timings a tile size")
    ap.add_argument("--site", default="0,0", help="LAT,LON degrees")
    ap.add_argument("--sun-elevation-deg", type=float, default=25.0)
    args = ap.parse_args()
    SITE[:] = [float(x) for x in args.site.split(",")]
    SUN_ELEVATION_DEG[0] = args.sun_elevation_deg
    sc = scene()
    result: dict = {}
    if not args.skip_tiles:
        result["tiles"] = tiles(sc, args.tile_runs)
    if args.frames < 1:
        return 0
    run, seconds = descent_run(sc, args.frames, args.size)
    print(f"descent: {args.frames} frames of {args.size}^2 from 100 km to 1 m in "
          f"{seconds:.1f} s", flush=True)
    shares = [top_octave_share(p) for _, p in run]
    ref = int(np.argmin([abs(np.log(f.altitude_m / 1e4)) for f, _ in run]))
    result["descent"] = {"frames": args.frames, "size": args.size, "seconds": seconds,
                         "reference_altitude_m": run[ref][0].altitude_m,
                         "per_frame": [{"altitude_m": f.altitude_m, "terrain": f.terrain,
                                        "craters": f.n_craters,
                                        "top_octave_share": s,
                                        "ratio_to_10km": s / shares[ref] if shares[ref] else 0}
                                       for (f, _), s in zip(run, shares, strict=True)]}
    ratios = [s / shares[ref] for s in shares]
    print(f"top-octave power share / its 10 km value: min {min(ratios):.3g} max "
          f"{max(ratios):.3g}")
    for (f, _), s, q in zip(run, shares, ratios, strict=True):
        print(f"  {f.altitude_m:10.4g} m  share {s:.3e}  ratio {q:.3g}")
    if len(run) > 1:
        rows = tracking(run)
        result["tracking"] = rows
        ok = [r for r in rows if "rotation_err_deg" in r]
        if ok:
            print(f"tracking: {len(ok)} of {len(rows)} pairs; worst rotation "
                  f"{max(r['rotation_err_deg'] for r in ok):.3g} deg, worst translation "
                  f"direction {max(r['translation_err_deg'] for r in ok):.3g} deg")
            lim = float(np.degrees(0.02))
            for name, pre in (("frames", ""), ("flat control", "control_")):
                rot = np.array([r[pre + "rotation_err_deg"] for r in ok])
                tra = np.array([r[pre + "translation_err_deg"] for r in ok])
                print(f"  {name}: {int(np.sum((rot <= 1.0) & (tra <= lim)))} pairs within "
                      f"1 deg and 2 % ({lim:.3g} deg); median rotation {np.nanmedian(rot):.3g}"
                      f" deg, translation {np.nanmedian(tra):.3g} deg")
            for tag, name in (("pnp", "USAC"), ("pnp_ransac", "EPnP-RANSAC + LM")):
                pn = [r for r in ok if f"{tag}_rotation_err_deg" in r]
                if not pn:
                    continue
                rot = np.array([r[f"{tag}_rotation_err_deg"] for r in pn])
                tra = np.array([r[f"{tag}_translation_rel_err"] for r in pn])
                print(f"  PnP ({name}) on frame a's depth: "
                      f"{int(np.sum((rot <= 1.0) & (tra <= 0.02)))} of {len(rows)} pairs within "
                      f"1 deg and 2 % of the translation; worst rotation {rot.max():.3g} deg, "
                      f"worst translation {tra.max():.3%}; median {np.median(rot):.3g} deg, "
                      f"{np.median(tra):.3%}")
            zoom = np.array([abs(r["zoom_error"]) for r in ok])
            print(f"  track geometry: |zoom / altitude ratio - 1| median {np.median(zoom):.2e}"
                  f" max {zoom.max():.2e}; shift median "
                  f"{np.median([r['shift_px'] for r in ok]):.3g} px max "
                  f"{max(r['shift_px'] for r in ok):.3g} px; track noise median "
                  f"{np.median([r['track_noise_px'] for r in ok]):.3g} px")
        for r in rows:
            print("  ", {k: (round(v, 4) if isinstance(v, float) else v) for k, v in r.items()})
    if args.strip:
        from PIL import Image

        picks = [int(np.argmin([abs(np.log(f.altitude_m / a)) for f, _ in run]))
                 for a in (1e5, 1e4, 1e3, 1e2, 1e1, 1.0)]
        pics = [run[i][1] for i in picks]
        gap = np.zeros((pics[0].shape[0], 6), np.uint8)
        strip = np.concatenate([x for p in pics for x in (p, gap)][:-1], axis=1)
        Image.fromarray(strip).save(args.strip)
        print(f"wrote {args.strip}")
    if args.json:
        Path(args.json).write_text(json.dumps(result, indent=1) + "\n")
        print(f"wrote {args.json}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
