"""The :class:`Dem` data object: heights, georeferencing and pixel size in metres."""

from __future__ import annotations

import json
import math
import numbers
import re
from types import MappingProxyType

import numpy as np
from affine import Affine
from rasterio.coords import BoundingBox
from rasterio.crs import CRS
from rasterio.errors import CRSError
from rasterio.windows import Window

from craters._shared import (
    ParameterError,
    ParameterTypeError,
    about,
    check_int,
    check_positive,
    check_range,
    package_version,
)

from .crscode import check_crs

__all__ = ["Dem", "HISTORY_TAG", "crs_label", "crs_sphere_radius_m", "parse_region",
           "raster_pixel_size_m"]

#: GeoTIFF tag holding the JSON list of craterform steps that made a layer.
HISTORY_TAG = "CRATERFORM_HISTORY"
#: Tags holding the layer's place on the global pixel lattice (see :attr:`Dem.level`).
LEVEL_TAG = "CRATERFORM_LEVEL"
#: Tag holding the body radius (metres) of a DEM craterform wrote.
RADIUS_TAG = "CRATERFORM_BODY_RADIUS_M"
#: Body radii a DEM may have, metres (a boulder to a gas giant): pixel sizes in metres
#: stay finite and non-zero.
BODY_RADIUS_RANGE_M = (1e-3, 1e9)
#: Tag holding the pixel size "x,y" (metres) of a DEM without CRS that craterform wrote.
PIXEL_SIZE_TAG = "CRATERFORM_PIXEL_SIZE_M"
ORIGIN_TAG = "CRATERFORM_ORIGIN"


def _readonly(a: np.ndarray) -> np.ndarray:
    a.setflags(write=False)
    return a


def _pixel_pair(name: str, value) -> tuple[float, float]:
    """A pixel size given as one number or an (x, y) pair, in metres, > 0."""
    if isinstance(value, numbers.Real) and not isinstance(value, bool):
        v = check_positive(name, value)
        return v, v
    try:
        x, y = value
    except (TypeError, ValueError):
        raise TypeError(f"`{name}` must be a number or an (x, y) pair of numbers; "
                        f"got {value!r}") from None
    return check_positive(name, x), check_positive(name, y)


def crs_label(crs: CRS | None) -> str:
    """A short name for a CRS: its authority code, else the name in its WKT."""
    if crs is None:
        return "none"
    auth = crs.to_authority()
    if auth:
        return ":".join(auth)
    m = re.match(r'\s*\w+\["([^"]*)"', crs.to_wkt())
    if m and m.group(1) != "unknown":
        return m.group(1)
    params = crs.to_dict()  # unnamed: "+proj=longlat +R=1737400"
    return " ".join(f"+{k}" if v is True else f"+{k}={v}" for k, v in params.items()
                    if k != "no_defs") or crs.to_string()


def parse_region(region) -> Window | BoundingBox:
    """A region of a DEM, given any way the ``dem`` package takes one (``region=`` of
    :meth:`Dem.window`, :meth:`Dem.crop` and :func:`dem.expand`; ``--region`` and the
    ``region`` config key of ``dem expand``):

    * ``(row, col, size)`` or the text ``"ROW,COL,SIZE"``: the square of ``size`` pixels
      whose top-left pixel is (``row``, ``col``), integers;
    * ``(left, bottom, right, top)`` or the text ``"LEFT,BOTTOM,RIGHT,TOP"``: bounds in
      CRS units, selecting the pixels whose centres lie inside (edges included);
    * a ``rasterio.windows.Window`` (pixels) or a ``rasterio.coords.BoundingBox``.

    Returns a Window or a BoundingBox (whether it lies inside a DEM is
    :meth:`Dem.window`'s question).

    Examples
    --------
    >>> parse_region("0,0,33")
    Window(col_off=0, row_off=0, width=33, height=33)
    >>> parse_region((10.0, 20.0, 30.0, 40.0))
    BoundingBox(left=10.0, bottom=20.0, right=30.0, top=40.0)
    """
    if isinstance(region, Window | BoundingBox):
        return region
    if isinstance(region, str):
        parts: list[str | int | float] = [p.strip() for p in region.split(",")]
        try:
            if len(parts) == 3:
                parts = [int(p) for p in parts]
            elif len(parts) == 4:
                parts = [float(p) for p in parts]
        except ValueError:
            parts = []
    elif isinstance(region, tuple | list):
        parts = list(region)
    else:
        raise ParameterTypeError("region", f"must be (row, col, size) in pixels, (left, bottom, "
                                 f"right, top) in CRS units, the same as text, a rasterio "
                                 f"Window or BoundingBox; got {type(region).__name__}")
    integral = all(isinstance(v, numbers.Integral) and not isinstance(v, bool) for v in parts)
    if len(parts) == 3 and integral:
        row, col, size = (int(v) for v in parts)
        return Window(col, row, size, size)
    if (len(parts) == 4 and all(isinstance(v, numbers.Real) and not isinstance(v, bool)
                                and math.isfinite(v) for v in parts)):
        return BoundingBox(*(float(v) for v in parts))
    raise ParameterError("region", f"must be ROW,COL,SIZE (integer pixels) or "
                         f"LEFT,BOTTOM,RIGHT,TOP (finite, CRS units); got {region!r}")


