"""dem: GeoTIFF digital elevation models: expansion, gap filling, crater layers, analysis."""

import logging

__all__: list[str] = []

logging.getLogger(__name__).addHandler(logging.NullHandler())
