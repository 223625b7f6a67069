"""``dem slopes``: slope distributions of DEMs or stack layers (a manifest: every layer is
one input), several overlaid in one plot and listed in one CSV and one summary table."""

from __future__ import annotations

from craters.cli.kit import check_report_outputs, print_written
from craters.cli.options import Setting, Values, default_of
from craters.cli.report import plot_slopes, slope_csv, slope_table

from ..terrain import slope_distribution
from .options import REPORT_OPTIONS, dem_command, legend, report_inputs

HELP = {
    "slopes": "slope distributions of DEMs or stack layers, with comparisons",
}

__all__ = ["register"]

OPTIONS = {**REPORT_OPTIONS,
           "method": Setting(default_of(slope_distribution, "method"), "slope estimator",
                             choices=("horn", "central")),
           "bin_deg": Setting(default_of(slope_distribution, "bin_deg"), "histogram bin, "
                              "degrees (0.01..90)", metavar="DEG")}


def _slopes(v: Values) -> int:
    check_report_outputs(v, [("input", p) for p in (v["input"], *(v["compare"] or []),
                                                     v.config_file)])
    inputs = report_inputs(v)
    results = [(label, slope_distribution(d, v.bin_deg, v.method))
               for label, d in inputs]
    if v.csv:
        slope_csv(v.csv, f"dem slopes: {v.method} slopes in degrees; pixels weighted by "
                  "ground area; area fractions sum to 1; percent of the area steeper than the "
                  "bin's lower edge", results)
    if v.plot:
        legends = [(legend(label, d.resolution_m), r)
                   for (label, d), (_, r) in zip(inputs, results, strict=True)]
        plot_slopes(v.plot, legends, xlabel=f"slope (deg), {v.bin_deg:g} deg bins",
                    ylabel="share of the area (%)",
                    title=f"slope-area distribution ({v.method})")
    if not v.quiet:
        print(slope_table(results))
    print_written(v)
    return 0


def register(sub) -> None:
    """Register ``dem slopes``."""
    dem_command(sub, "slopes", _slopes, OPTIONS,
                HELP["slopes"])
