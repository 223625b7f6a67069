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

Bodies cratered with these kernels: ``latlong build --backend implicit --lcsn ...``
(:mod:`latlong.implicit`).

.. code-block:: python

    import craters

    print(craters.lcsn_morphometry(3, "numeric",
                                   **craters.LCSN_PRESETS["table-a1-1km-0gyr"].raw))
    # {'H_t': 180.1, 'D_a': 766.75, 'D_rim': 962.38, 'H_rim': 35.53, 'L_d': nan}

:func:`lcsn_morphometry` has three methods: ``"numeric"`` measures the sampled profile;
``"paper"`` evaluates Li et al.'s eq. 4-16 as printed, whose eq. 9-11 put the crest at
1/sqrt(gamma) and assume kappa = a (on Table A.1's fresh craters, kappa = 0.22-0.34 a:
D_a 8-11 % short, L_d 50-60 % long); ``"closed"`` (default) refines those Lambert-W roots
with three explicit Newton steps on the exact equations and keeps each only if a sign
change proves a true root within 0.5 % (else NaN): on the 0 Gyr rows it equals
``"numeric"`` to 1e-5 at 1/30 of its cost (``python tests/benchmarks/bench_implicit.py``
prints every row). :func:`lcsn_raw` inverts each.
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
