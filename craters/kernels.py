"""Numba-compiled crater building blocks for packages that stamp on other geometries.

``latlong`` maps each crater's region of the body to a local height grid and uses these
to evaluate the same profile, plane fit, rim offsets and roughness as
:func:`craters.stamp_many`. They take no validation: callers validate first.

* ``profile_params(diameter_m, d, morph, deg)`` -> (R, H, Hr, alpha, beta, E0)
* ``inside(x, H, Hr, alpha)`` and ``outside(x, Hr + delta, beta, E0, x_e)``: the profile
* ``fit_plane(h, cy, cx, r_px, pixel)`` -> (p0, gx, gy, n): least-squares plane
* ``rim_offsets(h, cy, cx, pixel, R, rim_tab, p0, gx, gy, out)``: plane - terrain at the rim
* ``table(tab, theta)``: periodic interpolation of a 64-sample azimuth table
* ``roughness_amp(x, x_e, a_bowl, a_wall, a_ejecta)`` and ``fbm2(seed, x, y, ...)``
* ``mix64(z)``: the splitmix64 finaliser (uint64 -> uint64), for counter-based noise
* ``lcsn_height(kind, r2, kappa, beta, gamma, a, b)``: LCSN crater kernel ``kind`` at
  squared distance r2 (the formulas of :func:`craters.lcsn_kernel`)
* ``N_RIM``: samples per azimuth table
"""

from ._lcsn_kernels import _lcsn_height as lcsn_height
from ._stamp_kernels import N_RIM
from ._stamp_kernels import _fbm2 as fbm2
from ._stamp_kernels import _fit_plane as fit_plane
from ._stamp_kernels import _inside as inside
from ._stamp_kernels import _mix64 as mix64
from ._stamp_kernels import _outside as outside
from ._stamp_kernels import _profile_params as profile_params
from ._stamp_kernels import _rim_offsets as rim_offsets
from ._stamp_kernels import _roughness_amp as roughness_amp
from ._stamp_kernels import _table as table

__all__ = ["N_RIM", "fbm2", "fit_plane", "inside", "lcsn_height", "mix64", "outside",
           "profile_params", "rim_offsets", "roughness_amp", "table"]
