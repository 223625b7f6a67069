"""The ray engine shared by the camera and the LIDAR: Embree (Intel's BVH ray tracer,
Wald et al. 2014, "Embree: a kernel framework for efficient CPU ray tracing", ACM TOG
33(4)) from the ``embreex`` wheel, every hit refined in float64.

:class:`RayMesh` is built once per model (the BVH) and shared by all frames:

* Embree holds float32 geometry, shifted to the centre of the model's bounding box (a
  DEM mesh in projected metres keeps its precision); each ray starts, in float32, just
  before the model's bounding sphere (a camera 1000 km away loses nothing).
* The face Embree reports is intersected again in float64 with the caller's exact ray
  and vertices (Möller & Trumbore 1997, "Fast, minimum storage ray-triangle
  intersection", J. Graphics Tools 2(1)): ranges are those of the float64 mesh to
  ~1e-12 relative, not float32's ~1e-7.
* Embree is called from numba's parallel loops through ``ctypes`` pointers into the
  library that ``embreex`` ships (its own Python binding copies the mesh element by
  element in Python: 8.5 s for 6 M vertices, and traces on one thread). Every ray's
  answer depends on that ray alone: same bytes for any thread count.

Examples
--------
>>> import numpy as np
>>> from latlong.sensors.engine import RayMesh
>>> tet = RayMesh([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]],
...               [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
>>> hits = tet.intersect([[0.2, 0.2, 5.0]], [[0, 0, -1]])
>>> float(hits.t_m[0]), int(hits.face[0])
(4.4, 3)
>>> tet.occluded([[0.2, 0.2, 5.0], [5, 5, 5]], [[0, 0, -1], [0, 0, 1]], 10.0).tolist()
[True, False]
"""

from __future__ import annotations

import ctypes
import ctypes.util
import functools
import glob
import os
from dataclasses import dataclass

import numpy as np

from craters._shared import ParameterError, ParameterTypeError

from ..geometry.meshes import bounds
from ..geometry.normals import triangle_normals
from ..geometry.normals import vertex_normals as weighted_vertex_normals

__all__ = ["BUILD_QUALITIES", "Hits", "RayMesh"]

#: Embree's BVH build qualities (``RTC_BUILD_QUALITY_*``): low = Morton (fastest build),
#: medium = binned SAH (Embree's default; faster rays), high = SAH with spatial splits.
BUILD_QUALITIES = {"low": 0, "medium": 1, "high": 2}
_SCENE_FLAG_ROBUST = 1 << 2  # conservative traversal: no rays leak between triangles
# a compact BVH: 12 M triangles built in 2.8-3.5 s instead of 7.0-10.6 s on this machine
# (less memory to fault in: peak 1.87 GB instead of 2.24 GB), frames ~20 % slower to trace
_SCENE_FLAG_COMPACT = 1 << 1
_GEOMETRY_TRIANGLE = 0
_BUFFER_INDEX, _BUFFER_VERTEX = 0, 1
_FORMAT_UINT3, _FORMAT_FLOAT3 = 0x5003, 0x9003
# the outputs a query does not write (_trace_kernel: closest hits or shadow rays)
_NO_FLOAT, _NO_INT, _NO_BOOL = np.empty(0), np.empty(0, dtype=np.int64), np.empty(0, np.bool_)


@dataclass(frozen=True, slots=True)
class Hits:
    """What each ray of :meth:`RayMesh.intersect` hit first."""

    t_m: np.ndarray
    """(k,) float64 distance along the unit direction, metres; inf on a miss."""
    face: np.ndarray
    """(k,) int64 index of the face hit; -1 on a miss."""
    u: np.ndarray
    """(k,) float64 barycentric weight of the face's second vertex (0 on a miss)."""
    v: np.ndarray
    """(k,) float64 barycentric weight of the face's third vertex; the hit point is
    (1 - u - v) a + u b + v c."""

    @property
    def hit(self) -> np.ndarray:
        """(k,) bool: the ray hit something."""
        return self.face >= 0

    def points(self, origins, directions) -> np.ndarray:
        """(k, 3) hit points o + t d (NaN on a miss) for the rays that were cast."""
        o, d = _rays(origins, directions)
        with np.errstate(invalid="ignore"):
            p = o + self.t_m[:, None] * d
        p[~self.hit] = np.nan
        return p


