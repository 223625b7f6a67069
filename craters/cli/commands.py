"""The ``craters`` command line: ``craters profile`` and ``craters population``."""

from __future__ import annotations

import argparse
import math
import sys

import numpy as np

from .._shared import atomic_path, check_output_path, package_version
from ..catalog import CATALOG_COLUMNS, write_catalog
from ..chronology import CHRONOLOGY_SYSTEMS, equilibrium_density, get_chronology_system
from ..layers import ModelAgeLayer, parse_layer_spec
from ..morphology import morphology_class
from ..population import population
from ..profile import crater_morphometry, radial_profile
from ..scc import write_scc
from ..targets import TARGETS, get_target
from .kit import CliError, OneLineParser, parse_seed, run_cli
from .report import save_figure

CHRONOLOGY_NAMES = tuple(CHRONOLOGY_SYSTEMS)


def _finite(flag: str, value: float, *, positive=False, lo=None, hi=None) -> float:
    if not math.isfinite(value):
        raise CliError(f"{flag} must be finite; got {value!r}")
    if positive and value <= 0:
        raise CliError(f"{flag} must be > 0; got {value!r}")
    if (lo is not None and value < lo) or (hi is not None and value > hi):
        raise CliError(f"{flag} must be in [{lo}, {hi}]; got {value!r}")
    return value


