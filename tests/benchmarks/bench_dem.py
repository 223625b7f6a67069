"""Benchmarks and acceptance figures for the dem package (plain script, not a test).

Speeds are reported as absolute times on this machine plus a ratio against a reference
measured in the same run (a plain-numpy version of the same diamond-square doubling;
GDAL's inverse-distance ``fillnodata`` for gap filling). Usage:
``python tests/benchmarks/bench_dem.py [--quick] [--only enhance|expand_file|...]``. Uses
``../shared/data`` (LOLA LDEM_4, 720 x 1440 = 1.04 Mpx) when present, else the
257 x 257 crop in tests/data. The ``dem enhance`` / ``dem mesh`` figures run the real
command line in a child process and report its wall time and peak RSS (GNU time), the
machine's load average, the exact consistency of every pair of layers, the crater
accounting and the byte identity of a rerun with ``NUMBA_NUM_THREADS=1``.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from affine import Affine
from rasterio.windows import Window

import dem

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_latlong import best_of  # noqa: E402  (the shared timing helper)

ROOT = Path(__file__).resolve().parents[2]
LDEM4 = ROOT.parent / "shared" / "data" / "dems" / "lola_ldem4" / "LDEM_4.LBL"
CROP = ROOT / "tests" / "data" / "ldem4_crop.lbl"


def numpy_doubling(old, sd_sq, sd_dia, rng):
    """Reference: one diamond-square doubling in vectorised numpy (uniform amplitude)."""
    rows, cols = old.shape
    out = np.empty((2 * rows - 1, 2 * cols - 1))
    out[::2, ::2] = old
    out[1::2, 1::2] = (old[:-1, :-1] + old[:-1, 1:] + old[1:, :-1] + old[1:, 1:]) / 4
    out[1::2, 1::2] += sd_sq * rng.standard_normal(out[1::2, 1::2].shape)
    pad = np.pad(out, 1, constant_values=np.nan)
    nbrs = np.stack([pad[:-2, 1:-1], pad[2:, 1:-1], pad[1:-1, :-2], pad[1:-1, 2:]])
    n = np.isfinite(nbrs).sum(axis=0)
    mean = np.nansum(nbrs, axis=0) / np.maximum(n, 1)
    for sl in ((slice(0, None, 2), slice(1, None, 2)), (slice(1, None, 2), slice(0, None, 2))):
        out[sl] = mean[sl] + sd_dia * rng.standard_normal(out[sl].shape)
    return out


def bench_expand(quick):
    n = 1025 if quick else 2049
    seed = dem.Dem(np.random.default_rng(3).normal(0, 100, (129, 129)), pixel_size_m=512.0)
    base = dem.expand(seed, int(np.log2((n - 1) // 128)), fractal_dimension=2.3,
                      roughness=0.5, rng=1)
    dem.expand(dem.Dem(np.zeros((5, 5)), pixel_size_m=1.0), 1, rng=0)  # warm the cache
    t_given, e = best_of(lambda: dem.expand(base, 1, fractal_dimension=2.3, roughness=0.5,
                                            rng=2))
    t_default, _ = best_of(lambda: dem.expand(base, 1, rng=2))
    sq, dia = dem.displacement_scales(1, 2.3, 0.5 * base.resolution_m)
    t_np, _ = best_of(lambda: numpy_doubling(base.heights, sq, dia,
                                             np.random.default_rng(0)), repeat=1)
    print(f"expand {n}^2 -> {e.shape[0]}^2, 1 level: {t_given:.3f} s with F and roughness "
          f"given, {t_default:.3f} s with both estimated (F fit + local amplitude); "
          f"numpy reference doubling {t_np:.3f} s (x{t_np / t_given:.1f} slower)")


def blobs(shape, frac, rng, rmin, rmax):
    yy, xx = np.mgrid[0:shape[0], 0:shape[1]]
    mask = np.zeros(shape, bool)
    while mask.mean() < frac:
        r = rng.uniform(rmin, rmax)
        cy, cx = rng.uniform(0, shape[0]), rng.uniform(0, shape[1])
        y0, y1 = max(int(cy - r - 1), 0), min(int(cy + r + 2), shape[0])
        x0, x1 = max(int(cx - r - 1), 0), min(int(cx + r + 2), shape[1])
        mask[y0:y1, x0:x1] |= (yy[y0:y1, x0:x1] - cy) ** 2 + (xx[y0:y1, x0:x1] - cx) ** 2 <= r * r
    return mask


def laplacian_ratio(filled, mask):
    lap = dem.laplacian(filled)
    known = ~mask
    stencil = known & np.roll(known, 1, 0) & np.roll(known, -1, 0) & np.roll(known, 1, 1) \
        & np.roll(known, -1, 1)
    ok = np.isfinite(lap)
    return np.std(lap[mask & ok]) / np.std(lap[stencil & ok])


def bench_fill(quick):
    from rasterio.fill import fillnodata

    source = dem.read(LDEM4 if LDEM4.exists() and not quick else CROP)
    name = "LOLA LDEM_4" if source.shape[0] == 720 else "LOLA LDEM_4 257^2 crop"
    dem.fill_gaps(dem.Dem(np.array([[1.0, np.nan]]), pixel_size_m=1.0), rng=0)  # warm
    for label, (rmin, rmax) in (("blobs r 3-20 px", (3, 20)), ("blobs r 30-60 px", (30, 60))):
        mask = blobs(source.shape, 0.10, np.random.default_rng(7), rmin, rmax)
        z = source.heights.copy()
        z[mask] = np.nan
        gappy = source.replace(heights=z)
        t, f = best_of(lambda g=gappy: dem.fill_gaps(g, rng=1))
        kept = np.array_equal(f.heights[~mask], source.heights[~mask])
        t_ref, _ = best_of(lambda m=mask, zz=z: fillnodata(np.where(m, 0, zz), ~m,
                                                           max_search_distance=200), repeat=1)
        print(f"fill_gaps {name} {source.shape[0]}x{source.shape[1]} "
              f"({source.heights.size / 1e6:.2f} Mpx), {100 * mask.mean():.1f} % cut out in "
              f"{label}: {t:.3f} s; GDAL fillnodata {t_ref:.3f} s (x{t_ref / t:.1f}); known "
              f"pixels bit for bit: {kept}; NaN left: {int(np.isnan(f.heights).sum())}; "
              f"Laplacian std filled/known {laplacian_ratio(f, mask):.2f}")


def fill_spectra(quick):
    """The fill's spectrum against the terrain's: crosshatch and mid-scale power, new fill
    and the paper's outside-in fill (tests/dem/test_fill.py's reference), with pictures."""
    sys.path.insert(0, str(ROOT / "tests" / "dem"))
    sys.path.insert(0, str(ROOT / "tests"))
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from conftest import spectral_fbm
    from matplotlib.colors import LightSource
    from test_fill import disc_gap, paper_fill, spectrum_ratios

    crop = dem.read(CROP)
    fbm = dem.Dem(spectral_fbm(257, 8 - 2 * 2.3, np.random.default_rng(0)) * 300.0,
                  pixel_size_m=100.0)
    seeds = (1,) if quick else (1, 2, 3, 4, 5, 6)
    patch = np.s_[73:183, 73:183]
    light = LightSource(azdeg=315, altdeg=40)
    fig, axes = plt.subplots(2, 3, figsize=(14, 9.5))
    for row, (name, d) in enumerate((("LOLA crop", crop), ("fBm F=2.3", fbm))):
        gappy, _ = disc_gap(d, 80)
        new = [dem.fill_gaps(gappy, rng=s) for s in seeds]
        r_new = np.array([spectrum_ratios(f.heights[patch], d.heights[patch]) for f in new])
        sigma = dem.expansion_fit(d).roughness * d.resolution_m * 0.63
        t = time.perf_counter()
        old = paper_fill(gappy.heights, sigma, np.random.default_rng(1))
        t_old = time.perf_counter() - t
        r_old = spectrum_ratios(old[patch], d.heights[patch])
        r_self = [spectrum_ratios(d.heights[q], d.heights[patch])
                  for q in (np.s_[0:110, 0:110], np.s_[147:257, 147:257])]
        print(f"fill of a 160-px disc in the {name}, Nyquist diagonal/axis power and 6-12 px "
              f"power relative to the original: new {r_new[:, 0].mean():.2f} "
              f"({r_new[:, 0].min():.2f}-{r_new[:, 0].max():.2f}, {len(seeds)} seeds) / "
              f"{r_new[:, 1].mean():.2f}; paper's outside-in fill {r_old[0]:.2f} / "
              f"{r_old[1]:.2f} (numpy reference, {t_old:.1f} s); two other patches of the "
              f"original {r_self[0][0]:.2f}, {r_self[1][0]:.2f} / {r_self[0][1]:.2f}, "
              f"{r_self[1][1]:.2f}")
        ex = 3.0 / np.std(np.diff(d.heights, axis=1))
        for col, (title, z) in enumerate((("original", d.heights),
                                          ("paper's outside-in fill", old),
                                          ("dem.fill_gaps", new[0].heights))):
            axes[row, col].imshow(light.hillshade(z[40:216, 40:216], vert_exag=ex),
                                  cmap="gray", interpolation="nearest")
            axes[row, col].set_title(f"{name}: {title}")
    fig.tight_layout()
    path = ROOT / "out" / "bench_fill.png"
    path.parent.mkdir(exist_ok=True)
    fig.savefig(path, dpi=80)
    print(f"wrote {path}")


def figures(quick):
    seeds = (1,) if quick else (1, 2, 3)
    for f in (2.2, 2.5, 2.8):
        seed = dem.Dem(np.random.default_rng(3).normal(0, 100, (17, 17)), pixel_size_m=128.0)
        e = dem.expand(seed, 7, fractal_dimension=f, roughness=1.0, rng=5)
        print(f"17^2 seed expanded 7 levels ({e.shape[0]}^2) with F = {f}: estimated F = "
              f"{dem.fractal_dimension(e):.3f}")
    crop = dem.read(CROP)
    k = 4
    coarse = dem.Dem(crop.heights[::k, ::k], crop.transform
                     @ Affine.translation(-(k - 1) / 2, -(k - 1) / 2) @ Affine.scale(k),
                     crop.crs, body_radius_m=crop.body_radius_m)

    def ratios(d):
        return (np.nanmedian(dem.slope(d)) / np.nanmedian(dem.slope(crop)),
                dem.band_power(d) / dem.band_power(crop),
                np.nanstd(dem.laplacian(d)) / np.nanstd(dem.laplacian(crop)))

    for s in seeds:
        r = ratios(dem.expand(coarse, 2, rng=s))
        print(f"LOLA crop decimated 4x, expand 2 levels (defaults, seed {s}): median slope "
              f"x{r[0]:.3f}, top-octave power x{r[1]:.3f}, Laplacian std x{r[2]:.3f}")
    from scipy.interpolate import RectBivariateSpline

    grid = np.arange(coarse.shape[0]) * k
    spline = RectBivariateSpline(grid, grid, coarse.heights, kx=3, ky=3)
    r = ratios(crop.replace(heights=spline(np.arange(257), np.arange(257))))
    print(f"same, bicubic spline: median slope x{r[0]:.3f}, top-octave power x{r[1]:.2e}, "
          f"Laplacian std x{r[2]:.3f}")
    if LDEM4.exists() and not quick:
        full = dem.read(LDEM4)
        passed = 0
        cols = range(0, 1440 - 257, 130)
        for c0 in cols:
            c = full.crop(Window(c0, 232, 257, 257))
            cc = dem.Dem(c.heights[::k, ::k], c.transform
                         @ Affine.translation(-(k - 1) / 2, -(k - 1) / 2) @ Affine.scale(k),
                         c.crs, body_radius_m=c.body_radius_m)
            e = dem.expand(cc, 2, rng=1)
            q = (np.nanmedian(dem.slope(e)) / np.nanmedian(dem.slope(c)),
                 dem.band_power(e) / dem.band_power(c),
                 np.nanstd(dem.laplacian(e)) / np.nanstd(dem.laplacian(c)))
            ok = 0.75 <= q[0] <= 1.33 and 1 / 3 <= q[1] <= 3 and 0.5 <= q[2] <= 2
            passed += ok
            print(f"  equatorial crop lon {c0 / 4:5.1f}-{(c0 + 257) / 4:5.1f} E: slope "
                  f"x{q[0]:.2f}, top octave x{q[1]:.2f}, Laplacian x{q[2]:.2f} "
                  f"{'ok' if ok else 'OUTSIDE'}")
        print(f"  {passed} of {len(cols)} equatorial crops inside all three bounds")


def timed_child(args, env=None):
    """Wall time and peak RSS (MiB) of one child process.

    The peak comes from ``/proc/<pid>/status`` ``VmHWM`` read by GNU time (``%M``) when
    ``/usr/bin/time`` exists: ``wait4``'s ``ru_maxrss`` of a child spawned from this
    (large) process starts at this process's own peak on Linux (exec records the old
    address space's high-water mark), which would report the benchmark, not the command.
    """
    full = dict(os.environ)
    full.update(env or {})
    gnu_time = Path("/usr/bin/time")
    prefix = [str(gnu_time), "-f", "maxrss_kb=%M"] if gnu_time.exists() else []
    t0 = time.perf_counter()
    proc = subprocess.run([*prefix, sys.executable, "-m", *args], env=full,
                          stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    wall = time.perf_counter() - t0
    if proc.returncode:
        raise RuntimeError(f"{' '.join(args)} failed: {proc.stderr}")
    lines = [x for x in proc.stderr.splitlines() if x.startswith("maxrss_kb=")]
    return wall, (int(lines[-1].split("=")[1]) / 1024 if lines else float("nan"))


def bench_enhance(quick):
    """`dem enhance`: an 11-level stack of 1025^2 layers from a 1025^2 base, with craters."""
    size, levels = (513, 6) if quick else (1025, 11)
    crop = dem.read(CROP)
    base = dem.expand(crop, 1 if quick else 2, rng=5)  # LOLA at 3.8 / 1.9 km per pixel
    with tempfile.TemporaryDirectory(dir=ROOT.parent) as tmp:
        tmp = Path(tmp)
        dem.write(base, tmp / "base.tif")
        scene = tmp / "scene.toml"
        scene.write_text(
            f'input = "{tmp / "base.tif"}"\nlayers = {levels}\nsize = {size}\n'
            'craters = ["c=0.05,k=-2,d_min_m=0.5,d_max_m=60000", '
            '"c=0.01,k=-1.8,d_min_m=5000,d_max_m=200000,age_min_gyr=3,age_max_gyr=3.9,kind=old"]\n')
        load = os.getloadavg()[0]
        wall, rss = timed_child(["dem", "enhance", "--config", str(scene), "-o", str(tmp / "a"),
                                 "--seed", "2014", "-q"])
        stack = dem.read_stack(tmp / "a")
        pairs = [np.array_equal(stack.layers[k].heights[::2, ::2],
                                stack.layers[k - 1].heights[r0:r0 + w, c0:c0 + w])
                 for k, (r0, c0, w) in enumerate(stack.windows, start=1)]
        c = stack.info["craters"]
        adds_up = c["drawn"] == (sum(c["stamped"]) + sum(c["erased_on_steep_ground"])
                                 + c["rejected"])
        ids = np.concatenate([cat["index"] for cat in stack.catalogs])
        sizes = stack.pixel_sizes_m()
        print(f"dem enhance {levels} layers of {size}^2 from a {size}^2 LOLA-based base "
              f"({sizes[0]:.4g} -> {sizes[-1]:.4g} m/px), 2 crater layers: {wall:.1f} s wall, "
              f"peak RSS {rss:.0f} MiB (load average before: {load:.2f})")
        print(f"  consistency, every pair of layers exact: {all(pairs)} ({len(pairs)} pairs); "
              f"craters stamped {sum(c['stamped'])} (per layer {c['stamped']}), erased on "
              f"steep ground {sum(c['erased_on_steep_ground'])}, rejected {c['rejected']}, "
              f"drawn {c['drawn']}: adds up {adds_up}; catalog rows {len(ids)}, distinct ids "
              f"{len(np.unique(ids))}")
        wall1, _ = timed_child(["dem", "enhance", "--config", str(scene), "-o", str(tmp / "b"),
                                "--seed", "2014", "-q"], env={"NUMBA_NUM_THREADS": "1"})
        same = all((tmp / "a" / f.name).read_bytes() == f.read_bytes()
                   for f in (tmp / "b").iterdir())
        print(f"  rerun with NUMBA_NUM_THREADS=1: {wall1:.1f} s, same bytes in all "
              f"{len(list((tmp / 'b').iterdir()))} files: {same}")
        for suffix in (".ply", ".vtp"):
            mesh = tmp / f"stack{suffix}"
            wall, rss = timed_child(["dem", "mesh", str(tmp / "a" / "manifest.json"), "-o",
                                     str(mesh), "-q"])
            print(f"dem mesh -> {suffix}: {wall:.1f} s, peak RSS {rss:.0f} MiB, "
                  f"{mesh.stat().st_size / 2**20:.0f} MiB")
        doc = json.loads((tmp / "a" / "manifest.json").read_text())
        assert doc["info"]["seed"] == 2014


def bench_expand_file(quick):
    """`dem expand` bigger than memory: a 1025^2 base by 4 levels (16385^2 pixels) tile by
    tile; peak RSS, the file (COG validation) and windows against separate expansions."""
    from rio_cogeo.cogeo import cog_validate

    crop = dem.read(CROP)
    base = crop if quick else dem.expand(crop, 2, rng=5)  # 257^2 or 1025^2
    with tempfile.TemporaryDirectory(dir=ROOT.parent) as tmp:
        tmp = Path(tmp)
        dem.write(base, tmp / "base.tif")
        load = os.getloadavg()[0]
        wall, rss = timed_child(["dem", "expand", str(tmp / "base.tif"), "-o",
                                 str(tmp / "big.tif"), "--levels", "4", "--seed", "2", "-q"])
        side = (base.shape[0] - 1) * 16 + 1
        size = (tmp / "big.tif").stat().st_size
        valid, errors, warnings = cog_validate(tmp / "big.tif", strict=True)
        print(f"dem expand {base.shape[0]}^2 by 4 levels -> {side}^2 ({side**2 / 1e6:.0f} "
              f"Mpx, {size / 1e9:.2f} GB file): {wall:.1f} s wall, peak RSS {rss:.0f} MiB "
              f"(load average before: {load:.2f}); cog_validate: {valid} {errors} {warnings}")
        same = []
        for r0, c0 in ((0, 0), (base.shape[0] // 2, base.shape[0] // 4)):
            part = dem.expand(base, 4, region=(r0, c0, 129), rng=2)
            win = dem.read(tmp / "big.tif", window=(16 * r0, 16 * c0, *part.shape))
            same.append(np.array_equal(win.heights, part.heights.astype(np.float32)))
        print(f"  windows of the file equal separate region expansions: {all(same)}")
        if quick:  # the whole raster fits: the same bytes in one piece
            whole = dem.write(dem.expand(base, 4, rng=2), tmp / "whole.tif")
            print(f"  tiled file == whole-raster file, byte for byte: "
                  f"{whole.read_bytes() == (tmp / 'big.tif').read_bytes()}")


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--quick", action="store_true", help="smaller sizes")
    parser.add_argument("--only", choices=["expand", "fill", "fill_spectra", "figures",
                                           "enhance", "expand_file"],
                        help="run one part")
    args = parser.parse_args()
    quick = args.quick
    print(f"machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cores, "
          f"numba threads {os.environ.get('NUMBA_NUM_THREADS', 'default')}")
    parts = {"expand": bench_expand, "fill": bench_fill, "fill_spectra": fill_spectra,
             "figures": figures, "enhance": bench_enhance, "expand_file": bench_expand_file}
    for name, func in parts.items():
        if args.only in (None, name):
            func(quick)


if __name__ == "__main__":
    main()
