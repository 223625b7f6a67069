"""Mesh export: PLY/OBJ/STL streamed band by band, VTP/VTK through pyvista.

The streamed writers never hold the whole triangle array: they generate the triangles
of a few latitude bands at a time (``LatLongGrid.band_triangles``), so a 24 M-vertex
body exports in a few hundred MB beyond the body itself. All writers are deterministic
(no timestamps) and atomic (temporary file, then rename).

Placed boulders (``body.boulders``) are merged in at their finest level after the
body's vertices and triangles; PLY and VTP/VTK then carry a per-vertex ``boulder_id``
(-1 on the body, else the boulder's row in the catalog) - ground truth for hazard
detection - and OBJ puts them in a group ``boulders``.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from craters._shared import atomic_path, progress_bar

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


def _boulders(body):
    """The body's placed boulders or None."""
    cat = getattr(body, "boulders", None)
    return cat if cat is not None and len(cat) else None


def _boulder_counts(body):
    """(vertices, triangles) the boulders add at their finest level."""
    from craters.boulders import catalog_shape

    cat = _boulders(body)
    if cat is None:
        return 0, 0
    top = catalog_shape(cat).levels[-1]
    return len(cat) * (10 * 4**top + 2), len(cat) * 20 * 4**top


def _boulder_heights(body, verts):
    """Height of boulder vertices above the reference sphere (metres), as for the body:
    the distance from the centre after undoing the stretch, minus the radius."""
    return np.linalg.norm(verts / np.asarray(body.stretch), axis=-1) - body.radius_m


def _vertex_chunks(n, chunk=1 << 21):
    for s in range(0, n, chunk):
        yield s, min(s + chunk, n)