def crs_sphere_radius_m(crs: CRS | None) -> float | None:
    """The radius of a CRS whose body is a sphere (``+R=``, equal axes, the IAU codes of
    spherical bodies such as ``IAU_2015:30100``, the Moon), in metres; else None.

    Examples
    --------
    >>> crs_sphere_radius_m(CRS.from_proj4("+proj=longlat +R=1737400 +no_defs"))
    1737400.0
    >>> crs_sphere_radius_m(CRS.from_epsg(4326)) is None  # an ellipsoid: no one radius
    True
    """
    if crs is None:
        return None
    radius = crs.to_dict().get("R")
    return None if radius is None else float(radius)


def _crs_radius_text(crs: CRS) -> str:
    """The CRS's own body radius for messages ('' when it has none)."""
    params = crs.to_dict()
    radius = params.get("R", params.get("a"))
    if radius is None and params.get("datum") == "WGS84":
        radius = 6378137.0
    return f", whose ellipsoid has radius {float(radius):.7g} m" if radius else ""



def raster_pixel_size_m(transform: Affine, crs, shape, *, body_radius_m=None,
                        pixel_size_m=None) -> tuple[float, float]:
    """Pixel size (x, y) in metres of a raster of ``shape`` (what :attr:`Dem.pixel_size_m`
    is, for a raster too big to hold as a Dem): the CRS's linear units, a geographic
    CRS's degrees at the raster's centre latitude on a sphere of ``body_radius_m``, or
    ``pixel_size_m`` (only without CRS)."""
    t = transform
    sx, sy = math.hypot(t.a, t.d), math.hypot(t.b, t.e)
    if crs is None:
        if pixel_size_m is None:
            raise ParameterError("pixel_size_m", "is needed: the DEM has no CRS; give "
                                 "its pixel size in metres")
        return pixel_size_m
    if pixel_size_m is not None:
        raise ParameterError("pixel_size_m", f"is only for DEMs without a CRS; this DEM's "
                             f"CRS ({crs_label(crs)}) gives the pixel size")
    if crs.is_geographic:
        if body_radius_m is None:
            raise ParameterError(
                "body_radius_m", f"is needed: the DEM has a geographic CRS "
                f"({crs_label(crs)}){_crs_radius_text(crs)}; give the body radius in "
                f"metres to convert degrees to metres")
        rad = crs.units_factor[1]  # radians per angular unit
        rows, cols = shape
        lat_c = t.d * cols / 2.0 + t.e * rows / 2.0 + t.f
        coslat = math.cos(lat_c * rad)
        return (body_radius_m * rad * sx * abs(coslat), body_radius_m * rad * sy)
    try:
        factor = crs.linear_units_factor[1]
    except CRSError as exc:
        raise ValueError(f"cannot get a pixel size in metres from the CRS "
                         f"{crs.to_string()!r}: {exc}") from None
    return sx * factor, sy * factor


