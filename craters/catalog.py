"""Crater catalogs: structured numpy arrays, CSV with units, GeoJSON (RFC 7946) points,
craterstats spatial crater counts (``.scc``).

A catalog is the ground truth that users feed to crater-detection and navigation
algorithms, so it must say exactly what was stamped. Columns (units in the names):

* position: ``lat_deg, lon_deg`` (on a body) or ``x_m, y_m`` (on a plane / DEM)
* ``diameter_m`` rim-crest diameter, ``age_gyr``, ``degradation`` (the share of the
  fresh depth removed, 0 fresh .. 1 no relief; NaN before stamping = from the age)
* ``kind``: the layer's free label (default ``crater``; e.g. ``mare``, ``old``)
* optional as-stamped columns: ``morphology`` (``simple``, ``transitional``, ``complex``,
  ``peak-ring``: the fresh shape class on the target body), ``rim_radius_m``, ``depth_m``,
  ``rim_height_m``, ``floor_diameter_m``, ``peak_height_m``, ``kappa_t_m2`` (the
  diffusion length squared it aged by), ``slope_deg``, ``seed`` and any extra float
  columns.

CSV files use these names, or with ``columns="robbins"`` the names of the Robbins
crater databases for the position and size (Robbins 2019, JGR Planets 124, 871, the
lunar database: ``CRATER_ID``, ``LAT_CIRC_IMG``, ``LON_CIRC_IMG`` in degrees east 0-360,
``DIAM_CIRC_IMG`` in km; the other columns keep their names), so tools written for
those databases read them. ``.scc`` files (:func:`write_scc`) are what crater-counting
tools read (craterstats, Michael & Neukum 2010; written by CraterTools, Kneissl et al.
2011): the counted area in km^2 and one row per crater with its diameter in km and
longitude/latitude in degrees (:mod:`craters.scc`).
"""

from __future__ import annotations

import csv
import json
from pathlib import Path
from typing import Any

import numpy as np

from ._shared import ParameterError, atomic_path, check_choice
from ._shared.files import check_regular_file
from .scc import read_scc, write_scc

__all__ = ["BOULDER_FORMAT", "CATALOG_COLUMNS", "CATALOG_FORMAT", "add_columns",
           "catalog_dtype", "is_boulder_catalog", "make_catalog", "read_catalog", "read_scc",
           "sort_oldest_first", "write_catalog", "write_geojson", "write_scc"]

CATALOG_FORMAT = "craterform crater catalog v1"
#: First line of a boulder catalog's CSV (a catalog with ``burial_frac``: the boulders of
#: :mod:`craters.boulders`, placed on a body or a DEM).
BOULDER_FORMAT = "craterform boulder catalog v1"
#: Columns a boulder catalog holds in memory (a crater catalog's) that mean nothing for a
#: boulder (always 0): left out of its CSV, put back by :func:`read_catalog`.
_CRATER_ONLY = ("age_gyr", "degradation")
_KIND_LEN = 16
_INT_COLUMNS = {"seed": np.uint64, "layer": np.int64, "level": np.int64, "index": np.int64,
                "n_vertices": np.int64}
_STR_COLUMNS = {"kind", "morphology"}
_PLANE = ("x_m", "y_m")
_SPHERE = ("lat_deg", "lon_deg")
_CORE = ("diameter_m", "age_gyr", "degradation", "kind")
#: Column-name styles of :func:`write_catalog`.
CATALOG_COLUMNS = ("craterform", "robbins")
# Robbins (2019) lunar database names of the position and size columns
_ROBBINS_ID = "CRATER_ID"
_ROBBINS = ("LAT_CIRC_IMG", "LON_CIRC_IMG", "DIAM_CIRC_IMG")


def _column_dtype(name: str):
    if name in _STR_COLUMNS:
        return f"U{_KIND_LEN}"
    return _INT_COLUMNS.get(name, np.float64)


def catalog_dtype(names) -> np.dtype:
    """The structured dtype for the given column names."""
    return np.dtype([(n, _column_dtype(n)) for n in names])


