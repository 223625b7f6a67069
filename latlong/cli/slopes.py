"""``latlong slopes``: slope distributions (3-degree bins) of bodies and real shape
models, geometric (against the radial direction) or gravitational (against the effective
gravity of the constant-density polyhedron, with rotation).

Inputs are saved bodies (``.npz``) or closed meshes (OBJ, PDS plate, PLY, STL, VTK;
``--shape-units`` says their units). Several inputs (``--compare``) are overlaid in one
plot with a legend and listed in one CSV and one summary table.
"""

from __future__ import annotations

import textwrap

import numpy as np

from craters.cli.kit import CliError, check_report_outputs, print_written
from craters.cli.options import REPORT, Setting, Values, command, default_of
from craters.cli.report import plot_slopes, slope_csv, slope_table
from latlong import gravity, slope_summary, slopes_and_areas

from ..slopes import SLOPE_BIN_DEG
from .inputs import INPUTS, labels, load_input

HELP = {
    "slopes": "slope distributions (3-degree bins) of bodies and shape models, with comparisons",
}

__all__ = ["register"]


def _axis(text: str) -> tuple[float, float, float]:
    """``X,Y,Z``: a rotation axis, three finite numbers, not all zero."""
    try:
        axis = tuple(float(x) for x in text.split(","))
    except ValueError:
        axis = ()
    if len(axis) != 3 or not np.all(np.isfinite(axis)) or not any(axis):
        raise ValueError(f"must be three numbers x,y,z, not all zero; got {text!r}")
    return axis


OPTIONS = {
    **INPUTS,
    "radius_deg": Setting(default_of(slopes_and_areas, "radius_deg"), "averaging cap radius",
                          unit="deg", range=(0.0, 90.0), run=True),
    "unweighted": Setting(False, "plain mean of vertex normals (off: area-weighted)",
                          run=True),
    "density_kg_m3": Setting(help="bulk density: slopes against the effective gravity of the "
                             "constant-density polyhedron", unit="kg/m^3", range=">0",
                             kind=float, run=True,
                             default_text="none, geometric slopes against the radial "
                             "direction"),
    "period_h": Setting(help="rotation period, for the centrifugal part", unit="h",
                        range=">0", kind=float, run=True, default_text="none, not rotating"),
    "spin_axis": Setting(default_of(gravity, "spin_axis"), "rotation axis in the body frame",
                         parse=_axis, commas=True, metavar="X,Y,Z", run=True),
    **REPORT,
}


def _gravity_args(v: Values):
    """(density, period, spin axis) from the flags, or None for geometric slopes."""
    if v.density_kg_m3 is None:
        for key in ("period_h", "spin_axis"):
            if key in v.given:
                raise CliError(f"{v.where(key)} needs --density-kg-m3 (gravitational slopes)")
        return None
    return v.density_kg_m3, np.inf if v.period_h is None else v.period_h, v.spin_axis


def _slopes(v: Values) -> int:
    inputs = [v.input, *(v.compare or [])]
    names = labels(inputs, v.label)
    grav = _gravity_args(v)
    check_report_outputs(v, [("input", p) for p in inputs])
    objs = [load_input(p, v.shape_units) for p in inputs]
    results, baselines = [], []
    for label, obj in zip(names, objs, strict=True):
        field = None if grav is None else gravity(obj.surface, grav[0], grav[1],
                                                  spin_axis=grav[2])
        s, a = obj.slopes(v.radius_deg, weighted=not v.unweighted, gravity=field)
        results.append((label, slope_summary(s, a, bin_deg=SLOPE_BIN_DEG)))
        baselines.append(np.radians(v.radius_deg) * float(obj.radii_m().mean()))
    if grav is None:
        kind, against = "geometric", "radial"
    else:
        rot = "not rotating" if np.isinf(grav[1]) else (
            f"period {grav[1]:g} h about ({','.join(f'{c:g}' for c in grav[2])})")
        kind = "gravitational"
        against = (f"minus the effective gravity (constant-density polyhedron, "
                   f"{grav[0]:g} kg/m^3, {rot})")
    if v.csv:
        baseline = "" if grav is None else " (cap radius " + ", ".join(
            f"{b:.4g} m" for b in baselines) + " at the mean radius)"
        slope_csv(v.csv, f"latlong slopes: {v.radius_deg:g} deg{baseline} "
                  f"{'unweighted' if v.unweighted else 'area-weighted'} cap-averaged "
                  f"normals vs {against}; bins in degrees; area fractions sum to 1; percent "
                  "of the area steeper than the bin's lower edge", results)
    if v.plot:
        shown = [(f"{label} (cap {b:.3g} m)", r) for (label, r), b in
                 zip(results, baselines, strict=True)]
        plot_slopes(v.plot, shown, xlabel=f"{kind} slope (deg), 3 deg bins",
                    ylabel="share of the surface area (%)",
                    title=(f"{kind} slopes: normals averaged over {v.radius_deg:g} deg "
                           "caps\n" + textwrap.fill("(" + ("vs the radial direction"
                                                           if grav is None
                                                           else f"vs {against}") + ")", 60)),
                    full_range=True)
    if not v.quiet:
        print(slope_table(results))
    print_written(v)
    return 0


def register(sub) -> None:
    """Register ``latlong slopes``."""
    command(sub, "slopes", _slopes, OPTIONS, prog="latlong",
            help=HELP["slopes"])
