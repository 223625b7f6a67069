"""``dem spectrum``: radially averaged power spectra of DEMs or stack layers (a manifest:
every layer is one input), several overlaid in one plot and listed in one CSV and one
summary table."""

from __future__ import annotations

from craters._shared import ParameterError
from craters.cli.kit import CliError, check_report_outputs, print_written
from craters.cli.options import Values
from craters.cli.report import plot_spectra, write_csv

from ..fractal import dimension_warning
from ..terrain import power_spectrum, spectral_exponent
from .options import REPORT_OPTIONS, dem_command, legend, report_inputs

HELP = {
    "spectrum": "radially averaged power spectra of DEMs or stack layers, with comparisons",
}

__all__ = ["register"]


def _spectrum(v: Values) -> int:
    check_report_outputs(v, [("input", p) for p in (v["input"], *(v["compare"] or []),
                                                     v.config_file)])
    results = []
    for label, d in report_inputs(v):
        if not d.known.all():
            raise CliError(f"{label}: the DEM has unknown pixels; fill them first (dem fill)")
        try:
            wl, p = power_spectrum(d)
        except ParameterError as exc:  # about this input, not an option
            if exc.name != "dem":
                raise
            raise CliError(exc.shown_as(f"{label}:")) from None
        results.append((label, wl, p, spectral_exponent(wl, p), d.resolution_m))
    if v.csv:
        n = max(len(wl) for _, wl, *_ in results)
        cols = sum(([f"wavelength_m[{lab}]", f"psd_m4[{lab}]"] for lab, *_ in results), [])
        rows = []
        for k in range(n):
            row = []
            for _, wl, p, *_ in results:
                row += [wl[k], p[k]] if k < len(wl) else ["", ""]
            rows.append(row)
        write_csv(v.csv, "dem spectrum: radially averaged power spectral density of the "
                   "heights (plane removed, Hann window), m^2 per (cycle/m)^2 = m^4, against "
                   "wavelength in metres", cols, rows)
    if v.plot:
        plot_spectra(v.plot, [(f"{legend(label, px)} (beta {beta:.2f})", wl, p)
                              for label, wl, p, beta, px in results],
                     xlabel="wavelength (m)", ylabel="power spectral density (m$^4$)",
                     title="radially averaged power spectrum", fmt=".-", ms=3,
                     invert_x=True)
    if not v.quiet:
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
    print_written(v)
    return 0


def register(sub) -> None:
    """Register ``dem spectrum``."""
    dem_command(sub, "spectrum", _spectrum, REPORT_OPTIONS,
                HELP["spectrum"])
