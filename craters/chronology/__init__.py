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
