"""The ``latlong`` command line: ``build``, ``info``, ``presets`` and ``render``.

Every ``build`` option has a key of the same name (dashes -> underscores) in a TOML
scene file given with ``--config`` (crater layers as ``[[craters]]`` tables or spec
strings); options on the command line override the file (see :mod:`latlong.scene`).
"""

from __future__ import annotations

import argparse
import logging
import sys
from pathlib import Path

from craters._shared import check_output_path, package_version, progress_bar
from craters._shared.cli import CliError, OneLineParser, run_cli

from .analysis_cli import add_parsers as add_analysis_parsers
from .body import load
from .scene import (
    BUILD_OPTIONS,
    RENDER_OPTIONS,
    build_body,
    check_render,
    config_settings,
    human_bytes,
    preset_table,
    resolve_settings,
    write_outputs,
)

logger = logging.getLogger(__name__)
_KEYS = {o.key for o in BUILD_OPTIONS}


def _given(args: argparse.Namespace, keys) -> dict:
    out = {}
    for key in keys:
        value = getattr(args, key, None)
        if value is None or value is False and key in ("quiet", "force"):
            continue
        if key == "crater_roughness" and value is True:
            continue  # the flag is --no-crater-roughness: True means "not given"
        out[key] = value
    return out


def _cmd_build(args: argparse.Namespace) -> int:
    given = config_settings(args.config) if args.config else {}
    given.update(_given(args, _KEYS))
    s = resolve_settings(given)
    if s.get("backend") == "implicit":
        from .implicit_cli import run_implicit

        return run_implicit(s)
    show = not s["quiet"]
    outs = [*s["output"], *[s[k] for k in ("catalog", "boulder_catalog", "preview") if s.get(k)]]
    bar = progress_bar(total=1 + len(outs), enabled=show, desc="build")
    bar.set_description("body")
    body = build_body(s, progress=show)
    bar.update()
    write_outputs(body, s, progress=show, on_written=lambda _: bar.update())
    bar.close()
    if show:
        r = body.radii_m
        n_craters = 0 if body.craters is None else len(body.craters)
        print(f"body: magnitude {body.magnitude}, {body.n_vertices} vertices, base {s['base']}"
              f" ({s['preset'] or '-'}), {n_craters} craters, seed {s['seed']}, radius "
              f"{r.min():.4g}..{r.max():.4g} m")
        for out in outs:
            print(f"wrote {out} ({human_bytes(Path(out).stat().st_size)})")
    return 0


def _cmd_info(args: argparse.Namespace) -> int:
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


def _cmd_presets(args: argparse.Namespace) -> int:
    for name, description, settings in preset_table():
        print(f"{name}\n  {description}")
        for key, value in settings.items():
            print(f"    {key} = {value!r}")
    return 0


def _cmd_render(args: argparse.Namespace) -> int:
    from .preview import render_from_settings

    s = {o.key: o.default for o in RENDER_OPTIONS}
    s.update({k: v for k, v in vars(args).items() if k in s and v is not None})
    check_render(s)
    check_output_path(args.output, force=args.force, suffixes=(".png",))
    body = load(args.model)
    render_from_settings(body, args.output, s)
    if not args.quiet:
        print(f"wrote {args.output} ({human_bytes(Path(args.output).stat().st_size)})")
    return 0


def _cmd_export(args: argparse.Namespace) -> int:
    from .gltf import export_glb, export_vtp_strips

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


def _add_options(parser, options, groups) -> None:
    for opt in options:
        kw: dict = {"dest": opt.key, "help": opt.help, "default": None}
        if opt.action in ("store_true", "store_false"):
            kw["action"] = opt.action
            kw.pop("default")
            kw["default"] = opt.action == "store_false"
        else:
            kw["type"] = opt.parse
            if opt.action == "append":
                kw["action"] = "append"
        groups[opt.group].add_argument(*opt.flags, **kw)


def build_parser() -> argparse.ArgumentParser:
    parser = OneLineParser(prog="latlong", description="Asteroid bodies on the lat/long mesh.")
    parser.add_argument("--version", action="version", version=f"craterform {package_version()}")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=OneLineParser)
    b = sub.add_parser("build", help="generate a body and write meshes / catalogs / pictures",
                       description="Generate a body (base shape and craters) and write it.")
    b.add_argument("--config", metavar="TOML", help="scene file; options override its keys")
    groups = {"body": b.add_argument_group("body"),
              "faulting": b.add_argument_group("two-phase faulting (--base faulting)"),
              "fbm": b.add_argument_group("Perlin fBm (--base fbm; detail on --base shape)"),
              "shape": b.add_argument_group("shape models (--base shape:PATH)"),
              "craters": b.add_argument_group("craters"),
              "boulders": b.add_argument_group("boulders"),
              "implicit": b.add_argument_group("implicit backend (--backend implicit)"),
              "output": b.add_argument_group("output"),
              "render": b.add_argument_group("preview picture")}
    _add_options(b, BUILD_OPTIONS, groups)
    b.set_defaults(func=_cmd_build)
    i = sub.add_parser("info", help="describe a saved body (.npz)")
    i.add_argument("model", help="a .npz written by latlong build")
    i.set_defaults(func=_cmd_info)
    p = sub.add_parser("presets", help="list the named scenes and their parameters")
    p.set_defaults(func=_cmd_presets)
    r = sub.add_parser("render", help="render a saved body to a PNG (off-screen)")
    r.add_argument("model", help="a .npz written by latlong build")
    r.add_argument("-o", "--output", required=True, help="PNG to write")
    r.add_argument("--force", action="store_true", help="overwrite an existing picture")
    r.add_argument("-q", "--quiet", action="store_true", help="no messages")
    _add_options(r, RENDER_OPTIONS, {"render": r})
    r.set_defaults(func=_cmd_render)
    e = sub.add_parser("export", help="renderer export: patched triangle strips (.glb, with "
                       "a JSON manifest, nested LODs) or a VTP with native strips")
    e.add_argument("model", help="a .npz written by latlong build")
    e.add_argument("-o", "--output", required=True, help="out.glb or out.vtp")
    e.add_argument("--patch-k", type=int, default=64, help="patch tree parameter K")
    e.add_argument("--lod", type=int, default=0,
                   help="coarsest level of detail (M / 2^lod), 0 = the body only")
    e.add_argument("--force", action="store_true", help="overwrite existing outputs")
    e.add_argument("-q", "--quiet", action="store_true", help="no progress or messages")
    e.set_defaults(func=_cmd_export)
    add_analysis_parsers(sub)
    return parser


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    return run_cli(lambda: args.func(args))


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
