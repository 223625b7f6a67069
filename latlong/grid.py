"""The evenly spaced 6M^2+2 latitude/longitude sphere mesh (Martin et al. 2014, III.A)."""

from __future__ import annotations

import math

import numpy as np

from craters._shared import check_int

from .geometry.normals import lat_long_vertex_normals

__all__ = ["BUILD_BASE_BYTES", "BUILD_BYTES_PER_VERTEX", "BUILD_BYTES_PER_VERTEX_THREAD",
           "LatLongGrid", "MAX_MAGNITUDE", "build_bytes_per_vertex"]

#: Largest magnitude whose vertex indices fit the int64 arrays used everywhere.
MAX_MAGNITUDE = 1_000_000
#: Peak memory of ``latlong build ... -o body.npz`` per grid vertex: the float64 radii.
BUILD_BYTES_PER_VERTEX = 8.0
#: ... plus, per stamping thread, the kernel's arrays for the crater it stamps (~95 B per
#: vertex of the crater's cap, a cap being ~0.6 (D/R)^2 of the body). Measured (issue 18):
#: fbm-cratered (D up to 15 m on R = 100 m) on 2 threads peaked (/usr/bin/time -v) at
#: 0.70 GB at M = 2048 and 1.49 GB at M = 4096, a slope of 10.8 B a vertex; eight 15 m
#: craters on a 100 m sphere at M = 4096 raised the peak by 1.50 B a vertex on 1 thread,
#: 2.58 on 2. Bodies whose largest craters are a larger share of the radius need more.
BUILD_BYTES_PER_VERTEX_THREAD = 1.5
#: ... and what does not grow with the grid: interpreter, libraries, numba and its
#: compiler (a first run without a kernel cache), bounded buffers, ~70 000 craters'
#: profile tables. The same fit's intercept is 0.45 GB (kernels cached); rounded up.
BUILD_BASE_BYTES = 0.6e9


def build_bytes_per_vertex(threads: int | None = None) -> float:
    """Peak memory of a build per grid vertex with ``threads`` stamping threads (default
    numba's current count): :data:`BUILD_BYTES_PER_VERTEX` + ``threads`` x
    :data:`BUILD_BYTES_PER_VERTEX_THREAD` (11 B with 2 threads)."""
    if threads is None:
        import numba

        threads = numba.get_num_threads()
    threads = int(threads)
    return BUILD_BYTES_PER_VERTEX + threads * BUILD_BYTES_PER_VERTEX_THREAD


def _readonly(a: np.ndarray) -> np.ndarray:
    a.setflags(write=False)
    return a


