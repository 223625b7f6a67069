"""craters: crater science shared by the body (latlong) and raster (dem) pipelines.

Pure functions over numpy arrays: crater profiles, degradation, populations and
catalogs. Imports neither ``latlong`` nor ``dem``.
"""

import logging

__all__: list[str] = []

logging.getLogger(__name__).addHandler(logging.NullHandler())
