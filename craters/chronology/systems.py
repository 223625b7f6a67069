"""Published production functions, chronologies and equilibrium functions, and the
named chronology systems that pair them (:data:`CHRONOLOGY_SYSTEMS`).

Coefficients are transcribed from craterstats 3.2.1's ``config/functions.txt`` (G.
Michael, BSD-3; the same numbers as ``crater_relations.json``), which carries them from
the papers cited with each entry; ``tests/craters/test_chronology.py`` checks every one
against a copy of that file. D in km, N per km^2, T in Gyr.
"""

from __future__ import annotations

import dataclasses
import types

from .._shared import ParameterError
from .functions import ChronologyFunction, EquilibriumFunction, ProductionFunction

__all__ = ["CHRONOLOGY_SYSTEMS", "EQUILIBRIUM_FUNCTIONS", "ChronologySystem",
           "get_chronology_system", "get_equilibrium"]

_NEUKUM_2001 = ("Neukum, G., Ivanov, B. A., Hartmann, W. K. (2001) Cratering records in "
                "the inner solar system in relation to the lunar reference system. Space "
                "Sci. Rev. 96, 55-86")
_NEUKUM_1983 = ("Neukum, G. (1983) Meteoritenbombardement und Datierung planetarer "
                "Oberflaechen. Habilitation thesis, Ludwig-Maximilians-Univ. Munich")
_IVANOV_2001 = ("Ivanov, B. A. (2001) Mars/Moon cratering rate ratio estimates. Space "
                "Sci. Rev. 96, 87-104")
_HARTMANN_NEUKUM_2001 = ("Hartmann, W. K., Neukum, G. (2001) Cratering chronology and "
                         "the evolution of Mars. Space Sci. Rev. 96, 165-194; equation "
                         "form in Neukum, Ivanov & Hartmann (2001)")
_STROM_NEUKUM_1988 = ("Strom, R. G., Neukum, G. (1988) The cratering record on Mercury "
                      "and the origin of impacting objects. In Mercury, Univ. Arizona "
                      "Press, 336-373")
_NEUKUM_MERCURY_2001 = ("Neukum, G., Oberst, J., Hoffmann, H., Wagner, R., Ivanov, B. A. "
                        "(2001) Geologic evolution and cratering history of Mercury. "
                        "Planet. Space Sci. 49, 1507-1521")
_SCHMEDEMANN_2014 = ("Schmedemann, N. et al. (2014) The cratering record, chronology and "
                     "surface ages of (4) Vesta in comparison to smaller asteroids and the "
                     "ages of HED meteorites. Planet. Space Sci. 103, 104-130")
_SCHMEDEMANN_PHOBOS_2014 = ("Schmedemann, N., Michael, G. G., Ivanov, B. A., Murray, J. "
                            "B., Neukum, G. (2014) The age of Phobos and its largest crater, "
                            "Stickney. Planet. Space Sci. 102, 152-163")
_HIESINGER_2016 = ("Hiesinger, H. et al. (2016) Cratering on Ceres: implications for its "
                   "crust and evolution. Science 353, aaf4759")

