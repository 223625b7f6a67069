"""The shared ray engine: Embree (through ``embreex``) for the search, float64 refinement.

A :class:`RayMesh` is built once per model and shared by every frame. Embree finds the
first triangle along each ray in single precision; the hit distance and barycentrics are
then recomputed in double precision against that exact triangle (Möller & Trumbore 1997,
"Fast, minimum storage ray-triangle intersection", J. Graphics Tools 2(1)), so ranges are
exact far below a millimetre even when float32 geometry is not. Rays are independent, so
the results do not depend on the thread count.

(Minimal version written by the LIDAR helper so that its code runs; the camera helper's
version of this module replaces it at merge.)
"""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass

import numpy as np
from numba import njit, prange

__all__ = ["Hits", "RayMesh"]

_CHUNK = 1 << 16  # rays per Embree call (fixed: results do not depend on the threads)


@dataclass(frozen=True, slots=True)
class Hits:
    """The first hit of each ray."""

    t_m: np.ndarray
    """(k,) float64 distance along the ray (metres for unit directions); inf on a miss."""
    face: np.ndarray
    """(k,) int64 index of the triangle hit; -1 on a miss."""
    u: np.ndarray
    """(k,) float64 barycentric weight of the triangle's second vertex (0 on a miss)."""
    v: np.ndarray
    """(k,) float64 barycentric weight of the triangle's third vertex (0 on a miss)."""


@njit(cache=True, parallel=True)
def _refine_kernel(vertices, faces, origins, directions, face, t, u, v):
    """Möller–Trumbore in float64 against the triangle Embree found (its plane: the hit
    is kept even when rounding puts it a hair outside the triangle)."""
    for i in prange(face.shape[0]):
        f = face[i]
        if f < 0:
            continue
        a = faces[f, 0]
        b = faces[f, 1]
        c = faces[f, 2]
        e1x = vertices[b, 0] - vertices[a, 0]
        e1y = vertices[b, 1] - vertices[a, 1]
        e1z = vertices[b, 2] - vertices[a, 2]
        e2x = vertices[c, 0] - vertices[a, 0]
        e2y = vertices[c, 1] - vertices[a, 1]
        e2z = vertices[c, 2] - vertices[a, 2]
        dx, dy, dz = directions[i, 0], directions[i, 1], directions[i, 2]
        px = dy * e2z - dz * e2y
        py = dz * e2x - dx * e2z
        pz = dx * e2y - dy * e2x
        det = e1x * px + e1y * py + e1z * pz
        if det == 0.0:
            continue
        inv = 1.0 / det
        sx = origins[i, 0] - vertices[a, 0]
        sy = origins[i, 1] - vertices[a, 1]
        sz = origins[i, 2] - vertices[a, 2]
        qx = sy * e1z - sz * e1y
        qy = sz * e1x - sx * e1z
        qz = sx * e1y - sy * e1x
        u[i] = (sx * px + sy * py + sz * pz) * inv
        v[i] = (dx * qx + dy * qy + dz * qz) * inv
        t[i] = (e2x * qx + e2y * qy + e2z * qz) * inv


@njit(cache=True, parallel=True)
def _face_normals_kernel(vertices, faces, out):
    """Unit normals (right-hand rule over the corners) of every triangle; 0 if degenerate."""
    for f in prange(faces.shape[0]):
        a, b, c = faces[f, 0], faces[f, 1], faces[f, 2]
        ux = vertices[b, 0] - vertices[a, 0]
        uy = vertices[b, 1] - vertices[a, 1]
        uz = vertices[b, 2] - vertices[a, 2]
        vx = vertices[c, 0] - vertices[a, 0]
        vy = vertices[c, 1] - vertices[a, 1]
        vz = vertices[c, 2] - vertices[a, 2]
        nx = uy * vz - uz * vy
        ny = uz * vx - ux * vz
        nz = ux * vy - uy * vx
        norm = np.sqrt(nx * nx + ny * ny + nz * nz)
        if norm > 0:
            out[f, 0], out[f, 1], out[f, 2] = nx / norm, ny / norm, nz / norm
        else:
            out[f, 0], out[f, 1], out[f, 2] = 0.0, 0.0, 0.0


