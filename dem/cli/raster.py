"""``dem info``, ``dem convert``, ``dem fill`` and ``dem expand``: one DEM in, one DEM (or
a description) out."""

from __future__ import annotations

import numpy as np

from craters._shared import about, normalize_rng, progress_bar

from ..core import crs_label
from ..craterdensity import RESOLVED_CRATER_PX, crater_density, detect_craters, resolved_diameter_m
from ..expansion import expand_to_file
from ..fractal import fractal_fit
from ..frame import crater_target
from ..gaps import fill_gaps
from ..io import DEM_SUFFIXES, write
from ..terrain import MATCHED_BAND_PX, spectral_fit
from ..tiledfill import fill_to_file, fits_whole, raster_shape
from .options import Settings, add_command, check_output, read_input

#: ``dem info`` counts craters of up to this many pixels on DEMs up to this many pixels
#: (a 257^2 crop: 1 s; LOLA LDEM_4, 1.04 Mpx, would take 12 s).
_CRATER_COUNT_MAX_D_PX = 64.0
_CRATER_COUNT_MAX_PX = 1_000_000


def _seed(s: Settings) -> int:
    """The given seed (checked before any work) or a fresh one; recorded in the output."""
    if s["seed"] is None:
        return int(np.random.SeedSequence().entropy % (2**63))
    with about("rng"):
        normalize_rng(s["seed"])
    return s["seed"]


def _transform(s: Settings) -> int:
    """``dem fill`` and ``dem expand``."""
    command = s.command
    check_output(s, DEM_SUFFIXES)
    seed = _seed(s)
    show = not s["quiet"]
    bar = progress_bar(total=3, enabled=show, desc=command)
    bar.set_description(f"read {s['input']}")
    head = read_input(s, window=(0, 0, 1, 1), allow_unknown=True) if command == "fill" \
        else None
    shape_in = None if head is None else raster_shape(s["input"])
    if head is not None and not fits_whole(shape_in, s["max_memory_gb"]):
        # bigger than memory: tile by tile from the file (the same bytes)
        bar.close()
        made = fill_to_file(s["input"], s["output"], s["roughness"],
                            fractal_dimension=s["fractal_dimension"], craters=s["craters"],
                            rng=seed, target=crater_target(head, s.get("body"),
                                                           s.get("gravity_m_s2")),
                            band=s["band"], pixel_size_m=s["pixel_size_m"],
                            body_radius_m=s["body_radius_m"], body=s.get("body"),
                            max_memory_gb=s["max_memory_gb"], progress=show)
        _summary(s, seed, shape_in, made.shape, made.parameters)
        return 0
    dem = read_input(s)
    bar.update()
    bar.set_description(command)
    if command == "fill":
        target = crater_target(dem, s.get("body"), s.get("gravity_m_s2"))
        out = fill_gaps(dem, s["roughness"], fractal_dimension=s["fractal_dimension"],
                        craters=s["craters"], rng=seed, target=target)
        bar.update()
        bar.set_description(f"write {s['output']}")
        write(out, s["output"])
        shape, params = out.shape, out.history[-1]["parameters"]
    else:  # tile by tile into the file: outputs bigger than memory
        made = expand_to_file(dem, s["output"], s["levels"], s["fractal_dimension"],
                              s["roughness"], s["region"], rng=seed, tile_px=s["tile_px"],
                              scheduler=s["scheduler"], workers=s["workers"], progress=show)
        bar.update()
        shape, params = made.shape, made.parameters
    bar.update()
    bar.close()
    _summary(s, seed, dem.shape, shape, params)
    return 0


def _summary(s: Settings, seed: int, shape_in, shape, params: dict) -> None:
    """The two lines ``dem fill`` / ``dem expand`` print unless ``--quiet``."""
    if s["quiet"]:
        return
    detail = ", ".join(f"{k} {params[k]:.4g}" if isinstance(params[k], float)
                       else f"{k} {params[k]}" for k in params
                       if k in ("levels", "fractal_dimension", "roughness",
                                "filled_pixels", "holes", "craters"))
    print(f"dem {s.command}: {shape_in[0]} x {shape_in[1]} -> {shape[0]} x "
          f"{shape[1]} pixels, seed {seed}, {detail}")
    print(f"wrote {s['output']}")


def _convert(s: Settings) -> int:
    """``dem convert``: any DEM :func:`dem.read` reads (PDS3, GeoTIFF, ...) -> GeoTIFF or
    Zarr."""
    check_output(s, DEM_SUFFIXES)
    dem = read_input(s)
    write(dem, s["output"])
    if not s["quiet"]:
        print(f"dem convert: {dem.shape[0]} x {dem.shape[1]} pixels, {crs_label(dem.crs)}, "
              f"{100 * dem.nan_fraction:.3g} % unknown")
        print(f"wrote {s['output']}")
    return 0


def _info(s: Settings) -> int:
    dem = read_input(s)
    z = dem.heights[dem.known]
    t = dem.transform
    px = dem.pixel_size_m
    rows = [
        ("file", s["input"]),
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
    """Add ``info``, ``convert``, ``fill`` and ``expand`` to the sub-command parser."""
    add_command(sub, "info", _info,
                "describe a DEM (size, CRS, pixel size, heights, fractal dimension, craters)")
    add_command(sub, "convert", _convert,
                "convert a DEM (PDS3 .lbl/.img, GeoTIFF, Zarr, any raster GDAL reads) to a "
                "cloud-optimised GeoTIFF or a Zarr store")
    add_command(sub, "fill", _transform,
                "fill the unknown pixels of a DEM with fractal terrain, outside in")
    add_command(sub, "expand", _transform,
                "double the resolution of a DEM (region) by random midpoint displacement")
