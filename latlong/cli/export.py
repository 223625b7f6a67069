"""``latlong export MODEL -o OUT``: the renderer export of a saved body (patched triangle
strips as .glb with a JSON manifest and nested levels of detail, or a VTP with native
strips)."""

from __future__ import annotations

from pathlib import Path

from craters._shared import check_output_path
from craters.cli.kit import CliError, check_not_input, wrote_line
from craters.cli.options import FORCE, QUIET, Setting, Values, command, default_of
from latlong import LatLongGrid, export_glb, export_vtp_strips, load
from latlong.gltf import LOD_LAYOUTS, level_path
from latlong.meshio.sizes import EXPORT_BYTES_PER_VERTEX, check_free_space

from .inputs import MODEL

HELP = {
    "export": "renderer export: patched triangle strips (.glb, with a JSON manifest, nested "
              "LODs) or a VTP with native strips",
}

__all__ = ["register"]

OPTIONS = {
    "model": MODEL,
    "output": Setting(help="out.glb or out.vtp", flag="-o/--output", required=True,
                      run=True),
    "patch_k": Setting(default_of(export_glb, "patch_k"), "patch tree parameter K",
                       range=(2, 1_000_000), run=True),
    "lod": Setting(default_of(export_glb, "lod"), "coarsest level of detail (M / 2^lod), 0 = "
                   "the body only", range=(0, 20), run=True),
    "lods": Setting(default_of(export_glb, "lods"), "levels of detail in one .glb, one "
                    "scene each (viewers show level 0; Blender imports them all into one "
                    "scene), or separate: level l in OUT.lod<l>.glb", choices=LOD_LAYOUTS,
                    run=True),
    "force": FORCE, "quiet": QUIET,
}


def _export(v: Values) -> int:
    out = Path(v["output"])
    suffix = out.suffix.lower()
    if suffix not in (".glb", ".vtp"):
        raise CliError(f"-o/--output must end in .glb or .vtp; got {str(out)!r}")
    check_output_path(out, force=v["force"], suffixes=(".glb", ".vtp"))
    written = [out]
    if suffix == ".glb":
        files = [level_path(out, level) for level in range(v["lod"] + 1)] \
            if v["lods"] == "separate" else [out]
        for f in files:
            written += [f, f.with_suffix(".json")]
            check_output_path(f, force=v["force"], suffixes=(".glb",))
            check_output_path(f.with_suffix(".json"), force=v["force"], suffixes=(".json",))
            for level in range(v["lod"] + 1):  # external buffers of exports past 4 GiB
                check_output_path(f.with_name(f"{f.stem}.lod{level}.bin"), force=v["force"])
    for f in written:
        check_not_input(f, [("MODEL", v["model"])])
    body = load(v["model"])
    if body.magnitude % (2 ** v["lod"]):
        raise CliError(f"--lod {v['lod']} needs a magnitude divisible by {2 ** v['lod']}; "
                       f"{v['model']} has M = {body.magnitude}")
    levels = range(v["lod"] + 1) if suffix == ".glb" else range(1)
    vertices = sum(LatLongGrid(body.magnitude // 2**level).n_vertices for level in levels)
    check_free_space([(out, EXPORT_BYTES_PER_VERTEX[suffix] * vertices)],
                     hint="choose another folder, or fewer levels of detail (--lod)")
    if suffix == ".glb":
        man = export_glb(body, out, patch_k=v["patch_k"], lod=v["lod"], lods=v["lods"],
                         progress=not v["quiet"])
        summary = ", ".join(f"LOD {lv['level']}: M={lv['magnitude']} "
                            f"{len(lv['patches'])} patches" for lv in man["levels"])
    else:
        export_vtp_strips(body, out)
        summary = f"{2 * body.magnitude} strips"
    if not v["quiet"]:
        print(f"{wrote_line(out)}: {summary}")
    return 0


def register(sub) -> None:
    """Register ``latlong export``."""
    command(sub, "export", _export, OPTIONS, prog="latlong",
            help=HELP["export"])
