"""Benchmark: PLY and GLB export speed of a large body against the disk (plain script).

Builds a magnitude-M body (default M = 2000: 24 M vertices; a sphere of radius 1 km
with Gaussian heights - the writers' speed does not depend on the relief), measures the
disk with ``dd if=/dev/zero of=FILE bs=16M count=128 conv=fdatasync`` in the output
folder, then writes the body as PLY and GLB (``Body.export``: the packed PLY records and
the patched-strip glTF of :func:`latlong.export_glb`) and reports MB/s (10^6 bytes per
second of wall time, file size / export time) beside the dd figure. With ``--reference``
it also runs the writers as they were before the fast paths (kept below: the generic
packing of ``write_ply`` and the per-patch numpy loop of the old glTF export), reports
the speed ratio and checks that the files are byte-identical (sha256). The machine is
shared: the load average is printed with every figure. Usage:
``python tests/benchmarks/bench_writers.py [--magnitude M] [--repeat N] [--reference]
[--out DIR]``.
"""

from __future__ import annotations

import argparse
import dataclasses
import hashlib
import json
import os
import re
import shutil
import struct
import subprocess
import tempfile
import time
from pathlib import Path

import numpy as np

from craters._shared import atomic_path, package_version
from latlong import Body, LatLongGrid
from latlong.export import body_mesh_source
from latlong.meshio.writers import write_mesh
from latlong.strips import join_strips, patch_tree, strip_triangles


def load() -> str:
    return "load {:.2f} {:.2f} {:.2f}".format(*os.getloadavg())


def dd_speed(folder: Path) -> float:
    """MB/s of dd writing 2 GiB of zeros with fdatasync into ``folder``."""
    target = folder / "dd.bin"
    proc = subprocess.run(["dd", "if=/dev/zero", f"of={target}", "bs=16M", "count=128",
                           "conv=fdatasync"], capture_output=True, text=True, check=True)
    target.unlink()
    line = proc.stderr.strip().splitlines()[-1]
    print(f"dd: {line}  ({load()})")
    nbytes, seconds = re.match(r"(\d+) bytes .* copied, ([\d.]+) s", line).groups()
    return int(nbytes) / float(seconds) / 1e6


def sha256(path: Path) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        while chunk := fh.read(1 << 24):
            h.update(chunk)
    return h.hexdigest()


def old_ply(body, path):
    """The PLY writer before the fast path: the generic packing of every chunk."""
    src = dataclasses.replace(body_mesh_source(body), vertex_records=None, face_records=None)
    write_mesh(src, path)


def old_glb(body, path, patch_k=64):
    """The glTF export before the fast path (level 0, no boulders): per patch, the
    joined strip, ``np.unique``, positions and normals in numpy, written to a temporary
    file that is then copied after the JSON. The manifest is not written."""
    grid = body.grid
    gl = {"asset": {"version": "2.0", "generator": f"craterform {package_version()}"},
          "scene": 0, "scenes": [], "nodes": [], "meshes": [], "accessors": [],
          "bufferViews": [], "buffers": []}
    normals = body.vertex_normals()
    radii, stretch = np.asarray(body.radii_m), np.asarray(body.stretch)
    offset, nodes = 0, []
    fd, tmp_bin = tempfile.mkstemp(dir=path.parent, suffix=".bin")
    os.close(fd)
    try:
        with open(tmp_bin, "wb") as binf:
            for leaf in patch_tree(grid, patch_k).leaves():
                strip = join_strips(leaf.strips(grid))
                if len(strip) < 3:
                    continue
                idx, local = np.unique(strip, return_inverse=True)
                pos = (grid.unit_vectors_of(idx) * radii[idx, None] * stretch).astype(np.float32)
                ind = local.astype(np.uint32)
                lo, hi = pos.min(axis=0), pos.max(axis=0)
                centre = 0.5 * (lo.astype(np.float64) + hi)
                radius = float(np.sqrt(((pos - centre) ** 2).sum(axis=1).max()))
                n_tri = len(strip_triangles(strip))
                for data, target in ((pos, 34962), (normals[idx], 34962), (ind, 34963)):
                    raw = np.ascontiguousarray(data).tobytes()
                    binf.write(raw)
                    gl["bufferViews"].append({"buffer": 0, "byteOffset": offset,
                                              "byteLength": len(raw), "target": target})
                    offset += len(raw)
                v0, a0 = len(gl["bufferViews"]) - 3, len(gl["accessors"])
                gl["accessors"] += [
                    {"bufferView": v0, "componentType": 5126, "count": len(pos),
                     "type": "VEC3", "min": [float(x) for x in lo],
                     "max": [float(x) for x in hi]},
                    {"bufferView": v0 + 1, "componentType": 5126, "count": len(pos),
                     "type": "VEC3"},
                    {"bufferView": v0 + 2, "componentType": 5125, "count": len(ind),
                     "type": "SCALAR"}]
                gl["meshes"].append({"primitives": [{
                    "attributes": {"POSITION": a0, "NORMAL": a0 + 1}, "indices": a0 + 2,
                    "mode": 5}]})
                pid = len(nodes)
                gl["nodes"].append({"name": f"lod0/patch{pid}", "mesh": len(gl["meshes"]) - 1,
                                    "extras": {"centre_m": [float(x) for x in centre],
                                               "radius_m": radius, "n_triangles": n_tri}})
                nodes.append(len(gl["nodes"]) - 1)
        gl["nodes"].append({"name": "lod0", "children": nodes,
                            "extras": {"magnitude": grid.magnitude, "level": 0}})
        gl["scenes"].append({"name": "lod0", "nodes": [len(gl["nodes"]) - 1]})
        gl["buffers"] = [{"byteLength": offset}]
        js = json.dumps(gl, separators=(",", ":"), sort_keys=True).encode("utf-8")
        js += b" " * ((4 - len(js) % 4) % 4)
        with atomic_path(path) as tmp, open(tmp, "wb") as out:
            out.write(struct.pack("<4sII", b"glTF", 2, 12 + 8 + len(js) + 8 + offset))
            out.write(struct.pack("<I4s", len(js), b"JSON") + js)
            out.write(struct.pack("<I4s", offset, b"BIN\x00"))
            with open(tmp_bin, "rb") as src:
                shutil.copyfileobj(src, out, length=16 << 20)
    finally:
        os.unlink(tmp_bin)


