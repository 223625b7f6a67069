"""``latlong info MODEL``: describe a saved body."""

from __future__ import annotations

from craters.cli.options import Values, command
from latlong import load

from .inputs import MODEL

HELP = {
    "info": "describe a saved body (.npz)",
}

__all__ = ["register"]


def _info(v: Values) -> int:
    body = load(v["model"])
    meta = body.metadata
    r = body.radii_m
    g = body.grid
    print(f"model      {v['model']}")
    print(f"magnitude  {g.magnitude}  ({g.n_vertices} vertices, {g.n_triangles} triangles)")
    print(f"radius_m   reference {body.radius_m:.6g}; min {r.min():.6g}  mean {r.mean():.6g}"
          f"  max {r.max():.6g}")
    print(f"stretch    {', '.join(f'{x:g}' for x in body.stretch)}")
    print(f"spacing_m  {g.spacing(body.radius_m):.4g} (ring spacing at the reference radius)")
    for key in ("generator", "version", "seed", "base", "preset"):
        if key in meta:
            print(f"{key:<10} {meta[key]}")
    for key, value in (meta.get("parameters") or {}).items():
        print(f"  {key:<16} {value}")
    cat = body.craters
    if cat is not None and len(cat):
        d = cat["diameter_m"]
        print(f"craters    {len(cat)} stamped, D {d.min():.4g}..{d.max():.4g} m, "
              f"degradation {cat['degradation'].min():.2f}..{cat['degradation'].max():.2f}")
    rocks = body.boulders
    if rocks is not None and len(rocks):
        d = rocks["diameter_m"]
        print(f"boulders   {len(rocks)} placed, D {d.min():.4g}..{d.max():.4g} m, buried "
              f"{rocks['burial_frac'].min():.2f}..{rocks['burial_frac'].max():.2f} of their "
              f"height")
    return 0


def register(sub) -> None:
    """Register ``latlong info``."""
    command(sub, "info", _info, {"model": MODEL}, help=HELP["info"],
            prog="latlong")
