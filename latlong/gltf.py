"""Renderer export: patched triangle strips as glTF 2.0 binary, VTP strips, a manifest.

``export_glb`` writes one glTF scene per level of detail (scene 0, the default, = the
full body, scene l = the nested magnitude M / 2^l body); each scene's one root node
``lod<l>`` turns the body frame's +Z (north) into glTF's +Y (up: :data:`Y_UP`), so
viewers show the body upright; every leaf of the patch tree
(:func:`latlong.strips.patch_tree`) is one node with one mesh whose single primitive is
a ``TRIANGLE_STRIP`` (mode 5) over the patch's own vertices: float32 ``POSITION`` (with
min/max) and unit ``NORMAL``, uint32 indices. The patch strips are the band strips cut
to the patch and joined with degenerate triangles. Node extras and the JSON manifest
give each patch's bounding sphere, bands, triangle count and the byte ranges of its
data, so a renderer can cull and stream patches. Nothing holds the whole body's
triangles, positions or normals: a first pass over the patches finds each one's strip
length, vertex count and bounds, which fixes the whole JSON; the second pass generates
the patches' data again and writes each at its offset. Both make the float32 positions
(and normals) of a window of rings at a time (:mod:`latlong.patchdata`), the patches on
worker threads. Only the boulder meshes go through a temporary file. Memory beyond the
body's radii: the windows (~100 MB), 32 MB buffers (two per thread, and two) and the
JSON.
A GLB is limited to 4 GiB (32-bit lengths); larger exports keep the JSON in the
``.glb`` and reference one external buffer file ``<stem>.lod<k>.bin`` per level, as
glTF 2.0 allows.

Placed boulders (``body.boulders``) are one node each (translation = centre, rotation =
the placement quaternion, uniform scale = diameter) under a root node
``lod<l>/boulders`` of each scene; their meshes (``TRIANGLES``, unit size, every level
of the boulder shape, uint16 indices shared by all boulders of a level) go with level
0's data. Scene l uses boulder level max(finest - l, coarsest); every boulder node's
extras list its mesh of each level (coarse to fine), the paper's bi-resolution levels,
so a renderer can switch by distance.
"""

from __future__ import annotations

import dataclasses
import json
import os
import shutil
import struct
from pathlib import Path
from typing import Any

import numpy as np

from craters._shared import (
    atomic_path,
    check_int,
    output_group,
    package_version,
    replace_output,
    temp_file,
)
from craters.boulders import boulder_meshes, catalog_shape, mesh_chunk

from .geometry.normals import vertex_normals
from .grid import LatLongGrid
from .meshio.writers import Y_UP
from .patchdata import leaf_metadata, write_leaf_data
from .strips import patch_tree, triangle_strips

__all__ = ["LOD_LAYOUTS", "export_glb", "export_vtp_strips", "level_path", "unit_vectors_of"]

_ARRAY_BUFFER = 34962
_ELEMENT_ARRAY_BUFFER = 34963
_FLOAT = 5126
_UINT = 5125
_USHORT = 5123
_TRIANGLES = 4
_TRIANGLE_STRIP = 5


def unit_vectors_of(grid: LatLongGrid, idx) -> np.ndarray:
    """Unit vectors of the vertices ``idx`` without the whole-grid cache."""
    return grid.unit_vectors_of(idx)


def _pad4(n: int) -> int:
    return (4 - n % 4) % 4