def write_ply(body, path, *, progress: bool = False) -> Path:
    """Binary little-endian PLY: float32 ``x y z height_m`` per vertex (plus int32
    ``boulder_id`` when the body has boulders), int32 triangles."""
    from craters.boulders import iter_boulder_meshes

    grid = body.grid
    n, t = grid.n_vertices, grid.n_triangles
    cat = _boulders(body)
    nbv, nbt = _boulder_counts(body)
    idx = "int" if n + nbv < 2**31 else "uint"
    header = (
        "ply\nformat binary_little_endian 1.0\n"
        "comment craterform lat/long body, metres\n"
        f"comment magnitude {grid.magnitude}\n"
        + (f"comment {len(cat)} boulders after the body, boulder_id = catalog row\n"
           if cat is not None else "")
        + f"element vertex {n + nbv}\n"
        "property float x\nproperty float y\nproperty float z\nproperty float height_m\n"
        + ("property int boulder_id\n" if cat is not None else "")
        + f"element face {t + nbt}\n"
        f"property list uchar {idx} vertex_indices\n"
        "end_header\n"
    ).encode("ascii")
    fields = [("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("h", "<f4")]
    vdt = np.dtype(fields + ([("b", "<i4")] if cat is not None else []))
    fdt = np.dtype([("n", "u1"), ("v", "<i4" if idx == "int" else "<u4", (3,))])
    heights = body.heights_m
    with atomic_path(path) as tmp, open(tmp, "wb") as fh:
        fh.write(header)
        for s, e in _vertex_chunks(n):
            rec = np.empty(e - s, dtype=vdt)
            v = body.vertices(s, e)
            rec["x"], rec["y"], rec["z"] = v[:, 0], v[:, 1], v[:, 2]
            rec["h"] = heights[s:e]
            if cat is not None:
                rec["b"] = -1
            fh.write(rec.tobytes())
        if cat is not None:
            for s0, world, _ in iter_boulder_meshes(cat):
                k, nv = world.shape[:2]
                rec = np.empty(k * nv, dtype=vdt)
                v = world.reshape(-1, 3)
                rec["x"], rec["y"], rec["z"] = v[:, 0], v[:, 1], v[:, 2]
                rec["h"] = _boulder_heights(body, v)
                rec["b"] = np.repeat(np.arange(s0, s0 + k), nv)
                fh.write(rec.tobytes())
        chunks = list(_band_chunks(grid))
        for lo, hi in progress_bar(chunks, enabled=progress, desc="PLY"):
            tri = grid.band_triangles(lo, hi)
            rec = np.empty(len(tri), dtype=fdt)
            rec["n"] = 3
            rec["v"] = tri
            fh.write(rec.tobytes())
        for tri in _boulder_face_chunks(body):
            rec = np.empty(len(tri), dtype=fdt)
            rec["n"] = 3
            rec["v"] = tri
            fh.write(rec.tobytes())
    return Path(path)


def _boulder_face_chunks(body, base: int = 0):
    """Boulder triangles a chunk at a time, indices after the body's vertices (+ base)."""
    from craters.boulders import catalog_shape, mesh_chunk

    cat = _boulders(body)
    if cat is None:
        return
    shape = catalog_shape(cat)
    top, chunk = shape.levels[-1], mesh_chunk(shape)
    nv = 10 * 4**top + 2
    from craters.boulders import boulder_faces

    faces = boulder_faces(top)
    n = body.grid.n_vertices + base
    for s0 in range(0, len(cat), chunk):
        k = min(chunk, len(cat) - s0)
        offsets = n + (s0 + np.arange(k))[:, None, None] * nv
        yield (faces[None] + offsets).reshape(-1, 3)


def write_stl(body, path, *, progress: bool = False) -> Path:
    """Binary STL (float32 facet normals and corners, metres)."""
    grid = body.grid
    tdt = np.dtype([("n", "<f4", (3,)), ("v", "<f4", (3, 3)), ("a", "<u2")])
    header = b"craterform lat/long body, metres".ljust(80, b" ")
    from craters.boulders import iter_boulder_meshes

    def facets(corners):
        normal = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
        norm = np.linalg.norm(normal, axis=1, keepdims=True)
        normal = np.divide(normal, norm, out=np.zeros_like(normal), where=norm > 0)
        rec = np.zeros(len(corners), dtype=tdt)
        rec["n"] = normal
        rec["v"] = corners
        return rec.tobytes()

    cat = _boulders(body)
    with atomic_path(path) as tmp, open(tmp, "wb") as fh:
        fh.write(header)
        fh.write(np.uint32(grid.n_triangles + _boulder_counts(body)[1]).tobytes())
        chunks = list(_band_chunks(grid))
        for lo, hi in progress_bar(chunks, enabled=progress, desc="STL"):
            tri = grid.band_triangles(lo, hi)
            vlo, vhi = int(tri.min()), int(tri.max()) + 1
            verts = body.vertices(vlo, vhi)
            fh.write(facets(verts[tri - vlo]))
        if cat is not None:
            for _, world, faces in iter_boulder_meshes(cat):
                fh.write(facets(world[:, faces].reshape(-1, 3, 3)))
    return Path(path)


def write_obj(body, path, *, progress: bool = False) -> Path:
    """Wavefront OBJ text (``v x y z`` in metres, 9 significant digits; 1-based faces)."""
    from craters.boulders import iter_boulder_meshes

    grid = body.grid
    with atomic_path(path) as tmp, open(tmp, "w", encoding="ascii", newline="\n") as fh:
        fh.write(f"# craterform lat/long body, magnitude {grid.magnitude}, metres\n")
        for s, e in _vertex_chunks(grid.n_vertices, 1 << 18):
            v = body.vertices(s, e)
            fh.write(("v %.9g %.9g %.9g\n" * (e - s)) % tuple(v.ravel().tolist()))
        cat = _boulders(body)
        if cat is not None:
            for _, world, _ in iter_boulder_meshes(cat, chunk=256):
                v = world.reshape(-1, 3)
                fh.write(("v %.9g %.9g %.9g\n" * len(v)) % tuple(v.ravel().tolist()))
            fh.write("g body\n")
        chunks = list(_band_chunks(grid))
        for lo, hi in progress_bar(chunks, enabled=progress, desc="OBJ"):
            tri = grid.band_triangles(lo, hi) + 1
            for s, e in _vertex_chunks(len(tri), 1 << 18):
                fh.write(("f %d %d %d\n" * (e - s)) % tuple(tri[s:e].ravel().tolist()))
        if cat is not None:
            fh.write("g boulders\n")
            for tri in _boulder_face_chunks(body, base=1):
                for s, e in _vertex_chunks(len(tri), 1 << 18):
                    fh.write(("f %d %d %d\n" * (e - s)) % tuple(tri[s:e].ravel().tolist()))
    return Path(path)


def _write_pyvista(body, path, *, progress: bool = False) -> Path:
    mesh = body.to_pyvista()
    cat = _boulders(body)
    if cat is not None:
        import pyvista as pv

        from craters.boulders import boulder_world_meshes

        bv, bf = boulder_world_meshes(cat)
        rocks = pv.PolyData(bv, np.hstack([np.full((len(bf), 1), 3), bf]).ravel())
        rocks.point_data["height_m"] = _boulder_heights(body, bv)
        rocks.point_data["boulder_id"] = np.repeat(np.arange(len(cat), dtype=np.int32),
                                                   len(bv) // len(cat))
        mesh.point_data["boulder_id"] = np.full(mesh.n_points, -1, dtype=np.int32)
        mesh = mesh.merge(rocks, merge_points=False)
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
