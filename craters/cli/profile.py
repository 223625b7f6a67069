"""``craters profile``: a crater's radial profile (Martin's model with the target's
morphometry, degraded by topographic diffusion) as CSV and/or a plot, and a summary."""

from __future__ import annotations

import numpy as np

from .._shared import atomic_path, check_output_path
from ..profile import crater_morphometry, radial_profile
from ..targets import TARGETS, get_target, small_body
from .kit import CliError
from .options import FORCE, QUIET, Setting, Values, command, default_of, shown_value
from .report import save_figure

HELP = {
    "profile": "a crater's radial profile as CSV and/or a plot",
}

__all__ = ["BODY", "register"]

#: The target body options of ``craters profile`` (``craters population`` has its own
#: ``--body`` and ``--radius-m``).
BODY = {
    "body": Setting(default_of(crater_morphometry, "target"),
                    "target body: crater morphology and diffusivity",
                    choices=(*TARGETS, "small-body"), run=True),
    "gravity_m_s2": Setting(help="surface gravity: the transition diameters scale as 1/g",
                            unit="m/s^2", kind=float, default_text="the body's"),
    "body_radius_m": Setting(help="radius of a small-body", unit="m", kind=float,
                             also=("radius_m",)),
    "density_kg_m3": Setting(help="bulk density of a small-body", unit="kg/m^3", kind=float,
                             default_text=shown_value(default_of(small_body,
                                                                 "density_kg_m3"))),
}
OPTIONS = {
    "diameter_m": Setting(help="rim diameter", unit="m", kind=float, range=">0",
                          required=True, run=True),
    "degradation": Setting(help="share of the fresh depth removed, 0 (fresh) to 1 (no "
                           "relief)", kind=float, default_text="from --age-gyr, else 0"),
    "age_gyr": Setting(help="age: topographic diffusion for that time", unit="Gyr",
                       kind=float, default_text="fresh"),
    **BODY,
    "csv": Setting(help="write x, r_m, height_m", run=True),
    "plot": Setting(help="PNG with profiles at several ages (like Martin Fig. 3)", run=True),
    "force": FORCE, "quiet": QUIET,
}


def _profile(args: Values) -> int:
    d = args.diameter_m
    target = get_target(args.body, gravity_m_s2=args.gravity_m_s2,
                        radius_m=args.body_radius_m, density_kg_m3=args.density_kg_m3)
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
    save_figure(fig, path)


def register(sub) -> None:
    """Register ``craters profile``."""
    command(sub, "profile", _profile, OPTIONS, prog="craters",
            help=HELP["profile"])