def export_glb(body, path, *, patch_k: int = 64, lod: int = 0, lods: str = "scenes",
               progress: bool = False) -> dict:
    """Write ``body`` as a patched, multi-LOD glTF binary and a JSON manifest.

    Parameters
    ----------
    body : Body
    path : str or Path
        The ``.glb`` to write; the manifest goes next to it as ``<stem>.json``.
    patch_k : int
        The patch tree parameter K (>= 2).
    lod : int
        Coarsest level of detail: levels 0..lod are written (M must be divisible by
        2^lod); level l is ``body.lod(l)``.
    lods : str
        ``"scenes"``: one file, one scene per level (viewers show the default scene,
        level 0; Blender's importer puts every scene's objects into one scene);
        ``"separate"``: one file per level, level l > 0 in ``<stem>.lod<l>.glb`` with its
        own manifest (what Blender users want).

    Returns
    -------
    The manifest (also written): per level the magnitude, triangle count and patches
    with their bounds and byte ranges; with ``separate``, ``files`` lists the files and
    ``levels`` each file's level.
    """
    if not isinstance(getattr(body, "grid", None), LatLongGrid):
        raise TypeError(f"`body` must be a latlong.Body; got {type(body).__name__}")
    path = Path(path)
    if path.suffix.lower() != ".glb":
        raise ValueError(f"`path` must end in .glb; got {str(path)!r}")
    patch_k = check_int("patch_k", patch_k, 2, 1_000_000)
    lod = check_int("lod", lod, 0, 20)
    if lods not in LOD_LAYOUTS:
        raise ValueError(f"`lods` must be one of {', '.join(LOD_LAYOUTS)}; got {lods!r}")
    if body.magnitude % (2**lod):
        raise ValueError(f"`lod` {lod} needs a magnitude divisible by {2**lod}; "
                         f"the body has M = {body.magnitude}")
    if lods == "scenes":
        return _export(body, path, patch_k, list(range(lod + 1)), progress)
    files = [level_path(path, level) for level in range(lod + 1)]
    with output_group():  # every level's files: together or not at all
        parts = [_export(body, f, patch_k, [level], progress)
                 for level, f in enumerate(files)]
    return {"format": "craterform.patches/1", "files": [f.name for f in files],
            "patch_k": patch_k, "levels": [m["levels"][0] for m in parts]}


#: How the levels of detail are laid out (:func:`export_glb`'s ``lods``).
LOD_LAYOUTS = ("scenes", "separate")


def level_path(path, level: int) -> Path:
    """The file of level ``level`` when the levels are separate files."""
    path = Path(path)
    return path if level == 0 else path.with_name(f"{path.stem}.lod{level}.glb")


def _export(body, path: Path, patch_k: int, levels: list[int], progress: bool) -> dict:
    """One .glb (and its manifest) holding ``levels``, one scene each."""
    gl = {"asset": {"version": "2.0", "generator": f"craterform {package_version()}"},
          "scene": 0, "scenes": [], "nodes": [], "meshes": [], "accessors": [],
          "bufferViews": [], "buffers": []}
    manifest = {"format": "craterform.patches/1", "glb": path.name, "patch_k": patch_k,
                "levels": []}
    temps = []
    try:
        sizes, plans = [], []
        for index, level in enumerate(levels):
            plan = _plan_level(body.lod(level), index, level, patch_k, gl, manifest)
            size = plan.size
            if body.boulders is not None and len(body.boulders):
                if index == 0:
                    tmp_bin = str(temp_file(path, ".boulders.bin"))
                    temps.append(tmp_bin)
                    plan.boulders = tmp_bin
                    with open(tmp_bin, "wb") as binf:
                        size, boulder_first = _write_boulder_meshes(body.boulders, gl,
                                                                     manifest, binf, size)
                _boulder_nodes(body.boulders, index, level, boulder_first, gl, manifest)
            sizes.append(size)
            plans.append(plan)
        with output_group():  # the .glb, its .json and .bin files: together or not at all
            _finish(path, gl, manifest, plans, sizes, temps, progress)
            with atomic_path(path.with_suffix(".json")) as tmp:
                tmp.write_text(json.dumps(manifest, indent=1, sort_keys=True),
                               encoding="utf-8")
    finally:
        for t in temps:
            if os.path.exists(t):
                os.unlink(t)
    return manifest


#: A GLB's length and chunk lengths are 32-bit: past this the levels go to .bin files.
GLB_LIMIT = 2**32 - 1


