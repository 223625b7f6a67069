"""Crater catalogs: structured numpy arrays, CSV with units, GeoJSON for planar catalogs.

A catalog is the ground truth that users feed to crater-detection and navigation
algorithms, so it must say exactly what was stamped. Columns (units in the names):

* position: ``lat_deg, lon_deg`` (on a body) or ``x_m, y_m`` (on a plane / DEM)
* ``diameter_m`` rim-crest diameter, ``age_gyr``, ``degradation`` (the share of the
  fresh depth removed, 0 fresh .. 1 no relief; NaN before stamping = from the age)
* ``kind`` (e.g. ``simple``)
* optional as-stamped columns: ``rim_radius_m``, ``depth_m``, ``rim_height_m``,
  ``slope_deg``, ``seed`` and any extra float columns.
"""

from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np

from ._shared import atomic_path

__all__ = ["CATALOG_FORMAT", "catalog_dtype", "make_catalog", "read_catalog",
           "sort_oldest_first", "write_catalog", "write_geojson"]

CATALOG_FORMAT = "craterform crater catalog v1"
_KIND_LEN = 16
_INT_COLUMNS = {"seed": np.uint64, "layer": np.int64, "level": np.int64, "index": np.int64,
                "n_vertices": np.int64}
_STR_COLUMNS = {"kind", "morphology"}
_PLANE = ("x_m", "y_m")
_SPHERE = ("lat_deg", "lon_deg")
_CORE = ("diameter_m", "age_gyr", "degradation", "kind")


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
    ``degradation`` (0) and ``kind`` (``simple``) get defaults.

    Examples
    --------
    >>> cat = make_catalog(x_m=[1.0, 2.0], y_m=[0.0, 0.0], diameter_m=[10.0, 20.0])
    >>> cat.dtype.names[:5], cat["kind"].tolist()
    (('x_m', 'y_m', 'diameter_m', 'age_gyr', 'degradation'), ['simple', 'simple'])
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
    columns.setdefault("kind", np.full(n, "simple"))
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
    """The catalog ordered by decreasing age (stable), the stamping order."""
    order = np.argsort(-cat["age_gyr"], kind="stable")
    return cat[order]


def _format(value) -> str:
    if isinstance(value, float | np.floating):
        return repr(float(value))
    return str(value)


def write_catalog(cat: np.ndarray, path) -> Path:
    """Write a catalog as CSV (atomic). Line 1: a ``#`` comment with format and units."""
    validate_catalog(cat)
    path = Path(path)
    units = "metres (_m), degrees (_deg), Gyr (_gyr); degradation 0 = fresh, 1 = gone"
    with atomic_path(path) as tmp, open(tmp, "w", newline="", encoding="utf-8") as fh:
        fh.write(f"# {CATALOG_FORMAT}; units: {units}\n")
        w = csv.writer(fh, lineterminator="\n")
        w.writerow(cat.dtype.names)
        for row in cat.tolist():
            w.writerow([_format(v) for v in row])
    return path


def read_catalog(path) -> np.ndarray:
    """Read a catalog written by :func:`write_catalog`."""
    path = Path(path)
    if not path.is_file():
        raise ValueError(f"catalog {str(path)!r} does not exist")
    with open(path, newline="", encoding="utf-8") as fh:
        lines = [ln for ln in fh if not ln.startswith("#")]
    rows = list(csv.reader(lines))
    if not rows:
        raise ValueError(f"catalog {str(path)!r} is empty")
    names, body = rows[0], rows[1:]
    cat = np.zeros(len(body), dtype=catalog_dtype(names))
    for k, name in enumerate(names):
        try:
            col = [r[k] for r in body]
            cat[name] = np.array(col, dtype=_column_dtype(name)) if col else []
        except (IndexError, ValueError) as exc:
            raise ValueError(f"catalog {str(path)!r}: bad column {name!r}: {exc}") from None
    return validate_catalog(cat)


def write_geojson(cat: np.ndarray, path, *, to_world=None, crs: str | None = None) -> Path:
    """Write a planar catalog as GeoJSON points (atomic).

    ``to_world(x_m, y_m) -> (X, Y)`` maps catalog coordinates to world coordinates
    (default identity); ``crs`` is recorded as a top-level ``crs`` name if given.
    """
    validate_catalog(cat)
    if "x_m" not in cat.dtype.names:
        raise ValueError("GeoJSON output needs a planar catalog (x_m, y_m)")
    xs, ys = cat["x_m"], cat["y_m"]
    if to_world is not None:
        xs, ys = to_world(xs, ys)
    feats = []
    for k, row in enumerate(cat.tolist()):
        props = {n: (float(v) if isinstance(v, float) else v)
                 for n, v in zip(cat.dtype.names, row, strict=True)}
        props = {n: (int(v) if isinstance(v, np.integer) else v) for n, v in props.items()}
        feats.append({"type": "Feature",
                      "geometry": {"type": "Point", "coordinates": [float(xs[k]), float(ys[k])]},
                      "properties": props})
    doc = {"type": "FeatureCollection", "features": feats}
    if crs:
        doc["crs"] = {"type": "name", "properties": {"name": crs}}
    path = Path(path)
    with atomic_path(path) as tmp:
        tmp.write_text(json.dumps(doc), encoding="utf-8")
    return path
