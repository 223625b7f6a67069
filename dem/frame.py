"""Local metric frames: where craters and meshes of a DEM (stack) live, in metres.

A :class:`LocalFrame` maps world coordinates (CRS units) to metres around an origin:

    x = (X - X0) * scale_x,    y = (Y - Y0) * scale_y

* projected CRS: ``scale_x = scale_y`` = the CRS's linear unit in metres (a translation);
* geographic CRS: an *equirectangular* frame tangent at the origin's latitude ``phi0``:
  ``scale_x = R * u * cos(phi0)``, ``scale_y = R * u`` (``R`` the body radius, ``u`` the
  angular unit in radians), exact along the meridian and parallel through the origin,
  with a relative scale error ~ ``tan(phi0) * dy / R`` away from them;
* no CRS: the DEM's ``pixel_size_m`` over the pixel's length in world units.

x grows towards larger world X (east for a usual map), y towards larger world Y (north),
so with z = height up the frame is right-handed. Crater catalogs of :func:`dem.enhance`,
the positions given to :func:`dem.fill_crater_gaps` / :func:`dem.replace_crater` and the
vertices of :func:`dem.to_mesh` are all in such a frame (a stack's frame has its origin
at the target pixel; a single DEM's at its centre pixel, ``rows // 2, cols // 2``).

Stamping (``craters.stamp_many``) uses the *grid frame* of a DEM instead: pixel
(row i, col j) centred at ``(j p, i p)`` with square pixels of ``p`` metres. The two
differ by an affine map (:func:`grid_affine`); pixels must be square in the local frame
to within :data:`SQUARE_TOLERANCE` (a geographic CRS away from the equator is not: use a
projection with square pixels, e.g. polar stereographic, or equirectangular with a true
scale latitude at the site).
"""

from __future__ import annotations

import dataclasses
import math
import re

import numpy as np
from affine import Affine

import craters
from craters._shared import check_finite, check_positive

from .core import Dem, crs_label

__all__ = ["SQUARE_TOLERANCE", "LocalFrame", "body_axes_m", "body_name", "crater_target",
           "geographic_crs", "grid_affine", "grid_pixel_size", "local_frame", "pixel_affine",
           "resolve_frame", "world_to_lonlat"]

#: Largest relative difference of the two pixel sides (and cosine of the angle between
#: them) accepted for stamping craters into a DEM.
SQUARE_TOLERANCE = 0.01


@dataclasses.dataclass(frozen=True, slots=True)
class LocalFrame:
    """A local metric frame: world coordinates -> metres around an origin (module notes)."""

    origin_x: float
    """World X of the origin, CRS units."""
    origin_y: float
    """World Y of the origin, CRS units."""
    scale_x: float
    """Metres per world unit along X (> 0)."""
    scale_y: float
    """Metres per world unit along Y (> 0)."""
    kind: str = "projected"
    """How the scales were derived: ``projected``, ``equirectangular`` or ``pixel``."""

    def __post_init__(self):
        check_finite("origin_x", self.origin_x)
        check_finite("origin_y", self.origin_y)
        check_positive("scale_x", self.scale_x)
        check_positive("scale_y", self.scale_y)
        if self.kind not in ("projected", "equirectangular", "pixel"):
            raise ValueError(f"`kind` must be projected, equirectangular or pixel; "
                             f"got {self.kind!r}")

    @property
    def affine(self) -> Affine:
        """World coordinates -> local metres."""
        return (Affine.scale(self.scale_x, self.scale_y)
                @ Affine.translation(-self.origin_x, -self.origin_y))

    def to_local(self, x, y) -> tuple[np.ndarray, np.ndarray]:
        """Local metres of world coordinates ``(x, y)`` (CRS units)."""
        x = np.asarray(x, dtype=np.float64)
        y = np.asarray(y, dtype=np.float64)
        return (x - self.origin_x) * self.scale_x, (y - self.origin_y) * self.scale_y

    def to_world(self, x_m, y_m) -> tuple[np.ndarray, np.ndarray]:
        """World coordinates (CRS units) of local metres ``(x_m, y_m)``."""
        x_m = np.asarray(x_m, dtype=np.float64)
        y_m = np.asarray(y_m, dtype=np.float64)
        return x_m / self.scale_x + self.origin_x, y_m / self.scale_y + self.origin_y

    def to_dict(self) -> dict:
        """A JSON-ready description (the manifest of a stack)."""
        return {"origin_world": [self.origin_x, self.origin_y],
                "metres_per_unit": [self.scale_x, self.scale_y], "kind": self.kind,
                "axes": "x = (X - X0) * sx (east), y = (Y - Y0) * sy (north), z = height, "
                        "metres"}

    @classmethod
    def from_dict(cls, d: dict) -> LocalFrame:
        """Inverse of :meth:`to_dict`."""
        try:
            (ox, oy), (sx, sy) = d["origin_world"], d["metres_per_unit"]
            return cls(float(ox), float(oy), float(sx), float(sy), str(d["kind"]))
        except (KeyError, TypeError, ValueError) as exc:
            raise ValueError(f"bad local frame description {d!r}: {exc}") from None


