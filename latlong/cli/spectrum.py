"""``latlong spectrum``: radius power spectra (degree variances of the radius in
spherical harmonics) of bodies and real shape models; mesh inputs are cast onto a
lat/long grid first. Several inputs (``--compare``) are overlaid in one plot with a legend
and listed in one CSV and one summary table.
"""

from __future__ import annotations

import numpy as np

from craters.cli.kit import check_report_outputs, print_written
from craters.cli.options import REPORT, Setting, Values, command
from craters.cli.report import plot_spectra, write_csv
from latlong import radius_spectrum

from .inputs import INPUTS, labels, load_input

HELP = {
    "spectrum": "radius power spectra of bodies and shape models, with comparisons",
}

__all__ = ["register"]

OPTIONS = {
    **INPUTS,
    "magnitude": Setting(200, "grid magnitude for mesh inputs", range=(1, 4000), run=True),
    "l_max": Setting(help="largest degree", kind=int, range=(1, None), run=True,
                     default_text="2M/3"),
    **REPORT,
}


def _spectrum(v: Values) -> int:
    inputs = [v.input, *(v.compare or [])]
    names = labels(inputs, v.label)
    check_report_outputs(v, [("input", p) for p in inputs])
    bodies = [load_input(p, v.shape_units).as_body(v.magnitude) for p in inputs]
    results = []
    for label, body in zip(names, bodies, strict=True):
        l_max = v.l_max or (2 * body.magnitude) // 3
        l_max = min(l_max, 2 * body.magnitude)
        degrees, power = radius_spectrum(body, l_max)
        mean_r = float(np.sqrt(power[0] / (4 * np.pi)))
        results.append((label, degrees, power, mean_r))
    if v.csv:
        n = min(len(d) for _, d, _, _ in results)
        cols = ["degree_l"]
        for label, *_ in results:
            cols += [f"wavelength_m[{label}]", f"power_m2[{label}]"]
        rows = []
        for k in range(n):
            row: list[float] = [k]
            for _, d, p, r in results:
                wl = 2 * np.pi * r / np.sqrt(d[k] * (d[k] + 1)) if d[k] else float("inf")
                row += [wl, p[k]]
            rows.append(row)
        write_csv(v.csv, "latlong spectrum: degree variance S_l = sum_m |a_lm|^2 of the "
                   "radius (metres) with orthonormal spherical harmonics; wavelength "
                   "2 pi R / sqrt(l(l+1)) at the mean radius R", cols, rows)
    if v.plot:
        plot_spectra(v.plot, [(label, d[1:], p[1:]) for label, d, p, _ in results],
                     xlabel="spherical-harmonic degree l", ylabel="degree variance S_l "
                     "(m$^2$)", title="radius power spectrum")
    if not v.quiet:
        print(f"{'input':<28} {'mean_radius_m':>13} {'rms_relief_m':>12} {'slope_l>=2':>10}")
        for label, d, p, r in results:
            rms = float(np.sqrt(p[1:].sum() / (4 * np.pi)))
            sel = (d >= 2) & (p > 0)
            beta = float(-np.polyfit(np.log(d[sel]), np.log(p[sel]), 1)[0]) if sel.sum() > 2 \
                else float("nan")
            print(f"{label[:28]:<28} {r:13.4g} {rms:12.4g} {-beta:10.2f}")
    print_written(v)
    return 0


def register(sub) -> None:
    """Register ``latlong spectrum``."""
    command(sub, "spectrum", _spectrum, OPTIONS, prog="latlong",
            help=HELP["spectrum"])
