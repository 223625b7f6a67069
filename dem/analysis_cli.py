"""``dem slopes`` and ``dem spectrum``: slope distributions and power spectra of DEMs.

Inputs are DEMs (GeoTIFF, PDS) or stack manifests (``dem enhance`` output: every layer
becomes one input). Several inputs (``--compare``) are overlaid in one plot with a
legend and listed in one CSV and one summary table.
"""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np

from craters._infra import CliError, atomic_path, check_output_path

from .io import read
from .stack import read_stack
from .terrain import power_spectrum, slope_distribution, spectral_exponent


def _inputs(args) -> list[tuple[str, object]]:
    out = []
    for path in [args.input, *(args.compare or [])]:
        p = Path(path)
        if p.suffix.lower() == ".json":
            stack = read_stack(p)
            out += [(f"{p.stem} layer {k}", layer) for k, layer in enumerate(stack.layers)]
        else:
            out.append((p.stem, read(p, pixel_size_m=args.pixel_size_m,
                                     body_radius_m=args.body_radius_m)))
    if args.label:
        if len(args.label) != len(out):
            raise CliError(f"--label: give one label per input ({len(out)}, stack layers "
                           f"count one each); got {len(args.label)}")
        out = [(lab, d) for lab, (_, d) in zip(args.label, out, strict=True)]
    return out


def _check_outputs(args) -> None:
    if args.csv:
        check_output_path(args.csv, force=args.force, suffixes=(".csv",))
    if args.plot:
        check_output_path(args.plot, force=args.force, suffixes=(".png",))


def _write_csv(path, comment: str, columns, rows) -> None:
    with atomic_path(path) as tmp, open(tmp, "w", newline="", encoding="utf-8") as fh:
        fh.write(f"# {comment}\n")
        w = csv.writer(fh, lineterminator="\n")
        w.writerow(columns)
        for row in rows:
            w.writerow([repr(float(v)) if isinstance(v, float | np.floating) else v
                        for v in row])


def _save(fig, path) -> None:
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=110, format="png")


def cmd_slopes(args) -> int:
    if not 0.01 <= args.bin_deg <= 90:
        raise CliError(f"--bin-deg must be in [0.01, 90]; got {args.bin_deg}")
    _check_outputs(args)
    results = [(label, slope_distribution(d, args.bin_deg, args.method))
               for label, d in _inputs(args)]
    edges = results[0][1]["edges_deg"]
    n_bins = min(len(r["area_fraction"]) for _, r in results)
    if args.csv:
        cols = ["slope_lo_deg", "slope_hi_deg"]
        for label, _ in results:
            cols += [f"area_fraction[{label}]", f"percent_area_steeper_than_lo[{label}]"]
        rows = [[edges[b], edges[b + 1], *sum(([r["area_fraction"][b], r["above_percent"][b]]
                                               for _, r in results), [])]
                for b in range(n_bins)]
        _write_csv(args.csv, f"dem slopes: {args.method} slopes in degrees; pixels weighted by "
                   "ground area; area fractions sum to 1; percent of the area steeper than the "
                   "bin's lower edge", cols, rows)
    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, (ax0, ax1) = plt.subplots(1, 2, figsize=(12, 4.8))
        centres = 0.5 * (edges[:n_bins] + edges[1:n_bins + 1])
        for label, r in results:
            ax0.plot(centres, 100 * r["area_fraction"][:n_bins], "o-", ms=3, label=label)
            above = r["above_percent"][:n_bins]
            ax1.semilogy(edges[:n_bins], np.where(above > 1e-6, above, np.nan), "o-", ms=3,
                         label=label)
        ax0.set_xlabel(f"slope (deg), {args.bin_deg:g} deg bins")
        ax0.set_ylabel("share of the area (%)")
        ax0.set_title(f"slope-area distribution ({args.method})")
        ax1.set_xlabel("slope (deg)")
        ax1.set_ylabel("area steeper than the slope (%)")
        ax1.set_title("cumulative slope-frequency")
        for ax in (ax0, ax1):
            ax.grid(True, which="both", alpha=0.3)
            ax.legend(fontsize=8)
        fig.tight_layout()
        _save(fig, args.plot)
        plt.close(fig)
    if not args.quiet:
        print(f"{'input':<28} {'median_deg':>10} {'mean_deg':>9} {'>10deg_%':>9} "
              f"{'>20deg_%':>9} {'>30deg_%':>9}")
        for label, r in results:
            pa = r["percent_above"]
            print(f"{label[:28]:<28} {r['median_deg']:10.2f} {r['mean_deg']:9.2f} "
                  f"{pa[10]:9.2f} {pa[20]:9.2f} {pa[30]:9.2f}")
    return 0


