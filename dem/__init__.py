"""dem: digital elevation models: GeoTIFF/PDS I/O, RMD expansion, gap filling, statistics.

Martin et al. (lunar crater model and DEM enhancement, IV): random-midpoint-displacement
expansion of real DEMs and outside-in fractal gap filling, on a :class:`Dem` that keeps
the georeferencing. See ``dem --help`` for the command line.
"""

import logging

from .core import Dem
from .io import read, write

__all__ = [
    "Dem",
    "read",
    "write",
]

logging.getLogger(__name__).addHandler(logging.NullHandler())
