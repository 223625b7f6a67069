"""Boulder populations and placement helpers (Martin 2014, V.C).

Populations follow N_cum = c D^k (D in metres, N per m^2; boulder exponents of Bennu and
Itokawa are about -2.5 to -3.5); burial is a uniform fraction of the boulder's height.
Placing boulders on a body is ``latlong.boulders``, on a DEM ``dem.boulders``: both use
:func:`orientations`, :func:`rest_on_ground` and :func:`placed_columns`.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from .._shared import check_finite, check_positive, check_range, parse_spec
from ..population import sample_power_law_diameters
from .meshes import BoulderShape

__all__ = ["MIN_BURIAL", "BoulderLayer", "draw_boulder_layer", "near_crater_draws", "orientations",
           "parse_boulder_spec", "placed_columns", "quaternions", "rest_on_ground"]


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


_SPEC = {"c": float, "k": float, "d_min_m": float, "d_max_m": float, "burial_max": float,
         "near": float}
_OLD_KEYS = {"dmin": "d_min_m", "dmax": "d_max_m", "burial": "burial_max"}


def parse_boulder_spec(spec: str) -> BoulderLayer:
    """Parse ``c=0.05,k=-3,d_min_m=0.5,d_max_m=10[,burial_max=0.5,near=0.3]``: the fields
    of :class:`BoulderLayer` (metres).

    Examples
    --------
    >>> parse_boulder_spec("c=0.05,k=-3,d_min_m=0.5,d_max_m=10").d_max_m
    10.0
    """
    values = parse_spec(str(spec), _SPEC, ("c", "k", "d_min_m", "d_max_m"), "boulder layer",
                        renamed=_OLD_KEYS)
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
                         "(limit 2e7); raise d_min_m or lower c")
    n = int(rng.poisson(mean)) if mean > 0 else 0
    d = sample_power_law_diameters(n, layer.d_min_m, layer.d_max_m, -layer.k, rng=rng)
    return {"diameter_m": d, "kind": np.full(n, "boulder"),
            "burial_frac": np.maximum(rng.uniform(0.0, layer.burial_max, n), MIN_BURIAL),
            "azimuth_deg": rng.uniform(0.0, 360.0, n),
            "seed": rng.integers(0, 2**63, n, dtype=np.uint64), "layer": np.full(n, index)}


#: Lowest vertices (along the normal) tested first for a boulder's deepest point.
_CANDIDATES = 64


def near_crater_draws(diameter_m, n_near: int, rng) -> tuple[np.ndarray, np.ndarray,
                                                             np.ndarray]:
    """Where ``n_near`` boulders thrown out by craters of ``diameter_m`` lie: for each a
    crater row picked with weight D^2, a distance from its centre in [1, 2] crater radii
    (metres) and an azimuth in [0, 2 pi) (radians), drawn from the Generator ``rng`` in
    that order (the same draws on every kind of body)."""
    diameter_m = np.asarray(diameter_m)
    weights = diameter_m ** 2
    pick = rng.choice(len(diameter_m), n_near, p=weights / weights.sum())
    r = 0.5 * diameter_m[pick] * rng.uniform(1.0, 2.0, n_near)
    return pick, r, rng.uniform(0.0, 2.0 * np.pi, n_near)


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
    # the product written out (a matmul goes to OpenBLAS, whose kernel, and so whose last
    # bits, depend on the CPU: craters.exact)
    return (frame[:, :, 0:1] * turn[:, 0:1, :] + frame[:, :, 1:2] * turn[:, 1:2, :]
            + frame[:, :, 2:3] * turn[:, 2:3, :])


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
