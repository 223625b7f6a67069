"""Mesh export: PLY/OBJ/STL streamed band by band, VTP/VTK through pyvista.

The streamed writers never hold the whole triangle array: they generate the triangles
of a few latitude bands at a time (``LatLongGrid.band_triangles``), so a 24 M-vertex
body exports in a few hundred MB beyond the body itself. All writers are deterministic
(no timestamps) and atomic (temporary file, then rename).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from craters._infra import atomic_path, progress_bar

__all__ = ["write_mesh", "write_obj", "write_ply", "write_stl"]

# triangles per streamed chunk
_CHUNK_TRIANGLES = 1 << 21


def _band_chunks(grid):
    """Yield (band_lo, band_hi) ranges holding about _CHUNK_TRIANGLES triangles."""
    bo = grid.band_offsets()
    n_bands = len(bo) - 1
    lo = 0
    while lo < n_bands:
        hi = int(np.searchsorted(bo, bo[lo] + _CHUNK_TRIANGLES, side="right")) - 1
        hi = min(max(hi, lo + 1), n_bands)
        yield lo, hi
        lo = hi


def _vertex_chunks(n, chunk=1 << 21):
    for s in range(0, n, chunk):
        yield s, min(s + chunk, n)


def write_ply(body, path, *, progress: bool = False) -> Path:
    """Binary little-endian PLY: float32 ``x y z height_m`` per vertex, int32 triangles."""
    grid = body.grid
    n, t = grid.n_vertices, grid.n_triangles
    idx = "int" if n < 2**31 else "uint"
    header = (
        "ply\nformat binary_little_endian 1.0\n"
        "comment craterform lat/long body, metres\n"
        f"comment magnitude {grid.magnitude}\n"
        f"element vertex {n}\n"
        "property float x\nproperty float y\nproperty float z\nproperty float height_m\n"
        f"element face {t}\n"
        f"property list uchar {idx} vertex_indices\n"
        "end_header\n"
    ).encode("ascii")
    vdt = np.dtype([("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("h", "<f4")])
    fdt = np.dtype([("n", "u1"), ("v", "<i4" if idx == "int" else "<u4", (3,))])
    heights = body.heights_m
    with atomic_path(path) as tmp, open(tmp, "wb") as fh:
        fh.write(header)
        for s, e in _vertex_chunks(n):
            rec = np.empty(e - s, dtype=vdt)
            v = body.vertices(s, e)
            rec["x"], rec["y"], rec["z"] = v[:, 0], v[:, 1], v[:, 2]
            rec["h"] = heights[s:e]
            fh.write(rec.tobytes())
        chunks = list(_band_chunks(grid))
        for lo, hi in progress_bar(chunks, enabled=progress, desc="PLY"):
            tri = grid.band_triangles(lo, hi)
            rec = np.empty(len(tri), dtype=fdt)
            rec["n"] = 3
            rec["v"] = tri
            fh.write(rec.tobytes())
    return Path(path)


def write_stl(body, path, *, progress: bool = False) -> Path:
    """Binary STL (float32 facet normals and corners, metres)."""
    grid = body.grid
    tdt = np.dtype([("n", "<f4", (3,)), ("v", "<f4", (3, 3)), ("a", "<u2")])
    header = b"craterform lat/long body, metres".ljust(80, b" ")
    with atomic_path(path) as tmp, open(tmp, "wb") as fh:
        fh.write(header)
        fh.write(np.uint32(grid.n_triangles).tobytes())
        chunks = list(_band_chunks(grid))
        for lo, hi in progress_bar(chunks, enabled=progress, desc="STL"):
            tri = grid.band_triangles(lo, hi)
            vlo, vhi = int(tri.min()), int(tri.max()) + 1
            verts = body.vertices(vlo, vhi)
            corners = verts[tri - vlo]
            normal = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
            norm = np.linalg.norm(normal, axis=1, keepdims=True)
            normal = np.divide(normal, norm, out=np.zeros_like(normal), where=norm > 0)
            rec = np.zeros(len(tri), dtype=tdt)
            rec["n"] = normal
            rec["v"] = corners
            fh.write(rec.tobytes())
    return Path(path)


def write_obj(body, path, *, progress: bool = False) -> Path:
    """Wavefront OBJ text (``v x y z`` in metres, 9 significant digits; 1-based faces)."""
    grid = body.grid
    with atomic_path(path) as tmp, open(tmp, "w", encoding="ascii", newline="\n") as fh:
        fh.write(f"# craterform lat/long body, magnitude {grid.magnitude}, metres\n")
        for s, e in _vertex_chunks(grid.n_vertices, 1 << 18):
            v = body.vertices(s, e)
            fh.write(("v %.9g %.9g %.9g\n" * (e - s)) % tuple(v.ravel().tolist()))
        chunks = list(_band_chunks(grid))
        for lo, hi in progress_bar(chunks, enabled=progress, desc="OBJ"):
            tri = grid.band_triangles(lo, hi) + 1
            for s, e in _vertex_chunks(len(tri), 1 << 18):
                fh.write(("f %d %d %d\n" * (e - s)) % tuple(tri[s:e].ravel().tolist()))
    return Path(path)


def _write_pyvista(body, path, *, progress: bool = False) -> Path:
    mesh = body.to_pyvista()
    with atomic_path(path) as tmp:
        # pyvista picks the writer from the suffix, which the temporary name keeps
        mesh.save(str(tmp), binary=True)
    return Path(path)


_WRITERS = {".ply": write_ply, ".obj": write_obj, ".stl": write_stl,
            ".vtp": _write_pyvista, ".vtk": _write_pyvista}


def write_mesh(body, path, *, progress: bool = False) -> Path:
    """Write ``body`` to ``path`` in the format given by its suffix."""
    path = Path(path)
    writer = _WRITERS.get(path.suffix.lower())
    if writer is None:
        raise ValueError(f"`path` {str(path)!r}: unknown mesh format {path.suffix!r}; "
                         f"allowed: {' '.join(_WRITERS)}")
    return writer(body, path, progress=progress)
