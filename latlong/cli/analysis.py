"""``latlong slopes`` and ``latlong spectrum``: compare bodies and real shape models.

Inputs are saved bodies (``.npz``) or closed meshes (OBJ, PDS plate, PLY, STL, VTK;
``--shape-units`` says their units). Several inputs (``--compare``) are overlaid in one
plot with a legend and listed in one CSV and one summary table.
"""

from __future__ import annotations

import functools
import textwrap
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from craters.cli.kit import CliError, add_report_arguments, check_report_outputs
from craters.cli.report import (
    plot_slopes,
    save_figure,
    series_colors,
    slope_csv,
    slope_table,
    write_csv,
)
from latlong import (
    from_shape_model,
    gravity,
    load,
    mesh_slopes,
    radius_spectrum,
    read_shape_model,
    slope_summary,
    slopes_and_areas,
)

from ..slopes import SLOPE_BIN_DEG


@dataclass(frozen=True)
class _Input:
    """An input as loaded: the surface and what each command does with it (a body .npz
    and a mesh file are measured differently: slopes over grid caps or direction caps)."""

    surface: object
    """The Body or ShapeModel."""
    slopes: Callable
    """``(radius_deg, weighted=, gravity=) -> (slopes_deg, areas_m2)``."""
    radii_m: Callable
    """``() -> distances (m) of the vertices from the centre the caps are taken around``."""
    as_body: Callable
    """``magnitude -> Body`` (a body: itself; a mesh: cast onto that grid)."""


def _load_input(path: str, units: str | None) -> _Input:
    p = Path(path)
    if p.suffix.lower() == ".npz":
        body = load(p)
        return _Input(body, functools.partial(slopes_and_areas, body),
                      lambda: np.linalg.norm(body.vertices(), axis=1), lambda _: body)
    if units is None:
        raise CliError(f"{path}: a mesh file needs --shape-units km or m")
    model = read_shape_model(p, units=units)
    return _Input(model, functools.partial(mesh_slopes, model),
                  lambda: np.linalg.norm(model.vertices - model.volume_centroid, axis=1),
                  lambda m: from_shape_model(model, m, crossings="outermost", smooth="linear"))


def _labels(inputs, labels) -> list[str]:
    if labels:
        if len(labels) != len(inputs):
            raise CliError(f"--label: give one label per input ({len(inputs)}); "
                           f"got {len(labels)}")
        return list(labels)
    names = [Path(p).stem for p in inputs]
    return [n if names.count(n) == 1 else f"{n} ({k})" for k, n in enumerate(names)]


# --------------------------------------------------------------------------- slopes
def _gravity_args(args):
    """(density, period, spin axis) from the flags, or None for geometric slopes."""
    if args.density_kg_m3 is None:
        for flag, value in (("--period-h", args.period_h), ("--spin-axis", args.spin_axis)):
            if value is not None:
                raise CliError(f"{flag} needs --density-kg-m3 (gravitational slopes)")
        return None
    if not np.isfinite(args.density_kg_m3) or args.density_kg_m3 <= 0:
        raise CliError(f"--density-kg-m3 must be finite and > 0; got {args.density_kg_m3}")
    period = np.inf if args.period_h is None else args.period_h
    if not period > 0 or np.isnan(period):
        raise CliError(f"--period-h must be > 0; got {args.period_h}")
    axis = (0.0, 0.0, 1.0)
    if args.spin_axis is not None:
        try:
            axis = tuple(float(x) for x in args.spin_axis.split(","))
        except ValueError:
            axis = ()
        if len(axis) != 3 or not np.all(np.isfinite(axis)) or not any(axis):
            raise CliError(f"--spin-axis must be three numbers x,y,z, not all zero; got "
                           f"{args.spin_axis!r}")
    return args.density_kg_m3, period, axis


def cmd_slopes(args) -> int:
    inputs = [args.input, *(args.compare or [])]
    labels = _labels(inputs, args.label)
    if not 0 <= args.radius_deg <= 90 or not np.isfinite(args.radius_deg):
        raise CliError(f"--radius-deg must be in [0, 90]; got {args.radius_deg}")
    grav = _gravity_args(args)
    check_report_outputs(args, [("input", p) for p in inputs])
    objs = [_load_input(p, args.shape_units) for p in inputs]
    results, baselines = [], []
    for label, obj in zip(labels, objs, strict=True):
        field = None if grav is None else gravity(obj.surface, grav[0], grav[1],
                                                  spin_axis=grav[2])
        s, a = obj.slopes(args.radius_deg, weighted=not args.unweighted, gravity=field)
        results.append((label, slope_summary(s, a, bin_deg=SLOPE_BIN_DEG)))
        baselines.append(np.radians(args.radius_deg) * float(obj.radii_m().mean()))
    if grav is None:
        kind, against = "geometric", "radial"
    else:
        rot = "not rotating" if np.isinf(grav[1]) else (
            f"period {grav[1]:g} h about ({','.join(f'{c:g}' for c in grav[2])})")
        kind = "gravitational"
        against = (f"minus the effective gravity (constant-density polyhedron, "
                   f"{grav[0]:g} kg/m^3, {rot})")
    if args.csv:
        baseline = "" if grav is None else " (cap radius " + ", ".join(
            f"{b:.4g} m" for b in baselines) + " at the mean radius)"
        slope_csv(args.csv, f"latlong slopes: {args.radius_deg:g} deg{baseline} "
                  f"{'unweighted' if args.unweighted else 'area-weighted'} cap-averaged "
                  f"normals vs {against}; bins in degrees; area fractions sum to 1; percent "
                  "of the area steeper than the bin's lower edge", results)
    if args.plot:
        shown = [(f"{label} (cap {b:.3g} m)", r) for (label, r), b in
                 zip(results, baselines, strict=True)]
        plot_slopes(args.plot, shown, xlabel=f"{kind} slope (deg), 3 deg bins",
                    ylabel="share of the surface area (%)",
                    title=(f"{kind} slopes: normals averaged over {args.radius_deg:g} deg "
                           "caps\n" + textwrap.fill("(" + ("vs the radial direction"
                                                           if grav is None
                                                           else f"vs {against}") + ")", 60)),
                    full_range=True)
    if not args.quiet:
        print(slope_table(results))
    return 0