# --------------------------------------------------------------------------- production
_PF = {pf.name: pf for pf in (
    ProductionFunction(
        "Moon, Neukum (1983)",
        (-2.5339, -3.6269, 0.43662, 0.79347, 0.086468, -0.26485, -0.066382, 0.037923,
         0.010596, -0.0022496, -0.00051797, 0.0000397),
        (0.01, 300.0), _NEUKUM_1983),
    ProductionFunction(
        "Moon, Neukum et al. (2001)",
        (-3.0768, -3.557528, 0.781027, 1.021521, -0.156012, -0.444058, 0.019977, 0.086850,
         -0.005874, -0.006809, 8.25e-04, 5.54e-05),
        (0.01, 300.0), _NEUKUM_2001),
    ProductionFunction(
        "Mars, Ivanov (2001)",
        (-3.383677, -3.197453, 1.256814, 7.915374e-01, -4.860814e-01, -3.630098e-01,
         1.015683e-01, 6.755923e-02, -1.180639e-02, -4.753462e-03, 6.232845e-04,
         5.805492e-05),
        (0.015, 362.0), _IVANOV_2001),
    ProductionFunction(
        "Mercury, Strom & Neukum (1988)",
        (-2.600300, -3.6712, 2.946e-01, 7.63e-01, 1.62e-01, -2.379e-01, -8.1361e-02,
         3.2493e-02, 1.1737e-02, -1.9272e-03, -5.4447e-04, 3.97e-05),
        (0.01, 100.0), _STROM_NEUKUM_1988),
    ProductionFunction(
        "Mercury, Neukum et al. (2001)",
        (-3.016675, -3.627417, 6.038601e-01, 1.026714, -3.767761e-03, -4.204364e-01,
         -3.2235e-02, 8.044575e-02, 3.170165e-03, -6.733922e-03, 1.334403e-04,
         1.428627e-04),
        (0.01, 100.0), _NEUKUM_MERCURY_2001),
    ProductionFunction(
        "Vesta, Rev4, Schmedemann et al (2014)",
        (-3.365, -2.9267, 0.6192, 0.59636, 0.11879, -0.30577, -0.20515, 0.068576, 0.058513,
         -0.010293, -0.0053325, 0.0009643),
        (0.03, 500.0), _SCHMEDEMANN_2014),
    ProductionFunction(
        "Ceres, Hiesinger et al. (2016)",
        (-2.8502, -3.2567, 0.48621, 0.60437, 0.07478, -0.18704, -0.072493, 0.02096,
         0.013396, -0.00072764, -0.00080732, 1.5624e-05),
        (0.0066, 301.0), _HIESINGER_2016),
    ProductionFunction(
        "Ida, Schmedemann et al (2014)",
        (-3.224142138786374, -2.734469281506526, 0.671929065421138, 0.324530500059052,
         -0.117050908572989, -0.061444221371560, 0.025122353823233, -0.016168430276488,
         -0.010553901203146, 0.006314954709733, 0.001418988794371, -0.000624930348572),
        (0.01, 500.0), _SCHMEDEMANN_2014),
    ProductionFunction(
        "Gaspra, Schmedemann et al (2014)",
        (-2.994946069972350, -2.837652592429328, 0.588639686417394, 0.362687108451849,
         -0.090567764875174, -0.081316576656523, 0.033630503955855, -0.005110350246025,
         -0.015222706637551, 0.004495261079555, 0.002050010873481, -0.000613330653994),
        (0.01, 500.0), _SCHMEDEMANN_2014),
    ProductionFunction(
        "Lutetia, Schmedemann et al (2014)",
        (-3.196962504355302, -2.750391206930112, 0.655546915146280, 0.320959334276113,
         -0.101901273684199, -0.051678170720090, 0.016546774685667, -0.020969106448107,
         -0.008409482560258, 0.007003716267793, 0.001211905612587, -0.000637909708634),
        (0.01, 500.0), _SCHMEDEMANN_2014),
    ProductionFunction(
        "Phobos, Case A - SOM, Schmedemann et al (2014)",
        (-2.5489, -2.9794, 0.42605, 0.32288, -0.030823, -0.022295, 0.019473, -0.022278,
         -0.0085611, 0.0053854, 0.00087331, -0.0003887),
        (0.01, 10.0), _SCHMEDEMANN_PHOBOS_2014),
    ProductionFunction(
        "Phobos, Case B - MBA, Schmedemann et al (2014)",
        (-2.8783, -2.8687, 0.53853, 0.30803, -0.048714, -0.018894, 0.00371, -0.025344,
         -0.0033966, 0.005711, 0.0004281, -0.00036638),
        (0.01, 10.0), _SCHMEDEMANN_PHOBOS_2014),
)}

