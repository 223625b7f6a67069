"""dem: digital elevation models: GeoTIFF/PDS I/O, RMD expansion, gap filling, statistics.

Martin et al. (lunar crater model and DEM enhancement, IV): random-midpoint-displacement
expansion of real DEMs and outside-in fractal gap filling, on a :class:`Dem` that keeps
the georeferencing. See ``dem --help`` for the command line.
"""

import logging

from .analysis import band_power, laplacian, slope_deg
from .core import Dem
from .enhance import EnhanceConfig, enhance
from .expansion import displacement_scales, expand, expansion_sizes
from .fractal import FractalFit, fractal_dimension, fractal_fit, local_roughness, variogram
from .frame import LocalFrame, local_frame
from .gaps import fill_gaps
from .io import read, write
from .stack import Stack, read_stack

__all__ = [
    "Dem",
    "EnhanceConfig",
    "FractalFit",
    "LocalFrame",
    "Stack",
    "band_power",
    "displacement_scales",
    "enhance",
    "expand",
    "expansion_sizes",
    "fill_gaps",
    "fractal_dimension",
    "fractal_fit",
    "laplacian",
    "local_frame",
    "local_roughness",
    "read",
    "read_stack",
    "slope_deg",
    "variogram",
    "write",
]

logging.getLogger(__name__).addHandler(logging.NullHandler())
