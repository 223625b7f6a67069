"""latlong: asteroid bodies on the evenly spaced 6M^2+2 latitude/longitude sphere mesh.

Martin et al. 2014: the lat/long mesh, two-phase Poisson faulting and Perlin fBm base
shapes, crater stamping via local DEM mapping, boulders, slopes, renderer export and
previews; and the implicit backend of Li et al. 2020/2022 (metaballs over a sphere
packing, LCSN craters, Gabor noise, marching cubes).

::

    grid (LatLongGrid) -> base radii: faulting | perlin | shapes (real models)
                       -> body (Body: radii + stretch + catalogs; .npz)
                       -> cratering (catalog on the true surface: surface; stamping)
                       -> boulders (populations, placement)
                       -> export (PLY/OBJ/STL/VTP/VTK) | gltf + strips (patches, LODs)
                          | slopes, preview
    scene (Scene: settings, presets) -> build(scene) -> Body   (writes nothing)
                                     -> outputs (write_outputs) | batch (seeds x settings, dask)
    implicit/ (packing, metaballs, LCSN layers, Gabor, marching cubes) -> to_body
    loader (load_surface: a body .npz or a mesh file -> a surface, what sensors/ see)
    sensors/ (ray engine over Embree, cameras, LIDAR, photometry: frames + ground truth of
              any surface; they use only latlong.geometry and latlong.meshio)
    cli/ (the `latlong` command; the library never imports it)

Imports point down that picture and into ``craters`` (never ``dem``). ``latlong build
--help`` describes the command line.
"""

import logging
from typing import TYPE_CHECKING

from craters._shared.lazy import lazy_package

if TYPE_CHECKING:  # at run time each name is imported on first use (lazy_package)
    from .batch import batch
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
    from .build import build
    from .cratering import body_population, crater_extents_deg, stamp_craters
    from .faulting import (
        FAULTING_PRESETS,
        FaultingParams,
        apply_faults,
        area_mean,
        poisson_faulting,
        random_faults,
        two_phase_faulting,
    )
    from .gltf import export_glb, export_vtp_strips
    from .gravity import GravityField, gravity
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
    from .loader import MeshFile, load_surface
    from .perlin import FBM_PRESETS, FbmParams, fbm3, perlin_fbm
    from .presets import PRESETS
    from .preview import PreviewSettings, render_preview
    from .scene import SETTING_DEFAULTS, SETTINGS, Scene
    from .sensors import render
    from .settings import (
        BodySettings,
        BoulderSettings,
        CraterSettings,
        ImplicitSettings,
        ShapeBase,
        SphereBase,
    )
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
    from .surface import surface_positions

__all__ = [
    "EXPORT_SUFFIXES",
    "FAULTING_PRESETS",
    "FBM_PRESETS",
    "GravityField",
    "PRESETS",
    "SETTINGS",
    "SETTING_DEFAULTS",
    "Body",
    "BodySettings",
    "BoulderSettings",
    "CraterSettings",
    "ImplicitSettings",
    "PreviewSettings",
    "Scene",
    "ShapeBase",
    "SphereBase",
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
    "MeshFile",
    "ShapeModel",
    "apply_faults",
    "area_mean",
    "batch",
    "body_population",
    "boulder",
    "boulder_meshes",
    "boulder_population",
    "boulder_world_meshes",
    "build",
    "cast_radii",
    "crater_extents_deg",
    "export_glb",
    "export_vtp_strips",
    "facet_slopes",
    "gravity",
    "fbm3",
    "fit_gabor",
    "fit_metaballs",
    "from_shape_model",
    "fwhm_to_sigma",
    "heat_smooth",
    "implicit_surface",
    "load",
    "load_surface",
    "mesh_slopes",
    "perlin_fbm",
    "place_boulders",
    "poisson_faulting",
    "radius_spectrum",
    "random_faults",
    "read_shape_model",
    "render",
    "render_preview",
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

lazy_package(__name__)

logging.getLogger(__name__).addHandler(logging.NullHandler())
