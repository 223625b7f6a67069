"""A CRS's authority code kept through GeoTIFFs whose keys cannot hold it (IAU codes).

A GeoTIFF stores a CRS as GeoTIFF keys; GDAL reads an EPSG code back, and a planetary
CRS of the IAU (``IAU_2015:30100``, the Moon) often by its name, but many IAU CRSs
(polar stereographic ``IAU_2015:30135``, the west-positive ``IAU_2015:49901`` of Mars)
come back as a CRS without a code, a little different from the original (another
polar stereographic variant, the longitude axis east). :func:`dem.write` then also
writes the code in the tag ``CRATERFORM_CRS``, and :func:`dem.read` gives back the
coded CRS when the file's CRS is exactly what a GeoTIFF of that code reads back as (a
file reprojected since, tags copied, keeps its own CRS).
"""

from __future__ import annotations

import functools
import logging
import warnings

from rasterio.crs import CRS
from rasterio.errors import CRSError, NotGeoreferencedWarning
from rasterio.io import MemoryFile

__all__ = ["CRS_TAG", "check_crs", "crs_tags", "restore_crs"]

logger = logging.getLogger(__name__)

#: GeoTIFF tag: the authority code (``AUTHORITY:CODE``) of a CRS the GeoTIFF keys lose.
CRS_TAG = "CRATERFORM_CRS"


@functools.lru_cache(maxsize=64)
def _geotiff_crs(wkt: str):
    """The CRS a GeoTIFF written with the CRS ``wkt`` reads back as (None if none)."""
    with warnings.catch_warnings(), MemoryFile() as mem:
        warnings.simplefilter("ignore", NotGeoreferencedWarning)
        with mem.open(driver="GTiff", width=1, height=1, count=1, dtype="uint8",
                      crs=CRS.from_wkt(wkt)):
            pass
        with mem.open() as ds:
            return ds.crs


def _code(crs) -> str | None:
    """``AUTHORITY:CODE`` the CRS itself carries (not a guess), or None."""
    found = crs.to_authority(confidence_threshold=100)
    return None if found is None else ":".join(found)


def crs_tags(crs) -> dict:
    """``{CRS_TAG: code}`` when a GeoTIFF of ``crs`` would lose its code, else ``{}``.

    Examples
    --------
    >>> crs_tags(CRS.from_user_input("IAU_2015:30135"))  # Moon, south polar stereographic
    {'CRATERFORM_CRS': 'IAU_2015:30135'}
    >>> crs_tags(CRS.from_epsg(32633)), crs_tags(None)  # GeoTIFF keys keep EPSG codes
    ({}, {})
    """
    if crs is None:
        return {}
    crs = CRS.from_user_input(crs)
    code = _code(crs)
    if code is None:
        return {}
    back = _geotiff_crs(crs.to_wkt())
    return {} if back is not None and _code(back) == code else {CRS_TAG: code}


def restore_crs(crs, tags: dict, where: str):
    """The coded CRS of a file craterform wrote (``tags[CRS_TAG]``, removed from
    ``tags``) if the file's ``crs`` is what a GeoTIFF of that code reads back as; else
    ``crs`` (a stale or malformed tag is logged and dropped)."""
    code = tags.pop(CRS_TAG, None)
    if code is None or crs is None:
        return crs
    try:
        coded = CRS.from_user_input(code)
    except CRSError:
        logger.warning("%s: ignoring the tag %s = %r (not a CRS code)", where, CRS_TAG, code)
        return crs
    if _geotiff_crs(coded.to_wkt()) == crs:
        return coded
    logger.warning("%s: ignoring the tag %s = %r: the file's CRS is another", where, CRS_TAG,
                   code)
    return crs


def check_crs(crs, parameter: str = "crs"):
    """``crs`` (a code such as ``IAU_2015:30100``, a WKT, a PROJ string or a CRS) as a
    rasterio CRS, or a one-line error naming ``parameter``."""
    import rasterio

    from craters._shared import ParameterError

    try:
        with rasterio.Env():  # GDAL's messages go to logging, not to stderr
            return crs if isinstance(crs, CRS) else CRS.from_user_input(crs)
    except (CRSError, TypeError, ValueError):
        raise ParameterError(parameter, f"must be a CRS PROJ knows (a code such as "
                             f"IAU_2015:30100, a WKT or a PROJ string); got {crs!r}") from None