def make_catalog(**columns) -> np.ndarray:
    """Build and validate a catalog from equal-length columns.

    Needs ``x_m, y_m`` or ``lat_deg, lon_deg`` and ``diameter_m``; ``age_gyr`` (0),
    ``degradation`` (0) and ``kind`` (``crater``) get defaults.

    Examples
    --------
    >>> cat = make_catalog(x_m=[1.0, 2.0], y_m=[0.0, 0.0], diameter_m=[10.0, 20.0])
    >>> cat.dtype.names[:5], cat["kind"].tolist()
    (('x_m', 'y_m', 'diameter_m', 'age_gyr', 'degradation'), ['crater', 'crater'])
    """
    if all(k in columns for k in _PLANE):
        pos = _PLANE
    elif all(k in columns for k in _SPHERE):
        pos = _SPHERE
    else:
        raise ValueError("a catalog needs columns x_m, y_m or lat_deg, lon_deg")
    if "diameter_m" not in columns:
        raise ValueError("a catalog needs a diameter_m column")
    n = len(np.atleast_1d(columns["diameter_m"]))
    columns.setdefault("age_gyr", np.zeros(n))
    columns.setdefault("degradation", np.zeros(n))
    columns.setdefault("kind", np.full(n, "crater"))
    names = [*pos, *_CORE] + [k for k in columns if k not in pos and k not in _CORE]
    out = np.zeros(n, dtype=catalog_dtype(names))
    for name in names:
        col = np.atleast_1d(np.asarray(columns[name]))
        if col.shape != (n,):
            raise ValueError(f"catalog column `{name}` must have length {n}; got {col.shape}")
        out[name] = col
    validate_catalog(out)
    return out


def validate_catalog(cat: np.ndarray) -> np.ndarray:
    """Check a catalog's columns and values; return it unchanged."""
    if not isinstance(cat, np.ndarray) or cat.dtype.names is None:
        raise TypeError("`catalog` must be a structured numpy array (see make_catalog)")
    names = cat.dtype.names
    if "diameter_m" not in names:
        raise ValueError("`catalog` needs a diameter_m column")
    d = cat["diameter_m"]
    if not np.isfinite(d).all() or (d <= 0).any():
        raise ValueError("catalog `diameter_m` must be finite and > 0")
    if "degradation" in names:
        g = cat["degradation"]
        known = g[~np.isnan(g)]  # NaN: the degradation follows from the age (diffusion)
        if (known < 0).any() or (known > 1).any() or np.isinf(known).any():
            raise ValueError("catalog `degradation` must be in [0, 1] (or NaN: from the age)")
    if "age_gyr" in names:
        a = cat["age_gyr"]
        if not np.isfinite(a).all() or (a < 0).any():
            raise ValueError("catalog `age_gyr` must be finite and >= 0")
    for pos in ("x_m", "y_m", "lat_deg", "lon_deg"):
        if pos in names and not np.isfinite(cat[pos]).all():
            raise ValueError(f"catalog `{pos}` must be finite")
    if "lat_deg" in names and (np.abs(cat["lat_deg"]) > 90).any():
        raise ValueError("catalog `lat_deg` must be in [-90, 90]")
    return cat


def sort_oldest_first(cat: np.ndarray) -> np.ndarray:
    """The catalog ordered by decreasing age (stable), the stamping order; without an
    ``age_gyr`` column every crater is fresh (age 0) and the order is kept."""
    if "age_gyr" not in (cat.dtype.names or ()):
        return cat
    order = np.argsort(-cat["age_gyr"], kind="stable")
    return cat[order]


def add_columns(cat: np.ndarray, names, columns) -> np.ndarray:
    """``cat`` with the columns ``columns`` appended under ``names`` (one name and column,
    or sequences of them), each keeping its dtype: what
    ``numpy.lib.recfunctions.append_fields(cat, names, columns, usemask=False)`` returns,
    made column by column (``append_fields`` walks the records in Python: 0.8 s for a
    descent frame's 25 000 craters).

    Examples
    --------
    >>> cat = add_columns(make_catalog(x_m=[1.0], y_m=[0.0], diameter_m=[10.0]), "id",
    ...                   np.array([7], dtype=np.uint64))
    >>> cat.dtype.names[-2:], cat["id"].dtype.name
    (('kind', 'id'), 'uint64')
    """
    if isinstance(names, str):
        names, columns = [names], [columns]
    cols = [np.asarray(c) for c in columns]
    fields, old = cat.dtype.fields, cat.dtype.names
    if fields is None or old is None:
        raise TypeError("`cat` must be a structured numpy array (see make_catalog)")
    if len(cols) != len(names) or any(c.shape != (len(cat),) for c in cols):
        raise ValueError(f"add_columns needs one column of length {len(cat)} per name; "
                         f"got {[c.shape for c in cols]} for {list(names)}")
    dtype = [(n, fields[n][0]) for n in old] + [
        (n, c.dtype) for n, c in zip(names, cols, strict=True)]
    out = np.empty(len(cat), dtype=dtype)
    for n in old:
        out[n] = cat[n]
    for n, c in zip(names, cols, strict=True):
        out[n] = c
    return out


