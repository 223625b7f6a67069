"""craters: crater science shared by the body (latlong) and raster (dem) pipelines.

Science only, pure functions over numpy arrays: the Martin crater profile with
degradation, irregular rims and roughness (lunar paper III), stamping into 2-D height
grids, power-law crater populations and catalogs, the locally controlled spot-noise
(LCSN) crater kernels of Li et al. 2022 with their morphometry, procedural boulders.
Imports neither ``latlong`` nor ``dem``.

::

    morphometry, degradation -> profile -> stamp (numba: _stamp_kernels)
    population (layers, sizes, positions, ages) -> catalog (CSV, GeoJSON)
    lcsn/ (kernel, morphometry, inverse, presets; numba: _lcsn_kernels)
    boulders/ (meshes, placement)
    kernels: the numba building blocks latlong and dem compile against

The plumbing every package needs (checks, RNG, atomic files, progress, ``key=value``
specs, reports, the mesh-writer registry) is the private ``craters._shared``, and the
command line ``craters.cli``; neither is crater science.
"""

import logging

from .boulders import (
    BoulderLayer,
    BoulderNode,
    BoulderShape,
    boulder,
    boulder_meshes,
    boulder_normals,
    parse_boulder_spec,
)
from .catalog import (
    make_catalog,
    read_catalog,
    sort_oldest_first,
    validate_catalog,
    write_catalog,
    write_geojson,
)
from .diffusion import kappa_m2_yr, profile_tables, tau_from_age, tau_from_degradation
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
    "BoulderNode",
    "BoulderShape",
    "DEFAULT_EJECTA_EDGE",
    "LCSN_PRESETS",
    "TARGETS",
    "Target",
    "Crater",
    "CraterLayer",
    "LcsnParams",
    "Roughness",
    "StampingProfiles",
    "as_stamped",
    "boulder",
    "boulder_meshes",
    "boulder_normals",
    "crater_morphometry",
    "crater_tau",
    "expected_count",
    "fit_power_law_exponent",
    "fresh_morphometry",
    "fresh_profile",
    "parse_boulder_spec",
    "parse_layer_spec",
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
    "rim_perturbations",
    "sample_power_law_diameters",
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
]

logging.getLogger(__name__).addHandler(logging.NullHandler())
