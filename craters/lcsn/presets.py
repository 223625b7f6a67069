"""Named LCSN kernels: Li et al. 2022 Table A.1 and the profiles of its Fig. 6.

Table A.1 (kernel_3 fits of Fassett & Thomson's degradation of 300 m, 1 km and 3 km
craters at 0-3 Gyr) lists ``a`` as a negative number: it is the signed coefficient of
the Gaussian in ``kappa L + a exp(-b r^2)``, so the bowl depth is ``-a``. Read that
way the 0 Gyr rows are realistic fresh craters (d/D 0.18-0.19, rim height 0.032-0.037
D); read as eq. 6's ``a`` they would be domes. :data:`LCSN_PRESETS` stores ``a = -a_table``.
"""

from __future__ import annotations

import dataclasses
import math

from .kernel import RAW_KEYS, check_kind, check_raw
from .morphometry import lcsn_morphometry

__all__ = ["LCSN_PRESETS", "LcsnParams"]


# --------------------------------------------------------------------------- presets
@dataclasses.dataclass(frozen=True, slots=True)
class LcsnParams:
    """A named LCSN kernel: its kind and raw parameters (metres; see the module notes)."""

    kind: int
    """1 simple bowl, 2 flat-floored, 3 fresh with rim, 4 complex with central uplift."""
    a: float
    """Bowl depth (kinds 1-3) or uplift height (kind 4), >= 0, metres."""
    b: float
    """Width of the Gaussian term, 1/m^2 (kind 2: 1/m^4), > 0."""
    kappa: float = 0.0
    """Ring (rim) height, metres, >= 0 (kinds 3-4)."""
    beta: float = 0.0
    """Ring sharpness, dimensionless, > 0 (kinds 3-4)."""
    gamma: float = 0.0
    """Ring position: the ring peaks at r = 1/sqrt(gamma); 1/m^2, > 0 (kinds 3-4)."""
    description: str = ""
    """Where the numbers come from."""

    def __post_init__(self):
        check_raw(check_kind(self.kind), self.raw)

    @property
    def raw(self) -> dict:
        """The raw parameters as keyword arguments of :func:`lcsn_kernel`."""
        return {k: getattr(self, k) for k in RAW_KEYS[self.kind]}

    def morphometry(self, method: str = "closed") -> dict:
        """:func:`lcsn_morphometry` of this kernel."""
        return lcsn_morphometry(self.kind, method, **self.raw)


def _table_rows() -> dict[str, LcsnParams]:
    rows = {  # diameter, age: kappa, beta, gamma, a (as printed, signed), b
        ("300m", 0): (16.3, 5.0, 0.000042, -55.1, 0.00009),
        ("300m", 1): (1.5, 5.0, 0.000042, -8.1, 0.00007),
        ("300m", 2): (0.7, 5.0, 0.000042, -5.1, 0.00005),
        ("300m", 3): (0.0, 5.0, 0.000042, -2.4, 0.00003),
        ("1km", 0): (40.3, 5.0, 0.0000045, -180.1, 0.000016),
        ("1km", 1): (15.3, 5.0, 0.0000045, -142.1, 0.000016),
        ("1km", 2): (3.3, 5.0, 0.0000045, -120.1, 0.000016),
        ("1km", 3): (1.3, 5.0, 0.0000045, -110.1, 0.000016),
        ("3km", 0): (190.3, 7.0, 0.00000045, -563.1, 0.00000088),
        ("3km", 1): (175.3, 5.5, 0.00000045, -558.1, 0.00000088),
        ("3km", 2): (172.3, 5.2, 0.00000045, -553.1, 0.00000088),
        ("3km", 3): (169.3, 4.9, 0.00000045, -548.1, 0.00000088),
    }
    return {f"table-a1-{d}-{age}gyr": LcsnParams(
        3, a=-a, b=b, kappa=k, beta=bt, gamma=g,
        description=f"Li et al. 2022 Table A.1, {d} crater at {age} Gyr (Fassett & Thomson "
                    f"2014 degradation); printed a = {a} (signed), bowl depth {-a} m")
        for (d, age), (k, bt, g, a, b) in rows.items()}


#: Named kernels. ``table-a1-<D>-<age>gyr``: the twelve kernel_3 rows of Li et al. 2022
#: Table A.1 (metres; ``a = -a_table``). ``fig6-kernel<k>``: the normalised profiles of
#: Fig. 6, rebuilt from the caption's morphometry: kernel 1 the unit-area Gaussian
#: (``H_t = 1``, ``D_a = 5 sqrt(ln 2/pi)``: b = pi); kernel 2 ``H_t = 1``,
#: ``D_a = 4 sqrt(ln 2/pi)`` (b = pi^2/ln 2); kernel 3 ``H_t = 1, D_a = 1.31,
#: D_rim = 2, H_rim = 0.309`` measured, with Table A.1's usual beta = 5
#: (``lcsn_raw(3, "numeric", beta=5, ...)``); kernel 4 ``H_c = 0.2, D_rim = 2,
#: H_rim = 0.471`` measured, with kernel 3's beta and b (the caption gives neither).
LCSN_PRESETS: dict[str, LcsnParams] = {
    **_table_rows(),
    "fig6-kernel1": LcsnParams(1, a=1.0, b=math.pi,
                               description="Li 2022 Fig. 6 simple crater 1 (normalised)"),
    "fig6-kernel2": LcsnParams(2, a=1.0, b=math.pi**2 / math.log(2.0),
                               description="Li 2022 Fig. 6 simple crater 2 (normalised)"),
    "fig6-kernel3": LcsnParams(3, a=1.0, b=11.08212495520453, kappa=0.3090153895909925,
                               beta=5.0, gamma=1.0000551840631648,
                               description="Li 2022 Fig. 6 fresh crater (normalised)"),
    "fig6-kernel4": LcsnParams(4, a=0.2, b=11.08212495520453, kappa=0.4709969231460819,
                               beta=5.0, gamma=0.9999927643928281,
                               description="Li 2022 Fig. 6 complex crater (normalised)"),
}
