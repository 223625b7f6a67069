"""The voxel grid of the implicit backend: a point lattice ``origin + (i, j, k) h``.

Fields on it are C arrays ``values[k, j, i]`` (x fastest, VTK's order). Work that adds
many local items (metaballs, crater impulses, Gabor impulses) into a field is organised
by bins of ``bin_size^3`` grid points (:meth:`VoxelGrid.bins`): each item is listed in
every bin its index box overlaps, and the numba kernels of :mod:`latlong.implicit` run
one parallel loop over the bins, so sums do not depend on the number of threads.
"""

from __future__ import annotations

import dataclasses
from typing import ClassVar

import numpy as np

from . import _kernels as _k

__all__ = ["VoxelGrid"]


@dataclasses.dataclass(frozen=True)
class VoxelGrid:
    """A regular 3-D point lattice (metres) and the helpers its fields need."""

    origin: np.ndarray
    """(3,) position of grid point (0, 0, 0), metres."""
    h: float
    """Spacing, metres."""
    shape: tuple[int, int, int]
    """(nz, ny, nx): the shape of a field ``values[k, j, i]``."""
    bin_size: ClassVar[int] = 16
    """Grid points per bin edge (:meth:`bins`)."""

    def index_boxes(self, centers, reach):
        """Inclusive (i, j, k) index boxes of balls (centre, reach) clipped to the grid."""
        c = (np.asarray(centers) - self.origin) / self.h
        rr = np.asarray(reach)[:, None] / self.h
        nx = np.array(self.shape[::-1])
        lo = np.clip(np.floor(c - rr), 0, nx - 1).astype(np.int64)
        hi = np.clip(np.ceil(c + rr), -1, nx - 1).astype(np.int64)
        hi[(c + rr < 0).any(axis=1) | (c - rr > nx - 1).any(axis=1)] = -1
        return np.ascontiguousarray(lo), np.ascontiguousarray(hi)

    def bins(self, lo, hi):
        """CSR bin lists of index boxes: ``(nbins, offsets, items, active)``, ``active``
        the bins that hold any item."""
        nbins = np.array([-(-n // self.bin_size) for n in self.shape[::-1]], dtype=np.int64)
        counts = np.zeros(int(nbins.prod()), np.int64)
        _k._bin_count(lo, hi, self.bin_size, nbins, counts)
        offsets = np.concatenate([[0], np.cumsum(counts)]).astype(np.int64)
        items = np.empty(offsets[-1], np.int64)
        _k._bin_fill(lo, hi, self.bin_size, nbins, offsets, items)
        return nbins, offsets, items, np.flatnonzero(counts).astype(np.int64)

    def _nearest(self, points):
        ijk = np.rint((np.asarray(points) - self.origin) / self.h).astype(np.int64)
        return np.clip(ijk, 0, np.array(self.shape[::-1]) - 1)

    def sample(self, values, points) -> np.ndarray:
        """``values`` at the grid point nearest to each point."""
        i, j, k = self._nearest(points).T
        return values[k, j, i]

    def gradient(self, values, points) -> np.ndarray:
        """Central-difference gradient of ``values`` at the grid point nearest to each
        point, (n, 3) per metre (one-sided on the border)."""
        ijk = self._nearest(points)
        top = np.array(self.shape[::-1]) - 1
        out = np.empty((len(ijk), 3))
        for axis in range(3):
            up, dn = ijk.copy(), ijk.copy()
            up[:, axis] = np.minimum(up[:, axis] + 1, top[axis])
            dn[:, axis] = np.maximum(dn[:, axis] - 1, 0)
            span = (up[:, axis] - dn[:, axis]) * self.h
            out[:, axis] = (values[up[:, 2], up[:, 1], up[:, 0]] -
                            values[dn[:, 2], dn[:, 1], dn[:, 0]]) / np.maximum(span, 1e-300)
        return out

    def normals(self, values, points) -> np.ndarray:
        """Outward unit normals ``-grad values / |grad values|`` at points (n, 3): the
        central-difference gradient trilinearly interpolated from the 8 grid points
        around each point."""
        pts = np.asarray(points, dtype=np.float64).reshape(-1, 3)
        top = np.array(self.shape[::-1]) - 2
        f = (pts - self.origin) / self.h
        i0 = np.clip(np.floor(f), 0, top).astype(np.int64)
        t = np.clip(f - i0, 0.0, 1.0)
        grad = np.zeros((len(pts), 3))
        for corner in np.ndindex(2, 2, 2):
            c = np.array(corner)
            w = np.prod(np.where(c == 1, t, 1.0 - t), axis=1)
            grad += w[:, None] * self.gradient(values, self.origin + (i0 + c) * self.h)
        return -grad / np.maximum(np.linalg.norm(grad, axis=1, keepdims=True), 1e-300)

    def contour(self, values: np.ndarray):
        """Flying-edges zero level of ``values`` (> 0 inside): (vertices, faces) outward."""
        import pyvista as pv

        img = pv.ImageData(dimensions=self.shape[::-1], spacing=(self.h,) * 3,
                           origin=tuple(self.origin))
        v = np.ascontiguousarray(values, dtype=np.float64).ravel()
        v = np.where(v == 0.0, -1e-9 * self.h, v)  # no vertex exactly on a grid point
        img.point_data["F"] = v
        surf = img.contour([0.0], scalars="F", method="flying_edges")
        if surf.n_cells == 0:
            raise ValueError("the implicit surface is empty at this resolution")
        surf = surf.triangulate()
        verts = np.asarray(surf.points, dtype=np.float64)
        faces = np.asarray(surf.faces).reshape(-1, 4)[:, 1:].astype(np.int64)
        a, b, c = (verts[faces[:, k]] for k in range(3))
        if np.einsum("ij,ij->", a, np.cross(b, c)) < 0:
            faces = faces[:, ::-1].copy()
        return verts, faces
