"""Procedural boulder meshes (Martin 2014, V.C): shapes, levels, placed meshes.

A boulder starts as a regular icosahedron stretched to an ellipsoid (``elongation``
along x, ``flatten`` along z), refined by edge subdivision: every edge gets a new vertex
at its midpoint, displaced along its direction from the boulder's centre by random
midpoint displacement (Gaussian, amplitude ``roughness`` x the level's edge length x
2^(-hurst (l - 1)), clipped so the vertex keeps 30 % of its distance: every level is
star-shaped about the centre, hence free of self-intersections). Level l has
10 4^l + 2 vertices; a level's vertices are the first ones of the next level, unchanged
(exact subsets), so a renderer can switch levels by distance. The levels B..B+3 form
the paper's bi-resolution node tree (:class:`BoulderNode`: the low branch holds level B,
the high branch the node of the finer levels). The mesh is scaled so that its longest
extent is 1 (metres after scaling by the diameter).
"""

from __future__ import annotations

import dataclasses
import functools
from typing import cast

import numpy as np

from .._shared import check_int, check_range, normalize_rng

__all__ = ["BoulderNode", "BoulderShape", "boulder", "boulder_faces", "boulder_meshes",
           "boulder_world_meshes", "catalog_shape", "iter_boulder_meshes",
           "mesh_chunk"]

_PHI = (1.0 + 5.0**0.5) / 2.0
_ICO_V = np.array([[-1, _PHI, 0], [1, _PHI, 0], [-1, -_PHI, 0], [1, -_PHI, 0],
                   [0, -1, _PHI], [0, 1, _PHI], [0, -1, -_PHI], [0, 1, -_PHI],
                   [_PHI, 0, -1], [_PHI, 0, 1], [-_PHI, 0, -1], [-_PHI, 0, 1]], dtype=float)
_ICO_V /= np.linalg.norm(_ICO_V, axis=1, keepdims=True)
_ICO_F = np.array([[0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11], [1, 5, 9],
                   [5, 11, 4], [11, 10, 2], [10, 7, 6], [7, 1, 8], [3, 9, 4], [3, 4, 2],
                   [3, 2, 6], [3, 6, 8], [3, 8, 9], [4, 9, 5], [2, 4, 11], [6, 2, 10],
                   [8, 6, 7], [9, 8, 1]], dtype=np.int64)


@functools.lru_cache(maxsize=16)
def _topology(level: int):
    """Faces of every level up to ``level`` and the parent edges of each new vertex.

    Returns (faces per level, parents per level >= 1 as (n_new, 2) vertex pairs).
    """
    faces = [_ICO_F]
    parents = [np.zeros((0, 2), dtype=np.int64)]
    n = 12
    for _ in range(level):
        f = faces[-1]
        e = np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]])
        key = np.sort(e, axis=1)
        uniq, inv = np.unique(key, axis=0, return_inverse=True)
        mid = n + inv.reshape(3, -1).T  # midpoint vertex of edges (01, 12, 20) per face
        a, b, c = f[:, 0], f[:, 1], f[:, 2]
        m01, m12, m20 = mid[:, 0], mid[:, 1], mid[:, 2]
        nf = np.concatenate([np.stack([a, m01, m20], 1), np.stack([m01, b, m12], 1),
                             np.stack([m20, m12, c], 1), np.stack([m01, m12, m20], 1)])
        faces.append(nf)
        parents.append(uniq)
        n += len(uniq)
    return faces, parents


def boulder_faces(level: int) -> np.ndarray:
    """Triangles (F, 3) of subdivision level ``level`` (20 4^level faces over its
    10 4^level + 2 vertices, outward), shared by every boulder; read-only use (cached).

    Examples
    --------
    >>> boulder_faces(1).shape
    (80, 3)
    """
    level = check_int("level", level, 0, 6)
    return _topology(level)[0][level]


