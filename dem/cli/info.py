"""``dem info``: describe a DEM (size, CRS, pixel size, heights, fractal dimension,
craters)."""

from __future__ import annotations

from craters.cli.options import Values

from ..core import crs_label
from ..craterdensity import RESOLVED_CRATER_PX, crater_density, detect_craters, resolved_diameter_m
from ..fractal import fractal_fit
from ..terrain import MATCHED_BAND_PX, spectral_fit
from .options import INPUT, READ, dem_command, read_input

HELP = {
    "info": "describe a DEM (size, CRS, pixel size, heights, fractal dimension, craters)",
}

__all__ = ["register"]

#: ``dem info`` counts craters of up to this many pixels on DEMs up to this many pixels
#: (a 257^2 crop: 1 s; LOLA LDEM_4, 1.04 Mpx, would take 12 s).
_CRATER_COUNT_MAX_D_PX = 64.0
_CRATER_COUNT_MAX_PX = 1_000_000


def _info(v: Values) -> int:
    dem = read_input(v)
    z = dem.heights[dem.known]
    t = dem.transform
    px = dem.pixel_size_m
    rows = [
        ("file", v["input"]),
        ("size", f"{dem.shape[0]} x {dem.shape[1]} pixels (rows x cols)"),
        ("crs", crs_label(dem.crs)),
        ("pixel_m", f"{px[0]:.6g} x {px[1]:.6g} (x, y; resolution {dem.resolution_m:.6g})"),
        ("transform", ", ".join(f"{v:.10g}" for v in tuple(t)[:6])),
        ("body_m", "-" if dem.body_radius_m is None else f"{dem.body_radius_m:.10g}"),
        ("unknown", f"{100 * dem.nan_fraction:.3f} % ({dem.heights.size - z.size} pixels)"),
        ("height_m", f"min {z.min():.6g}  mean {z.mean():.6g}  max {z.max():.6g}"),
    ]
    rows += _dimension_rows(dem)
    rows += _crater_rows(dem)
    for step in dem.history:
        rows.append(("history", f"{step['op']} seed {step['seed']}"))
    for key, value in rows:
        print(f"{key:<10} {value}")
    return 0


def _dimension(fit, method: str) -> str:
    """F with its method, or the sentence that says it is no surface dimension."""
    if fit.warning:
        return f"n/a: {fit.warning} ({method})"
    return f"{fit.fractal_dimension:.4f} ({method})"


def _dimension_rows(dem) -> list[tuple[str, str]]:
    """``fractal_d`` (variogram), ``spectral_d`` (same scales) and ``roughness`` rows."""
    rows = []
    try:
        fit = fractal_fit(dem)
        lo_lag, hi_lag = fit.lag_range_px
        rows.append(("fractal_d", _dimension(
            fit, f"locally normalised variogram, lags {lo_lag}-{hi_lag} px")))
        rough = fit.roughness
    except ValueError as exc:
        rows.append(("fractal_d", f"n/a ({exc})"))
        rough = None
    lo, hi = MATCHED_BAND_PX
    band = f"power-spectrum slope, wavelengths {lo:g}-{hi:g} px"
    if not dem.known.all():
        rows.append(("spectral_d", f"n/a (unknown pixels; fill them first) ({band})"))
    else:
        try:
            rows.append(("spectral_d", _dimension(spectral_fit(dem, lo, hi), band)))
        except ValueError as exc:
            rows.append(("spectral_d", f"n/a ({exc})"))
    if rough is not None:
        rows.append(("roughness", f"{rough:.6g} (RMS neighbour slope, m/m)"))
    return rows


def _crater_rows(dem) -> list[tuple[str, str]]:
    """``resolves`` (the crater resolution limit) and ``craters`` (the detector's count
    and density), skipped on DEMs over :data:`_CRATER_COUNT_MAX_PX` pixels."""
    limit = resolved_diameter_m(dem)
    rows = [("resolves", f"craters from {limit:.6g} m ({RESOLVED_CRATER_PX:g} px)")]
    if dem.heights.size > _CRATER_COUNT_MAX_PX:
        note = f"n/a (over {_CRATER_COUNT_MAX_PX / 1e6:g} Mpx: use dem.crater_density)"
        return [*rows, ("craters", note)]
    top = min(_CRATER_COUNT_MAX_D_PX, min(dem.shape) / 4.0)
    if top <= RESOLVED_CRATER_PX * 1.5:
        return [*rows, ("craters", "n/a (the DEM is too small to count craters)")]
    found = detect_craters(dem, max_diameter_px=top)
    density = crater_density(dem, max_diameter_px=top)
    text = (f"{len(found)} found of {RESOLVED_CRATER_PX:g}-{top:g} px (rim-over-floor "
            f"detector)")
    if density is not None:
        text += (f"; from {density.d_lo_m:.6g} m: {density.count}, N(>D) = {density.c:.4g} "
                 f"D^{density.k:g} (D in m, per m^2), N(>{density.d_lo_m / 1e3:.4g} km) = "
                 f"{density.count / density.area_m2 * 1e6:.4g} per km^2")
    return [*rows, ("craters", text)]


def register(sub) -> None:
    """Register ``dem info``."""
    dem_command(sub, "info", _info, {"input": INPUT, **READ},
                HELP["info"])