def _finish(path: Path, gl: dict, manifest: dict, plans: list, sizes: list, temps: list,
            progress: bool) -> None:
    """Write the GLB with the levels' binary data embedded, or - past 4 GiB, the format's
    limit - with one external ``<stem>.lod<k>.bin`` per level (glTF external buffers)."""
    starts = np.concatenate([[0], np.cumsum(sizes)]).astype(int)
    embedded = dict(gl, buffers=[{"byteLength": int(starts[-1])}],
                    bufferViews=[dict(v, buffer=0, byteOffset=v["byteOffset"]
                                      + int(starts[v["buffer"]])) for v in gl["bufferViews"]])
    js = _json_chunk(embedded)
    if 12 + 8 + len(js) + 8 + int(starts[-1]) <= GLB_LIMIT:
        for level, info in enumerate(manifest["levels"]):
            for patch in info["patches"]:
                for rng in patch["bytes"].values():
                    rng[0] += int(starts[level])
        manifest["bin_chunk_offset"] = 12 + 8 + len(js) + 8
        manifest["buffers"] = [path.name]
        with atomic_path(path) as tmp, open(tmp, "wb") as out:
            out.write(struct.pack("<4sII", b"glTF", 2, 12 + 8 + len(js) + 8 + int(starts[-1])))
            out.write(struct.pack("<I4s", len(js), b"JSON"))
            out.write(js)
            out.write(struct.pack("<I4s", int(starts[-1]), b"BIN\x00"))
            for plan in plans:
                _write_level_data(plan, out, progress)
        return
    names = [f"{path.stem}.lod{k}.bin" for k in range(len(plans))]
    gl["buffers"] = [{"uri": n, "byteLength": int(sz)} for n, sz in zip(names, sizes,
                                                                       strict=True)]
    js = _json_chunk(gl)
    manifest["bin_chunk_offset"] = None
    manifest["buffers"] = names
    for plan, n in zip(plans, names, strict=True):
        tmp_bin = str(temp_file(path, f".lod{plan.level}.bin"))
        temps.append(tmp_bin)
        with open(tmp_bin, "wb") as out:
            _write_level_data(plan, out, progress)
        replace_output(tmp_bin, path.parent / n)
    with atomic_path(path) as tmp, open(tmp, "wb") as out:
        out.write(struct.pack("<4sII", b"glTF", 2, 12 + 8 + len(js)))
        out.write(struct.pack("<I4s", len(js), b"JSON"))
        out.write(js)


def _json_chunk(gl: dict) -> bytes:
    js = json.dumps(gl, separators=(",", ":"), sort_keys=True).encode("utf-8")
    return js + b" " * _pad4(len(js))


@dataclasses.dataclass
class _LevelPlan:
    """One level's patches after the first pass: what the second pass writes where."""

    level: int
    body: Any
    """The :class:`latlong.Body` (not imported: latlong.body reaches this module)."""
    leaves: tuple
    """(band_lo, entry pointers, triangle range lo, hi) arrays of the patch tree leaves."""
    at: np.ndarray
    """(leaves, 3) byte offsets of each leaf's positions, normals, indices in the level
    (-1: no patch, its strip has fewer than 3 vertices)."""
    nbytes: np.ndarray
    """Bytes of each leaf's data."""
    size: int
    """Bytes of the level's patch data."""
    boulders: str | None = None
    """Temporary file with the boulder meshes (after level 0's patches)."""


def _leaf_table(grid: LatLongGrid, leaves: list) -> tuple:
    """The leaves' bands and per-band triangle ranges as flat arrays
    (``Patch.triangle_range`` of every band of every leaf)."""
    band_lo = np.array([p.band_lo for p in leaves], dtype=np.int64)
    counts = np.array([p.band_hi - p.band_lo for p in leaves], dtype=np.int64)
    ptr = np.concatenate([[0], np.cumsum(counts)]).astype(np.int64)
    band = np.repeat(band_lo, counts) + np.arange(ptr[-1]) - np.repeat(ptr[:-1], counts)
    bo = grid.band_offsets()
    n = (bo[band + 1] - bo[band]).astype(np.float64)
    f_lo = np.repeat(np.array([p.frac_lo for p in leaves], dtype=np.float64), counts)
    f_hi = np.repeat(np.array([p.frac_hi for p in leaves], dtype=np.float64), counts)
    lo = np.floor(f_lo * n + 0.5).astype(np.int64)
    hi = np.floor(f_hi * n + 0.5).astype(np.int64)
    return band_lo, ptr, lo, hi


