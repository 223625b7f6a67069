"""craterstats spatial crater counts (``.scc``): what crater-counting tools read.

The format of craterstats (Michael & Neukum 2010; G. Michael's craterstats 3,
``Cratercount.ReadSCCfile``) as written by CraterTools (Kneissl, van Gasselt & Neukum
2011) and in craterstats' samples: ``#`` comments, ``key = value`` lines and tables
``name = {col,col,...`` followed by whitespace-separated rows and a closing ``}``::

    # Spatial crater count
    #
    # Ellipsoid axes:
    a_axis_radius = 1737.4 <km>
    b_axis_radius = 1737.4 <km>
    c_axis_radius = 1737.4 <km>
    coordinate_system_name = Moon
    #
    Total_area = 2000 <km^2>
    #
    # crater_diameters:
    crater = {diam,fraction,lon,lat
    1.52	1	-12.5	3.25
    }

craterstats reads ``Total_area`` with the pattern ``[\\d.]*`` (so it is written as a
plain decimal, never in exponent notation), the ``crater`` table's ``diam`` (km) and
``fraction`` (the share of the crater inside the area, 1 here); longitude (degrees,
-180..180) and latitude are for display. An optional ``unit_boundary`` table gives the
outline of the counted area (``vertex,sub_area,tag,lon,lat``).
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from ._shared import ParameterError, atomic_path, check_positive
from ._shared.files import check_regular_file

__all__ = ["read_scc", "write_scc"]


def _num(x: float) -> str:
    """A plain decimal (no exponent), the shortest that reads back as ``x``."""
    return np.format_float_positional(float(x), unique=True, trim="-")


def write_scc(catalog, path, *, area_m2: float, body_radius_m: float | None = None,
              axes_m=None, coordinate_system: str | None = None,
              boundary_lonlat_deg=None, note: str | None = None) -> Path:
    """Write a crater catalog as a craterstats spatial crater count (atomic).

    Parameters
    ----------
    catalog : structured array
        A crater catalog (``diameter_m``; with ``lat_deg, lon_deg`` the rows carry the
        positions, otherwise only diameter and fraction).
    path : str or Path
        The ``.scc`` file.
    area_m2 : float
        The counted area, m^2 (written in km^2): the area over which the catalog is
        complete.
    body_radius_m, axes_m : float or (3,) floats, optional
        The body's radius or its three semi-axes (metres; written in km as the
        ellipsoid axes). At most one.
    coordinate_system : str, optional
        ``coordinate_system_name`` (e.g. the body or the DEM's CRS).
    boundary_lonlat_deg : (n, 2) array_like, optional
        Outline of the counted area, (lon, lat) degrees per vertex.
    note : str, optional
        A comment line (what the count is).

    Examples
    --------
    >>> import tempfile, os
    >>> from craters import make_catalog
    >>> cat = make_catalog(lat_deg=[1.0], lon_deg=[350.0], diameter_m=[1500.0])
    >>> p = write_scc(cat, os.path.join(tempfile.mkdtemp(), "c.scc"), area_m2=2e9,
    ...               body_radius_m=1737400.0)
    >>> print(p.read_text().split("Total_area")[1].splitlines()[0])
     = 2000 <km^2>
    >>> read_scc(p)["diameter_m"].tolist(), read_scc(p)["lon_deg"].tolist()
    ([1500.0], [-10.0])
    """
    names = catalog.dtype.names if isinstance(catalog, np.ndarray) else None
    if names is None or "diameter_m" not in names:
        raise ParameterError("catalog", "must be a crater catalog with a diameter_m column")
    area_km2 = check_positive("area_m2", area_m2) * 1e-6
    if body_radius_m is not None and axes_m is not None:
        raise ParameterError("axes_m", "give body_radius_m or axes_m, not both")
    if body_radius_m is not None:
        axes_m = (check_positive("body_radius_m", body_radius_m),) * 3
    if axes_m is not None:
        axes_m = [check_positive("axes_m", a) for a in np.asarray(axes_m, float).ravel()]
        if len(axes_m) != 3:
            raise ParameterError("axes_m", f"must be three semi-axes; got {len(axes_m)}")
    lines = ["# Spatial crater count", "#",
             f"# {note or 'Synthetic crater population (craterform)'}", "#"]
    if axes_m is not None:
        lines.append("# Ellipsoid axes:")
        lines += [f"{n}_axis_radius = {_num(a * 1e-3)} <km>"
                  for n, a in zip("abc", axes_m, strict=True)]
    if coordinate_system:
        lines.append(f"coordinate_system_name = {coordinate_system}")
    if boundary_lonlat_deg is not None:
        b = np.asarray(boundary_lonlat_deg, dtype=np.float64).reshape(-1, 2)
        lines += ["#", "# area_shapes:", "unit_boundary = {vertex,sub_area,tag,lon,lat"]
        lines += [f"{i + 1}\t1\text\t{_num(_lon180(lo))}\t{_num(la)}"
                  for i, (lo, la) in enumerate(b.tolist())]
        lines.append("}")
    lines += ["#", f"Total_area = {_num(area_km2)} <km^2>", "#", "# crater_diameters:"]
    d_km = np.asarray(catalog["diameter_m"], dtype=np.float64) * 1e-3
    if "lat_deg" in names and "lon_deg" in names:
        lines.append("crater = {diam,fraction,lon,lat")
        lines += [f"{_num(d)}\t1\t{_num(_lon180(lo))}\t{_num(la)}"
                  for d, lo, la in zip(d_km.tolist(), catalog["lon_deg"].tolist(),
                                       catalog["lat_deg"].tolist(), strict=True)]
    else:
        lines.append("crater = {diam,fraction")
        lines += [f"{_num(d)}\t1" for d in d_km.tolist()]
    lines.append("}")
    path = Path(path)
    with atomic_path(path) as tmp:
        tmp.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


def _lon180(lon: float) -> float:
    """Longitude in (-180, 180]."""
    x = float(np.mod(lon, 360.0))
    return x - 360.0 if x > 180.0 else x


def read_scc(path) -> dict:
    """Read a spatial crater count (``.scc``, module notes).

    Returns a dict: ``area_m2``, ``axes_m`` (three semi-axes or None), ``diameter_m``,
    ``fraction``, ``lon_deg``, ``lat_deg`` (arrays; positions None if the file has
    none).
    """
    path = Path(path)
    check_regular_file(path, "crater count")
    text = path.read_text(encoding="utf-8-sig")
    values: dict[str, str] = {}
    tables: dict[str, tuple[list[str], list[list[str]]]] = {}
    table: tuple[str, list[str]] | None = None
    rows: list[list[str]] = []
    for raw in text.splitlines():
        line = raw.split("#", 1)[0].strip()
        if not line:
            continue
        if table is not None:
            if line.startswith("}"):
                tables[table[0]] = (table[1], rows)
                table, rows = None, []
            else:
                rows.append(line.split())
            continue
        key, sep, value = line.partition("=")
        if not sep:
            raise ValueError(f"{str(path)!r}: cannot read line {raw!r}")
        key, value = key.strip(), value.strip()
        if value.startswith("{"):
            table = (key, [c.strip() for c in value.strip("{ ").split(",")])
        else:
            values[key] = value
    if "crater" not in tables or "Total_area" not in values:
        raise ValueError(f"{str(path)!r} is not a spatial crater count (needs Total_area "
                         f"and a crater table)")
    cols, rows = tables["crater"]

    def column(name):
        if name not in cols:
            return None
        j = cols.index(name)
        return np.array([float(r[j]) for r in rows], dtype=np.float64)

    number = re.match(r"\s*([\d.]+)", values["Total_area"])
    if number is None:
        raise ValueError(f"{str(path)!r}: Total_area must start with a number; got "
                         f"{values['Total_area']!r}")
    area = float(number.group(1))
    axes = [values.get(f"{n}_axis_radius") for n in "abc"]
    given = [a for a in axes if a is not None]
    axes_m = tuple(float(a.split()[0]) * 1e3 for a in given) if len(given) == 3 else None
    fraction = column("fraction")
    diam = column("diam")
    return {"area_m2": area * 1e6, "axes_m": axes_m, "diameter_m": diam * 1e3,
            "fraction": np.ones_like(diam) if fraction is None else fraction,
            "lon_deg": column("lon"), "lat_deg": column("lat")}
