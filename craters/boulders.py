"""Boulders (Martin 2014, V.C): multi-resolution procedural shapes and size populations.

Pure functions over numpy; placing boulders on a body is ``latlong.boulders``, on a DEM
``dem.boulders``.

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

Populations follow N_cum = c D^k (D in metres, N per m^2; boulder exponents of Bennu and
Itokawa are about -2.5 to -3.5); burial is a uniform fraction of the boulder's height.
"""

from __future__ import annotations

import dataclasses
import functools

import numpy as np

from ._boulder_kernels import _noise_kernel
from ._shared import check_finite, check_int, check_positive, check_range, normalize_rng
from .population import sample_power_law_diameters

__all__ = ["BoulderLayer", "BoulderNode", "BoulderShape", "boulder", "boulder_meshes",
           "boulder_normals", "boulder_world_meshes", "catalog_shape", "iter_boulder_meshes",
           "orientations", "parse_boulder_spec", "quaternions", "rest_on_ground"]

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


# --------------------------------------------------------------------------- populations
@dataclasses.dataclass(frozen=True, slots=True)
class BoulderLayer:
    """A power-law boulder population (N_cum = c D^k per m^2, D in metres)."""

    c: float
    k: float
    d_min_m: float
    d_max_m: float
    burial_max: float = 0.5
    """Burial fraction of the boulder's height, uniform in [0.001, burial_max]."""
    near: float = 0.0
    """Share of the boulders placed around crater rims and ejecta (needs craters)."""

    def __post_init__(self):
        check_positive("c", self.c)
        if check_finite("k", self.k) >= 0:
            raise ValueError(f"`k` must be < 0; got {self.k!r}")
        check_positive("d_min_m", self.d_min_m)
        check_positive("d_max_m", self.d_max_m)
        if self.d_min_m >= self.d_max_m:
            raise ValueError(f"`d_min_m` must be < d_max_m ({self.d_max_m}); got {self.d_min_m}")
        check_range("burial_max", self.burial_max, 0.0, 0.9)
        check_range("near", self.near, 0.0, 1.0)


_SPEC = {"c": "c", "k": "k", "dmin": "d_min_m", "dmax": "d_max_m", "burial": "burial_max",
         "near": "near"}


def parse_boulder_spec(spec: str) -> BoulderLayer:
    """Parse ``c=0.05,k=-3,dmin=0.5,dmax=10[,burial=0.5,near=0.3]`` (metres).

    Examples
    --------
    >>> parse_boulder_spec("c=0.05,k=-3,dmin=0.5,dmax=10").d_max_m
    10.0
    """
    values = {}
    for part in str(spec).split(","):
        key, sep, raw = part.partition("=")
        key = key.strip()
        if not sep or key not in _SPEC:
            raise ValueError(f"boulder layer {spec!r}: unknown item {part.strip()!r}; "
                             f"allowed keys: {', '.join(_SPEC)}")
        try:
            values[_SPEC[key]] = float(raw)
        except ValueError:
            raise ValueError(f"boulder layer {spec!r}: {key} must be a number; got {raw!r}") \
                from None
    missing = [k for k in ("c", "k", "dmin", "dmax") if _SPEC[k] not in values]
    if missing:
        raise ValueError(f"boulder layer {spec!r}: missing {', '.join(missing)}")
    try:
        return BoulderLayer(**values)
    except ValueError as exc:
        raise ValueError(f"boulder layer {spec!r}: {exc}") from None


#: Smallest burial, fraction of the height: every boulder touches the ground.
MIN_BURIAL = 1e-3


def draw_boulder_layer(layer: BoulderLayer, area_m2: float, index: int, rng) -> dict:
    """Everything of one layer's boulders but their positions, over ``area_m2``.

    The count is Poisson with mean ``area_m2 c (d_min^k - d_max^k)`` (refused above 2e7);
    returns catalog columns ``diameter_m`` (the truncated power law), ``kind``,
    ``burial_frac`` (uniform in [``MIN_BURIAL``, ``burial_max``]), ``azimuth_deg``,
    ``seed`` (of each boulder's shape) and ``layer`` (= ``index``). ``rng``: a Generator.
    """
    mean = area_m2 * layer.c * (layer.d_min_m**layer.k - layer.d_max_m**layer.k)
    if mean > 20_000_000:
        raise ValueError(f"boulder layer {index} asks for about {mean:.3g} boulders "
                         "(limit 2e7); raise dmin or lower c")
    n = int(rng.poisson(mean)) if mean > 0 else 0
    d = sample_power_law_diameters(n, layer.d_min_m, layer.d_max_m, -layer.k, rng=rng)
    return {"diameter_m": d, "kind": np.full(n, "boulder"),
            "burial_frac": np.maximum(rng.uniform(0.0, layer.burial_max, n), MIN_BURIAL),
            "azimuth_deg": rng.uniform(0.0, 360.0, n),
            "seed": rng.integers(0, 2**63, n, dtype=np.uint64), "layer": np.full(n, index)}