def _format(value) -> str:
    if isinstance(value, float | np.floating):
        return repr(float(value))
    return str(value)


def is_boulder_catalog(cat: np.ndarray) -> bool:
    """Whether ``cat`` holds boulders (it has their ``burial_frac`` column)."""
    return "burial_frac" in (cat.dtype.names or ())


def write_catalog(cat: np.ndarray, path, *, columns: str = "craterform") -> Path:
    """Write a catalog as CSV (atomic).

    ``columns="craterform"``: line 1 is a ``#`` comment with format and units, then the
    column names. A boulder catalog (:func:`is_boulder_catalog`) says so on line 1 and
    has no crater-only columns (``age_gyr``, ``degradation``): its columns are the
    position, ``diameter_m``, ``kind``, ``burial_frac``, ``height_m`` and the placement's
    others (centre, normal, orientation, shape parameters). ``columns="robbins"``
    (catalogs on a body, with ``lat_deg, lon_deg``): the Robbins (2019) database names
    (module notes) and no comment line, so that readers of that database
    (``pandas.read_csv``) take it as it is: ``CRATER_ID``
    (``CF-`` and the row number), ``LAT_CIRC_IMG``, ``LON_CIRC_IMG`` (degrees east,
    0-360), ``DIAM_CIRC_IMG`` (km), then the other columns under their own names.
    :func:`read_catalog` reads both.
    """
    validate_catalog(cat)
    check_choice("columns", columns, CATALOG_COLUMNS)
    path = Path(path)
    boulders = is_boulder_catalog(cat)
    fields = cat.dtype.names
    assert fields is not None  # validate_catalog: a structured array
    if boulders:
        cat = cat[[n for n in fields if n not in _CRATER_ONLY]]
        fields = cat.dtype.names
        assert fields is not None
    names = list(fields)
    rows = [[_format(v) for v in row] for row in cat.tolist()]
    if columns == "robbins":
        if "lat_deg" not in names:
            raise ParameterError("columns", "robbins needs a catalog on a body (lat_deg, "
                                 "lon_deg); this one is planar (x_m, y_m)")
        rest = [n for n in names if n not in ("lat_deg", "lon_deg", "diameter_m")]
        lon = np.mod(cat["lon_deg"], 360.0)
        lead = [[f"CF-{i:07d}", _format(la), _format(lo), _format(d / 1000.0)]
                for i, (la, lo, d) in enumerate(zip(cat["lat_deg"].tolist(), lon.tolist(),
                                                    cat["diameter_m"].tolist(), strict=True))]
        keep = [names.index(n) for n in rest]
        rows = [h + [r[j] for j in keep] for h, r in zip(lead, rows, strict=True)]
        names = [_ROBBINS_ID, *_ROBBINS, *rest]
    if boulders:
        head = (f"{BOULDER_FORMAT}; units: metres (_m), degrees (_deg); diameter_m = "
                "size across, height_m = height above the surface, burial_frac = buried share")
    else:
        head = (f"{CATALOG_FORMAT}; units: metres (_m), degrees (_deg), Gyr (_gyr); "
                "degradation 0 = fresh, 1 = gone")
    with atomic_path(path) as tmp, open(tmp, "w", newline="", encoding="utf-8") as fh:
        if columns == "craterform":
            fh.write(f"# {head}\n")
        w = csv.writer(fh, lineterminator="\n")
        w.writerow(names)
        w.writerows(rows)
    return path


