"""Terrain on demand: the scene's surface at any points and any resolution, computed from
what is near each point only (:mod:`latlong.ondemand.field`), so the same bytes come back
whichever other points are asked with it, on one core or many.

::

    base (BaseField: the base shape by direction)
      -> field (CraterField: catalogue by cells, crater bases, composition)
      -> heights_at (points), tile (windows: checked first by window), descent

The names load on first use (:mod:`craters._shared.lazy`): a command line checks a
window's size (:mod:`latlong.ondemand.window`) before the field's kernels load.
"""

from typing import TYPE_CHECKING

from craters._shared.lazy import lazy_package

if TYPE_CHECKING:  # at run time each name is imported on first use (lazy_package)
    from .base import BaseField, base_field
    from .field import CraterField, crater_field, heights_at_units
    from .points import heights_at, units_of

__all__ = ["BaseField", "CraterField", "base_field", "crater_field", "heights_at",
           "heights_at_units", "units_of"]
lazy_package(__name__)