def timed(label: str, write, path: Path, repeat: int) -> tuple[float, str]:
    """Best MB/s of ``repeat`` runs of ``write(path)``; returns it and the file's sha256."""
    best = 0.0
    for _ in range(repeat):
        t0 = time.perf_counter()
        write(path)
        dt = time.perf_counter() - t0
        size = path.stat().st_size
        best = max(best, size / dt / 1e6)
        print(f"  {label}: {size / 1e6:,.0f} MB in {dt:.2f} s = {size / dt / 1e6:,.0f} MB/s "
              f"({load()})", flush=True)
    digest = sha256(path)
    path.unlink()
    for extra in (path.with_suffix(".json"),):
        if extra.exists():
            extra.unlink()
    return best, digest


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--magnitude", type=int, default=2000)
    parser.add_argument("--repeat", type=int, default=2)
    parser.add_argument("--reference", action="store_true",
                        help="also time the old writers, check identical bytes")
    parser.add_argument("--out", default=None, help="folder for the files (default: temp)")
    args = parser.parse_args()
    folder = Path(args.out or tempfile.mkdtemp(prefix="craterform-bench-"))
    folder.mkdir(parents=True, exist_ok=True)
    grid = LatLongGrid(args.magnitude)
    heights = np.random.default_rng(1).normal(0.0, 5.0, grid.n_vertices)
    body = Body.from_heights(grid, 1000.0, heights)
    small = Body.from_heights(LatLongGrid(8), 1000.0, heights[:LatLongGrid(8).n_vertices])
    for suffix in (".ply", ".glb"):  # compile / load the kernels outside the timings
        small.export(folder / f"warm{suffix}")
        (folder / f"warm{suffix}").unlink()
    (folder / "warm.json").unlink()
    print(f"body M={args.magnitude}: {body.n_vertices:,} vertices, "
          f"{grid.n_triangles:,} triangles; folder {folder}")
    disk = dd_speed(folder)
    results = {"dd_MBps": round(disk)}
    for suffix in ("ply", "glb"):
        path = folder / f"body.{suffix}"
        new, digest = timed(f"{suffix} (new)", body.export, path, args.repeat)
        results[f"{suffix}_MBps"] = round(new)
        line = f"{suffix.upper()}: {new:,.0f} MB/s = {new / disk:.2f} x dd ({disk:,.0f} MB/s)"
        if args.reference:
            writer = old_ply if suffix == "ply" else old_glb
            old, old_digest = timed(f"{suffix} (old)", lambda p, w=writer: w(body, p), path, 1)
            same = digest == old_digest
            results[f"{suffix}_old_MBps"] = round(old)
            results[f"{suffix}_identical"] = same
            line += f"; old writer {old:,.0f} MB/s, x{new / old:.1f}; bytes identical: {same}"
        print(line, flush=True)
    disk2 = dd_speed(folder)
    results["dd_after_MBps"] = round(disk2)
    print(json.dumps(results))
    if not args.out:
        shutil.rmtree(folder, ignore_errors=True)


if __name__ == "__main__":
    main()
