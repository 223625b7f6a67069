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
from .degradation import (
    DegradationModel,
    degradation_factors,
    degradation_from_age,
    slope_erosion,
)
from .lcsn import (
    LCSN_PRESETS,
    LcsnParams,
    lcsn_degrade,
    lcsn_kernel,
    lcsn_morphometry,
    lcsn_raw,
    lcsn_scaled,
)
from .morphometry import (
    MORPHOMETRY_PRESETS,
    Morphometry,
    fresh_depth,
    fresh_rim_height,
    get_morphometry,
)
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
from .profile import DEFAULT_EJECTA_EDGE, ProfileParams, profile_params, radial_profile
from .stamp import Crater, Roughness, rim_perturbations, stamp, stamp_many
from .targets import TARGETS, Target, get_target, small_body

__all__ = [
    "BoulderLayer",
    "BoulderNode",
    "BoulderShape",
    "DEFAULT_EJECTA_EDGE",
    "LCSN_PRESETS",
    "MORPHOMETRY_PRESETS",
    "TARGETS",
    "Target",
    "Crater",
    "CraterLayer",
    "DegradationModel",
    "LcsnParams",
    "Morphometry",
    "ProfileParams",
    "Roughness",
    "boulder",
    "boulder_meshes",
    "boulder_normals",
    "degradation_factors",
    "degradation_from_age",
    "expected_count",
    "fit_power_law_exponent",
    "parse_boulder_spec",
    "parse_layer_spec",
    "fresh_depth",
    "fresh_rim_height",
    "get_morphometry",
    "get_target",
    "lcsn_degrade",
    "lcsn_kernel",
    "lcsn_morphometry",
    "lcsn_raw",
    "lcsn_scaled",
    "make_catalog",
    "population",
    "power_law_population",
    "profile_params",
    "radial_profile",
    "read_catalog",
    "rim_perturbations",
    "sample_power_law_diameters",
    "slope_erosion",
    "small_body",
    "sort_oldest_first",
    "stamp",
    "stamp_many",
    "uniform_sphere_directions",
    "validate_catalog",
    "write_catalog",
    "write_geojson",
]

logging.getLogger(__name__).addHandler(logging.NullHandler())
