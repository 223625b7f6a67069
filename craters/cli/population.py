"""``craters population``: a crater catalog (CSV or craterstats .scc) from power laws or
production functions at a model age, on a sphere, an area or a rectangle, with the
size-frequency plot against the requested law."""

from __future__ import annotations

import argparse
import math

import numpy as np

from .._shared import check_output_path
from ..catalog import CATALOG_COLUMNS, add_columns, write_catalog
from ..chronology import CHRONOLOGY_SYSTEMS, equilibrium_density, get_chronology_system
from ..layers import ModelAgeLayer, parse_layer_spec
from ..morphology import morphology_class
from ..population import population
from ..scc import write_scc
from ..targets import get_target
from .kit import CliError, parse_seed
from .options import FORCE, QUIET, Setting, Values, command, default_of
from .profile import BODY
from .report import save_figure

HELP = {
    "population": "a crater catalog (CSV or craterstats .scc) from power laws or production "
                  "functions at a model age",
}

__all__ = ["register"]


def _pair(text: str) -> tuple[float, float]:
    try:
        a, b = (float(v) for v in text.split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected LOW,HIGH; got {text!r}") from None
    return a, b


OPTIONS = {
    "craters": Setting(help="crater layer: a power law c=0.5,k=-2,d_min_m=5,d_max_m=800"
                       "[,age_min_gyr=0,age_max_gyr=3.5,degradation=0.2,kind=mare] (the "
                       "fields of craters.CraterLayer: N_cum = c D^k per m^2) or a model age "
                       "npf=moon,age_gyr=3.8,d_min_m=1000,d_max_m=20000[,equilibrium="
                       "trask|hartmann,degradation=0.2,kind=mare] (craters.ModelAgeLayer; npf: "
                       + ", ".join(CHRONOLOGY_SYSTEMS) + "); metres, Gyr; repeatable",
                       many="append", metavar="SPEC", run=True,
                       default_text="none; at least one is required"),
    "radius_m": Setting(help="sphere radius (positions lat/lon)", unit="m", kind=float,
                        range=">0", run=True),
    "area_m2": Setting(help="area for the count (positions lat/lon)", unit="m^2", kind=float,
                       range=">0", run=True),
    "x_range_m": Setting(help="LOW,HIGH: a rectangle (positions x/y)", unit="m", parse=_pair,
                         commas=True, metavar="LOW,HIGH"),
    "y_range_m": Setting(help="LOW,HIGH", unit="m", parse=_pair, commas=True,
                         metavar="LOW,HIGH"),
    "body": Setting(help="target body: its whole surface is the area unless --radius-m, "
                    "--area-m2 or a rectangle is given (a small-body's radius is --radius-m), "
                    "and each crater's fresh morphology class is listed",
                    choices=BODY["body"].choices, run=True),
    "gravity_m_s2": BODY["gravity_m_s2"], "density_kg_m3": BODY["density_kg_m3"],
    "age_max_gyr": Setting(default_of(parse_layer_spec, "age_max_gyr"),
                           "oldest age of layers that do not give age_max_gyr", unit="Gyr"),
    "seed": Setting(help="random seed", parse=parse_seed, kind=int,
                    default_text="a fresh one"),
    "output": Setting(help="catalog: .csv, or .scc (craterstats spatial crater count: area in "
                      "km^2, diameters in km, lon/lat)", flag="-o/--output", required=True,
                      run=True),
    "columns": Setting(default_of(write_catalog, "columns"), "CSV column names: craterform "
                       "(units in the names) or robbins (LAT_CIRC_IMG, LON_CIRC_IMG, "
                       "DIAM_CIRC_IMG in km, as the Robbins 2019 lunar crater database)",
                       choices=CATALOG_COLUMNS,
                       run=True),
    "plot": Setting(help="PNG of the cumulative SFD against the requested law", run=True),
    "force": FORCE, "quiet": QUIET,
}


def _population(args: Values) -> int:
    specs = args.craters or []
    if not specs:
        raise CliError("give at least one --craters c=...,k=...,d_min_m=...,d_max_m=... or "
                       "npf=moon,age_gyr=...,d_min_m=...,d_max_m=...")
    try:
        layers = [parse_layer_spec(s, age_max_gyr=args.age_max_gyr) for s in specs]
    except (TypeError, ValueError) as exc:
        raise CliError(f"--craters: {exc}") from None
    target = _population_target(args)
    where = [args.radius_m is not None, args.area_m2 is not None,
             args.x_range_m is not None or args.y_range_m is not None]
    if target is not None and not any(where):
        args["radius_m"] = target.radius_m  # the body's whole surface
        where[0] = True
    if sum(where) != 1:
        raise CliError("give exactly one of --radius-m, --area-m2 or --x-range-m/--y-range-m"
                       " (or --body alone: its whole surface)")
    check_output_path(args.output, force=args.force, suffixes=(".csv", ".scc"))
    scc = args.output.lower().endswith(".scc")
    if scc and args.columns != "craterform":
        raise CliError("--columns applies to CSV output, not .scc")
    if args.plot:
        check_output_path(args.plot, force=args.force, suffixes=(".png",))
    cat = population(layers, radius_m=args.radius_m, area_m2=args.area_m2,
                     x_range_m=args.x_range_m, y_range_m=args.y_range_m, rng=args.seed)
    if target is not None:
        cat = _with_morphology(cat, target)
    if args.radius_m is not None:
        area = 4 * math.pi * args.radius_m**2
    elif args.area_m2 is not None:
        area = args.area_m2
    else:
        (x0, x1), (y0, y1) = args.x_range_m, args.y_range_m
        area = (x1 - x0) * (y1 - y0)
    if scc:
        write_scc(cat, args.output, area_m2=area, body_radius_m=_body_radius(args, layers),
                  note=f"craters population: {' '.join('--craters ' + s for s in specs)}")
    else:
        write_catalog(cat, args.output, columns=args.columns)
    if args.plot:
        _plot_sfd(cat, layers, area, args.plot)
    if not args.quiet:
        want = sum(la.expected_count(area) for la in layers)
        print(f"{len(cat)} craters (expected {want:.1f}) on {area:.6g} m^2 -> {args.output}")
        for i, la in enumerate(layers):
            if isinstance(la, ModelAgeLayer) and la.equilibrium is not None:
                ds = la.saturation_diameter_m
                state = ("never saturated in its range" if ds is None
                         else f"saturated below D = {ds:.4g} m")
                print(f"layer {i}: {la.npf} at {la.age_gyr:g} Gyr, {la.equilibrium} "
                      f"equilibrium: {state}")
    return 0


def _population_target(args):
    """The --body target of ``craters population`` (None without --body)."""
    if args.body is None:
        for flag, value in (("--gravity-m-s2", args.gravity_m_s2),
                            ("--density-kg-m3", args.density_kg_m3)):
            if value is not None:
                raise CliError(f"{flag} needs --body")
        return None
    if args.body == "small-body" and args.radius_m is None:
        raise CliError("--body small-body needs --radius-m (the body's radius)")
    radius = args.radius_m if args.body == "small-body" else None
    return get_target(args.body, gravity_m_s2=args.gravity_m_s2, radius_m=radius,
                      density_kg_m3=args.density_kg_m3)


def _with_morphology(cat, target):
    """The catalog with a ``morphology`` column: each crater's fresh class on ``target``."""
    kinds = morphology_class(cat["diameter_m"], target) if len(cat) else np.zeros(0, "U12")
    return add_columns(cat, "morphology", kinds)


def _body_radius(args, layers) -> float | None:
    """The radius of the .scc's ellipsoid: --radius-m, else the body of the layers'
    chronology system if they share one, else none."""
    if args.radius_m is not None:
        return args.radius_m
    bodies = {get_chronology_system(la.npf).body_radius_m for la in layers
              if isinstance(la, ModelAgeLayer)}
    if len(bodies) == 1 and all(isinstance(la, ModelAgeLayer) for la in layers):
        return bodies.pop()
    return None


def _plot_sfd(cat, layers, area: float, path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.5, 5))
    d = np.sort(cat["diameter_m"])[::-1]
    if len(d):
        ax.loglog(d, np.arange(1, len(d) + 1) / area, ".", ms=3, label="generated")
    lo = min(la.d_min_m for la in layers)
    hi = max(la.d_max_m for la in layers)
    grid = np.geomspace(lo, hi, 200)
    want = np.zeros_like(grid)
    for la in layers:
        inside = np.clip(grid, la.d_min_m, la.d_max_m)
        want += la.cumulative_m2(inside) - la.cumulative_m2(la.d_max_m)
    ax.loglog(grid, np.where(want > 0, want, np.nan), "k-", lw=1.5, label="requested law")
    for name in sorted({la.equilibrium for la in layers
                        if isinstance(la, ModelAgeLayer) and la.equilibrium}):
        ax.loglog(grid, equilibrium_density(name, grid), "--", lw=1,
                  label=f"{name} equilibrium")
    ax.set_xlabel("diameter D (m)")
    ax.set_ylabel("cumulative number per m$^2$, N(>D)")
    ax.set_title(f"Crater size-frequency distribution ({len(cat)} craters)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    save_figure(fig, path)


def register(sub) -> None:
    """Register ``craters population``."""
    command(sub, "population", _population, OPTIONS, prog="craters",
            help=HELP["population"])