def _pair(text: str) -> tuple[float, float]:
    try:
        a, b = (float(v) for v in text.split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected LOW,HIGH; got {text!r}") from None
    return a, b




# --------------------------------------------------------------------------- profile
def _target(args):
    return get_target(args.body, gravity_m_s2=args.gravity_m_s2,
                      radius_m=args.body_radius_m, density_kg_m3=args.density_kg_m3)


def _cmd_profile(args) -> int:
    d = _finite("--diameter-m", args.diameter_m, positive=True)
    target = _target(args)
    m = crater_morphometry(d, target=target, age_gyr=args.age_gyr,
                           degradation=args.degradation)
    if args.csv is None and args.plot is None and args.quiet:
        raise CliError("nothing to do: give --csv, --plot or drop --quiet for the summary")
    for path, suffixes in ((args.csv, (".csv",)), (args.plot, (".png",))):
        if path is not None:
            check_output_path(path, force=args.force, suffixes=suffixes)
    x = np.linspace(0.0, 3.2, 641)
    h = radial_profile(x, d, target=target, age_gyr=args.age_gyr, degradation=args.degradation)
    state = (f"age_gyr={args.age_gyr!r}" if args.age_gyr is not None
             else f"degradation={args.degradation or 0.0!r}")
    if args.csv:
        with atomic_path(args.csv) as tmp, open(tmp, "w", encoding="utf-8") as fh:
            fh.write(f"# craters profile: diameter_m={d!r} body={target.name} {state} "
                     f"morphology={m['morphology']}; depth_m={m['depth_m']!r} "
                     f"rim_height_m={m['rim_height_m']!r} "
                     f"floor_diameter_m={m['floor_diameter_m']!r} "
                     f"peak_height_m={m['peak_height_m']!r} "
                     f"degradation={m['degradation']!r}\n")
            fh.write("x,r_m,height_m\n")
            for xi, hi in zip(x.tolist(), h.tolist(), strict=True):
                fh.write(f"{xi!r},{xi * d / 2!r},{hi!r}\n")
    if args.plot:
        _plot_profiles(args.plot, d, target, x, h, m)
    if not args.quiet:
        when = (f"{args.age_gyr:g} Gyr old" if args.age_gyr is not None
                else "fresh" if not args.degradation else f"degradation {args.degradation:g}")
        shape = ""
        if m["floor_diameter_m"] > 0:
            shape += f", floor {m['floor_diameter_m']:.4g} m wide when fresh"
        if m["peak_height_m"] > 0:
            shape += f", peak {m['peak_height_m']:.4g} m"
        print(f"D = {d:g} m on {target.name} ({m['morphology']}), {when}: depth "
              f"{m['depth_m']:.4g} m (d/D {m['depth_diameter']:.3f}), rim height "
              f"{m['rim_height_m']:.4g} m, degradation {m['degradation']:.3f}{shape}")
    return 0


def _plot_profiles(path, d: float, target, x, h, m) -> None:
    """The requested profile over the same crater at several ages (diffusion)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(8, 4.5))
    for age in (0.0, 0.5, 1.0, 2.0, 3.5):
        ha = radial_profile(x, d, target=target, age_gyr=age)
        ax.plot(x * d / 2, ha, lw=1, label=f"{age:g} Gyr")
    ax.plot(x * d / 2, h, "k--", lw=2, label=f"requested (degradation {m['degradation']:.2f})")
    ax.axhline(0, color="0.6", lw=0.5)
    ax.set_xlabel("distance from centre (m)")
    ax.set_ylabel("height (m)")
    ax.set_title(f"Crater profile, D = {d:g} m on {target.name} ({m['morphology']}); "
                 f"topographic diffusion with age")
    ax.legend(fontsize=8)
    fig.tight_layout()
    save_figure(fig, path)
    plt.close(fig)


# --------------------------------------------------------------------------- population
def _cmd_population(args) -> int:
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
        args.radius_m = target.radius_m  # the body's whole surface
        where[0] = True
    if sum(where) != 1:
        raise CliError("give exactly one of --radius-m, --area-m2 or --x-range-m/--y-range-m"
                       " (or --body alone: its whole surface)")
    if args.radius_m is not None:
        _finite("--radius-m", args.radius_m, positive=True)
    if args.area_m2 is not None:
        _finite("--area-m2", args.area_m2, positive=True)
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
    from numpy.lib import recfunctions

    kinds = morphology_class(cat["diameter_m"], target) if len(cat) else np.zeros(0, "U12")
    return recfunctions.append_fields(cat, "morphology", kinds, usemask=False)


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
    fig.tight_layout()
    save_figure(fig, path)
    plt.close(fig)


# --------------------------------------------------------------------------- parser
def _add_body_options(p, *, population: bool = False) -> None:
    if population:
        p.add_argument("--body", choices=(*TARGETS, "small-body"),
                       help="target body: its whole surface is the area unless --radius-m, "
                       "--area-m2 or a rectangle is given (a small-body's radius is "
                       "--radius-m), and each crater's fresh morphology class is listed "
                       "(default: none)")
    else:
        p.add_argument("--body", default="moon", choices=(*TARGETS, "small-body"),
                       help="target body: crater morphology and diffusivity (default: moon)")
    p.add_argument("--gravity-m-s2", type=float,
                   help="surface gravity, m/s^2: the transition diameters scale as 1/g "
                   "(default: the body's)")
    if not population:
        p.add_argument("--body-radius-m", type=float,
                       help="radius of a small-body, metres (default: none)")
    p.add_argument("--density-kg-m3", type=float,
                   help="bulk density of a small-body, kg/m^3 (default: 2000)")


def build_parser() -> OneLineParser:
    parser = OneLineParser(prog="craters", description="Crater profiles and populations.")
    parser.add_argument("--version", action="version", version=f"craterform {package_version()}")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=OneLineParser)
    p = sub.add_parser("profile", help="a crater's radial profile as CSV and/or a plot")
    p.add_argument("--diameter-m", type=float, required=True,
                   help="rim diameter, metres (required)")
    p.add_argument("--degradation", type=float,
                   help="share of the fresh depth removed, 0 (fresh) to 1 (no relief) "
                   "(default: from --age-gyr, else 0)")
    p.add_argument("--age-gyr", type=float,
                   help="age in Gyr: topographic diffusion for that time (default: fresh)")
    _add_body_options(p)
    p.add_argument("--csv", help="write x, r_m, height_m (default: none)")
    p.add_argument("--plot", help="PNG with profiles at several ages (like Martin Fig. 3) "
                   "(default: none)")
    p.add_argument("--force", action="store_true", help="overwrite existing outputs (default: off)")
    p.add_argument("-q", "--quiet", action="store_true",
                   help="no progress bars or messages (default: off)")
    p.set_defaults(func=_cmd_profile, flags={
        "body": "--body", "gravity_m_s2": "--gravity-m-s2", "radius_m": "--body-radius-m",
        "density_kg_m3": "--density-kg-m3", "age_gyr": "--age-gyr",
        "degradation": "--degradation", "diameter_m": "--diameter-m"})
    q = sub.add_parser("population", help="a crater catalog (CSV or craterstats .scc) from "
                       "power laws or production functions at a model age")
    q.add_argument("--craters", action="append", metavar="SPEC",
                   help="crater layer: a power law c=0.5,k=-2,d_min_m=5,d_max_m=800"
                        "[,age_min_gyr=0,age_max_gyr=3.5,degradation=0.2,kind=mare] (the "
                        "fields of craters.CraterLayer: N_cum = c D^k per m^2) or a model "
                        "age npf=moon,age_gyr=3.8,d_min_m=1000,d_max_m=20000[,equilibrium="
                        "trask|hartmann,degradation=0.2,kind=mare] (craters.ModelAgeLayer; "
                        "npf: " + ", ".join(CHRONOLOGY_NAMES) + "); metres, Gyr; repeatable; "
                        "required")
    q.add_argument("--radius-m", type=float,
                   help="sphere radius (positions lat/lon) (default: none)")
    q.add_argument("--area-m2", type=float,
                   help="area for the count (positions lat/lon) (default: none)")
    q.add_argument("--x-range-m", type=_pair,
                   help="LOW,HIGH: a rectangle (positions x/y) (default: none)")
    q.add_argument("--y-range-m", type=_pair, help="LOW,HIGH (default: none)")
    _add_body_options(q, population=True)
    q.add_argument("--age-max-gyr", type=float, default=3.5,
                   help="oldest age of layers that do not give age_max_gyr (default: 3.5)")
    q.add_argument("--seed", type=parse_seed,
                   help="random seed (default: a fresh one)")
    q.add_argument("-o", "--output", required=True,
                   help="catalog: .csv, or .scc (craterstats spatial crater count: area in "
                        "km^2, diameters in km, lon/lat) (required)")
    q.add_argument("--columns", default="craterform", choices=CATALOG_COLUMNS,
                   help="CSV column names: craterform (units in the names) or robbins "
                        "(LAT_CIRC_IMG, LON_CIRC_IMG, DIAM_CIRC_IMG in km, as the Robbins "
                        "2019 lunar crater database) (default: craterform)")
    q.add_argument("--plot", help="PNG of the cumulative SFD against the requested law "
                   "(default: none)")
    q.add_argument("--force", action="store_true", help="overwrite existing outputs (default: off)")
    q.add_argument("-q", "--quiet", action="store_true",
                   help="no progress bars or messages (default: off)")
    q.set_defaults(func=_cmd_population, flags={
        "body": "--body", "gravity_m_s2": "--gravity-m-s2", "radius_m": "--radius-m",
        "density_kg_m3": "--density-kg-m3"})
    return parser


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    return run_cli(lambda: args.func(args), flags=args.flags)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
