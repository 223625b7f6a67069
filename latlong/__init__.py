"""latlong: asteroid bodies on the evenly spaced 6M^2+2 latitude/longitude sphere mesh.

Martin et al. 2014: the lat/long mesh, two-phase Poisson faulting and Perlin fBm base
shapes, mesh export and previews; and the implicit backend of Li et al. 2020/2022
(metaballs over a sphere packing, LCSN craters, Gabor noise, marching cubes). See
``latlong build --help`` for the command line.
"""

import logging

from .body import EXPORT_SUFFIXES, Body, load
from .boulders import (
    BoulderLayer,
    BoulderNode,
    BoulderShape,
    boulder,
    boulder_meshes,
    boulder_population,
    boulder_world_meshes,
    place_boulders,
)
from .cratering import crater_extents_deg, stamp_craters
from .faulting import (
    FAULTING_PRESETS,
    FaultingParams,
    apply_faults,
    area_mean,
    poisson_faulting,
    random_faults,
    two_phase_faulting,
)
from .grid import LatLongGrid
from .implicit import (
    GaborNoise,
    GaborPatch,
    ImplicitSurface,
    LcsnLayer,
    fit_gabor,
    fit_metaballs,
    implicit_surface,
    sphere_packing,
)
from .perlin import FBM_PRESETS, FbmParams, fbm3, perlin_fbm
from .scene import PRESETS, body_population, build_body, resolve_settings, surface_positions
from .shapes import ShapeModel, cast_radii, from_shape_model, read_shape_model
from .slopes import (
    facet_slopes,
    mesh_slopes,
    radius_spectrum,
    slope_summary,
    slopes,
    slopes_and_areas,
    vertex_normals,
)
from .smoothing import fwhm_to_sigma, heat_smooth, smooth

__all__ = [
    "EXPORT_SUFFIXES",
    "FAULTING_PRESETS",
    "FBM_PRESETS",
    "PRESETS",
    "Body",
    "BoulderLayer",
    "BoulderNode",
    "BoulderShape",
    "FaultingParams",
    "FbmParams",
    "GaborNoise",
    "GaborPatch",
    "ImplicitSurface",
    "LatLongGrid",
    "LcsnLayer",
    "ShapeModel",
    "apply_faults",
    "area_mean",
    "body_population",
    "boulder",
    "boulder_meshes",
    "boulder_population",
    "boulder_world_meshes",
    "build_body",
    "cast_radii",
    "crater_extents_deg",
    "facet_slopes",
    "fbm3",
    "fit_gabor",
    "fit_metaballs",
    "from_shape_model",
    "fwhm_to_sigma",
    "heat_smooth",
    "implicit_surface",
    "load",
    "mesh_slopes",
    "perlin_fbm",
    "place_boulders",
    "poisson_faulting",
    "radius_spectrum",
    "random_faults",
    "read_shape_model",
    "resolve_settings",
    "slope_summary",
    "slopes",
    "slopes_and_areas",
    "smooth",
    "sphere_packing",
    "stamp_craters",
    "surface_positions",
    "vertex_normals",
    "two_phase_faulting",
]

logging.getLogger(__name__).addHandler(logging.NullHandler())
