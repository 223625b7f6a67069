"""``latlong info``, ``presets``, ``render`` and ``export``: saved bodies and presets."""

from __future__ import annotations

from pathlib import Path

from craters._shared import check_not_input, check_output_path, human_bytes
from craters.cli.kit import CliError
from latlong import PreviewSettings, export_glb, export_vtp_strips, load, render_preview

from ..presets import preset_table
from .options import RENDER_OPTIONS, given_options

__all__ = ["add_body_parsers"]


def cmd_info(args) -> int:
    body = load(args.model)
    meta = body.metadata
    r = body.radii_m
    g = body.grid
    print(f"model      {args.model}")
    print(f"magnitude  {g.magnitude}  ({g.n_vertices} vertices, {g.n_triangles} triangles)")
    print(f"radius_m   reference {body.radius_m:.6g}; min {r.min():.6g}  mean {r.mean():.6g}"
          f"  max {r.max():.6g}")
    print(f"stretch    {', '.join(f'{v:g}' for v in body.stretch)}")
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
    return 0


def cmd_presets(args) -> int:
    for name, description, settings in preset_table():
        print(f"{name}\n  {description}")
        for key, value in settings.items():
            print(f"    {key} = {value!r}")
    return 0


def cmd_render(args) -> int:
    settings = PreviewSettings(**given_options(args, RENDER_OPTIONS))
    check_not_input(args.output, [("MODEL", args.model)])
    check_output_path(args.output, force=args.force, suffixes=(".png",))
    body = load(args.model)
    render_preview(body, args.output, settings)
    if not args.quiet:
        print(f"wrote {args.output} ({human_bytes(Path(args.output).stat().st_size)})")
    return 0


def cmd_export(args) -> int:
    out = Path(args.output)
    suffix = out.suffix.lower()
    if suffix not in (".glb", ".vtp"):
        raise CliError(f"-o/--output must end in .glb or .vtp; got {str(out)!r}")
    if not 2 <= args.patch_k <= 1_000_000:
        raise CliError(f"--patch-k must be in [2, 1000000]; got {args.patch_k}")
    if not 0 <= args.lod <= 20:
        raise CliError(f"--lod must be in [0, 20]; got {args.lod}")
    check_output_path(out, force=args.force, suffixes=(".glb", ".vtp"))
    if suffix == ".glb":
        check_output_path(out.with_suffix(".json"), force=args.force, suffixes=(".json",))
        for level in range(args.lod + 1):  # external buffers of exports past 4 GiB
            check_output_path(out.with_name(f"{out.stem}.lod{level}.bin"), force=args.force)
    for written in (out, out.with_suffix(".json")):
        check_not_input(written, [("MODEL", args.model)])
    body = load(args.model)
    if body.magnitude % (2**args.lod):
        raise CliError(f"--lod {args.lod} needs a magnitude divisible by {2**args.lod}; "
                       f"{args.model} has M = {body.magnitude}")
    if suffix == ".glb":
        man = export_glb(body, out, patch_k=args.patch_k, lod=args.lod,
                         progress=not args.quiet)
        summary = ", ".join(f"LOD {lv['level']}: M={lv['magnitude']} "
                            f"{len(lv['patches'])} patches" for lv in man["levels"])
    else:
        export_vtp_strips(body, out)
        summary = f"{2 * body.magnitude} strips"
    if not args.quiet:
        print(f"wrote {out} ({human_bytes(out.stat().st_size)}): {summary}")
    return 0


def add_body_parsers(sub, add_groups) -> None:
    """Register ``info``, ``presets``, ``render`` and ``export``."""
    i = sub.add_parser("info", help="describe a saved body (.npz)")
    i.add_argument("model", help="a .npz written by latlong build")
    i.set_defaults(func=cmd_info)
    p = sub.add_parser("presets", help="list the named scenes and their parameters")
    p.set_defaults(func=cmd_presets)
    r = sub.add_parser("render", help="render a saved body to a PNG (off-screen)")
    r.add_argument("model", help="a .npz written by latlong build")
    r.add_argument("-o", "--output", required=True, help="PNG to write (required)")
    r.add_argument("--force", action="store_true",
                   help="overwrite an existing picture (default: off)")
    r.add_argument("-q", "--quiet", action="store_true",
                   help="no progress bars or messages (default: off)")
    add_groups(r, RENDER_OPTIONS)
    r.set_defaults(func=cmd_render)
    e = sub.add_parser("export", help="renderer export: patched triangle strips (.glb, with "
                       "a JSON manifest, nested LODs) or a VTP with native strips")
    e.add_argument("model", help="a .npz written by latlong build")
    e.add_argument("-o", "--output", required=True, help="out.glb or out.vtp (required)")
    e.add_argument("--patch-k", type=int, default=64,
                   help="patch tree parameter K (default: 64)")
    e.add_argument("--lod", type=int, default=0,
                   help="coarsest level of detail (M / 2^lod), 0 = the body only (default: 0)")
    e.add_argument("--force", action="store_true", help="overwrite existing outputs (default: off)")
    e.add_argument("-q", "--quiet", action="store_true",
                   help="no progress bars or messages (default: off)")
    e.set_defaults(func=cmd_export)