def boulder_normals(vertices, faces) -> np.ndarray:
    """Unit area-weighted vertex normals of boulder meshes: vertices (n, V, 3) or (V, 3),
    faces (F, 3) shared by all; same shape as ``vertices``."""
    v = np.asarray(vertices, dtype=np.float64)
    single = v.ndim == 2
    if single:
        v = v[None]
    f = np.asarray(faces)
    a, b, c = v[:, f[:, 0]], v[:, f[:, 1]], v[:, f[:, 2]]
    fn = np.cross(b - a, c - a)  # twice the area along the face normal
    acc = np.zeros_like(v)
    for k in range(3):
        np.add.at(acc, (slice(None), f[:, k]), fn)
    acc /= np.linalg.norm(acc, axis=2, keepdims=True)
    return acc[0] if single else acc


def catalog_shape(catalog) -> BoulderShape:
    """The :class:`BoulderShape` recorded in a placed catalog."""
    cat = np.asarray(catalog)
    if len(cat) == 0 or "shape_flatten" not in cat.dtype.names:
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


# --------------------------------------------------------------------------- placement
#: Lowest vertices (along the normal) tested first for a boulder's deepest point.
_CANDIDATES = 64


def orientations(normals, azimuth_rad) -> np.ndarray:
    """Rotations (k, 3, 3) taking a boulder's up axis +z to each unit normal (k, 3) after
    turning it by ``azimuth_rad`` about z (the paper: align with the zenith, then turn)."""
    n = np.asarray(normals, dtype=np.float64)
    az = np.asarray(azimuth_rad, dtype=np.float64)
    k = len(n)
    ref = np.where(np.abs(n[:, 2:3]) < 0.9, [[0.0, 0.0, 1.0]], [[1.0, 0.0, 0.0]])
    e = np.cross(ref, n)
    e /= np.linalg.norm(e, axis=1, keepdims=True)
    f = np.cross(n, e)
    frame = np.stack([e, f, n], axis=2)  # columns: where x, y, z go
    c, s = np.cos(az), np.sin(az)
    turn = np.zeros((k, 3, 3))
    turn[:, 0, 0], turn[:, 0, 1], turn[:, 1, 0], turn[:, 1, 1] = c, -s, s, c
    turn[:, 2, 2] = 1.0
    return frame @ turn


def quaternions(rot) -> np.ndarray:
    """(w, x, y, z) unit quaternions (w >= 0) of rotation matrices (k, 3, 3)."""
    from scipy.spatial.transform import Rotation

    rot = np.asarray(rot, dtype=np.float64)
    if len(rot) == 0:
        return np.zeros((0, 4))
    q = Rotation.from_matrix(rot).as_quat()  # x, y, z, w
    q = np.concatenate([q[:, 3:], q[:, :3]], axis=1)
    return q * np.where(q[:, :1] < 0, -1.0, 1.0)


def _converge(depths, centre, cand, nrm, burial, size, max_iterations):
    """Move each boulder along its normal until its deepest candidate point is ``burial``
    below the ground (within 1e-9 of its size): the depth grows one for one with the
    move where the ground is smooth. Updates ``centre`` in place; a boulder whose depth
    is not finite (its points left the ground's domain) is left where it is."""
    achieved = depths(centre[:, None, :] + cand, nrm).max(axis=1)
    active = np.arange(len(centre))
    for _ in range(max_iterations):
        miss = burial[active] - achieved[active]
        keep = np.abs(miss) >= 1e-9 * size[active]  # False for NaN: nothing to move by
        active, miss = active[keep], miss[keep]
        if len(active) == 0:
            break
        centre[active] -= nrm[active] * miss[:, None]
        achieved[active] = depths(centre[active, None, :] + cand[active],
                                  nrm[active]).max(axis=1)