# --------------------------------------------------------------------------- chronology
_CF = {cf.name: cf for cf in (
    ChronologyFunction("Moon, Neukum (1983)", (5.44e-14, 6.93, 0.0, 8.38e-4), _NEUKUM_1983),
    ChronologyFunction("Moon, Neukum et al. (2001)", (5.44e-14, 6.93, 0.0, 8.38e-4),
                       _NEUKUM_2001),
    ChronologyFunction("Mars, Hartmann & Neukum (2001)", (3.22e-14, 6.93, 0.0, 4.875e-4),
                       _HARTMANN_NEUKUM_2001),
    ChronologyFunction("Mars, Ivanov (2001)", (2.68e-14, 6.93, 0.0, 4.13e-4), _IVANOV_2001),
    ChronologyFunction("Mercury, Strom & Neukum (1988)", (1.186e-13, 6.93, 0.0, 1.818e-3),
                       _STROM_NEUKUM_1988),
    ChronologyFunction("Mercury, Neukum et al. (2001)", (6.247e-14, 6.93, 0.0, 9.620e-4),
                       _NEUKUM_MERCURY_2001),
    ChronologyFunction("Vesta, Rev4, Schmedemann et al (2014)",
                       (1.28501204957199e-12, 6.93, 0.0, 0.0197948547342156),
                       _SCHMEDEMANN_2014),
    ChronologyFunction("Ceres, Hiesinger et al. (2016)", (3.79e-12, 6.93, 0.0, 0.0584),
                       _HIESINGER_2016),
    ChronologyFunction("Ida, Schmedemann et al (2014)",
                       (1.58098379906017e-12, 6.93, 0.0, 0.0243541254340518),
                       _SCHMEDEMANN_2014),
    ChronologyFunction("Gaspra, Schmedemann et al (2014)",
                       (2.63540786651188e-12, 6.93, 0.0, 0.0405969079436940),
                       _SCHMEDEMANN_2014),
    ChronologyFunction("Lutetia, Schmedemann et al (2014)",
                       (2.04789006742868e-12, 6.93, 0.0, 0.0315465418475227),
                       _SCHMEDEMANN_2014),
    ChronologyFunction("Phobos, Case A - SOM, Schmedemann et al (2014)",
                       (5.24956219344925e-14, 6.93, 0.0, 0.000808981039512889),
                       _SCHMEDEMANN_PHOBOS_2014),
    ChronologyFunction("Phobos, Case B - MBA, Schmedemann et al (2014)",
                       (4.02087515959294e-12, 6.93, 0.0, 0.0619392166128471),
                       _SCHMEDEMANN_PHOBOS_2014),
)}

# --------------------------------------------------------------------------- equilibrium
#: Equilibrium (saturation) functions by short name.
EQUILIBRIUM_FUNCTIONS = types.MappingProxyType({
    "trask": EquilibriumFunction(
        "Lunar equilibrium (Trask, 1966)", (-1.1, -2.0), (0.001, 1000.0),
        "Trask, N. J. (1966) Size and spatial distribution of craters estimated from Ranger "
        "photographs. JPL Tech. Rep. 32-800, 252-263"),
    "hartmann": EquilibriumFunction(
        "Hartmann (1984)", (-1.14, -1.83), (0.001, 1000.0),
        "Hartmann, W. K. (1984) Does crater 'saturation equilibrium' occur in the solar "
        "system? Icarus 60, 56-74 (cumulative form, b0 corrected by K. Kinch 2017 as in "
        "craterstats)"),
})


@dataclasses.dataclass(frozen=True, slots=True)
class ChronologySystem:
    """A body's production function paired with its chronology (a craterstats
    "chronology system"): what ``npf=NAME`` in a crater layer means."""

    key: str
    """Short name (a key of :data:`CHRONOLOGY_SYSTEMS`)."""
    title: str
    """craterstats' name of the chronology system (its ``-cs`` argument)."""
    body: str
    """The body it applies to."""
    body_radius_m: float
    """Mean radius of that body, metres (the axes of an ``.scc`` file)."""
    production: ProductionFunction
    """The production function (the shape of the size distribution)."""
    chronology: ChronologyFunction
    """The chronology (N(>1 km) against age)."""

    @property
    def d_range_m(self) -> tuple[float, float]:
        """Diameters (metres) on which the production function is valid."""
        lo, hi = self.production.d_range_km
        return lo * 1e3, hi * 1e3


def _system(key, title, body, radius_km, pf, cf) -> ChronologySystem:
    return ChronologySystem(key, title, body, radius_km * 1e3, _PF[pf], _CF[cf])


