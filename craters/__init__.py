"""craters: crater science shared by the body (latlong) and raster (dem) pipelines.

Science only, pure functions over numpy arrays: fresh crater shapes on any target body
(simple bowls, flat floors, terraces, central peaks, peak rings; Pike 1977 and the
bodies' published laws), degradation by topographic diffusion (Fassett & Thomson 2014),
irregular rims and roughness (lunar paper III), stamping into 2-D height grids, crater
populations (power laws, or production functions and chronologies at a model age with
equilibrium) and catalogs (CSV, GeoJSON, craterstats .scc), the locally controlled
spot-noise (LCSN) crater kernels of Li et al. 2022 with their morphometry, procedural
boulders.
Imports neither ``latlong`` nor ``dem``.

::

    targets -> morphology (fresh), diffusion (ageing) -> profile -> stamp
      (numba: _stamp_kernels)
    chronology/ (production functions, chronologies, equilibrium; model-age sampling)
      -> layers (power-law and model-age layers) -> population (positions, ages)
      -> catalog (CSV, GeoJSON, craterstats .scc)
    lcsn/ (kernel, morphometry, inverse, presets; numba: _lcsn_kernels)
    boulders/ (meshes, placement)
    kernels: the numba building blocks latlong and dem compile against

The plumbing every package needs (checks, RNG, atomic files, progress, ``key=value``
specs, reports, the mesh-writer registry) is the private ``craters._shared``, and the
command line ``craters.cli``; neither is crater science.
"""

import logging
from typing import TYPE_CHECKING

from ._shared.lazy import lazy_package

if TYPE_CHECKING:  # at run time each name is imported on first use (lazy_package)
    from .boulders import (
        BoulderLayer,
        BoulderNode,
        BoulderShape,
        boulder,
        boulder_meshes,
        parse_boulder_spec,
    )
    from .catalog import (
        CATALOG_COLUMNS,
        make_catalog,
        read_catalog,
        read_scc,
        sort_oldest_first,
        validate_catalog,
        write_catalog,
        write_geojson,
        write_scc,
    )
    from .chronology import (
        CHRONOLOGY_SYSTEMS,
        EQUILIBRIUM_FUNCTIONS,
        ChronologySystem,
        cap_at_equilibrium,
        cumulative_density,
        formation_ages,
        get_chronology_system,
        sample_pf_diameters,
        saturation_diameter_m,
    )
    from .diffusion import kappa_m2_yr, profile_tables, tau_from_age, tau_from_degradation
    from .layers import LAYER_TYPES, ModelAgeLayer, as_crater_layer
    from .lcsn import (
        LCSN_PRESETS,
        LcsnParams,
        lcsn_degrade,
        lcsn_kernel,
        lcsn_morphometry,
        lcsn_raw,
        lcsn_scaled,
    )
    from .morphology import fresh_morphometry, fresh_profile, morphology_class
    from .population import (
        CraterLayer,
        expected_count,
        fit_power_law_exponent,
        parse_layer_spec,
        population,
        power_law_population,
        sample_power_law_diameters,
        uniform_sphere_directions,
    )
    from .profile import (
        DEFAULT_EJECTA_EDGE,
        crater_morphometry,
        crater_tau,
        radial_profile,
        slope_erosion,
    )
    from .stamp import (
        Crater,
        Roughness,
        StampingProfiles,
        as_stamped,
        rim_perturbations,
        stamp,
        stamp_many,
        stamping_profiles,
    )
    from .targets import TARGETS, Target, get_target, small_body

__all__ = [
    "BoulderLayer",
    "CATALOG_COLUMNS",
    "BoulderNode",
    "BoulderShape",
    "CHRONOLOGY_SYSTEMS",
    "ChronologySystem",
    "DEFAULT_EJECTA_EDGE",
    "EQUILIBRIUM_FUNCTIONS",
    "LAYER_TYPES",
    "LCSN_PRESETS",
    "TARGETS",
    "Target",
    "Crater",
    "CraterLayer",
    "LcsnParams",
    "ModelAgeLayer",
    "Roughness",
    "StampingProfiles",
    "as_crater_layer",
    "as_stamped",
    "boulder",
    "boulder_meshes",
    "cap_at_equilibrium",
    "crater_morphometry",
    "crater_tau",
    "cumulative_density",
    "expected_count",
    "fit_power_law_exponent",
    "fresh_morphometry",
    "fresh_profile",
    "parse_boulder_spec",
    "parse_layer_spec",
    "formation_ages",
    "get_chronology_system",
    "get_target",
    "kappa_m2_yr",
    "lcsn_degrade",
    "lcsn_kernel",
    "lcsn_morphometry",
    "lcsn_raw",
    "lcsn_scaled",
    "make_catalog",
    "morphology_class",
    "population",
    "power_law_population",
    "profile_tables",
    "radial_profile",
    "read_catalog",
    "read_scc",
    "rim_perturbations",
    "sample_pf_diameters",
    "sample_power_law_diameters",
    "saturation_diameter_m",
    "slope_erosion",
    "small_body",
    "sort_oldest_first",
    "stamp",
    "stamp_many",
    "stamping_profiles",
    "tau_from_age",
    "tau_from_degradation",
    "uniform_sphere_directions",
    "validate_catalog",
    "write_catalog",
    "write_geojson",
    "write_scc",
]

lazy_package(__name__)

logging.getLogger(__name__).addHandler(logging.NullHandler())