class RayMesh:
    """A triangle mesh ready for ray queries (the Embree BVH is built once, here).

    Parameters
    ----------
    vertices : (n, 3) array_like
        Positions in metres (kept in float64 for the refinement).
    faces : (m, 3) array_like of int
        Vertex indices of each triangle.
    """

    def __init__(self, vertices, faces):
        from embreex import mesh_construction, rtcore, rtcore_scene

        self.vertices = np.ascontiguousarray(vertices, dtype=np.float64)
        self.faces = np.ascontiguousarray(faces, dtype=np.int64)
        if self.vertices.ndim != 2 or self.vertices.shape[1] != 3 or not len(self.vertices):
            raise ValueError(f"`vertices` must be a non-empty (n, 3) array; got shape "
                             f"{self.vertices.shape}")
        if self.faces.ndim != 2 or self.faces.shape[1] != 3 or not len(self.faces):
            raise ValueError(f"`faces` must be a non-empty (m, 3) array; got shape "
                             f"{self.faces.shape}")
        if self.faces.min() < 0 or self.faces.max() >= len(self.vertices):
            raise ValueError("`faces` index vertices that do not exist")
        self.face_normals = np.empty((len(self.faces), 3))
        _face_normals_kernel(self.vertices, self.faces, self.face_normals)
        self._device = rtcore.EmbreeDevice()
        self._scene = rtcore_scene.EmbreeScene(self._device)
        mesh_construction.TriangleMesh(self._scene, self.vertices.astype(np.float32),
                                       self.faces.astype(np.int32))
        # Embree builds the BVH at the first query: build it here, once
        self._scene.run(np.zeros((1, 3), np.float32), np.ones((1, 3), np.float32))

    def _rays(self, origins, directions):
        o = np.ascontiguousarray(origins, dtype=np.float64).reshape(-1, 3)
        d = np.ascontiguousarray(directions, dtype=np.float64).reshape(-1, 3)
        if o.shape != d.shape:
            raise ValueError(f"`origins` and `directions` must have the same shape; got "
                             f"{o.shape} and {d.shape}")
        return o, d

    def _run(self, o, d, t_max, query):
        k = len(o)
        tm = np.broadcast_to(np.asarray(t_max, dtype=np.float64), (k,))
        tm32 = np.minimum(tm, np.finfo(np.float32).max).astype(np.float32)
        o32, d32 = o.astype(np.float32), d.astype(np.float32)

        def call(s):
            e = min(s + _CHUNK, k)
            if query == "OCCLUDED":
                return self._scene.run(o32[s:e], d32[s:e], dists=tm32[s:e].copy(),
                                       query="OCCLUDED")
            return self._scene.run(o32[s:e], d32[s:e], dists=tm32[s:e].copy(), output=1)

        starts = range(0, k, _CHUNK)
        if k > _CHUNK:
            with ThreadPoolExecutor(2) as pool:
                return list(pool.map(call, starts))
        return [call(s) for s in starts]

    def intersect(self, origins, directions, t_max=np.inf) -> Hits:
        """The first hit of each ray ``origins + t directions``, 0 < t <= ``t_max``."""
        o, d = self._rays(origins, directions)
        k = len(o)
        face = np.full(k, -1, dtype=np.int64)
        if k:
            parts = self._run(o, d, t_max, "INTERSECT")
            face[:] = np.concatenate([p["primID"] for p in parts])
            face[np.concatenate([p["geomID"] for p in parts]) < 0] = -1
        t = np.full(k, np.inf)
        u = np.zeros(k)
        v = np.zeros(k)
        _refine_kernel(self.vertices, self.faces, o, d, face, t, u, v)
        tm = np.broadcast_to(np.asarray(t_max, dtype=np.float64), (k,))
        lost = (face >= 0) & ((t <= 0) | (t > tm))  # the float32 search's edge cases
        if lost.any():
            face[lost], t[lost], u[lost], v[lost] = -1, np.inf, 0.0, 0.0
        return Hits(t, face, u, v)

    def occluded(self, origins, directions, t_max) -> np.ndarray:
        """(k,) bool: does anything lie along each ray before ``t_max``? (shadow rays)"""
        o, d = self._rays(origins, directions)
        if not len(o):
            return np.zeros(0, dtype=bool)
        return np.concatenate(self._run(o, d, t_max, "OCCLUDED")) != -1
