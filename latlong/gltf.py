"""Renderer export: patched triangle strips as glTF 2.0 binary, VTP strips, a manifest.

``export_glb`` writes one glTF scene per level of detail (scene 0 = the full body,
scene l = the nested magnitude M / 2^l body); every leaf of the patch tree
(:func:`latlong.strips.patch_tree`) is one node with one mesh whose single primitive is
a ``TRIANGLE_STRIP`` (mode 5) over the patch's own vertices: float32 ``POSITION`` (with
min/max) and unit ``NORMAL``, uint32 indices. The patch strips are the band strips cut
to the patch and joined with degenerate triangles. Node extras and the JSON manifest
give each patch's bounding sphere, bands, triangle count and the byte ranges of its
data, so a renderer can cull and stream patches. Nothing holds the whole body's
triangles: patches are generated and written one by one, normals come from a
band-streaming kernel, and each level's binary data goes to a temporary file first.
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

import json
import os
import shutil
import struct
import tempfile
from pathlib import Path

import numpy as np

from craters._shared import atomic_path, check_int, package_version, progress_bar
from craters.boulders import boulder_meshes, boulder_normals, catalog_shape, mesh_chunk

from .grid import LatLongGrid
from .strips import join_strips, patch_tree, strip_triangles, triangle_strips

__all__ = ["export_glb", "export_vtp_strips", "unit_vectors_of"]

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


def export_glb(body, path, *, patch_k: int = 64, lod: int = 0,
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

    Returns
    -------
    The manifest (also written): per level the magnitude, triangle count and patches
    with their bounds and byte ranges.
    """
    if not isinstance(getattr(body, "grid", None), LatLongGrid):
        raise TypeError(f"`body` must be a latlong.Body; got {type(body).__name__}")
    path = Path(path)
    if path.suffix.lower() != ".glb":
        raise ValueError(f"`path` must end in .glb; got {str(path)!r}")
    patch_k = check_int("patch_k", patch_k, 2, 1_000_000)
    lod = check_int("lod", lod, 0, 20)
    if body.magnitude % (2**lod):
        raise ValueError(f"`lod` {lod} needs a magnitude divisible by {2**lod}; "
                         f"the body has M = {body.magnitude}")
    gl = {"asset": {"version": "2.0", "generator": f"craterform {package_version()}"},
          "scene": 0, "scenes": [], "nodes": [], "meshes": [], "accessors": [],
          "bufferViews": [], "buffers": []}
    manifest = {"format": "craterform.patches/1", "glb": path.name, "patch_k": patch_k,
                "levels": []}
    folder = path.parent if str(path.parent) else Path(".")
    temps = []
    try:
        sizes = []
        for level in range(lod + 1):
            fd, tmp_bin = tempfile.mkstemp(prefix=f".{path.name}.", suffix=f".lod{level}.bin",
                                           dir=folder)
            os.close(fd)
            temps.append(tmp_bin)
            with open(tmp_bin, "wb") as binf:
                size = _write_level(body.lod(level), level, patch_k, gl, manifest, binf,
                                    progress)
                if body.boulders is not None and len(body.boulders):
                    if level == 0:
                        size, boulder_first = _write_boulder_meshes(body.boulders, gl,
                                                                     manifest, binf, size)
                    _boulder_nodes(body.boulders, level, boulder_first, gl, manifest)
                sizes.append(size)
        _finish(path, gl, manifest, temps, sizes)
    finally:
        for t in temps:
            if os.path.exists(t):
                os.unlink(t)
    with atomic_path(path.with_suffix(".json")) as tmp:
        tmp.write_text(json.dumps(manifest, indent=1, sort_keys=True), encoding="utf-8")
    return manifest


#: A GLB's length and chunk lengths are 32-bit: past this the levels go to .bin files.
GLB_LIMIT = 2**32 - 1


def _finish(path: Path, gl: dict, manifest: dict, temps: list, sizes: list) -> None:
    """Embed the levels' binary data in the GLB, or - past 4 GiB, the format's limit -
    reference one external ``<stem>.lod<k>.bin`` per level (glTF external buffers)."""
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
            for t in temps:
                with open(t, "rb") as src:
                    shutil.copyfileobj(src, out, length=16 << 20)
        return
    names = [f"{path.stem}.lod{k}.bin" for k in range(len(temps))]
    gl["buffers"] = [{"uri": n, "byteLength": int(sz)} for n, sz in zip(names, sizes,
                                                                       strict=True)]
    js = _json_chunk(gl)
    manifest["bin_chunk_offset"] = None
    manifest["buffers"] = names
    for t, n in zip(temps, names, strict=True):
        os.replace(t, path.parent / n)
    with atomic_path(path) as tmp, open(tmp, "wb") as out:
        out.write(struct.pack("<4sII", b"glTF", 2, 12 + 8 + len(js)))
        out.write(struct.pack("<I4s", len(js), b"JSON"))
        out.write(js)