_MOON_2001 = "Moon, Neukum et al. (2001)"
_MERCURY_2001 = "Mercury, Neukum et al. (2001)"
_SN88 = "Mercury, Strom & Neukum (1988)"
_VESTA = "Vesta, Rev4, Schmedemann et al (2014)"
_CERES = "Ceres, Hiesinger et al. (2016)"
_PHOBOS_A = "Phobos, Case A - SOM, Schmedemann et al (2014)"
_PHOBOS_B = "Phobos, Case B - MBA, Schmedemann et al (2014)"

#: Chronology systems by short name (radii: Moon 1737.4 km, Mars 3389.5 km, Mercury
#: 2439.4 km (IAU 2015, Archinal et al. 2018), Vesta 262.7 km (Russell et al. 2012),
#: Ceres 469.7 km (Park et al. 2016), Ida 15.7 km, Gaspra 6.1 km (Thomas et al. 1994, 1996),
#: Lutetia 49 km (Sierks et al. 2011), Phobos 11.08 km (Willner et al. 2014)).
CHRONOLOGY_SYSTEMS = types.MappingProxyType({s.key: s for s in (
    _system("moon", _MOON_2001, "Moon", 1737.4, _MOON_2001, _MOON_2001),
    _system("moon-neukum-1983", "Moon, Neukum (1983)", "Moon", 1737.4, "Moon, Neukum (1983)",
            "Moon, Neukum (1983)"),
    _system("mars", "Mars, Neukum-Ivanov (2001)", "Mars", 3389.5, "Mars, Ivanov (2001)",
            "Mars, Hartmann & Neukum (2001)"),
    _system("mars-ivanov-2001", "Mars, Ivanov (2001)", "Mars", 3389.5, "Mars, Ivanov (2001)",
            "Mars, Ivanov (2001)"),
    _system("mercury", _MERCURY_2001, "Mercury", 2439.4, _MERCURY_2001, _MERCURY_2001),
    _system("mercury-strom-neukum-1988", _SN88, "Mercury", 2439.4, _SN88, _SN88),
    _system("vesta", _VESTA, "Vesta", 262.7, _VESTA, _VESTA),
    _system("ceres", _CERES, "Ceres", 469.7, _CERES, _CERES),
    _system("ida", "Ida, Schmedemann et al (2014)", "Ida", 15.7,
            "Ida, Schmedemann et al (2014)", "Ida, Schmedemann et al (2014)"),
    _system("gaspra", "Gaspra, Schmedemann et al (2014)", "Gaspra", 6.1,
            "Gaspra, Schmedemann et al (2014)", "Gaspra, Schmedemann et al (2014)"),
    _system("lutetia", "Lutetia, Schmedemann et al (2014)", "Lutetia", 49.0,
            "Lutetia, Schmedemann et al (2014)", "Lutetia, Schmedemann et al (2014)"),
    _system("phobos-som", _PHOBOS_A, "Phobos", 11.08, _PHOBOS_A, _PHOBOS_A),
    _system("phobos-mba", _PHOBOS_B, "Phobos", 11.08, _PHOBOS_B, _PHOBOS_B),
)})


def get_chronology_system(name, *, parameter: str = "npf") -> ChronologySystem:
    """The :class:`ChronologySystem` called ``name`` (a key of
    :data:`CHRONOLOGY_SYSTEMS`); ParameterError under ``parameter`` otherwise.

    Examples
    --------
    >>> get_chronology_system("moon").title
    'Moon, Neukum et al. (2001)'
    """
    if isinstance(name, ChronologySystem):
        return name
    system = CHRONOLOGY_SYSTEMS.get(name) if isinstance(name, str) else None
    if system is None:
        raise ParameterError(parameter, f"must be one of {', '.join(CHRONOLOGY_SYSTEMS)}; "
                             f"got {name!r}")
    return system


def get_equilibrium(name, *, parameter: str = "equilibrium") -> EquilibriumFunction:
    """The :class:`EquilibriumFunction` called ``name`` (``trask`` or ``hartmann``)."""
    if isinstance(name, EquilibriumFunction):
        return name
    eq = EQUILIBRIUM_FUNCTIONS.get(name) if isinstance(name, str) else None
    if eq is None:
        raise ParameterError(parameter, f"must be one of {', '.join(EQUILIBRIUM_FUNCTIONS)}; "
                             f"got {name!r}")
    return eq