def _plan_level(body, index: int, level: int, patch_k: int, gl: dict,
                manifest: dict) -> _LevelPlan:
    """First pass over one level's patches: their JSON (buffer = the level; offsets
    within it), manifest entries and where their data goes (positions made ring window
    by ring window: :mod:`latlong.patchdata`)."""
    grid = body.grid
    leaves = list(patch_tree(grid, patch_k).leaves())
    leaves_table = _leaf_table(grid, leaves)
    nl = len(leaves)
    meta, bounds = leaf_metadata(grid, body.radii_m, body.stretch, leaves_table)
    at = np.full((nl, 3), -1, dtype=np.int64)
    nbytes = np.zeros(nl, dtype=np.int64)
    offset = 0
    scene_nodes = []
    level_info = {"level": level, "magnitude": grid.magnitude, "n_vertices": grid.n_vertices,
                  "n_triangles": grid.n_triangles, "scene": index, "patches": []}
    for i, leaf in enumerate(leaves):
        length, nv, n_tri = (int(x) for x in meta[i])
        if length < 3:
            continue
        lo, hi = bounds[i, 0:3].tolist(), bounds[i, 3:6].tolist()
        centre, radius = bounds[i, 6:9].tolist(), float(bounds[i, 9])
        ranges = {}
        for k, (name, nbyte, target) in enumerate((
                ("positions", 12 * nv, _ARRAY_BUFFER), ("normals", 12 * nv, _ARRAY_BUFFER),
                ("indices", 4 * length, _ELEMENT_ARRAY_BUFFER))):
            gl["bufferViews"].append({"buffer": index, "byteOffset": offset,
                                      "byteLength": nbyte, "target": target})
            ranges[name] = [offset, nbyte]
            at[i, k] = offset
            offset += nbyte
        nbytes[i] = 24 * nv + 4 * length
        v0 = len(gl["bufferViews"]) - 3
        a0 = len(gl["accessors"])
        gl["accessors"] += [
            {"bufferView": v0, "componentType": _FLOAT, "count": nv, "type": "VEC3",
             "min": lo, "max": hi},
            {"bufferView": v0 + 1, "componentType": _FLOAT, "count": nv, "type": "VEC3"},
            {"bufferView": v0 + 2, "componentType": _UINT, "count": length,
             "type": "SCALAR"}]
        gl["meshes"].append({"primitives": [{"attributes": {"POSITION": a0, "NORMAL": a0 + 1},
                                             "indices": a0 + 2, "mode": _TRIANGLE_STRIP}]})
        pid = len(level_info["patches"])
        info = {"id": pid, "bands": [leaf.band_lo, leaf.band_hi],
                "fraction": [leaf.frac_lo, leaf.frac_hi], "depth": leaf.depth,
                "centre_m": centre, "radius_m": radius, "n_vertices": nv,
                "n_triangles": n_tri, "strip_length": length, "bytes": ranges}
        gl["nodes"].append({"name": f"lod{level}/patch{pid}", "mesh": len(gl["meshes"]) - 1,
                            "extras": {"centre_m": info["centre_m"], "radius_m": radius,
                                       "n_triangles": n_tri}})
        scene_nodes.append(len(gl["nodes"]) - 1)
        level_info["patches"].append(info)
    gl["nodes"].append({"name": f"lod{level}", "children": scene_nodes, "rotation": Y_UP,
                        "extras": {"magnitude": grid.magnitude, "level": level,
                                   "up": "the body frame's +Z is glTF's +Y (rotation)"}})
    gl["scenes"].append({"name": f"lod{level}", "nodes": [len(gl["nodes"]) - 1]})
    manifest["levels"].append(level_info)
    return _LevelPlan(index, body, leaves_table, at, nbytes, offset)


def _write_level_data(plan: _LevelPlan, fh, progress: bool) -> None:
    """Second pass: the level's patch data (:func:`latlong.patchdata.write_leaf_data`:
    ring window by ring window, each leaf at its offset), then the boulder meshes after
    level 0."""
    body = plan.body
    write_leaf_data(body.grid, body.radii_m, body.stretch, plan.leaves, plan.at, plan.nbytes,
                    fh, progress=progress, desc=f"LOD {plan.level}")
    if plan.boulders is not None:
        with open(plan.boulders, "rb") as src:
            shutil.copyfileobj(src, fh, length=16 << 20)


