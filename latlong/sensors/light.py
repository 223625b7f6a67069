"""The light a frame's points receive (:mod:`.render`'s module notes): the sun and its
cast shadows, light bounced between surfaces, planetshine. Each shading function takes
a list of reflectance models, one per band of the camera, and returns one column per
band; the rays (shadows, bounces) are cast once and shared by the bands.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from craters._shared import ParameterError, check_range

from .camera import unit_direction
from .engine import RayMesh
from .photometry import radiance_factor
from .planetshine import Planet

__all__ = ["PLANET_STREAM", "SHADOW_OFFSET", "SUN_RADIUS_1AU_DEG", "Sun", "filter_bounced",
           "indirect", "planet_light", "shade", "sunlit", "vertex_albedo_at"]

#: Angular radius of the sun seen from 1 au, degrees (696 000 km / 1 au).
SUN_RADIUS_1AU_DEG = math.degrees(math.asin(6.957e8 / 1.495978707e11))
#: Shadow rays start this fraction of the point's distance from the model's centre (the
#: centre of its bounding box, where the engine's float32 frame is) above the surface, at
#: least 1e-3 of that times the bounding radius: a 700 km DEM mesh lifts points near its
#: centre by millimetres, not by 2e-6 of its radius (1.4 m, shortening low-sun shadows).
SHADOW_OFFSET = 2e-6
#: The counter streams of the samples over the planet's disk (the sun's: 1 + sample).
PLANET_STREAM = 1 << 36


@dataclass(frozen=True, slots=True)
class Sun:
    """The light: a direction towards the sun and its angular size."""

    direction: np.ndarray
    """(3,) unit vector from the surface towards the sun, body frame (normalised; a zero
    vector is an error)."""
    angular_radius_deg: float = 0.0
    """Angular radius of the solar disk, degrees (0: a point; 0.2666 at 1 au), [0, 5]."""

    def __post_init__(self):
        d = unit_direction("sun_direction", self.direction)
        object.__setattr__(self, "direction", d)
        object.__setattr__(self, "angular_radius_deg", check_range(
            "angular_radius_deg", self.angular_radius_deg, 0.0, 5.0))

    @classmethod
    def at_distance(cls, direction, distance_au: float) -> Sun:
        """The sun seen from ``distance_au`` au (its angular radius from its size)."""
        d = check_range("distance_au", distance_au, 0.01, 1000.0)
        return cls(direction, math.degrees(math.asin(6.957e8 / (d * 1.495978707e11))))


def vertex_albedo_at(mesh: RayMesh, vertex_albedo, hits) -> np.ndarray:
    """The per-vertex albedo factor blended at each hit (1 without one, 0 on a miss)."""
    if vertex_albedo is None:
        return np.ones(len(hits.face))
    a = np.asarray(vertex_albedo, dtype=np.float64)
    if a.shape != (len(mesh.vertices),) or not np.isfinite(a).all() or (a < 0).any():
        raise ParameterError("vertex_albedo", f"must be {len(mesh.vertices)} finite factors "
                             ">= 0, one per vertex")
    out = np.zeros(len(hits.face))
    ok = hits.hit
    tri = mesh.faces[hits.face[ok]]
    u, v = hits.u[ok], hits.v[ok]
    out[ok] = (1 - u - v) * a[tri[:, 0]] + u * a[tri[:, 1]] + v * a[tri[:, 2]]
    return out


def sunlit(mesh, pos, ng, facing, sun: Sun | Planet, samples: int, seed: int,
           stream: int = 0) -> np.ndarray:
    """Lit fraction per hit: facet faces the light and the shadow ray is free (samples
    over the light's disk from the counter streams ``stream`` + sample)."""
    from ._render_kernels import _shadow_rays_kernel  # numba loads here
    lit = np.zeros(len(pos))
    cand = np.flatnonzero(facing)
    if not len(cand):
        return lit
    centre, radius_m = mesh.bounding_sphere  # the engine's float32 frame is centred here
    floor = 1e-3 * SHADOW_OFFSET * radius_m
    radius = math.radians(sun.angular_radius_deg) if samples else 0.0
    p, n = np.ascontiguousarray(pos[cand]), np.ascontiguousarray(ng[cand])
    o, d = np.empty_like(p), np.empty_like(p)
    face_ok = np.empty(len(cand), dtype=np.bool_)
    total = np.zeros(len(cand))
    for k in range(max(samples, 1)):
        _shadow_rays_kernel(p, n, SHADOW_OFFSET, centre, floor, sun.direction, radius, seed,
                            stream + k, o, d, face_ok)
        free = face_ok & ~mesh.occluded(o, d, np.inf)
        total += free
    lit[cand] = total / max(samples, 1)
    return lit


def shade(models, cosines, lit, albedo) -> np.ndarray:
    """(n, bands) I/F: each model at the cosines x lit fraction x albedo factor."""
    from ._render_kernels import _shade_kernel  # numba loads here
    out = np.empty((len(cosines), len(models)))
    column = np.empty(len(cosines))
    for b, model in enumerate(models):
        _shade_kernel(model.code, model.vector(), cosines, lit, albedo, column)
        out[:, b] = column
    return out


def indirect(mesh: RayMesh, models, pos, ng, ns, albedo, vertex_albedo, sun: Sun,
             samples: int, seed: int, bounces: int = 1, smooth=None,
             sunlit_full=None) -> np.ndarray:
    """Bounced light (:mod:`.render`'s notes): (n, bands) I/F added at each point ``pos``
    (n, 3) by the sunlit surface it sees (``samples`` cosine-weighted rays a point) and,
    with ``bounces`` 2, by the light that surface received once from the rest (one ray
    on from each hit). ``smooth`` (optional) maps the light received, (n, bands) as a
    white Lambertian surface would send it back, and the rays a point's estimate averages
    (n,) to a smoothed estimate (:func:`filter_bounced`) before each point's albedo
    multiplies it; with it, the points ``sunlit_full`` marks (n,) trace a quarter of the
    rays (their bounced light is a few per cent of their direct light: its noise, smoothed,
    is not seen), the others all."""
    from ._bounce_kernels import SECOND_BOUNCE, _bounce_rays_kernel  # numba loads here
    centre, radius_m = mesh.bounding_sphere
    floor = 1e-3 * SHADOW_OFFSET * radius_m
    n = len(pos)
    rays = np.full(n, samples, dtype=np.int64)
    if smooth is not None and sunlit_full is not None:
        rays[np.asarray(sunlit_full, dtype=np.bool_)] = max(1, samples // 4)
    total = np.zeros((n, len(models)))
    # the receiving points as Lambertian surfaces of each model's normal albedo
    normal_albedo = [float(radiance_factor(m, 1.0, 1.0, 1.0)[0]) for m in models]
    active = np.arange(n)
    p, g, h = (np.ascontiguousarray(a) for a in (pos, ng, ns))
    o, d = np.empty((n, 3)), np.empty((n, 3))
    above = np.empty(n, dtype=np.bool_)
    fewest = int(rays.min()) if n else samples
    for k in range(samples):
        if k == fewest:  # the sunlit points have traced theirs: the others go on
            active = np.flatnonzero(rays > k)
            p, g, h = (np.ascontiguousarray(a[active]) for a in (pos, ng, ns))
            o, d, above = o[:len(active)], d[:len(active)], above[:len(active)]
        _bounce_rays_kernel(p, g, h, active, SHADOW_OFFSET, centre, floor, seed, k, o, d,
                            above)
        face, q, nq, facing, hits = _secondary_hits(mesh, o, d, above, sun)
        light, va = _seen_light(mesh, models, d, face, q, nq, facing, hits, vertex_albedo,
                                sun, seed)
        total[active] += light
        if bounces < 2:
            continue
        front = np.flatnonzero((face >= 0) & (np.einsum("ij,ij->i", nq, d) < 0.0))
        if not len(front):
            continue
        # one ray on from each front-facing hit: its own once-bounced light, received as
        # a Lambertian surface of its albedo (the second counter stream of the sample)
        q2, n2 = np.ascontiguousarray(q[front]), np.ascontiguousarray(nq[front])
        o2, d2 = np.empty_like(q2), np.empty_like(q2)
        above2 = np.empty(len(front), dtype=np.bool_)
        _bounce_rays_kernel(q2, n2, n2, np.arange(len(front)), SHADOW_OFFSET, centre, floor,
                            seed, SECOND_BOUNCE + k, o2, d2, above2)
        face2, r2, nr2, facing2, hits2 = _secondary_hits(mesh, o2, d2, above2, sun)
        light2, _ = _seen_light(mesh, models, d2, face2, r2, nr2, facing2, hits2,
                                vertex_albedo, sun, seed)
        for b in range(len(models)):
            total[active[front], b] += normal_albedo[b] * va[front] * light2[:, b]
    out = np.empty_like(total)
    if smooth is not None:
        received = smooth(total / rays[:, None], rays)
        for b in range(len(models)):
            out[:, b] = normal_albedo[b] * albedo * received[:, b]
        return out
    for b in range(len(models)):
        out[:, b] = normal_albedo[b] * albedo * total[:, b] / samples
    return out


def filter_bounced(received: np.ndarray, seen: np.ndarray, pos: np.ndarray, ns: np.ndarray,
                   radius_px: int, rays=None) -> np.ndarray:
    """The bounced light ``received`` by the seen pixels, (n_seen, bands), smoothed across
    the image (h, w) = ``seen.shape`` over about ``radius_px`` pixels on the same surface:
    an edge-avoiding a-trous filter (Dammertz et al. 2010; passes of 5 x 5 taps 1, 2, 4
    ... px apart, :func:`~._bounce_kernels.atrous_steps`: a Gaussian of sigma ~radius / 2
    in 75 taps a pixel at 8 px instead of 289) whose weights keep to one surface (a
    neighbour counts less the more its shading normal turns away, ``ns`` (h, w, 3), and
    the farther it lies off the point's tangent plane, ``pos`` (h, w, 3): a crater rim
    in front of a floor is not averaged into it) and count each estimate by its ``rays``
    ((n_seen,): the rays it averages; all 1 by default). Light bounced from the
    surroundings changes over metres, not from pixel to pixel, while the Monte Carlo
    noise of a few rays a pixel does: the mean over ~radius^2 pixels removes most of it.
    The direct light and its shadow edges are not touched."""
    from ._bounce_kernels import B3_TAPS, _atrous_pass_kernel, atrous_steps  # numba loads
    h, w = seen.shape
    nb = received.shape[1]
    flat = seen.ravel()
    weight = np.ones(len(received)) if rays is None else np.asarray(rays, dtype=np.float64)
    num = np.zeros((h * w, nb))
    num[flat] = received * weight[:, None]
    den = np.ones(h * w)
    den[flat] = weight
    num, den = num.reshape(h, w, nb), den.reshape(h, w)
    seen_c = np.ascontiguousarray(seen)
    p = np.ascontiguousarray(pos, dtype=np.float64)
    n = np.ascontiguousarray(ns, dtype=np.float64)
    out_num, out_den = np.empty_like(num), np.empty_like(den)
    for step in atrous_steps(int(radius_px)):
        _atrous_pass_kernel(num, den, seen_c, p, n, B3_TAPS, step, out_num, out_den)
        num, out_num = out_num, num
        den, out_den = out_den, den
    return (num / den[..., None]).reshape(h * w, nb)[flat]


def _secondary_hits(mesh: RayMesh, o, d, above, sun: Sun):
    """(face or -1, hit points, their facet normals (0 on a miss), facets facing the sun,
    hits) of rays that leave their facet (``above``)."""
    from ._bounce_kernels import _secondary_kernel  # numba loads here
    hits = mesh.intersect(o, d)
    n = len(hits.face)
    face, facing = np.empty(n, dtype=np.int64), np.empty(n, dtype=np.bool_)
    q, nq = np.empty((n, 3)), np.empty((n, 3))
    _secondary_kernel(np.ascontiguousarray(o, dtype=np.float64),
                      np.ascontiguousarray(d, dtype=np.float64), hits.t_m, hits.face,
                      np.ascontiguousarray(above), mesh.face_normals, sun.direction, face, q,
                      nq, facing)
    return face, q, nq, facing, hits


def _seen_light(mesh: RayMesh, models, d, face, q, nq, facing, hits, vertex_albedo,
                sun: Sun, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """((n, bands) direct I/F of each secondary hit seen back along its ray (0 for a
    miss), (n,) the albedo factor at the hits)."""
    from ._bounce_kernels import _bounce_light_kernel  # numba loads here
    lit = sunlit(mesh, q, nq, facing, sun, 0, seed)
    va = vertex_albedo_at(mesh, vertex_albedo, hits)
    out = np.empty((len(face), len(models)))
    light = np.empty(len(face))
    for b, model in enumerate(models):
        _bounce_light_kernel(model.code, model.vector(), d, face, mesh.face_normals, va,
                             sun.direction, lit, light)
        out[:, b] = light
    return out, va


def planet_light(mesh: RayMesh, models, origin, dirs, hits, vnormals, planet: Planet,
                 sun: Sun, albedo, samples: int, seed: int) -> np.ndarray:
    """(n, bands) I/F the planet's light adds at each pixel (:mod:`.planetshine`): each
    model lit from the planet, its cast shadows, times its irradiance ratio."""
    from ._render_kernels import _surface_kernel  # numba loads here
    n = len(hits.face)
    pos, ng, ns, cosines = (np.empty((n, 3)) for _ in range(4))
    facing = np.empty(n, dtype=np.bool_)
    smooth = vnormals is not None
    _surface_kernel(origin, dirs, hits.t_m, hits.face, hits.u, hits.v, mesh.vertices,
                    mesh.faces, vnormals if smooth else np.zeros((1, 3)), smooth,
                    planet.direction, pos, ng, ns, cosines, facing)
    lit = sunlit(mesh, pos, ng, facing, planet, samples, seed, PLANET_STREAM)
    return planet.irradiance_ratio(sun.direction) * shade(models, cosines, lit, albedo)
