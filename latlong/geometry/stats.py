"""Slope statistics shared by bodies (latlong) and rasters (dem)."""

from __future__ import annotations

import numpy as np

from craters._shared import check_range

__all__ = ["area_slope_summary"]


def area_slope_summary(slopes_deg, areas, *, bin_deg: float = 3.0) -> dict:
    """Area-weighted slope statistics shared by bodies (latlong) and rasters (dem).

    Returns ``edges_deg`` (bin edges from 0), ``area_fraction`` (per bin, sums to 1),
    ``above_percent`` (share of the area steeper than each edge), ``median_deg``,
    ``mean_deg`` and ``percent_above`` for 10, 20 and 30 degrees. NaN slopes (unknown
    terrain) are left out.
    """
    s = np.asarray(slopes_deg, dtype=np.float64).ravel()
    w = np.asarray(areas, dtype=np.float64).ravel()
    if s.shape != w.shape or s.size == 0:
        raise ValueError("`slopes_deg` and `areas` must be non-empty and the same length")
    ok = np.isfinite(s) & np.isfinite(w)
    if not ok.any():
        raise ValueError("no finite slope to summarise")
    s, w = s[ok], w[ok]
    bin_deg = check_range("bin_deg", bin_deg, 0.01, 90.0)
    edges = np.arange(0.0, 180.0 + bin_deg, bin_deg)
    edges = edges[edges <= max(90.0, float(s.max()) + bin_deg)]
    hist, _ = np.histogram(s, bins=edges, weights=w)
    frac = hist / w.sum()
    order = np.argsort(s)
    cw = np.cumsum(w[order]) / w.sum()
    median = float(s[order][min(int(np.searchsorted(cw, 0.5)), len(s) - 1)])
    above = 100.0 * (1.0 - np.concatenate([[0.0], np.cumsum(frac)]))[:len(edges)]
    return {"edges_deg": edges, "area_fraction": frac, "above_percent": above,
            "median_deg": median, "mean_deg": float(np.average(s, weights=w)),
            "percent_above": {a: float(100.0 * w[s > a].sum() / w.sum()) for a in (10, 20, 30)}}