def _write_boulder_meshes(cat, gl: dict, manifest: dict, binf, offset: int):
    """Every level's unit boulder meshes into ``binf`` (buffer 0); returns the new offset
    and {level: first mesh index} (boulder i's mesh at level l = first[l] + i)."""
    shape = catalog_shape(cat)
    chunk = mesh_chunk(shape)
    first = {}

    def view(raw: bytes, target: int) -> int:
        nonlocal offset
        binf.write(raw)
        gl["bufferViews"].append({"buffer": 0, "byteOffset": offset, "byteLength": len(raw),
                                  "target": target})
        offset += len(raw)
        pad = _pad4(len(raw))
        binf.write(b"\0" * pad)
        offset += pad
        return len(gl["bufferViews"]) - 1

    _, faces = boulder_meshes(cat["seed"][:1], shape)
    index_acc = {}
    for lv in shape.levels:
        ind = faces[lv].astype(np.uint16).ravel()
        gl["accessors"].append({"bufferView": view(ind.tobytes(), _ELEMENT_ARRAY_BUFFER),
                                "componentType": _USHORT, "count": len(ind),
                                "type": "SCALAR"})
        index_acc[lv] = len(gl["accessors"]) - 1
    for lv in shape.levels:
        first[lv] = len(gl["meshes"])
        nv = 10 * 4**lv + 2
        for s0 in range(0, len(cat), chunk):
            verts, _ = boulder_meshes(cat["seed"][s0:s0 + chunk], shape)
            v = verts[:, :nv]
            nrm = vertex_normals(v, faces[lv], "area", order="corners").astype(np.float32)
            v = v.astype(np.float32)
            for k in range(len(v)):
                pos = view(v[k].tobytes(), _ARRAY_BUFFER)
                nv_ = view(nrm[k].tobytes(), _ARRAY_BUFFER)
                a0 = len(gl["accessors"])
                gl["accessors"] += [
                    {"bufferView": pos, "componentType": _FLOAT, "count": nv, "type": "VEC3",
                     "min": [float(x) for x in v[k].min(axis=0)],
                     "max": [float(x) for x in v[k].max(axis=0)]},
                    {"bufferView": nv_, "componentType": _FLOAT, "count": nv, "type": "VEC3"}]
                gl["meshes"].append({"primitives": [{
                    "attributes": {"POSITION": a0, "NORMAL": a0 + 1},
                    "indices": index_acc[lv], "mode": _TRIANGLES}]})
    manifest["boulders"] = {"count": int(len(cat)), "levels": list(shape.levels),
                            "first_mesh": {str(lv): m for lv, m in first.items()}}
    return offset, first


def _boulder_nodes(cat, index: int, level: int, first: dict, gl: dict,
                   manifest: dict) -> None:
    """One node per boulder in scene ``index`` (level ``level``'s boulder level), under
    a root node."""
    levels = sorted(first)
    blevel = max(levels[-1] - level, levels[0])
    children = []
    for i in range(len(cat)):
        gl["nodes"].append({
            "name": f"boulder{i}", "mesh": first[blevel] + i,
            "translation": [float(cat[f"centre_{a}_m"][i]) for a in "xyz"],
            "rotation": [float(cat[f"quat_{a}"][i]) for a in "xyzw"],
            "scale": [float(cat["diameter_m"][i])] * 3,
            "extras": {"id": i, "lod_meshes": [first[lv] + i for lv in levels]}})
        children.append(len(gl["nodes"]) - 1)
    gl["nodes"].append({"name": f"lod{level}/boulders", "children": children,
                        "extras": {"boulder_level": blevel}})
    root = gl["scenes"][index]["nodes"][0]  # the level's node: the body's frame, +Y up
    gl["nodes"][root]["children"].append(len(gl["nodes"]) - 1)
    manifest["levels"][index]["boulder_level"] = blevel


def export_vtp_strips(body, path) -> Path:
    """VTP with native triangle strips (one per band) and point normals/heights."""
    import pyvista as pv


    path = Path(path)
    strips = triangle_strips(body.grid)
    cells = np.concatenate([np.concatenate([[len(s)], s]) for s in strips])
    mesh = pv.PolyData(body.vertices(), strips=cells)
    mesh.point_data["Normals"] = body.vertex_normals("area")
    mesh.point_data["height_m"] = body.heights_m
    with atomic_path(path) as tmp:
        mesh.save(str(tmp), binary=True)
    return path
