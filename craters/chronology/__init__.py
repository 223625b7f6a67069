"""Production functions, chronologies and equilibrium functions: crater populations of a
given model age (what craterstats fits, run forwards).

A *chronology system* (:data:`CHRONOLOGY_SYSTEMS`, keyed by body: ``moon``, ``mars``,
``mercury``, ``vesta``, ``ceres``, ``ida``, ``gaspra``, ``lutetia``, ``phobos-som``,
``phobos-mba`` and the older ``moon-neukum-1983``, ``mars-ivanov-2001``,
``mercury-strom-neukum-1988``) pairs a production function (the shape of the crater
size-frequency distribution, Neukum's 11-degree polynomial in log D) with a chronology
(the density of craters >= 1 km against the surface's age). ``moon`` is craterstats'
"Moon, Neukum et al. (2001)" system; ``mars`` its "Mars, Neukum-Ivanov (2001)" (Ivanov
2001 production function, Hartmann & Neukum 2001 chronology).

::

    functions (the records: ProductionFunction, ChronologyFunction, EquilibriumFunction)
      -> systems (the published coefficients, CHRONOLOGY_SYSTEMS, EQUILIBRIUM_FUNCTIONS)
      -> sampling (metres: density, diameters, formation ages, saturation, equilibrium cap)

Populations by model age
------------------------
A crater layer ``npf=NAME,age_gyr=T,d_min_m=..,d_max_m=..`` (:class:`craters.ModelAgeLayer`;
the same keys on every command line, in TOML tables and in Python) takes its size
distribution from a body's production function, the 11-degree polynomial
log10 N(>D) = Σ a_j (log10 D)^j of Neukum (D in km, N per km²), scaled to
N(1 km) = c0 (exp(c1 T) − 1) + c3 T of its chronology, and each crater's formation age
from that chronology's flux: P(age ≤ t) = N1(t) / N1(T), so most craters of a 3.8 Gyr
surface formed in its first 300 Myr. ``NAME`` is a key of :data:`CHRONOLOGY_SYSTEMS`,
with coefficients from craterstats' ``functions.txt``: ``moon`` (Neukum et al. 2001
production function and chronology, craterstats' "Moon, Neukum et al. (2001)"),
``moon-neukum-1983``, ``mars`` (Ivanov 2001, Hartmann & Neukum 2001: "Mars,
Neukum-Ivanov (2001)"), ``mars-ivanov-2001``, ``mercury`` (Neukum et al. 2001),
``mercury-strom-neukum-1988``, ``vesta`` (Schmedemann et al. 2014, Rev4), ``ceres``
(Hiesinger et al. 2016), ``ida``, ``gaspra``, ``lutetia``, ``phobos-som``, ``phobos-mba``
(Schmedemann et al. 2014). Ages lie in (0, 4.5] Gyr and diameters in the production
function's valid range (the Moon's: 10 m to 300 km); a spec mixing ``npf`` with
``c``/``k``/``age_max_gyr`` is refused. ``equilibrium=trask`` (Trask 1966) or
``hartmann`` (Hartmann 1984) caps the density: wherever the production function exceeds
the equilibrium function (bins of 1/20 decade) the area keeps only the equilibrium
number of craters, the youngest (young craters erase old ones), and ``craters
population`` prints the saturation diameter where the two meet. The commands and the
round trip through craterstats are in :mod:`craters`.
"""

from .functions import ChronologyFunction, EquilibriumFunction, ProductionFunction
from .sampling import (
    cap_at_equilibrium,
    check_age,
    check_diameter_range,
    cumulative_density,
    equilibrium_bin_edges,
    equilibrium_caps,
    equilibrium_density,
    expected_survivors,
    formation_ages,
    sample_pf_diameters,
    saturation_diameter_m,
)
from .systems import (
    CHRONOLOGY_SYSTEMS,
    EQUILIBRIUM_FUNCTIONS,
    ChronologySystem,
    get_chronology_system,
    get_equilibrium,
)

__all__ = [
    "CHRONOLOGY_SYSTEMS",
    "EQUILIBRIUM_FUNCTIONS",
    "ChronologyFunction",
    "ChronologySystem",
    "EquilibriumFunction",
    "ProductionFunction",
    "cap_at_equilibrium",
    "check_age",
    "check_diameter_range",
    "cumulative_density",
    "equilibrium_bin_edges",
    "equilibrium_caps",
    "equilibrium_density",
    "expected_survivors",
    "formation_ages",
    "get_chronology_system",
    "get_equilibrium",
    "sample_pf_diameters",
    "saturation_diameter_m",
]