def read_catalog(path) -> np.ndarray:
    """Read a catalog written by :func:`write_catalog` (either column style)."""
    path = Path(path)
    check_regular_file(path, "catalog")
    with open(path, newline="", encoding="utf-8") as fh:
        lines = [ln for ln in fh if not ln.startswith("#")]
    try:
        rows = list(csv.reader(lines))
    except csv.Error as exc:  # a field over 128 KiB, a NUL byte
        raise ValueError(f"catalog {str(path)!r}: {exc}") from None
    if not rows:
        raise ValueError(f"catalog {str(path)!r} is empty")
    names, body = rows[0], rows[1:]
    robbins = all(n in names for n in _ROBBINS)
    if robbins:
        drop = {names.index(n) for n in (_ROBBINS_ID,) if n in names}
        rename = dict(zip(_ROBBINS, ("lat_deg", "lon_deg", "diameter_m"), strict=True))
        keep = [j for j in range(len(names)) if j not in drop]
        names = [rename.get(names[j], names[j]) for j in keep]
        body = [[r[j] if j < len(r) else "" for j in keep] for r in body]
    cat = np.zeros(len(body), dtype=catalog_dtype(names))
    for k, name in enumerate(names):
        try:
            col = [r[k] for r in body]
            cat[name] = np.array(col, dtype=_column_dtype(name)) if col else []
        except (IndexError, ValueError) as exc:
            raise ValueError(f"catalog {str(path)!r}: bad column {name!r}: {exc}") from None
    if robbins:
        cat["diameter_m"] *= 1000.0
    if is_boulder_catalog(cat) and not any(n in names for n in _CRATER_ONLY):
        cat = make_catalog(**{n: cat[n] for n in names})  # the crater-only columns back, 0
    return validate_catalog(cat)


def write_geojson(cat: np.ndarray, path, *, lonlat=None, body: str | None = None,
                  crs: str | None = None, prj: str | None = None) -> Path:
    """Write a catalog as RFC 7946 GeoJSON points (atomic): each feature's coordinates
    are its longitude and latitude in degrees, the longitude wrapped to [-180, 180).

    The positions are ``lonlat(x_m, y_m) -> (lon_deg, lat_deg)`` of a planar catalog, or
    the ``lon_deg``, ``lat_deg`` columns of one on a body. RFC 7946 has no ``crs`` member
    (its coordinates are WGS 84's on the Earth); on another body they are the body's
    planetocentric longitude and latitude, and the document says so in a foreign member
    ``"craterform": {"body", "crs", "coordinates"}`` (``crs``: the geographic CRS's code
    such as ``IAU_2015:30100``, or its WKT). ``prj`` (a WKT) is also written as the
    sidecar ``<name>.prj`` for GIS programs. Every column is kept in the properties.
    Points never cross the antimeridian, so none is split.
    """
    validate_catalog(cat)
    fields = cat.dtype.names
    assert fields is not None  # validate_catalog: a structured array
    if "x_m" in fields:
        if lonlat is None:
            raise ValueError("GeoJSON (RFC 7946) needs longitude and latitude: give "
                             "`lonlat` for a planar catalog")
        lon, lat = (np.asarray(a, dtype=np.float64) for a in lonlat(cat["x_m"], cat["y_m"]))
    else:
        lon, lat = cat["lon_deg"].astype(np.float64), cat["lat_deg"].astype(np.float64)
    if not (np.isfinite(lon).all() and np.isfinite(lat).all()
            and (np.abs(lat) <= 90.0).all()):
        raise ValueError("GeoJSON positions must be finite, latitudes in [-90, 90]")
    lon = (lon + 180.0) % 360.0 - 180.0
    if is_boulder_catalog(cat):  # as its CSV: no crater-only columns
        cat = cat[[n for n in fields if n not in _CRATER_ONLY]]
        fields = cat.dtype.names
        assert fields is not None
    feats = []
    for k, row in enumerate(cat.tolist()):
        props = {n: (float(v) if isinstance(v, float) else v)
                 for n, v in zip(fields, row, strict=True)}
        props = {n: (int(v) if isinstance(v, np.integer) else v) for n, v in props.items()}
        feats.append({"type": "Feature",
                      "geometry": {"type": "Point",
                                   "coordinates": [float(lon[k]), float(lat[k])]},
                      "properties": props})
    doc: dict[str, Any] = {"type": "FeatureCollection", "features": feats}
    if body or crs:
        doc["craterform"] = {"body": body, "crs": crs, "coordinates":
                             "longitude, latitude in degrees (east, planetocentric)"}
    path = Path(path)
    if prj:
        with atomic_path(path.with_suffix(".prj")) as tmp:
            tmp.write_text(prj, encoding="utf-8")
    with atomic_path(path) as tmp:
        tmp.write_text(json.dumps(doc, allow_nan=False), encoding="utf-8")
    return path