def _bisect(depths, centre, world, nrm, burial, size, steps: int = 60):
    """Fallback for boulders the Newton-like moves did not settle (very rough ground):
    bisection along the normal on the deepest-vertex depth, which only grows as the
    boulder moves down. Updates ``centre`` in place where a bracket is found."""
    def miss(t):
        return depths(centre[:, None, :] - (nrm * t[:, None])[:, None, :] + world,
                      nrm).max(axis=1) - burial

    lo, hi = -size.copy(), size.copy()
    for _ in range(8):  # widen until the depth is too small at lo and too large at hi
        m_lo, m_hi = miss(lo), miss(hi)
        lo = np.where(m_lo > 0, 2 * lo, lo)
        hi = np.where(m_hi < 0, 2 * hi, hi)
    ok = (miss(lo) <= 0) & (miss(hi) >= 0)
    for _ in range(steps):
        mid = 0.5 * (lo + hi)
        up = miss(mid) > 0
        hi, lo = np.where(up, mid, hi), np.where(up, lo, mid)
    # the bracket end that is buried (never the floating one)
    centre[ok] -= nrm[ok] * hi[ok, None]


def rest_on_ground(depths, world, ground, nrm, burial_frac, size, *, max_iterations=12):
    """Centres that put each boulder's deepest point ``burial_frac`` x its height below
    the ground.

    Parameters
    ----------
    depths : callable
        ``depths(points (k, c, 3), normals (k, 3)) -> (k, c)``: depth of each point below
        the ground (positive = buried), measured along the boulder's normal.
    world : (k, V, 3)
        The oriented vertices of each boulder about its centre (metres).
    ground : (k, 3)
        The ground point under each boulder's position.
    nrm : (k, 3)
        Unit up axes.
    burial_frac, size : (k,)
        Buried fraction of the height (extent along the normal) and boulder sizes.

    Returns
    -------
    centres (k, 3), achieved depths of the deepest vertex, heights, burials (metres).

    The boulder first sits with its lowest vertex (along the normal) at the ground point,
    and moves until the deepest of its _CANDIDATES lowest vertices has the burial; then
    every vertex is checked, and where another vertex is deeper (ground tilted against
    the normal under a wide boulder) the deepest ones become the candidates and the
    boulder moves again.
    """
    k, nv, _ = world.shape
    height = np.einsum("kvi,ki->kv", world, nrm)
    extent = height.max(axis=1) - height.min(axis=1)
    burial = burial_frac * extent
    kc = min(_CANDIDATES, nv)
    idx = np.sort(np.argpartition(height, kc - 1, axis=1)[:, :kc], axis=1)
    cand = np.take_along_axis(world, idx[:, :, None], axis=1)
    lowest = np.take_along_axis(height, idx, axis=1).min(axis=1)
    centre = ground - nrm * (lowest + burial)[:, None]
    _converge(depths, centre, cand, nrm, burial, size, max_iterations)
    achieved = np.empty(k)
    todo = np.arange(k)
    for attempt in range(5):  # check every vertex; move the boulders that were wrong
        depth = depths(centre[todo, None, :] + world[todo], nrm[todo])
        achieved[todo] = depth.max(axis=1)
        bad = ~(np.abs(achieved[todo] - burial[todo]) < 1e-9 * size[todo])  # NaN is bad
        if not bad.any():
            break
        todo, depth = todo[bad], depth[bad]
        if attempt == 4:  # not settled: bisect, then measure once more
            sub = centre[todo]
            _bisect(depths, sub, world[todo], nrm[todo], burial[todo], size[todo])
            centre[todo] = sub
            achieved[todo] = depths(centre[todo, None, :] + world[todo],
                                    nrm[todo]).max(axis=1)
            break
        idx = np.sort(np.argpartition(-np.nan_to_num(depth, nan=-np.inf), kc - 1,
                                      axis=1)[:, :kc], axis=1)
        sub = centre[todo]
        _converge(depths, sub, np.take_along_axis(world[todo], idx[:, :, None], axis=1),
                  nrm[todo], burial[todo], size[todo], max_iterations)
        centre[todo] = sub
    return centre, achieved, extent, burial


def placed_columns(cat, centre, nrm, rot, height, burial, achieved, shape) -> dict:
    """The columns a placement adds to a boulder catalog (see ``place_boulders``)."""
    quat = quaternions(rot)
    cols = {name: cat[name] for name in cat.dtype.names}
    cols.update(centre_x_m=centre[:, 0], centre_y_m=centre[:, 1], centre_z_m=centre[:, 2],
                normal_x=nrm[:, 0], normal_y=nrm[:, 1], normal_z=nrm[:, 2],
                quat_w=quat[:, 0], quat_x=quat[:, 1], quat_y=quat[:, 2], quat_z=quat[:, 3],
                height_m=height, burial_m=burial, bottom_depth_m=achieved)
    # the shape parameters travel with every boulder: a catalog regenerates its meshes
    for field in dataclasses.fields(BoulderShape):
        cols[f"shape_{field.name}"] = np.full(len(cat), float(getattr(shape, field.name)))
    return cols