class Dem:
    """A digital elevation model: a 2-D height array plus its georeferencing.

    Heights are metres, float64, with NaN for unknown pixels. The object is immutable:
    the array is a read-only copy and every operation returns a new ``Dem``.

    The pixel size in metres comes from the CRS: a projected CRS gives it through its
    linear unit; a geographic CRS needs the body radius (``body_radius_m``) and gives
    the ground size at the DEM's centre latitude (x shrinks with cos(latitude)); a DEM
    without CRS needs an explicit ``pixel_size_m``.

    ``level`` and ``origin`` place the pixels on a global lattice used by the
    counter-based randomness of :func:`dem.expand` and :func:`dem.fill_gaps`: pixel
    ``(r, c)`` is lattice pixel ``(origin[0] + r, origin[1] + c)`` of expansion level
    ``level`` (0 for a DEM read from a file that craterform did not make). Cropping
    shifts the origin, expanding doubles it, so a tile or a sub-window gets exactly the
    random numbers the whole DEM would get.

    Parameters
    ----------
    heights : (rows, cols) array_like
        Heights in metres; NaN = unknown. Infinite values are rejected.
    transform : affine.Affine, optional
        Pixel corner -> world coordinates (default: identity).
    crs : rasterio.crs.CRS or str, optional
        Coordinate reference system (anything ``CRS.from_user_input`` accepts) or None.
    pixel_size_m : float or (float, float), optional
        Pixel size (x, y) in metres; only for DEMs without CRS, where it is required.
    body_radius_m : float, optional
        Radius of the body in metres; required with a geographic CRS, unless the CRS is
        on a sphere (``+R=``, e.g. ``IAU_2015:30100``): then that sphere's radius.
    tags : mapping of str to str, optional
        Metadata tags (kept through operations, written to GeoTIFF).
    level : int
        Expansion level of the global lattice (>= 0).
    origin : (int, int)
        Lattice index (row, col) of pixel (0, 0).

    Examples
    --------
    >>> d = Dem(np.zeros((3, 4)), pixel_size_m=2.0)
    >>> d.shape, d.pixel_size_m, d.resolution_m
    ((3, 4), (2.0, 2.0), 2.0)
    >>> d.crop(Window(1, 1, 2, 2)).origin
    (1, 1)
    """

    __slots__ = ("_h", "_transform", "_crs", "_px", "_radius", "_tags", "_level", "_origin",
                 "_own_px", "_cache")

    def __init__(self, heights, transform: Affine | None = None, crs=None, *,
                 pixel_size_m=None, body_radius_m: float | None = None, tags=None,
                 level: int = 0, origin=(0, 0)):
        if np.iscomplexobj(heights):
            raise ParameterTypeError("heights", "must be real numbers; got complex values")
        h = np.array(heights, dtype=np.float64, copy=True)
        self._init(h, transform, crs, pixel_size_m, body_radius_m, tags, level, origin)

    @classmethod
    def _own(cls, heights: np.ndarray, transform, crs, *, pixel_size_m=None,
             body_radius_m=None, tags=None, level=0, origin=(0, 0)) -> Dem:
        """Wrap a freshly made float64 array without copying it (internal)."""
        obj = cls.__new__(cls)
        obj._init(np.ascontiguousarray(heights, dtype=np.float64), transform, crs,
                  pixel_size_m, body_radius_m, tags, level, origin)
        return obj

    def _init(self, h, transform, crs, pixel_size_m, body_radius_m, tags, level, origin):
        if h.ndim != 2 or h.shape[0] < 1 or h.shape[1] < 1:
            raise ValueError(f"`heights` must be a non-empty 2-D array; got shape {h.shape}")
        if np.isinf(h).any():
            raise ValueError("`heights` must be finite or NaN (unknown); got infinite values")
        transform = Affine.identity() if transform is None else transform
        if not isinstance(transform, Affine):
            raise TypeError(f"`transform` must be an affine.Affine; got {type(transform).__name__}")
        if not math.isfinite(transform.determinant) or transform.determinant == 0:
            raise ValueError(f"`transform` must be invertible; got {tuple(transform)[:6]}")
        if crs is not None:
            crs = check_crs(crs)
        with about("body_radius_m"):
            radius = None if body_radius_m is None else check_range(
                "body_radius_m", body_radius_m, *BODY_RADIUS_RANGE_M)
        if radius is None and crs is not None and crs.is_geographic:
            radius = crs_sphere_radius_m(crs)  # a sphere's CRS gives the radius itself
        self._h = _readonly(h)
        self._transform = transform
        self._crs = crs
        self._radius = radius
        with about("pixel_size_m"):
            self._own_px = None if pixel_size_m is None else _pixel_pair("pixel_size_m",
                                                                        pixel_size_m)
        self._px = self._derive_pixel_size()
        tags = {} if tags is None else dict(tags)
        for k, v in tags.items():
            if not isinstance(k, str) or not isinstance(v, str):
                raise TypeError(f"`tags` must map str to str; got {k!r}: {v!r}")
        self._tags = MappingProxyType(tags)
        self._level = check_int("level", level, 0, 62)
        try:
            r0, c0 = origin
        except (TypeError, ValueError):
            raise TypeError(f"`origin` must be a (row, col) pair; got {origin!r}") from None
        self._origin = (check_int("origin", r0), check_int("origin", c0))
        self._cache: dict = {}

    def _derive_pixel_size(self) -> tuple[float, float]:
        return raster_pixel_size_m(self._transform, self._crs, self._h.shape,
                                   body_radius_m=self._radius, pixel_size_m=self._own_px)

    # ------------------------------------------------------------------ data
    @property
    def heights(self) -> np.ndarray:
        """Heights in metres, (rows, cols) float64, NaN = unknown, read-only."""
        return self._h

    @property
    def shape(self) -> tuple[int, int]:
        """(rows, cols)."""
        return self._h.shape

    @property
    def transform(self) -> Affine:
        """Affine transform from pixel corners (col, row) to world coordinates."""
        return self._transform

    @property
    def crs(self) -> CRS | None:
        """The coordinate reference system, or None."""
        return self._crs

    @property
    def pixel_size_m(self) -> tuple[float, float]:
        """Pixel size (x, y) in metres on the ground (at the centre latitude if geographic)."""
        return self._px

    @property
    def resolution_m(self) -> float:
        """Horizontal resolution in metres: the geometric mean of the pixel sizes."""
        return math.sqrt(self._px[0] * self._px[1])

    @property
    def body_radius_m(self) -> float | None:
        """Body radius in metres, if known."""
        return self._radius

    @property
    def tags(self) -> MappingProxyType:
        """Metadata tags (read-only mapping of str to str)."""
        return self._tags

    @property
    def level(self) -> int:
        """Expansion level of the global pixel lattice."""
        return self._level

    @property
    def origin(self) -> tuple[int, int]:
        """Lattice index (row, col) of pixel (0, 0) at :attr:`level`."""
        return self._origin

    @property
    def known(self) -> np.ndarray:
        """Boolean mask of known (finite) pixels, read-only."""
        mask = self._cache.get("known")
        if mask is None:
            mask = self._cache["known"] = _readonly(np.isfinite(self._h))
        return mask

    @property
    def nan_fraction(self) -> float:
        """Fraction of unknown (NaN) pixels."""
        return 1.0 - float(self.known.mean())

    @property
    def bounds(self) -> BoundingBox:
        """(left, bottom, right, top) of the pixel footprints in CRS units."""
        rows, cols = self.shape
        t = self._transform
        corners = ((0, 0), (cols, 0), (0, rows), (cols, rows))
        xs = [t.a * c + t.b * r + t.c for c, r in corners]
        ys = [t.d * c + t.e * r + t.f for c, r in corners]
        return BoundingBox(min(xs), min(ys), max(xs), max(ys))

    @property
    def history(self) -> list[dict]:
        """The craterform steps that made this DEM (from the history tag), oldest first."""
        text = self._tags.get(HISTORY_TAG)
        return json.loads(text) if text else []

    def xy(self, rows, cols) -> tuple[np.ndarray, np.ndarray]:
        """World coordinates of pixel centres ``(rows, cols)``."""
        rows = np.asarray(rows, dtype=np.float64) + 0.5
        cols = np.asarray(cols, dtype=np.float64) + 0.5
        t = self._transform
        return t.a * cols + t.b * rows + t.c, t.d * cols + t.e * rows + t.f

    def __repr__(self) -> str:
        px = self._px
        return (f"Dem(shape={self.shape}, crs={crs_label(self._crs)!r}, "
                f"pixel_size_m=({px[0]:.6g}, {px[1]:.6g}), "
                f"nan_fraction={self.nan_fraction:.3g}, level={self._level})")

    # ------------------------------------------------------------------ new objects
    def replace(self, *, heights=None, tags=None) -> Dem:
        """A new DEM with the same georeferencing and new ``heights`` and/or ``tags``."""
        h = self._h if heights is None else np.array(heights, dtype=np.float64, copy=True)
        if h.shape != self.shape:
            raise ValueError(f"`heights` must keep the shape {self.shape}; got {h.shape}")
        return Dem._own(h, self._transform, self._crs, pixel_size_m=self._own_px,
                        body_radius_m=self._radius,
                        tags=self._tags if tags is None else tags,
                        level=self._level, origin=self._origin)

    def with_step(self, heights: np.ndarray, op: str, seed, parameters: dict, *,
                  transform: Affine | None = None, pixel_size_m=None, level=None,
                  origin=None) -> Dem:
        """A new DEM made by a craterform step; the step is appended to the history tag.

        ``heights`` is taken over without copying (callers pass fresh arrays).
        """
        level = self._level if level is None else level
        origin = self._origin if origin is None else origin
        own_px = self._own_px if pixel_size_m is None else pixel_size_m
        return Dem._own(heights, self._transform if transform is None else transform,
                        self._crs, pixel_size_m=own_px, body_radius_m=self._radius,
                        tags=self.step_tags(op, seed, parameters, level=level, origin=origin),
                        level=level, origin=origin)

    def step_tags(self, op: str, seed, parameters: dict, *, level: int | None = None,
                  origin=None) -> dict:
        """The tags of the DEM :meth:`with_step` makes (for a result written window by
        window, which never exists as one ``Dem``): these tags, the step's
        ``CRATERFORM_*`` tags and history, the lattice level and origin."""
        history = self.history
        history.append({"op": op, "seed": seed, "parameters": parameters})
        tags = dict(self._tags)
        tags.update({
            "CRATERFORM_GENERATOR": f"craterform {op}",
            "CRATERFORM_VERSION": package_version(),
            "CRATERFORM_SEED": json.dumps(seed),
            "CRATERFORM_PARAMETERS": json.dumps(parameters, sort_keys=True),
            HISTORY_TAG: json.dumps(history, sort_keys=True),
        })
        level = self._level if level is None else level
        origin = self._origin if origin is None else origin
        if level or origin != (0, 0) or LEVEL_TAG in tags:
            tags[LEVEL_TAG] = str(level)
            tags[ORIGIN_TAG] = f"{origin[0]},{origin[1]}"
        return tags

    def window(self, region) -> Window:
        """The integer pixel window of ``region`` (any form :func:`parse_region` takes).

        Raises ValueError if the window is empty or not entirely inside the DEM.
        """
        with about("region"):
            return self._window(parse_region(region))

    def _window(self, region: Window | BoundingBox) -> Window:
        rows, cols = self.shape
        if isinstance(region, Window):
            vals = (region.row_off, region.col_off, region.height, region.width)
            if any(not float(v).is_integer() for v in vals):
                raise ParameterError("region", f"window must have integer offsets and sizes; "
                                     f"got {region!r}")
            r0, c0, h, w = (int(v) for v in vals)
        else:
            r0, c0, h, w = self._bounds_window(region)
        if h < 1 or w < 1:
            raise ParameterError("region", f"selects no pixels (rows {r0}..{r0 + h - 1}, cols "
                                 f"{c0}..{c0 + w - 1}); the DEM has {rows} x {cols} pixels")
        if r0 < 0 or c0 < 0 or r0 + h > rows or c0 + w > cols:
            raise ParameterError(
                "region", f"(rows {r0}..{r0 + h - 1}, cols {c0}..{c0 + w - 1}) is not inside "
                f"the DEM (rows 0..{rows - 1}, cols 0..{cols - 1})")
        return Window(c0, r0, w, h)

    def _bounds_window(self, box: BoundingBox) -> tuple[int, int, int, int]:
        t = self._transform
        if t.b != 0 or t.d != 0:
            raise ParameterError("region", "bounds need a north-up (unrotated) transform; "
                                 "give a pixel Window instead")
        if not (box.left <= box.right and box.bottom <= box.top):
            raise ParameterError("region", f"bounds must have left <= right and bottom <= "
                                 f"top; got {tuple(box)}")
        # the box corners in pixel index units (north-up: each axis on its own)
        c_a, c_b = (box.left - t.c) / t.a, (box.right - t.c) / t.a
        r_a, r_b = (box.top - t.f) / t.e, (box.bottom - t.f) / t.e
        c_lo, c_hi = sorted((c_a - 0.5, c_b - 0.5))
        r_lo, r_hi = sorted((r_a - 0.5, r_b - 0.5))
        eps = 1e-9  # centres on the edge count as inside despite rounding
        c0, c1 = math.ceil(c_lo - eps), math.floor(c_hi + eps)
        r0, r1 = math.ceil(r_lo - eps), math.floor(r_hi + eps)
        return r0, c0, r1 - r0 + 1, c1 - c0 + 1

    def crop(self, region) -> Dem:
        """The sub-DEM of ``region`` (see :meth:`window`), with its transform and origin."""
        win = self.window(region)
        r0, c0 = int(win.row_off), int(win.col_off)
        h = self._h[r0:r0 + int(win.height), c0:c0 + int(win.width)].copy()
        return Dem._own(h, self._transform @ Affine.translation(c0, r0), self._crs,
                        pixel_size_m=self._own_px, body_radius_m=self._radius,
                        tags=self._tags, level=self._level,
                        origin=(self._origin[0] + r0, self._origin[1] + c0))
