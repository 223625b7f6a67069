"""Locally controlled spot-noise (LCSN) crater kernels of Li et al. (2022, §3.2-3.3).

Four radial kernels (simple bowl, flat-floored, fresh with rim, complex with central
uplift), their morphometry in closed form or measured, the inverse, degradation vectors
and the named kernels of Table A.1 / Fig. 6.

* :mod:`~craters.lcsn.kernel`: the formulas (:func:`lcsn_kernel`), parameter checks,
  :func:`lcsn_degrade`, :func:`lcsn_scaled`; their compiled form is
  ``craters.kernels.lcsn_height``
* :mod:`~craters.lcsn.morphometry`: :func:`lcsn_morphometry` (``"paper"``,
  ``"closed"``, ``"numeric"``)
* :mod:`~craters.lcsn.inverse`: :func:`lcsn_raw`
* :mod:`~craters.lcsn.presets`: :class:`LcsnParams`, :data:`LCSN_PRESETS`
"""

from .inverse import lcsn_raw
from .kernel import (
    BORDER_THRESHOLD,
    MORPH_KEYS,
    RAW_KEYS,
    lcsn_degrade,
    lcsn_kernel,
    lcsn_scaled,
)
from .morphometry import lcsn_morphometry
from .presets import LCSN_PRESETS, LcsnParams

__all__ = ["BORDER_THRESHOLD", "LCSN_PRESETS", "MORPH_KEYS", "RAW_KEYS", "LcsnParams",
           "lcsn_degrade", "lcsn_kernel", "lcsn_morphometry", "lcsn_raw", "lcsn_scaled"]