def _json_chunk(gl: dict) -> bytes:
    js = json.dumps(gl, separators=(",", ":"), sort_keys=True).encode("utf-8")
    return js + b" " * _pad4(len(js))


def _write_level(body, level: int, patch_k: int, gl: dict, manifest: dict, binf,
                 progress: bool) -> int:
    """Write one level's patches to ``binf`` (buffer = the level); returns its size."""
    offset = 0
    grid = body.grid
    normals = body.vertex_normals()
    radii = np.asarray(body.radii_m)
    stretch = np.asarray(body.stretch)
    root = patch_tree(grid, patch_k)
    leaves = list(root.leaves())
    scene_nodes = []
    level_info = {"level": level, "magnitude": grid.magnitude, "n_vertices": grid.n_vertices,
                  "n_triangles": grid.n_triangles, "scene": level, "patches": []}
    for leaf in progress_bar(leaves, enabled=progress, desc=f"LOD {level}"):
        strip = join_strips(leaf.strips(grid))
        if len(strip) < 3:
            continue
        idx, local = np.unique(strip, return_inverse=True)
        pos = (unit_vectors_of(grid, idx) * radii[idx, None] * stretch).astype(np.float32)
        nrm = normals[idx]
        ind = local.astype(np.uint32)
        lo, hi = pos.min(axis=0), pos.max(axis=0)
        centre = 0.5 * (lo.astype(np.float64) + hi)
        radius = float(np.sqrt(((pos - centre) ** 2).sum(axis=1).max()))
        n_tri = len(strip_triangles(strip))
        ranges = {}
        for name, data, target in (("positions", pos, _ARRAY_BUFFER),
                                   ("normals", nrm, _ARRAY_BUFFER),
                                   ("indices", ind, _ELEMENT_ARRAY_BUFFER)):
            raw = np.ascontiguousarray(data).tobytes()
            binf.write(raw)
            gl["bufferViews"].append({"buffer": level, "byteOffset": offset,
                                      "byteLength": len(raw), "target": target})
            ranges[name] = [offset, len(raw)]
            offset += len(raw)
        v0 = len(gl["bufferViews"]) - 3
        a0 = len(gl["accessors"])
        gl["accessors"] += [
            {"bufferView": v0, "componentType": _FLOAT, "count": len(pos), "type": "VEC3",
             "min": [float(x) for x in lo], "max": [float(x) for x in hi]},
            {"bufferView": v0 + 1, "componentType": _FLOAT, "count": len(pos), "type": "VEC3"},
            {"bufferView": v0 + 2, "componentType": _UINT, "count": len(ind),
             "type": "SCALAR"}]
        gl["meshes"].append({"primitives": [{"attributes": {"POSITION": a0, "NORMAL": a0 + 1},
                                             "indices": a0 + 2, "mode": _TRIANGLE_STRIP}]})
        pid = len(level_info["patches"])
        info = {"id": pid, "bands": [leaf.band_lo, leaf.band_hi],
                "fraction": [leaf.frac_lo, leaf.frac_hi], "depth": leaf.depth,
                "centre_m": [float(x) for x in centre], "radius_m": radius,
                "n_vertices": len(pos), "n_triangles": n_tri, "strip_length": len(ind),
                "bytes": ranges}
        gl["nodes"].append({"name": f"lod{level}/patch{pid}", "mesh": len(gl["meshes"]) - 1,
                            "extras": {"centre_m": info["centre_m"], "radius_m": radius,
                                       "n_triangles": n_tri}})
        scene_nodes.append(len(gl["nodes"]) - 1)
        level_info["patches"].append(info)
    gl["nodes"].append({"name": f"lod{level}", "children": scene_nodes,
                        "extras": {"magnitude": grid.magnitude, "level": level}})
    gl["scenes"].append({"name": f"lod{level}", "nodes": [len(gl["nodes"]) - 1]})
    manifest["levels"].append(level_info)
    return offset


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
            nrm = boulder_normals(v, faces[lv]).astype(np.float32)
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


def _boulder_nodes(cat, level: int, first: dict, gl: dict, manifest: dict) -> None:
    """One node per boulder in scene ``level`` (its boulder level), under a root node."""
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
    gl["scenes"][level]["nodes"].append(len(gl["nodes"]) - 1)
    manifest["levels"][level]["boulder_level"] = blevel


def export_vtp_strips(body, path) -> Path:
    """VTP with native triangle strips (one per band) and point normals/heights."""
    import pyvista as pv


    path = Path(path)
    strips = triangle_strips(body.grid)
    cells = np.concatenate([np.concatenate([[len(s)], s]) for s in strips])
    mesh = pv.PolyData(body.vertices(), strips=cells)
    mesh.point_data["Normals"] = body.vertex_normals()
    mesh.point_data["height_m"] = body.heights_m
    with atomic_path(path) as tmp:
        mesh.save(str(tmp), binary=True)
    return path
