"""Reports shared by the ``latlong`` and ``dem`` analysis commands (slopes, spectra).

Both packages compare several inputs in one CSV (a comment line with the units, then a
header) and one PNG, and print one summary table; latlong and dem never import each
other, so the pieces live here. Outputs are written atomically.
"""

from __future__ import annotations

import csv

import numpy as np

from .._shared.files import atomic_path

__all__ = ["plot_slopes", "plot_spectra", "save_figure", "series_colors", "slope_csv",
           "slope_table", "write_csv"]


def write_csv(path, comment: str, columns, rows) -> None:
    """A ``# comment`` line (units, definitions), the header, the rows; floats by repr."""
    with atomic_path(path) as tmp, open(tmp, "w", newline="", encoding="utf-8") as fh:
        fh.write(f"# {comment}\n")
        w = csv.writer(fh, lineterminator="\n")
        w.writerow(columns)
        for row in rows:
            w.writerow([repr(float(v)) if isinstance(v, float | np.floating) else v
                        for v in row])


def save_figure(fig, path) -> None:
    """Lay out a matplotlib figure, write it as PNG (110 dpi), atomically, and close it."""
    import matplotlib.pyplot as plt

    try:
        fig.tight_layout()
        with atomic_path(path) as tmp:
            fig.savefig(tmp, dpi=110, format="png")
    finally:
        plt.close(fig)


def series_colors(n: int) -> list:
    """``n`` colours that do not repeat: matplotlib's ten-colour cycle up to ten series,
    else a colormap (viridis) sampled once per series (an 11-layer stack's layer 0 and
    layer 10 were both blue with the cycle)."""
    import matplotlib

    if n <= 10:
        return [matplotlib.colormaps["tab10"](k) for k in range(n)]
    return [matplotlib.colormaps["viridis"](k / (n - 1)) for k in range(n)]


def _common_bins(results):
    return results[0][1]["edges_deg"], min(len(r["area_fraction"]) for _, r in results)


def slope_csv(path, comment: str, results) -> None:
    """``results``: (label, slope summary) pairs; one row per slope bin, two columns per
    input (area fraction, percent of the area steeper than the bin's lower edge)."""
    edges, n_bins = _common_bins(results)
    cols = ["slope_lo_deg", "slope_hi_deg"]
    for label, _ in results:
        cols += [f"area_fraction[{label}]", f"percent_area_steeper_than_lo[{label}]"]
    rows = []
    for b in range(n_bins):
        row = [edges[b], edges[b + 1]]
        for _, r in results:
            row += [r["area_fraction"][b], r["above_percent"][b]]
        rows.append(row)
    write_csv(path, comment, cols, rows)


def plot_slopes(path, results, *, xlabel: str, ylabel: str, title: str,
                full_range: bool = False) -> None:
    """Histogram and cumulative slope-frequency panels of every input, side by side
    (``results``: (legend label, slope summary) pairs; colours from
    :func:`series_colors`)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    edges, n_bins = _common_bins(results)
    fig, (ax0, ax1) = plt.subplots(1, 2, figsize=(12, 4.8))
    centres = 0.5 * (edges[:n_bins] + edges[1:n_bins + 1])
    for (label, r), color in zip(results, series_colors(len(results)), strict=True):
        ax0.plot(centres, 100 * r["area_fraction"][:n_bins], "o-", ms=3, label=label,
                 color=color)
        above = r["above_percent"][:n_bins]
        ax1.semilogy(edges[:n_bins], np.where(above > 1e-6, above, np.nan), "o-", ms=3,
                     label=label, color=color)
    ax0.set_xlabel(xlabel)
    ax0.set_ylabel(ylabel)
    ax0.set_title(title)
    ax1.set_xlabel("slope (deg)")
    ax1.set_ylabel("area steeper than the slope (%)")
    ax1.set_title("cumulative slope-frequency")
    for ax in (ax0, ax1):
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
        if full_range:
            ax.set_xlim(0, 90)
    save_figure(fig, path)


def plot_spectra(path, series, *, xlabel: str, ylabel: str, title: str, fmt: str = "-",
                 invert_x: bool = False, **style) -> None:
    """Log-log power spectra of every input in one plot (``series``: (legend label, x, y)
    triples; colours from :func:`series_colors`; ``fmt`` and ``style`` for every line)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 5))
    for (label, x, y), color in zip(series, series_colors(len(series)), strict=True):
        ax.loglog(x, y, fmt, **style, color=color, label=label)
    if invert_x:
        ax.invert_xaxis()
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_title(title)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    save_figure(fig, path)


def slope_table(results) -> str:
    """The summary table of ``(label, slope summary)`` pairs, one line per input."""
    header = (f"{'input':<28} {'median_deg':>10} {'mean_deg':>9} {'>10deg_%':>9} "
              f"{'>20deg_%':>9} {'>30deg_%':>9}")
    lines = [header]
    for label, r in results:
        pa = r["percent_above"]
        lines.append(f"{label[:28]:<28} {r['median_deg']:10.2f} {r['mean_deg']:9.2f} "
                     f"{pa[10]:9.2f} {pa[20]:9.2f} {pa[30]:9.2f}")
    return "\n".join(lines)