@dataclasses.dataclass(frozen=True, slots=True)
class BoulderShape:
    """Shape parameters of procedural boulders."""

    base_level: int = 0
    """B: the coarsest level (10 4^B + 2 vertices)."""
    n_levels: int = 4
    """Number of levels B .. B + n_levels - 1."""
    flatten: float = 0.6
    """Scale of the up axis (z) relative to y: boulders rest on their flat side."""
    elongation: float = 1.4
    """Scale of x relative to y."""
    roughness: float = 0.22
    """Midpoint displacement as a fraction of the edge length at level 1."""
    hurst: float = 0.8
    """Displacements shrink by 2^-hurst per level beyond the edge-length scaling."""

    def __post_init__(self):
        object.__setattr__(self, "base_level", check_int("base_level", self.base_level, 0, 6))
        object.__setattr__(self, "n_levels", check_int("n_levels", self.n_levels, 1, 6))
        if self.base_level + self.n_levels > 7:
            raise ValueError(f"`base_level` + `n_levels` must be <= 7 (finest level 6: 40 962 "
                             f"vertices); got {self.base_level} + {self.n_levels}")
        check_range("flatten", self.flatten, 0.1, 2.0)
        check_range("elongation", self.elongation, 0.5, 4.0)
        check_range("roughness", self.roughness, 0.0, 1.0)
        check_range("hurst", self.hurst, 0.0, 2.0)

    @property
    def levels(self) -> range:
        return range(self.base_level, self.base_level + self.n_levels)