# --------------------------------------------------------------------------- spectrum
def cmd_spectrum(args) -> int:
    inputs = [args.input, *(args.compare or [])]
    labels = _labels(inputs, args.label)
    if not 1 <= args.magnitude <= 4000:
        raise CliError(f"--magnitude must be in [1, 4000]; got {args.magnitude}")
    if args.l_max is not None and args.l_max < 1:
        raise CliError(f"--l-max must be >= 1; got {args.l_max}")
    check_report_outputs(args, [("input", p) for p in inputs])
    bodies = [_load_input(p, args.shape_units).as_body(args.magnitude) for p in inputs]
    results = []
    for label, body in zip(labels, bodies, strict=True):
        l_max = args.l_max or (2 * body.magnitude) // 3
        l_max = min(l_max, 2 * body.magnitude)
        degrees, power = radius_spectrum(body, l_max)
        mean_r = float(np.sqrt(power[0] / (4 * np.pi)))
        results.append((label, degrees, power, mean_r))
    if args.csv:
        n = min(len(d) for _, d, _, _ in results)
        cols = ["degree_l"]
        for label, *_ in results:
            cols += [f"wavelength_m[{label}]", f"power_m2[{label}]"]
        rows = []
        for k in range(n):
            row = [k]
            for _, d, p, r in results:
                wl = 2 * np.pi * r / np.sqrt(d[k] * (d[k] + 1)) if d[k] else float("inf")
                row += [wl, p[k]]
            rows.append(row)
        write_csv(args.csv, "latlong spectrum: degree variance S_l = sum_m |a_lm|^2 of the "
                   "radius (metres) with orthonormal spherical harmonics; wavelength "
                   "2 pi R / sqrt(l(l+1)) at the mean radius R", cols, rows)
    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(7, 5))
        for (label, d, p, _), color in zip(results, series_colors(len(results)), strict=True):
            ax.loglog(d[1:], p[1:], label=label, color=color)
        ax.set_xlabel("spherical-harmonic degree l")
        ax.set_ylabel("degree variance S_l (m$^2$)")
        ax.set_title("radius power spectrum")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
        fig.tight_layout()
        save_figure(fig, args.plot)
        plt.close(fig)
    if not args.quiet:
        print(f"{'input':<28} {'mean_radius_m':>13} {'rms_relief_m':>12} {'slope_l>=2':>10}")
        for label, d, p, r in results:
            rms = float(np.sqrt(p[1:].sum() / (4 * np.pi)))
            sel = (d >= 2) & (p > 0)
            beta = float(-np.polyfit(np.log(d[sel]), np.log(p[sel]), 1)[0]) if sel.sum() > 2 \
                else float("nan")
            print(f"{label[:28]:<28} {r:13.4g} {rms:12.4g} {-beta:10.2f}")
    return 0


def add_parsers(sub) -> None:
    """Register ``slopes`` and ``spectrum`` on the latlong sub-command parser."""
    for name, func, text in (("slopes", cmd_slopes, "slope distributions (3-degree bins)"),
                             ("spectrum", cmd_spectrum, "radius power spectra")):
        p = sub.add_parser(name, help=f"{text} of bodies and shape models, with comparisons")
        p.add_argument("input", help="a body (.npz) or a closed mesh file")
        p.add_argument("--compare", nargs="+", metavar="OTHER",
                       help="more inputs to overlay (default: none)")
        p.add_argument("--label", nargs="+",
                       help="legend labels, one per input (default: the file names)")
        p.add_argument("--shape-units", choices=("km", "m"),
                       help="units of mesh inputs (default: none; required for meshes)")
        if name == "slopes":
            p.add_argument("--radius-deg", type=float, default=3.0,
                           help="averaging cap radius, degrees of arc (default: 3)")
            p.add_argument("--unweighted", action="store_true",
                           help="plain mean of vertex normals (default: area-weighted)")
            p.add_argument("--density-kg-m3", type=float,
                           help="bulk density: slopes against the effective gravity of "
                           "the constant-density polyhedron (default: none, geometric "
                           "slopes against the radial direction)")
            p.add_argument("--period-h", type=float,
                           help="rotation period, hours, for the centrifugal part "
                           "(default: none, not rotating)")
            p.add_argument("--spin-axis", metavar="X,Y,Z",
                           help="rotation axis in the body frame (default: 0,0,1)")
        else:
            p.add_argument("--magnitude", type=int, default=200,
                           help="grid magnitude for mesh inputs (default: 200)")
            p.add_argument("--l-max", type=int, help="largest degree (default: 2M/3)")
        add_report_arguments(p)
        p.set_defaults(func=func)
