"""Numba-compiled building blocks shared with the packages that build on craters.

``latlong`` maps each crater's region of the body to a local height grid and uses these
to evaluate the same profile, plane fit, rim offsets and roughness as
:func:`craters.stamp_many`; ``dem`` uses the raster helpers and the counter-based
Gaussian. They take no validation: callers validate first.

Crater profile and stamping:

* ``table_value(tab, x, x_e)``: a crater's profile table (heights at evenly spaced radii
  over [0, x_e], :func:`craters.diffusion.profile_tables`) at x radii (Catmull-Rom, C1);
  ``table_row_value(tabs, k, x, x_e)`` the same of row k, read in place (no row view in a
  parallel loop)
* ``outer_weight(x, x_e)``: the share of the plane-to-terrain offset at the rim carried
  at x outside the rim
* ``fit_plane(h, cy, cx, r_px, pixel)`` -> (p0, gx, gy, n): least-squares plane
* ``rim_offsets(h, cy, cx, pixel, R, rim_tab, p0, gx, gy, out)``: plane - terrain at the rim
* ``table(tab, theta)``: periodic interpolation of a 64-sample azimuth table
  (``table_row(tabs, k, theta)`` of row k, read in place);
  ``azimuth(y, x)``: atan2 in plain arithmetic (:mod:`craters._angle_kernels`), for hot loops
* ``slope_factor(slope, onset_deg, full_deg)``: the share of the relief kept on a slope
* ``roughness_amp(x, x_e, a_bowl, a_wall, a_ejecta)``, ``roughness_octaves(wavelength,
  spacing)`` and ``fbm2(seed, x, y, wavelength, octaves, gain)``: the roughness overlay
* ``lattice_coord(x)`` -> (index, fraction, quintic fade): a noise lattice coordinate
* ``crater_rough(rough, warp)``: a crater's overlay settings (roughness amplitudes and its
  wall warp) for the writers; ``warp_x(x, u, v, R, warp, seed)``: the warped profile
  coordinate inside the rim (irregular terraces and central peaks)
* ``lcsn_height(kind, r2, kappa, beta, gamma, a, b)``: LCSN crater kernel ``kind`` at
  squared distance r2 (the formulas of :func:`craters.lcsn_kernel`)
* ``N_RIM``: samples per azimuth table
* a crater on steep ground, made in the frame of its tilted base (:mod:`craters._tilt_kernels`):
  ``tilted_frame(gx, gy, out)`` -> tilt (degrees), ``out`` = (E', N', N, N_z);
  ``tilted_coords(x, y, z, fr, R, rim_tab)`` -> (u1, u2, w, azimuth, x/R);
  ``tilted_root(...)``: the vertical change onto the crater's surface inside the rim;
  ``tilted_ejecta(...)``: its profile and roughness outside the rim, as a vertical height;
  ``TILT_MIN_DEG`` (from which a base counts as tilted), ``TILT_MAX_COS`` (the steepest)

Counter-based random numbers:

* ``mix64(z)``: the splitmix64 finaliser (uint64 -> uint64); ``splitmix64(x)`` =
  ``mix64(x + GOLDEN)``; ``hash_normal(a)``: a standard normal from a 64-bit hash

Grids and point sets:

* ``bilinear(h, fy, fx, blend)``: bilinear sample at fractional (row, col), NaN outside
* ``PLANE_SUMS0``, ``plane_sums_add(s, x, y, v)``, ``plane_solve(s, scale)``: the
  least-squares plane from its nine running sums
* ``idw8(z, known, r, c, step_len, empty)``: 8-direction inverse-distance hole fill;
  ``DR8``, ``DC8``: its directions

Calling kernels from Python:

* ``read_only_inputs(*outputs)``: a kernel's decorator (outside ``njit``) passing every
  array argument but its outputs read-only, so it compiles once
* from numba code, flags and counts go to a compiled (not inlined) kernel as
  ``np.bool_(...)`` and ``np.int64(...)``: a constant ``True`` or ``0`` is a literal type
  of its own, and numba compiles the callee once per literal (``_stamp_one`` ~10 s a
  time; ``tests/test_architecture.py`` checks the source)

Cube-sphere cells (:mod:`craters.cells`):

* ``face_uv(x, y, z)`` -> (face, u, v); ``face_point(face, u, v)`` -> (x, y, z);
  ``cell_id(level, face, u, v)``: the uint64 id of the cell holding (u, v)
"""

from ._angle_kernels import _azimuth as azimuth
from ._calls import read_only_inputs
from ._counter_kernels import _cell_id as cell_id
from ._counter_kernels import _face_point as face_point
from ._counter_kernels import _face_uv as face_uv
from ._lcsn_kernels import _lcsn_height as lcsn_height
from ._raster_kernels import DC8, DR8, PLANE_SUMS0
from ._raster_kernels import _bilinear as bilinear
from ._raster_kernels import _idw8 as idw8
from ._raster_kernels import _plane_solve as plane_solve
from ._raster_kernels import _plane_sums_add as plane_sums_add
from ._rng_kernels import GOLDEN
from ._rng_kernels import _hash_normal as hash_normal
from ._rng_kernels import _mix64 as mix64
from ._rng_kernels import _splitmix64 as splitmix64
from ._stamp_kernels import N_RIM
from ._stamp_kernels import _crater_rough as crater_rough
from ._stamp_kernels import _fbm2 as fbm2
from ._stamp_kernels import _fit_plane as fit_plane
from ._stamp_kernels import _lattice_coord as lattice_coord
from ._stamp_kernels import _outer_weight as outer_weight
from ._stamp_kernels import _rim_offsets as rim_offsets
from ._stamp_kernels import _roughness_amp as roughness_amp
from ._stamp_kernels import _roughness_octaves as roughness_octaves
from ._stamp_kernels import _slope_factor as slope_factor
from ._stamp_kernels import _table as table
from ._stamp_kernels import _table_row as table_row
from ._stamp_kernels import _table_row_value as table_row_value
from ._stamp_kernels import _table_value as table_value
from ._stamp_kernels import _warp_x as warp_x
from ._tilt_kernels import _TILT_MAX_COS as TILT_MAX_COS
from ._tilt_kernels import TILT_MIN_DEG, tilted_coords, tilted_ejecta, tilted_root
from ._tilt_kernels import _tilted_frame as tilted_frame

__all__ = ["DC8", "DR8", "GOLDEN", "N_RIM", "PLANE_SUMS0", "azimuth", "bilinear", "cell_id",
           "crater_rough", "face_point", "face_uv", "fbm2", "fit_plane", "hash_normal", "idw8",
           "lattice_coord", "lcsn_height", "mix64", "outer_weight", "plane_solve", "plane_sums_add",
           "read_only_inputs", "rim_offsets", "roughness_amp", "roughness_octaves",
           "slope_factor", "splitmix64", "table", "table_row", "table_row_value", "table_value",
           "TILT_MAX_COS",
           "TILT_MIN_DEG",
           "tilted_coords", "tilted_ejecta", "tilted_frame", "tilted_root", "warp_x"]
