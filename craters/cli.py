"""The ``craters`` command line: ``craters profile`` and ``craters population``."""

from __future__ import annotations

import argparse
import math
import sys

import numpy as np

from ._shared import atomic_path, check_output_path, package_version
from ._shared.cli import CliError, OneLineParser, parse_seed, run_cli
from ._shared.report import save_figure
from .catalog import CATALOG_COLUMNS, write_catalog
from .chronology import CHRONOLOGY_SYSTEMS, equilibrium_density, get_chronology_system
from .degradation import degradation_from_age
from .layers import ModelAgeLayer, parse_layer_spec
from .population import population
from .profile import profile_params, radial_profile
from .scc import write_scc

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
def _cmd_profile(args) -> int:
    d = _finite("--diameter-m", args.diameter_m, positive=True)
    if args.degradation is not None and args.age_gyr is not None:
        raise CliError("give --degradation or --age-gyr, not both")
    if args.age_gyr is not None:
        _finite("--age-gyr", args.age_gyr, lo=0.0, hi=100.0)
        deg = float(degradation_from_age(d, args.age_gyr))
    else:
        deg = 0.0 if args.degradation is None else args.degradation
        _finite("--degradation", deg, lo=0.0, hi=1.0)
    if args.csv is None and args.plot is None:
        raise CliError("nothing to write: give --csv and/or --plot")
    for path, suffixes in ((args.csv, (".csv",)), (args.plot, (".png",))):
        if path is not None:
            check_output_path(path, force=args.force, suffixes=suffixes)
    x = np.linspace(0.0, 3.2, 641)
    p = profile_params(d, deg, morphometry=args.morphometry)
    h = radial_profile(x, d, deg, morphometry=args.morphometry)
    if args.csv:
        with atomic_path(args.csv) as tmp, open(tmp, "w", encoding="utf-8") as fh:
            fh.write(f"# craters profile: diameter_m={d!r} degradation={deg!r} "
                     f"morphometry={args.morphometry}; depth_m={p.depth_m!r} "
                     f"rim_height_m={p.rim_height_m!r}\n")
            fh.write("x,r_m,height_m\n")
            for xi, hi in zip(x.tolist(), h.tolist(), strict=True):
                fh.write(f"{xi!r},{xi * d / 2!r},{hi!r}\n")
    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(8, 4.5))
        ages = (0.0, 1.0, 3.0, 6.0, 10.0)
        for age in ages:
            da = float(degradation_from_age(d, age))
            ax.plot(x * d / 2, radial_profile(x, d, da, morphometry=args.morphometry), lw=1,
                    label=f"{age:g} Gyr (d = {da:.2f})")
        ax.plot(x * d / 2, h, "k--", lw=2, label=f"requested: d = {deg:.2f}")
        ax.axhline(0, color="0.6", lw=0.5)
        ax.set_xlabel("distance from centre (m)")
        ax.set_ylabel("height (m)")
        ax.set_title(f"Crater profile, D = {d:g} m ({args.morphometry}); rim at {d / 2:g} m")
        ax.legend(fontsize=8)
        fig.tight_layout()
        save_figure(fig, args.plot)
        plt.close(fig)
    if not args.quiet:
        print(f"D = {d:g} m, degradation {deg:.3f}: depth {p.depth_m:.4g} m, rim height "
              f"{p.rim_height_m:.4g} m, alpha {p.alpha:.3f}, beta {p.beta:.3f}")
    return 0


# --------------------------------------------------------------------------- population
def _cmd_population(args) -> int:
    specs = args.craters or []
    if not specs:
        raise CliError("give at least one --craters c=...,k=...,d_min_m=...,d_max_m=... or "
                       "npf=moon,age_gyr=...,d_min_m=...,d_max_m=...")
    layers = [parse_layer_spec(s, age_max_gyr=args.age_max_gyr) for s in specs]
    where = [args.radius_m is not None, args.area_m2 is not None,
             args.x_range_m is not None or args.y_range_m is not None]
    if sum(where) != 1:
        raise CliError("give exactly one of --radius-m, --area-m2 or --x-range-m/--y-range-m")
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
def build_parser() -> OneLineParser:
    parser = OneLineParser(prog="craters", description="Crater profiles and populations.")
    parser.add_argument("--version", action="version", version=f"craterform {package_version()}")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=OneLineParser)
    p = sub.add_parser("profile", help="a crater's radial profile as CSV and/or a plot")
    p.add_argument("--diameter-m", type=float, required=True,
                   help="rim diameter, metres (required)")
    p.add_argument("--degradation", type=float,
                   help="0 (fresh) to 1 (fully degraded) (default: from --age-gyr, else 0)")
    p.add_argument("--age-gyr", type=float,
                   help="age in Gyr (degradation from age) (default: none)")
    p.add_argument("--morphometry", default="lunar-simple",
                   choices=("lunar-simple", "asteroid-fresh"),
                   help="fresh d/D laws (default: lunar-simple)")
    p.add_argument("--csv", help="write x, r_m, height_m (default: none)")
    p.add_argument("--plot", help="PNG with profiles at several ages (like Martin Fig. 3) "
                   "(default: none)")
    p.add_argument("--force", action="store_true", help="overwrite existing outputs (default: off)")
    p.add_argument("-q", "--quiet", action="store_true",
                   help="no progress bars or messages (default: off)")
    p.set_defaults(func=_cmd_profile)
    q = sub.add_parser("population", help="a crater catalog (CSV or craterstats .scc) from "
                       "power laws or production functions at a model age")
    q.add_argument("--craters", action="append", metavar="SPEC",
                   help="crater layer: a power law c=0.5,k=-2,d_min_m=5,d_max_m=800"
                        "[,age_min_gyr=0,age_max_gyr=3.5,degradation=0.2,kind=simple] (the "
                        "fields of craters.CraterLayer: N_cum = c D^k per m^2) or a model "
                        "age npf=moon,age_gyr=3.8,d_min_m=1000,d_max_m=20000[,equilibrium="
                        "trask|hartmann,degradation=0.2,kind=simple] (craters.ModelAgeLayer; "
                        "npf: " + ", ".join(CHRONOLOGY_NAMES) + "); metres, Gyr; repeatable; "
                        "required")
    q.add_argument("--radius-m", type=float,
                   help="sphere radius (positions lat/lon) (default: none)")
    q.add_argument("--area-m2", type=float,
                   help="area for the count (positions lat/lon) (default: none)")
    q.add_argument("--x-range-m", type=_pair,
                   help="LOW,HIGH: a rectangle (positions x/y) (default: none)")
    q.add_argument("--y-range-m", type=_pair, help="LOW,HIGH (default: none)")
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
    q.set_defaults(func=_cmd_population)
    return parser


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    return run_cli(lambda: args.func(args))


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