class LatLongGrid:
    """Geometry of the lat/long sphere mesh of magnitude M.

    Global ring ``r`` runs from 0 (north pole) to ``2M`` (south pole) at colatitude
    ``pi r / (2M)``; ring ``L = 1..M`` of the northern hemisphere holds ``6L`` vertices,
    ring ``M`` is the equator and the southern rings mirror the northern ones, so the
    grid has ``6M^2 + 2`` vertices. Vertex ``j`` of a ring of ``n`` vertices sits at
    longitude ``2 pi j / n``, so a magnitude-M grid is exactly the rings ``k r`` /
    vertices ``k j`` of the magnitude-``kM`` grid (nesting, :meth:`nested_indices`).
    Vertices are numbered ring by ring from the north pole.

    The object is immutable; derived arrays are computed once and returned read-only.

    Parameters
    ----------
    magnitude : int
        M >= 1, the number of latitude rings per hemisphere (the equator included).

    Examples
    --------
    >>> g = LatLongGrid(2)
    >>> g.n_vertices, g.n_triangles
    (26, 48)
    >>> g.ring_sizes().tolist()
    [1, 6, 12, 6, 1]
    """

    __slots__ = ("_m", "_cache")

    def __init__(self, magnitude: int):
        self._m = check_int("magnitude", magnitude, 1, MAX_MAGNITUDE)
        self._cache: dict = {}

    # ------------------------------------------------------------------ basics
    @property
    def magnitude(self) -> int:
        """M, the number of rings per hemisphere (equator included)."""
        return self._m

    @property
    def n_vertices(self) -> int:
        """6 M^2 + 2."""
        return 6 * self._m * self._m + 2

    @property
    def n_triangles(self) -> int:
        """2 N - 4 = 12 M^2."""
        return 12 * self._m * self._m

    @property
    def n_rings(self) -> int:
        """2 M + 1 rings, the two poles included."""
        return 2 * self._m + 1

    def __repr__(self) -> str:
        return f"LatLongGrid(magnitude={self._m})"

    def __eq__(self, other) -> bool:
        return isinstance(other, LatLongGrid) and other._m == self._m

    def __hash__(self) -> int:
        return hash(("LatLongGrid", self._m))

    def __getstate__(self):
        return {"magnitude": self._m}

    def __setstate__(self, state):
        self._m = state["magnitude"]
        self._cache = {}

    def _cached(self, key, make):
        value = self._cache.get(key)
        if value is None:
            value = make()
            if isinstance(value, np.ndarray):
                _readonly(value)
            self._cache[key] = value
        return value

    @staticmethod
    def estimate_bytes(magnitude: int, bytes_per_vertex: float | None = None,
                       base_bytes: float | None = None) -> int:
        """Memory (peak resident set) needed to build a body of this magnitude and write
        it as .npz: ``base_bytes + (6 M^2 + 2) * bytes_per_vertex``.

        Defaults (measured, see the module's constants): :data:`BUILD_BASE_BYTES` and
        :func:`build_bytes_per_vertex` for numba's current thread count. Mesh exports
        may need more.

        Examples
        --------
        >>> LatLongGrid.estimate_bytes(10, 8, 0)
        4816
        """
        m = int(magnitude)
        bpv = build_bytes_per_vertex() if bytes_per_vertex is None else bytes_per_vertex
        base = BUILD_BASE_BYTES if base_bytes is None else base_bytes
        return int(base + (6 * m * m + 2) * bpv)

    # ------------------------------------------------------------------ rings
    def ring_sizes(self) -> np.ndarray:
        """Vertices per ring, shape (2M+1,), int64: 1, 6, 12, ..., 6M, ..., 6, 1."""

        def make():
            m = self._m
            r = np.arange(2 * m + 1, dtype=np.int64)
            sizes = 6 * np.minimum(r, 2 * m - r)
            sizes[0] = sizes[-1] = 1
            return sizes

        return self._cached("ring_sizes", make)

    def ring_offsets(self) -> np.ndarray:
        """Index of each ring's first vertex, shape (2M+2,), the last entry = N."""
        return self._cached(
            "ring_offsets",
            lambda: np.concatenate([[0], np.cumsum(self.ring_sizes())]).astype(np.int64),
        )

    def ring_colatitudes(self) -> np.ndarray:
        """Colatitude of each ring in radians, ``pi r / (2M)``, shape (2M+1,)."""
        step = np.pi / (2 * self._m)
        return self._cached("ring_colat",
                            lambda: np.arange(self.n_rings, dtype=np.float64) * step)

    def vertex_rings(self) -> np.ndarray:
        """Global ring index of every vertex, shape (N,), int64."""
        return self._cached(
            "vertex_rings",
            lambda: np.repeat(np.arange(self.n_rings, dtype=np.int64), self.ring_sizes()),
        )

    def vertex_positions(self) -> np.ndarray:
        """Position ``j`` of every vertex within its ring, shape (N,), int64."""

        def make():
            starts = np.repeat(self.ring_offsets()[:-1], self.ring_sizes())
            return np.arange(self.n_vertices, dtype=np.int64) - starts

        return self._cached("vertex_positions", make)

    def index(self, ring, position) -> np.ndarray | int:
        """Vertex index of (global ring, position in ring); positions wrap around."""
        ring = np.asarray(ring, dtype=np.int64)
        if np.any((ring < 0) | (ring > 2 * self._m)):
            raise ValueError(f"`ring` must be in [0, {2 * self._m}]; got {ring!r}")
        sizes = self.ring_sizes()[ring]
        out = self.ring_offsets()[ring] + np.mod(np.asarray(position, dtype=np.int64), sizes)
        return int(out) if out.ndim == 0 else out

    # ------------------------------------------------------------------ coordinates
    def latitudes(self) -> np.ndarray:
        """Latitude of every vertex in radians, shape (N,)."""
        return self._cached(
            "lat", lambda: (np.pi / 2) - self.ring_colatitudes()[self.vertex_rings()]
        )

    def longitudes(self) -> np.ndarray:
        """Longitude of every vertex in radians in [0, 2 pi), shape (N,)."""

        def make():
            sizes = self.ring_sizes()[self.vertex_rings()]
            return (2 * np.pi) * self.vertex_positions() / sizes

        return self._cached("lon", make)

    def unit_vectors(self) -> np.ndarray:
        """Unit direction of every vertex, shape (N, 3), float64 (poles exactly +-z).

        Cached; for very large grids prefer :meth:`unit_vectors_range` /
        :meth:`unit_vectors_of`, which compute the same values without keeping them.
        """
        return self._cached("unit", lambda: self.unit_vectors_range(0, self.n_vertices))

    def unit_vectors_range(self, lo: int = 0, hi: int | None = None) -> np.ndarray:
        """Unit vectors of vertices ``lo .. hi - 1`` (from the cache if it exists)."""
        from ._grid_kernels import _unit_range_kernel, _unit_range_serial  # numba loads here
        hi = self.n_vertices if hi is None else min(int(hi), self.n_vertices)
        lo = max(0, int(lo))
        cached = self._cache.get("unit")
        if cached is not None:
            return cached[lo:hi]
        out = np.empty((max(hi - lo, 0), 3), dtype=np.float64)
        if hi - lo > 1_000_000:
            _unit_range_kernel(self._m, self.ring_offsets(), lo, hi, out)
        elif hi > lo:
            _unit_range_serial(self._m, self.ring_offsets(), lo, hi, out)
        return out

    def unit_vectors_of(self, idx) -> np.ndarray:
        """Unit vectors of the vertices ``idx`` (any shape of indices), shape (..., 3)."""
        from ._grid_kernels import _unit_index_kernel  # numba loads here
        idx = np.asarray(idx, dtype=np.int64)
        flat = np.ascontiguousarray(idx.ravel())
        if flat.size and (flat.min() < 0 or flat.max() >= self.n_vertices):
            raise ValueError(f"`idx` must be in [0, {self.n_vertices - 1}]")
        out = np.empty((flat.size, 3), dtype=np.float64)
        if flat.size:
            _unit_index_kernel(self._m, self.ring_offsets(), flat, out)
        return out.reshape(idx.shape + (3,))

    def ring_areas(self) -> np.ndarray:
        """Area represented by each vertex of each ring on the unit sphere, shape (2M+1,).

        Ring ``r`` owns the zone between colatitudes ``(r -+ 1/2) pi / (2M)`` (the pole
        caps end at the poles), shared evenly by its vertices.
        """

        def make():
            d = np.pi / (2 * self._m)
            theta = self.ring_colatitudes()
            lo = np.clip(theta - d / 2, 0.0, np.pi)
            hi = np.clip(theta + d / 2, 0.0, np.pi)
            zone = 2 * np.pi * (np.cos(lo) - np.cos(hi))
            return zone / self.ring_sizes()

        return self._cached("ring_areas", make)

    def vertex_areas(self) -> np.ndarray:
        """Area represented by each vertex on the unit sphere (sum 4 pi), shape (N,):
        its ring's :meth:`ring_areas` entry (cached; 8 B a vertex)."""
        return self._cached("areas", lambda: np.repeat(self.ring_areas(), self.ring_sizes()))

    def spacing(self, radius_m: float = 1.0) -> float:
        """Nominal vertex spacing: the ring spacing ``pi R / (2M)`` in metres."""
        return math.pi * float(radius_m) / (2 * self._m)

    # ------------------------------------------------------------------ topology
    def band_offsets(self) -> np.ndarray:
        """First triangle of each band (ring r to r+1), shape (2M+1,), last = 12 M^2."""

        def make():
            s = self.ring_sizes()
            counts = s[:-1] + s[1:]
            counts[0] = counts[-1] = 6  # pole fans
            return np.concatenate([[0], np.cumsum(counts)]).astype(np.int64)

        return self._cached("band_offsets", make)

    def band_triangles(self, band_lo: int = 0, band_hi: int | None = None) -> np.ndarray:
        """Triangles of the bands ``band_lo .. band_hi - 1`` (not cached; for streaming).

        Band ``b`` joins ring ``b`` and ring ``b + 1``. Returns int64 (T, 3) vertex
        indices, counter-clockwise seen from outside.
        """
        from ._grid_kernels import _triangles_kernel, _triangles_serial  # numba loads here
        nb = 2 * self._m
        band_hi = nb if band_hi is None else int(band_hi)
        band_lo = int(band_lo)
        if not 0 <= band_lo <= band_hi <= nb:
            raise ValueError(f"bands must satisfy 0 <= band_lo <= band_hi <= {nb}; "
                             f"got {band_lo}, {band_hi}")
        bo = self.band_offsets()
        out = np.empty((bo[band_hi] - bo[band_lo], 3), dtype=np.int64)
        if len(out) > 500_000:
            _triangles_kernel(self._m, band_lo, band_hi, self.ring_offsets(), bo, out)
        elif band_hi > band_lo:
            _triangles_serial(self._m, band_lo, band_hi, self.ring_offsets(), bo, out)
        return out

    def triangles(self) -> np.ndarray:
        """All ``2N - 4`` triangles, int64 (12 M^2, 3), outward (counter-clockwise)."""
        return self._cached("triangles", lambda: self.band_triangles())

    def edges(self) -> np.ndarray:
        """Unique undirected edges ``(i, j)`` with ``i < j``, int64 (3N - 6, 2), sorted."""

        def make():
            t = self.triangles()
            e = np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]])
            e.sort(axis=1)
            key = np.unique(e[:, 0] * self.n_vertices + e[:, 1])
            return np.stack([key // self.n_vertices, key % self.n_vertices], axis=1)

        return self._cached("edges", make)

    def adjacency(self) -> tuple[np.ndarray, np.ndarray]:
        """Vertex neighbours in CSR form ``(indptr, indices)``; neighbours sorted by index."""

        def make():
            e = self.edges()
            both = np.concatenate([e, e[:, ::-1]])
            order = np.lexsort((both[:, 1], both[:, 0]))
            both = both[order]
            indptr = np.zeros(self.n_vertices + 1, dtype=np.int64)
            np.cumsum(np.bincount(both[:, 0], minlength=self.n_vertices), out=indptr[1:])
            return (_readonly(indptr), _readonly(np.ascontiguousarray(both[:, 1])))

        return self._cached("adjacency", make)

    def neighbours(self, i: int) -> np.ndarray:
        """Indices of the vertices sharing an edge with vertex ``i`` (sorted)."""
        i = check_int("i", i, 0, self.n_vertices - 1)
        indptr, indices = self.adjacency()
        return indices[indptr[i]:indptr[i + 1]]

    # ------------------------------------------------------------------ nesting, sampling
    def nested_indices(self, coarse: LatLongGrid | int) -> np.ndarray:
        """Indices in this grid of the vertices of a coarser nested grid.

        ``coarse`` (a grid or magnitude) must divide this magnitude: its vertex at
        (ring r, position j) is this grid's vertex (k r, k j) with k = M / M_coarse.
        """
        mc = coarse.magnitude if isinstance(coarse, LatLongGrid) else check_int(
            "coarse", coarse, 1, self._m)
        if self._m % mc:
            raise ValueError(f"coarse magnitude {mc} must divide magnitude {self._m}")
        k = self._m // mc
        cg = LatLongGrid(mc)
        rings = cg.vertex_rings() * k
        pos = cg.vertex_positions() * k
        return self.ring_offsets()[rings] + pos

    def interpolate(self, values, colatitudes, longitudes) -> np.ndarray:
        """Sample a per-vertex field at arbitrary (colatitude, longitude) in radians.

        Linear along each ring (with wrap-around) and linear between the two rings that
        bracket the colatitude; exact at the grid's own vertices.
        """
        from ._grid_kernels import _interpolate_kernel  # numba loads here
        return self._sample(_interpolate_kernel, "values", values, colatitudes, longitudes)

    def surface_radii(self, radii, colatitudes, longitudes) -> np.ndarray:
        """Distance from the centre to the triangle mesh along arbitrary directions.

        ``radii`` are the per-vertex radii of a body on this grid; the answer is where
        the ray from the centre towards (colatitude, longitude) (radians) crosses the flat
        triangles a renderer draws, not an interpolation (``interpolate`` blends ring
        values; it differs from the flat triangles by a fraction of the relief between
        neighbouring vertices). For a stretched body pass the direction of ``p / stretch``:
        stretching maps the rays from the centre and the triangles onto themselves.
        """
        from ._grid_kernels import _surface_radius_kernel  # numba loads here
        return self._sample(_surface_radius_kernel, "radii", radii, colatitudes, longitudes)

    def vertex_normals(self, radii, stretch=(1.0, 1.0, 1.0), *,
                       lon_table: np.ndarray | None = None) -> np.ndarray:
        """Unit area-weighted vertex normals, float32 (N, 3), of the mesh whose vertex
        ``i`` is ``stretch * radii[i] * u_i``
        (:func:`latlong.geometry.normals.lat_long_vertex_normals`: band by band, 12 B a
        vertex; ``lon_table`` - ``latlong._grid_kernels.lon_table(M, ring_offsets)`` -
        reuses a longitude table).

        Examples
        --------
        >>> g = LatLongGrid(4)
        >>> n = g.vertex_normals(np.full(g.n_vertices, 2.0))
        >>> bool(np.allclose(n, g.unit_vectors(), atol=0.2))
        True
        """
        return lat_long_vertex_normals(self, radii, stretch, lon_table=lon_table)

    def _sample(self, kernel, name: str, values, colatitudes, longitudes) -> np.ndarray:
        """Run a per-point kernel(m, ring_offsets, values, colat, lon, out) after checks."""
        values = np.ascontiguousarray(values, dtype=np.float64)
        if values.shape != (self.n_vertices,):
            raise ValueError(f"`{name}` must have shape ({self.n_vertices},); got "
                             f"{values.shape}")
        colat = np.ascontiguousarray(colatitudes, dtype=np.float64).ravel()
        lon = np.ascontiguousarray(longitudes, dtype=np.float64).ravel()
        if colat.shape != lon.shape:
            raise ValueError("`colatitudes` and `longitudes` must have the same shape")
        out = np.empty(colat.shape[0], dtype=np.float64)
        kernel(self._m, self.ring_offsets(), values, colat, lon, out)
        return out.reshape(np.shape(colatitudes))