def local_frame(dem: Dem, origin=None) -> LocalFrame:
    """The local metric frame of ``dem`` with its origin at pixel ``origin`` (row, col).

    Default origin: the centre pixel ``(rows // 2, cols // 2)``. See the module notes.

    Examples
    --------
    >>> from affine import Affine
    >>> d = Dem(np.zeros((5, 5)), Affine(10.0, 0, 500.0, 0, -10.0, 800.0), "EPSG:32633")
    >>> f = local_frame(d)
    >>> [float(v) for v in f.to_local(525.0, 775.0)]   # centre of pixel (2, 2)
    [0.0, 0.0]
    >>> [float(v) for v in f.to_local(535.0, 775.0)]   # one pixel east
    [10.0, 0.0]
    """
    if not isinstance(dem, Dem):
        raise TypeError(f"`dem` must be a Dem; got {type(dem).__name__}")
    rows, cols = dem.shape
    r, c = (rows // 2, cols // 2) if origin is None else origin
    ox, oy = (float(v) for v in dem.xy(r, c))
    crs = dem.crs
    if crs is None:
        t = dem.transform
        px, py = dem.pixel_size_m
        return LocalFrame(ox, oy, px / math.hypot(t.a, t.d), py / math.hypot(t.b, t.e),
                          "pixel")
    if crs.is_geographic:
        rad = crs.units_factor[1]
        radius = dem.body_radius_m  # a geographic Dem always has one
        coslat = math.cos(oy * rad)
        if coslat < 1e-6:
            raise ValueError(f"the frame origin (latitude {oy:g}, {crs_label(crs)}) is at a "
                             f"pole: an equirectangular frame is degenerate there; use a polar "
                             f"projection")
        return LocalFrame(ox, oy, radius * rad * coslat, radius * rad, "equirectangular")
    unit = crs.linear_units_factor[1]
    return LocalFrame(ox, oy, unit, unit, "projected")


def resolve_frame(dem: Dem, frame: LocalFrame | None = None) -> LocalFrame:
    """``frame``, or the default frame of ``dem`` (:func:`local_frame`) if None; checks
    that ``dem`` is a Dem and ``frame`` a LocalFrame."""
    if not isinstance(dem, Dem):
        raise TypeError(f"`dem` must be a Dem; got {type(dem).__name__}")
    if frame is None:
        return local_frame(dem)
    if not isinstance(frame, LocalFrame):
        raise TypeError(f"`frame` must be a LocalFrame; got {type(frame).__name__}")
    return frame


def pixel_affine(dem: Dem, frame: LocalFrame) -> Affine:
    """Pixel-centre indices ``(col, row)`` of ``dem`` -> local metres of ``frame``."""
    return frame.affine @ dem.transform @ Affine.translation(0.5, 0.5)


def grid_pixel_size(a: Affine, what: str = "the DEM", *, square: bool = True) -> float:
    """Side ``p`` (metres) of the square pixels of a pixel affine ``a``.

    Raises ValueError if the pixels are not square within :data:`SQUARE_TOLERANCE`
    (with ``square=False``: the side of a square of the same area, unchecked).
    """
    lx, ly = math.hypot(a.a, a.d), math.hypot(a.b, a.e)
    cosang = abs(a.a * a.b + a.d * a.e) / (lx * ly)
    if square and (abs(lx / ly - 1.0) > SQUARE_TOLERANCE or cosang > SQUARE_TOLERANCE):
        raise ValueError(
            f"craters need square pixels: {what} has pixels of {lx:.6g} x {ly:.6g} m in its "
            f"local frame (tolerance {100 * SQUARE_TOLERANCE:g} %); reproject it to a CRS "
            f"with square pixels at the site (e.g. polar stereographic, or equirectangular "
            f"with the site's latitude of true scale)")
    return math.sqrt(lx * ly)


def grid_affine(a: Affine, pixel_m: float) -> Affine:
    """Local metres -> the stamping grid frame (``x = col p``, ``y = row p``) of a DEM
    whose pixel affine is ``a``."""
    return Affine.scale(pixel_m) @ ~a


# the PROJ parameters that say which body (sphere or ellipsoid) a CRS lives on
_BODY_KEYS = ("R", "a", "b", "rf", "f", "ellps", "datum", "pm", "towgs84")


def _body_of(crs) -> dict:
    """The PROJ parameters of the sphere or ellipsoid ``crs`` lives on ({} for none)."""
    return {} if crs is None else {k: v for k, v in crs.to_dict().items() if k in _BODY_KEYS}


def geographic_crs(crs):
    """The longitude/latitude CRS (degrees, east) of the sphere or ellipsoid ``crs`` lives
    on -- the IAU_2015 (or EPSG) CRS of that body when PROJ identifies one (the Moon's
    sphere: ``IAU_2015:30100``) -- or None when ``crs`` names no body."""
    from rasterio.crs import CRS
    from rasterio.errors import CRSError

    body = _body_of(crs)
    if not body:
        return None
    try:
        geo = CRS.from_dict({"proj": "longlat", **body})
    except CRSError:
        return None
    code = geo.to_authority(confidence_threshold=50)
    return CRS.from_user_input(":".join(code)) if code else geo


def body_name(geo) -> str:
    """The body of a geographic CRS, from its name (``Moon (2015) - Sphere / Ocentric``:
    ``Moon``; ``WGS 84``)."""
    m = re.match(r'\s*\w+\["([^"(]*)', geo.to_wkt())
    return m.group(1).strip() if m else "unknown"


def world_to_lonlat(crs, x, y):
    """Longitude and latitude (degrees) on the body of ``crs`` of world coordinates
    ``(x, y)`` (CRS units), or None if ``crs`` is None or names no body (then positions
    on the body are unknown). A geographic CRS gives them directly (in degrees); a
    projected one is inverted onto the longitude/latitude system of its own sphere or
    ellipsoid (``rasterio.warp.transform``)."""
    x = np.asarray(x, dtype=np.float64)
    y = np.asarray(y, dtype=np.float64)
    if crs is None:
        return None
    if crs.is_geographic:
        deg = math.degrees(crs.units_factor[1])
        return x * deg, y * deg
    from rasterio.crs import CRS
    from rasterio.errors import CRSError
    from rasterio.warp import transform

    body = _body_of(crs)
    if not body or not x.size:
        return (x.copy(), y.copy()) if body else None
    try:
        lon, lat = transform(crs, CRS.from_dict({"proj": "longlat", **body}), x, y)
    except CRSError:
        return None
    return np.asarray(lon, dtype=np.float64), np.asarray(lat, dtype=np.float64)


def body_axes_m(crs, body_radius_m: float | None = None):
    """The three semi-axes (metres) of the body of ``crs`` (``body_radius_m`` if given: a
    sphere), read from its WKT ``SPHEROID``/``ELLIPSOID[name, a, inverse flattening]``
    (0 = a sphere), or None if unknown."""
    if body_radius_m is not None:
        r = check_positive("body_radius_m", body_radius_m)
        return (r, r, r)
    if crs is None:
        return None
    m = re.search(r'(?:SPHEROID|ELLIPSOID)\["[^"]*",\s*([0-9.eE+-]+),\s*([0-9.eE+-]+)',
                  crs.to_wkt())
    if m is None:
        return None
    a, rf = float(m.group(1)), float(m.group(2))
    b = a if rf == 0 else a * (1.0 - 1.0 / rf)
    return (a, a, b)


def crater_target(dem: Dem, body: str | None = None, gravity_m_s2: float | None = None):
    """The craters' target body on ``dem``: ``body`` if given, else the body its CRS names
    (Moon, Mars, Mercury ...; e.g. IAU_2015:30100 is the Moon), else the Moon.

    Examples
    --------
    >>> crater_target(Dem(np.zeros((3, 3)), pixel_size_m=1.0)).name
    'moon'
    """
    if body is None:
        label = "" if dem.crs is None else dem.crs.to_wkt().lower()
        iau = {"iau_2015:301": "moon", "iau_2015:499": "mars", "iau_2015:199": "mercury",
               "iau_2015:399": "earth"}
        body = next((name for name in craters.TARGETS if name in label), None)
        if body is None:
            auth = dem.crs.to_authority() if dem.crs is not None else None
            code = ":".join(auth).lower() if auth else ""
            body = next((v for k, v in iau.items() if code.startswith(k)), "moon")
    return craters.get_target(body, gravity_m_s2=gravity_m_s2)