def mesh_chunk(shape: BoulderShape) -> int:
    """How many boulders to build at once: about 4 M finest-level vertices (~100 MB of
    float64 coordinates), at most 4096 boulders."""
    return max(1, min(4096, (1 << 22) // (10 * 4**shape.levels[-1] + 2)))


def boulder_meshes(seeds, shape: BoulderShape = BoulderShape()):
    """Vertices of many boulders at the finest level and the faces of every level.

    Returns ``(vertices, faces_by_level)``: vertices (n, V_finest, 3), unit longest
    extent, centred on the bounding box; level l's vertices are ``vertices[:, :10 4^l +
    2]`` and its faces ``faces_by_level[l]``. Each boulder's shape depends only on its
    seed.
    """
    v, faces, _ = _boulder_meshes(seeds, shape)
    return v, faces


def _boulder_meshes(seeds, shape: BoulderShape):
    """:func:`boulder_meshes` plus each boulder's star centre (n, 3).

    Every new vertex lies on the ray from the construction centre through its parent
    edge's midpoint, at a positive distance (the displacement is clipped to keep at least
    30 % of the midpoint's distance), and a midpoint's ray lies between its parents'
    rays: each level is star-shaped about that centre, so every level is embedded (no
    self-intersections) whatever the roughness.
    """
    seeds = np.atleast_1d(np.asarray(seeds, dtype=np.uint64))
    top = shape.base_level + shape.n_levels - 1
    faces, parents = _topology(top)
    n = len(seeds)
    n_final = 10 * 4**top + 2
    v = np.empty((n, n_final, 3))
    v[:, :12] = _ICO_V * np.array([shape.elongation, 1.0, shape.flatten])
    # the random numbers of boulder i come from its own seed: same seed, same boulder
    noise = np.empty((n, n_final - 12))
    if n:
        # imported here: the boulder specs' parsers (every dem command's settings) load
        # this module without numba
        from .._boulder_kernels import _noise_kernel

        _noise_kernel(np.ascontiguousarray(seeds), noise)
    edge0 = np.linalg.norm(_ICO_V[0] - _ICO_V[1])
    count = 12
    for level in range(1, top + 1):
        par = parents[level]
        mid = 0.5 * (v[:, par[:, 0]] + v[:, par[:, 1]])
        dist = np.linalg.norm(mid, axis=2)
        # the parent edges are edge0 / 2^(level-1) long; displacements shrink by a
        # further 2^-hurst per level
        sigma = shape.roughness * edge0 * 2.0 ** (-(level - 1) * (1.0 + shape.hurst))
        k = len(par)
        new = np.maximum(dist + sigma * noise[:, count - 12:count - 12 + k], 0.3 * dist)
        v[:, count:count + k] = mid * (new / dist)[:, :, None]
        count += k
    # centre on the bounding box, longest extent 1
    lo, hi = v.min(axis=1, keepdims=True), v.max(axis=1, keepdims=True)
    scale = (hi - lo).max(axis=2, keepdims=True)
    centre = 0.5 * (lo + hi)
    v = (v - centre) / scale
    return v, {lv: faces[lv] for lv in shape.levels}, (-centre / scale)[:, 0, :]


@dataclasses.dataclass
class BoulderNode:
    """Bi-resolution node: ``low`` = (vertices, faces) of one level, ``high`` = the node of
    the finer levels (or the finest mesh itself)."""

    level: int
    low: tuple
    high: BoulderNode | tuple | None
    """None when the boulder has a single level."""

    def meshes(self) -> list[tuple]:
        """The (vertices, faces) of every level, coarse to fine."""
        out = [self.low]
        node = self.high
        while isinstance(node, BoulderNode):
            out.append(node.low)
            node = node.high
        return out if node is None else [*out, node]


def boulder(*, rng=None, shape: BoulderShape = BoulderShape()) -> BoulderNode:
    """One procedural boulder as the paper's bi-resolution node tree.

    Examples
    --------
    >>> node = boulder(rng=1)
    >>> [len(v) for v, f in node.meshes()]
    [12, 42, 162, 642]
    """
    seed = normalize_rng(rng).integers(0, 2**63, dtype=np.uint64)
    v, faces = boulder_meshes([seed], shape)
    meshes = [(v[0, :10 * 4**lv + 2].copy(), faces[lv]) for lv in shape.levels]
    node: BoulderNode | tuple = meshes[-1]
    for lv, mesh in zip(list(shape.levels)[-2::-1], meshes[-2::-1], strict=True):
        node = BoulderNode(lv, mesh, node)
    if isinstance(node, tuple):  # a single level
        return BoulderNode(shape.base_level, node, None)
    return node


def catalog_shape(catalog) -> BoulderShape:
    """The :class:`BoulderShape` recorded in a placed catalog."""
    cat = np.asarray(catalog)
    names = cast(tuple[str, ...], cat.dtype.names)  # a catalog: a structured array
    if len(cat) == 0 or "shape_flatten" not in names:
        return BoulderShape()
    vals = {}
    for f in dataclasses.fields(BoulderShape):
        col = cat[f"shape_{f.name}"]
        if not (col == col[0]).all():
            raise ValueError(f"the catalog mixes boulder shapes (column shape_{f.name} is not "
                             "constant); keep one catalog per BoulderShape")
        vals[f.name] = col[0]
    vals["base_level"] = int(vals["base_level"])
    vals["n_levels"] = int(vals["n_levels"])
    return BoulderShape(**vals)


def iter_boulder_meshes(catalog, level: int | None = None, chunk: int | None = None):
    """Placed boulders a chunk at a time: yields ``(first, vertices (k, V, 3) m, faces
    (F, 3))`` with the faces shared by the k boulders (outward). A placed catalog has
    ``seed, diameter_m``, the centre ``centre_x_m, centre_y_m, centre_z_m`` and the
    rotation ``quat_w, quat_x, quat_y, quat_z`` (of the frame the centre is in: body
    coordinates on a body, the local frame on a DEM) and the ``shape_*`` columns."""
    from scipy.spatial.transform import Rotation

    cat = np.asarray(catalog)
    shape = catalog_shape(cat)
    level = shape.levels[-1] if level is None else check_int("level", level,
                                                            shape.base_level,
                                                            shape.levels[-1])
    nv = 10 * 4**level + 2
    chunk = mesh_chunk(shape) if chunk is None else check_int("chunk", chunk, 1, 1 << 30)
    for s0 in range(0, len(cat), chunk):
        sub = cat[s0:s0 + chunk]
        verts, faces = boulder_meshes(sub["seed"], shape)
        v = verts[:, :nv] * sub["diameter_m"][:, None, None]
        quat = np.stack([sub["quat_x"], sub["quat_y"], sub["quat_z"], sub["quat_w"]], 1)
        rot = Rotation.from_quat(quat).as_matrix()
        centre = np.stack([sub["centre_x_m"], sub["centre_y_m"], sub["centre_z_m"]], 1)
        yield s0, np.einsum("kij,kvj->kvi", rot, v) + centre[:, None, :], faces[level]


def boulder_world_meshes(catalog, level: int | None = None):
    """All placed boulders of a catalog as one triangle mesh (the catalog's frame).

    ``level`` defaults to the finest; returns ``(vertices (K, 3) m, faces (L, 3))``,
    outward triangles, boulder after boulder.
    """
    verts_all, faces_all = [], []
    for s0, world, faces in iter_boulder_meshes(catalog, level):
        k, nv = world.shape[:2]
        verts_all.append(world.reshape(-1, 3))
        offsets = (s0 + np.arange(k))[:, None, None] * nv
        faces_all.append((faces[None] + offsets).reshape(-1, 3))
    if not verts_all:
        return np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64)
    return np.concatenate(verts_all), np.concatenate(faces_all)