@functools.cache
def _embree():
    """The Embree 4 shared library of the ``embreex`` wheel, with ctypes signatures."""
    try:
        import embreex
    except ImportError:  # pragma: no cover - a dependency
        raise ImportError("the ray engine needs `embreex` (pip install embreex)") from None
    import embreex.rtcore  # noqa: F401 - loads the library into the process

    pkg = os.path.dirname(embreex.__file__)
    site = os.path.dirname(pkg)
    patterns = [os.path.join(site, "embreex.libs", "libembree4*.so*"),
                os.path.join(pkg, ".dylibs", "libembree4*.dylib"),
                os.path.join(site, "embreex.libs", "embree4*.dll"),
                os.path.join(pkg, "*embree4*")]
    found = sorted(p for pat in patterns for p in glob.glob(pat))
    if not found and ctypes.util.find_library("embree4"):
        found = [ctypes.util.find_library("embree4")]
    if not found:  # pragma: no cover - depends on the wheel's layout
        raise ImportError(f"cannot find the Embree 4 library of embreex under {site}")
    lib = ctypes.CDLL(found[0])
    vp, c_int, c_uint, c_size = ctypes.c_void_p, ctypes.c_int, ctypes.c_uint, ctypes.c_size_t
    sigs = {"rtcNewDevice": (vp, [ctypes.c_char_p]), "rtcReleaseDevice": (None, [vp]),
            "rtcGetDeviceError": (c_int, [vp]), "rtcNewScene": (vp, [vp]),
            "rtcReleaseScene": (None, [vp]), "rtcSetSceneFlags": (None, [vp, c_int]),
            "rtcSetSceneBuildQuality": (None, [vp, c_int]),
            "rtcNewGeometry": (vp, [vp, c_int]),
            "rtcSetSharedGeometryBuffer": (None, [vp, c_int, c_uint, c_int, vp, c_size,
                                                  c_size, c_size]),
            "rtcSetGeometryBuildQuality": (None, [vp, c_int]),
            "rtcCommitGeometry": (None, [vp]), "rtcAttachGeometry": (c_uint, [vp, vp]),
            "rtcReleaseGeometry": (None, [vp]), "rtcCommitScene": (None, [vp])}
    for name, (res, args) in sigs.items():
        fn = getattr(lib, name)
        fn.restype, fn.argtypes = res, args
    # rtcIntersect8(valid, scene, rayhit, args), rtcOccluded8(valid, scene, ray, args)
    query = ctypes.CFUNCTYPE(None, vp, vp, vp, vp)
    return lib, query(("rtcIntersect8", lib)), query(("rtcOccluded8", lib))


def _rays(origins, directions) -> tuple[np.ndarray, np.ndarray]:
    """Float64 origins ((1, 3) when one origin serves all rays, else (k, 3)) and unit
    directions (k, 3)."""
    from ._engine_kernels import _unit_kernel  # numba loads here
    d = np.ascontiguousarray(directions, dtype=np.float64)
    o = np.ascontiguousarray(origins, dtype=np.float64)
    if d.ndim != 2 or d.shape[1] != 3:
        raise ParameterError("directions", f"must be (k, 3); got shape {d.shape}")
    if o.shape == (3,):
        o = o.reshape(1, 3)
    if o.shape != d.shape and o.shape != (1, 3):
        raise ParameterError("origins", f"must be (k, 3) like `directions` {d.shape} or one "
                             f"(3,) origin; got shape {o.shape}")
    if not np.isfinite(o).all():
        raise ParameterError("origins", "must be finite")
    unit = np.empty_like(d)
    bad = _unit_kernel(d, unit)
    if bad >= 0:
        raise ParameterError("directions", f"must be finite and non-zero; ray {bad} is "
                             f"{d[bad].tolist()}")
    return o, unit