def cmd_spectrum(args) -> int:
    _check_outputs(args)
    results = []
    for label, d in _inputs(args):
        if not d.known.all():
            raise CliError(f"{label}: the DEM has unknown pixels; fill them first (dem fill)")
        wl, p = power_spectrum(d)
        results.append((label, wl, p, spectral_exponent(wl, p), d.resolution_m))
    if args.csv:
        n = max(len(wl) for _, wl, *_ in results)
        cols = sum(([f"wavelength_m[{lab}]", f"psd_m4[{lab}]"] for lab, *_ in results), [])
        rows = []
        for k in range(n):
            row = []
            for _, wl, p, *_ in results:
                row += [wl[k], p[k]] if k < len(wl) else ["", ""]
            rows.append(row)
        _write_csv(args.csv, "dem spectrum: radially averaged power spectral density of the "
                   "heights (plane removed, Hann window), m^2 per (cycle/m)^2 = m^4, against "
                   "wavelength in metres", cols, rows)
    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(7, 5))
        for label, wl, p, beta, _ in results:
            ax.loglog(wl, p, ".-", ms=3, label=f"{label} (beta {beta:.2f})")
        ax.invert_xaxis()
        ax.set_xlabel("wavelength (m)")
        ax.set_ylabel("power spectral density (m$^4$)")
        ax.set_title("radially averaged power spectrum")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
        fig.tight_layout()
        _save(fig, args.plot)
        plt.close(fig)
    if not args.quiet:
        print(f"{'input':<28} {'pixel_m':>9} {'beta':>6} {'F=(8-beta)/2':>12}")
        for label, _, _, beta, px in results:
            print(f"{label[:28]:<28} {px:9.4g} {beta:6.2f} {(8 - beta) / 2:12.2f}")
    return 0


def add_parsers(sub) -> None:
    """Register ``slopes`` and ``spectrum`` on the dem sub-command parser."""
    for name, func, text in (("slopes", cmd_slopes, "slope distributions"),
                             ("spectrum", cmd_spectrum, "radially averaged power spectra")):
        p = sub.add_parser(name, help=f"{text} of DEMs or stack layers, with comparisons")
        p.add_argument("input", help="a DEM (GeoTIFF, PDS .lbl/.img) or a stack manifest")
        p.add_argument("--compare", nargs="+", metavar="OTHER", help="more inputs to overlay")
        p.add_argument("--label", nargs="+", help="legend labels, one per input (layer)")
        p.add_argument("--pixel-size-m", type=float, help="pixel size of DEMs without CRS")
        p.add_argument("--body-radius-m", type=float, help="body radius for geographic CRS")
        if name == "slopes":
            p.add_argument("--method", choices=("horn", "central"), default="horn",
                           help="slope estimator (default horn)")
            p.add_argument("--bin-deg", type=float, default=3.0, help="histogram bin, degrees")
        p.add_argument("--csv", help="write the table (CSV, units in the header)")
        p.add_argument("--plot", help="write the plot (PNG)")
        p.add_argument("--force", action="store_true", help="overwrite existing outputs")
        p.add_argument("-q", "--quiet", action="store_true", help="no summary table")
        p.set_defaults(func=func)
