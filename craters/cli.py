"""The ``craters`` command line: ``craters profile`` and ``craters population``."""

from __future__ import annotations

import argparse
import math
import sys

import numpy as np

from ._shared import atomic_path, check_output_path, package_version
from ._shared.cli import CliError, OneLineParser, parse_seed, run_cli
from ._shared.report import save_figure
from .catalog import write_catalog
from .population import CraterLayer, expected_count, parse_layer_spec, population
from .profile import crater_morphometry, radial_profile
from .targets import TARGETS, get_target


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
        print(f"D = {d:g} m on {target.name} ({m['morphology']}), {state}: depth "
              f"{m['depth_m']:.4g} m (d/D {m['depth_diameter']:.3f}), rim height "
              f"{m['rim_height_m']:.4g} m, degradation {m['degradation']:.3f}")
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
        raise CliError("give at least one --craters c=...,k=...,d_min_m=...,d_max_m=...")
    layers = [parse_layer_spec(s, age_max_gyr=args.age_max_gyr) for s in specs]
    where = [args.radius_m is not None, args.area_m2 is not None,
             args.x_range_m is not None or args.y_range_m is not None]
    if sum(where) != 1:
        raise CliError("give exactly one of --radius-m, --area-m2 or --x-range-m/--y-range-m")
    if args.radius_m is not None:
        _finite("--radius-m", args.radius_m, positive=True)
    if args.area_m2 is not None:
        _finite("--area-m2", args.area_m2, positive=True)
    check_output_path(args.output, force=args.force, suffixes=(".csv",))
    if args.plot:
        check_output_path(args.plot, force=args.force, suffixes=(".png",))
    cat = population(layers, radius_m=args.radius_m, area_m2=args.area_m2,
                     x_range_m=args.x_range_m, y_range_m=args.y_range_m, rng=args.seed)
    write_catalog(cat, args.output)
    if args.radius_m is not None:
        area = 4 * math.pi * args.radius_m**2
    elif args.area_m2 is not None:
        area = args.area_m2
    else:
        (x0, x1), (y0, y1) = args.x_range_m, args.y_range_m
        area = (x1 - x0) * (y1 - y0)
    if args.plot:
        _plot_sfd(cat, layers, area, args.plot)
    if not args.quiet:
        want = sum(expected_count(area, la.c, la.k, la.d_min_m, la.d_max_m) for la in layers)
        print(f"{len(cat)} craters (expected {want:.1f}) on {area:.6g} m^2 -> {args.output}")
    return 0


def _plot_sfd(cat, layers: list[CraterLayer], area: float, path) -> None:
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
        want += la.c * (inside**la.k - la.d_max_m**la.k)
    ax.loglog(grid, np.where(want > 0, want, np.nan), "k-", lw=1.5, label="requested law")
    ax.set_xlabel("diameter D (m)")
    ax.set_ylabel("cumulative number per m$^2$, N(>D)")
    ax.set_title(f"Crater size-frequency distribution ({len(cat)} craters)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    fig.tight_layout()
    save_figure(fig, path)
    plt.close(fig)


# --------------------------------------------------------------------------- parser
def _add_body_options(p) -> None:
    p.add_argument("--body", default="moon", choices=(*TARGETS, "small-body"),
                   help="target body: crater morphology and diffusivity (default: moon)")
    p.add_argument("--gravity-m-s2", type=float,
                   help="surface gravity, m/s^2: the transition diameters scale as 1/g "
                   "(default: the body's)")
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
    p.set_defaults(func=_cmd_profile)
    q = sub.add_parser("population", help="a power-law crater catalog (CSV)")
    q.add_argument("--craters", action="append", metavar="SPEC",
                   help="crater layer c=0.5,k=-2,d_min_m=5,d_max_m=800[,age_min_gyr=0,"
                        "age_max_gyr=3.5,degradation=0.2,kind=simple] (the fields of "
                        "craters.CraterLayer; metres, Gyr; repeatable for piecewise laws; "
                        "required)")
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
    q.add_argument("-o", "--output", required=True, help="catalog CSV (required)")
    q.add_argument("--plot", help="PNG of the cumulative SFD against the requested law "
                   "(default: none)")
    q.add_argument("--force", action="store_true", help="overwrite existing outputs (default: off)")
    q.add_argument("-q", "--quiet", action="store_true",
                   help="no progress bars or messages (default: off)")
    q.set_defaults(func=_cmd_population)
    return parser


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    flags = {"body": "--body", "gravity_m_s2": "--gravity-m-s2", "radius_m": "--body-radius-m",
             "density_kg_m3": "--density-kg-m3", "age_gyr": "--age-gyr",
             "degradation": "--degradation", "diameter_m": "--diameter-m"}
    return run_cli(lambda: args.func(args), flags=flags)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
