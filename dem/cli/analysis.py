"""``dem slopes`` and ``dem spectrum``: slope distributions and power spectra of DEMs.

Inputs are DEMs (GeoTIFF, PDS) or stack manifests (``dem enhance`` output: every layer
becomes one input). Several inputs (``--compare``) are overlaid in one plot with a
legend and listed in one CSV and one summary table.
"""

from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace

from craters._shared import ParameterError
from craters.cli.kit import CliError, check_report_outputs
from craters.cli.report import (
    plot_slopes,
    save_figure,
    series_colors,
    slope_csv,
    slope_table,
    write_csv,
)

from ..fractal import dimension_warning
from ..stack import read_stack
from ..terrain import power_spectrum, slope_distribution, spectral_exponent
from .options import Settings, add_command, read_input


def _inputs(s: Settings) -> list[tuple[str, object]]:
    out = []
    for path in [s["input"], *(s["compare"] or [])]:
        p = Path(path)
        if p.suffix.lower() == ".json":
            stack = read_stack(p)
            out += [(f"{p.stem} layer {k}", layer) for k, layer in enumerate(stack.layers)]
        else:
            out.append((p.stem, read_input(s, p)))
    if s["label"]:
        if len(s["label"]) != len(out):
            raise CliError(f"{s.where('label')}: give one label per input ({len(out)}, stack "
                           f"layers count one each); got {len(s['label'])}")
        out = [(lab, d) for lab, (_, d) in zip(s["label"], out, strict=True)]
    return out


def _legend(label: str, pixel_m: float) -> str:
    """A plot legend entry: the input's label and its pixel size ('layer 3, 0.25 m/px')."""
    return f"{label}, {pixel_m:.3g} m/px"


def _slopes(s: Settings) -> int:
    args = SimpleNamespace(**s)
    check_report_outputs(args, [("input", p) for p in (s["input"], *(s["compare"] or []),
                                                     s.config)])
    inputs = _inputs(s)
    results = [(label, slope_distribution(d, args.bin_deg, args.method))
               for label, d in inputs]
    if args.csv:
        slope_csv(args.csv, f"dem slopes: {args.method} slopes in degrees; pixels weighted by "
                  "ground area; area fractions sum to 1; percent of the area steeper than the "
                  "bin's lower edge", results)
    if args.plot:
        legends = [(_legend(label, d.resolution_m), r)
                   for (label, d), (_, r) in zip(inputs, results, strict=True)]
        plot_slopes(args.plot, legends, xlabel=f"slope (deg), {args.bin_deg:g} deg bins",
                    ylabel="share of the area (%)",
                    title=f"slope-area distribution ({args.method})")
    if not args.quiet:
        print(slope_table(results))
    return 0


def _spectrum(s: Settings) -> int:
    args = SimpleNamespace(**s)
    check_report_outputs(args, [("input", p) for p in (s["input"], *(s["compare"] or []),
                                                     s.config)])
    results = []
    for label, d in _inputs(s):
        if not d.known.all():
            raise CliError(f"{label}: the DEM has unknown pixels; fill them first (dem fill)")
        try:
            wl, p = power_spectrum(d)
        except ParameterError as exc:  # about this input, not an option
            if exc.name != "dem":
                raise
            raise CliError(exc.shown_as(f"{label}:")) from None
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
        write_csv(args.csv, "dem spectrum: radially averaged power spectral density of the "
                   "heights (plane removed, Hann window), m^2 per (cycle/m)^2 = m^4, against "
                   "wavelength in metres", cols, rows)
    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(7, 5))
        for (label, wl, p, beta, px), color in zip(results, series_colors(len(results)),
                                                   strict=True):
            ax.loglog(wl, p, ".-", ms=3, color=color,
                      label=f"{_legend(label, px)} (beta {beta:.2f})")
        ax.invert_xaxis()
        ax.set_xlabel("wavelength (m)")
        ax.set_ylabel("power spectral density (m$^4$)")
        ax.set_title("radially averaged power spectrum")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
        fig.tight_layout()
        save_figure(fig, args.plot)
        plt.close(fig)
    if not args.quiet:
        print(f"{'input':<28} {'pixel_m':>9} {'beta':>6} {'F=(8-beta)/2':>12}")
        notes = []
        for label, _, _, beta, px in results:
            warning = dimension_warning((8 - beta) / 2)
            f_text = "n/a" if warning else f"{(8 - beta) / 2:.2f}"
            print(f"{label[:28]:<28} {px:9.4g} {beta:6.2f} {f_text:>12}")
            if warning:
                notes.append(f"{label}: {warning}")
        for note in notes:
            print(note)
    return 0


def register(sub) -> None:
    """Add ``slopes`` and ``spectrum`` to the sub-command parser."""
    add_command(sub, "slopes", _slopes,
                "slope distributions of DEMs or stack layers, with comparisons")
    add_command(sub, "spectrum", _spectrum,
                "radially averaged power spectra of DEMs or stack layers, with comparisons")
