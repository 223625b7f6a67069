"""dem: digital elevation models: I/O, RMD expansion, gap filling, layer stacks, meshes.

::

    GeoTIFF, PDS3 --io.read--> Dem (core: heights, NaN = unknown, transform, CRS, metres)
      -> fill_gaps (gaps, gapcraters), fill_crater_gaps / replace_crater (craterfill)
      -> detect_craters, crater_density, resolved_diameter_m (craterdensity)
      -> expand (expansion: RMD, 2x per level)                              -> Dem
      -> enhance (EnhanceConfig in config, the plan in planning)            -> Stack
         batch (seeds x varied keys on dask.distributed)          -> stack folders
    Stack (stack: consistent layers + catalogs; write, read_stack)
      -> to_mesh (mesh: PLY/VTP) | slope, power_spectrum (terrain), fractal_fit (fractal)
      -> DemSurface (surface: a DEM or a stack as a latlong surface, what the camera and
         the LIDAR of latlong.sensors see)

Beside them: ``frame`` (local metric frames), ``boulders`` (boulders on rasters),
``_*kernels`` (numba) and ``cli/`` (the
``dem`` command line, which imports the library, never the reverse; ``dem --help``).

Martin et al. (lunar crater model and DEM enhancement, IV): random-midpoint-displacement
expansion of real DEMs, fractal gap filling (conditioned on the gaps' rims, with craters
at the density around large gaps), crater gap filling and crater
replacement, boulders (:func:`stamp_boulders`), multi-resolution layer stacks with
craters and boulders per layer (:func:`enhance`) and their stitched meshes
(:func:`to_mesh`), on a :class:`Dem` that keeps the georeferencing.
"""

import logging
from typing import TYPE_CHECKING

from craters._shared.lazy import lazy_package

if TYPE_CHECKING:  # at run time each name is imported on first use (lazy_package)
    from .analysis import band_power, laplacian
    from .batch import batch
    from .boulders import boulder_population, stamp_boulders
    from .config import EnhanceConfig, SourceCraterLayer
    from .core import Dem
    from .craterdensity import CraterDensity, crater_density, detect_craters, resolved_diameter_m
    from .craterfill import fill_crater_gaps, replace_crater
    from .enhance import enhance
    from .expansion import (
        ExpandedFile,
        displacement_scales,
        expand,
        expand_to_file,
        expansion_sizes,
    )
    from .fractal import (
        FractalFit,
        SpectralFit,
        dimension_warning,
        expansion_fit,
        fractal_dimension,
        fractal_fit,
        local_roughness,
        variogram,
    )
    from .frame import LocalFrame, local_frame
    from .gaps import fill_gaps
    from .io import WindowWriter, read, write
    from .mesh import to_mesh
    from .stack import Stack, read_stack
    from .surface import DemSurface
    from .terrain import (
        pixel_sizes_by_row,
        power_spectrum,
        roughness,
        slope,
        slope_distribution,
        spectral_exponent,
        spectral_fit,
    )
    from .tiledfill import FilledFile, fill_to_file

__all__ = [
    "CraterDensity",
    "Dem",
    "DemSurface",
    "EnhanceConfig",
    "ExpandedFile",
    "FilledFile",
    "SourceCraterLayer",
    "FractalFit",
    "LocalFrame",
    "SpectralFit",
    "Stack",
    "WindowWriter",
    "band_power",
    "batch",
    "boulder_population",
    "crater_density",
    "detect_craters",
    "dimension_warning",
    "displacement_scales",
    "enhance",
    "expand",
    "expand_to_file",
    "expansion_fit",
    "expansion_sizes",
    "fill_crater_gaps",
    "fill_gaps",
    "fill_to_file",
    "fractal_dimension",
    "fractal_fit",
    "laplacian",
    "local_frame",
    "local_roughness",
    "read",
    "read_stack",
    "replace_crater",
    "resolved_diameter_m",
    "pixel_sizes_by_row",
    "power_spectrum",
    "roughness",
    "slope",
    "slope_distribution",
    "spectral_exponent",
    "spectral_fit",
    "stamp_boulders",
    "to_mesh",
    "variogram",
    "write",
]

lazy_package(__name__)

logging.getLogger(__name__).addHandler(logging.NullHandler())