def _limits(name: str, value, k: int) -> np.ndarray:
    arr = np.asarray(value, dtype=np.float64)
    if arr.ndim == 0:
        arr = np.full(k, float(arr))
    if arr.shape != (k,):
        raise ParameterError(name, f"must be a number or a (k,) array, k = {k}; got shape "
                             f"{arr.shape}")
    if np.isnan(arr).any() or (arr < 0).any():
        raise ParameterError(name, "must be >= 0 (inf allowed)")
    return np.ascontiguousarray(arr)


class RayMesh:
    """A triangle mesh with its Embree BVH, ready for ray queries (module notes).

    Parameters
    ----------
    vertices : (n, 3) float
        Positions, metres (kept in float64 for the exact refinement).
    faces : (m, 3) int
        Vertex indices per triangle (any orientation; both sides are hit).
    build_quality : {"medium", "low", "high"}
        Embree's BVH build quality (:data:`BUILD_QUALITIES`).
    """

    def __init__(self, vertices, faces, *, build_quality: str = "medium"):
        from ._engine_kernels import _shift_kernel  # numba loads here
        v = np.ascontiguousarray(vertices, dtype=np.float64)
        f = np.asarray(faces)
        if v.ndim != 2 or v.shape[1] != 3 or not len(v):
            raise ParameterError("vertices", f"must be (n, 3) with n >= 1; got shape {v.shape}")
        if not np.isfinite(v).all():
            raise ParameterError("vertices", "must be finite")
        if f.ndim != 2 or f.shape[1] != 3 or not len(f):
            raise ParameterError("faces", f"must be (m, 3) with m >= 1; got shape {f.shape}")
        if not np.issubdtype(f.dtype, np.integer):
            raise ParameterTypeError("faces", f"must be integers; got {f.dtype}")
        if len(v) >= 2**32 - 1 or len(f) >= 2**32 - 1:
            raise ParameterError("vertices", "at most 2**32 - 2 vertices and faces")
        if f.min() < 0 or f.max() >= len(v):
            raise ParameterError("faces", f"indices must be in [0, {len(v) - 1}]")
        if build_quality not in BUILD_QUALITIES:
            raise ParameterError("build_quality", f"must be one of {sorted(BUILD_QUALITIES)}; "
                                 f"got {build_quality!r}")
        lo, hi = bounds(v)
        centre = 0.5 * (lo + hi)
        self._vertices = v
        self._vertices.flags.writeable = False
        self._index = np.ascontiguousarray(f, dtype=np.uint32)  # Embree's index buffer
        self._index.flags.writeable = False
        self._centre = centre
        self._face_normals: np.ndarray | None = None
        self._vertex_normals: np.ndarray | None = None
        lib, self._intersect8, self._occluded8 = _embree()
        self._lib = lib
        self._device = self._scene = None
        self._device = lib.rtcNewDevice(None)
        if not self._device:  # pragma: no cover
            raise MemoryError("Embree could not create a device")
        quality = BUILD_QUALITIES[build_quality]
        # float32 vertices relative to the centre; one padding row: Embree reads the last
        # vertex with a 16-byte load
        self._vbuf = np.zeros((len(v) + 1, 3), dtype=np.float32)
        r2 = _shift_kernel(v, centre, self._vbuf)
        # bounding sphere of the float32 geometry, with room for its rounding
        self._radius = float(np.sqrt(r2)) * (1 + 1e-5) + 1e-6
        scene = lib.rtcNewScene(self._device)
        self._scene = scene
        lib.rtcSetSceneFlags(scene, _SCENE_FLAG_ROBUST | _SCENE_FLAG_COMPACT)
        lib.rtcSetSceneBuildQuality(scene, quality)
        geom = lib.rtcNewGeometry(self._device, _GEOMETRY_TRIANGLE)
        lib.rtcSetSharedGeometryBuffer(geom, _BUFFER_VERTEX, 0, _FORMAT_FLOAT3,
                                       self._vbuf.ctypes.data, 0, 12, len(v))
        lib.rtcSetSharedGeometryBuffer(geom, _BUFFER_INDEX, 0, _FORMAT_UINT3,
                                       self._index.ctypes.data, 0, 12, len(f))
        lib.rtcSetGeometryBuildQuality(geom, quality)
        lib.rtcCommitGeometry(geom)
        lib.rtcAttachGeometry(scene, geom)
        lib.rtcReleaseGeometry(geom)
        lib.rtcCommitScene(scene)
        err = lib.rtcGetDeviceError(self._device)
        if err:
            self._release()
            if err == 3:  # RTC_ERROR_OUT_OF_MEMORY
                raise MemoryError(f"Embree ran out of memory building the BVH of {len(f)} "
                                  "triangles")
            raise RuntimeError(f"Embree error {err} building the BVH")  # pragma: no cover

    def _release(self) -> None:
        if getattr(self, "_scene", None):
            self._lib.rtcReleaseScene(self._scene)
            self._scene = None
        if getattr(self, "_device", None):
            self._lib.rtcReleaseDevice(self._device)
            self._device = None

    def __del__(self):
        self._release()

    def __repr__(self) -> str:
        return f"RayMesh({len(self._vertices)} vertices, {len(self._index)} faces)"

    @property
    def vertices(self) -> np.ndarray:
        """(n, 3) float64 vertex positions, metres (read-only)."""
        return self._vertices

    @property
    def faces(self) -> np.ndarray:
        """(m, 3) uint32 vertex indices (read-only; Embree's own index buffer)."""
        return self._index

    @property
    def face_normals(self) -> np.ndarray:
        """(m, 3) float64 unit normals (b - a) x (c - a) of the faces (computed once)."""
        if self._face_normals is None:
            n = np.empty((len(self._index), 3))
            step = 1 << 20
            for lo in range(0, len(self._index), step):
                n[lo:lo + step] = triangle_normals(self._vertices[self._index[lo:lo + step]],
                                                   unit=True)
            n.flags.writeable = False
            self._face_normals = n
        return self._face_normals

    @property
    def vertex_normals(self) -> np.ndarray:
        """(n, 3) float64 unit vertex normals, angle-weighted (each facet's unit normal times
        its angle at the vertex: :mod:`latlong.geometry.normals`, as Mitsuba 3 and Blender
        weight them and as the glTF export writes them), computed once; they follow the
        faces' orientation; smooth shading blends them."""
        if self._vertex_normals is None:
            out = weighted_vertex_normals(self._vertices, self._index, "angle", order="faces")
            out.flags.writeable = False
            self._vertex_normals = out
        return self._vertex_normals

    @property
    def bounding_sphere(self) -> tuple[np.ndarray, float]:
        """(centre, radius) in metres of a sphere that holds every vertex."""
        return self._centre.copy(), self._radius

    def intersect(self, origins, directions, t_max=np.inf) -> Hits:
        """The first face each ray hits within ``t_max`` metres (:class:`Hits`).

        ``directions`` need not be unit vectors (they are normalised; distances are in
        metres); ``origins`` is (k, 3) or one (3,) origin for all rays.
        """
        from ._engine_kernels import _trace_kernel  # numba loads here
        o, d = _rays(origins, directions)
        k = len(d)
        t_out = np.empty(k)
        face = np.empty(k, dtype=np.int64)
        u = np.empty(k)
        v = np.empty(k)
        t_max = _limits("t_max", t_max, k)
        _trace_kernel(self._intersect8, self._scene, o, d, t_max, t_max, self._centre,
                      self._radius, self._vertices, self._index, np.bool_(False), t_out, face,
                      u, v, _NO_BOOL)
        return Hits(t_out, face, u, v)

    def occluded(self, origins, directions, t_max, *, t_min=0.0) -> np.ndarray:
        """(k,) bool: something lies on the ray between ``t_min`` and ``t_max`` metres
        (shadow rays; ``t_min`` keeps a ray from hitting the face it starts on)."""
        from ._engine_kernels import _trace_kernel  # numba loads here
        o, d = _rays(origins, directions)
        k = len(d)
        out = np.empty(k, dtype=np.bool_)
        _trace_kernel(self._occluded8, self._scene, o, d, _limits("t_min", t_min, k),
                      _limits("t_max", t_max, k), self._centre, self._radius, self._vertices,
                      self._index, np.bool_(True), _NO_FLOAT, _NO_INT, _NO_FLOAT, _NO_FLOAT,
                      out)
        return out
