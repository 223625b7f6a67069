"""The rim-to-floor depth of one crater from sampled heights, shared by the benchmarks that
measure depth/diameter on meshes, rasters and real DEMs (``ondemand_faithfulness``,
``measure_crater_morphology``, ``measure_old_craters_lola``)."""

import numpy as np


def rim_minus_floor(h, r, az, *, annulus=(0.8, 1.2), floor_r=0.5,
                    min_sectors=8) -> float | None:
    """Rim crest minus floor of heights ``h`` (m or km) at radii ``r`` (in crater radii)
    and azimuths ``az`` (radians, from -pi): the median over 8 azimuth sectors of each
    sector's highest point in the ``annulus`` (a neighbouring crater's rim raises one
    sector, not the median) minus the lowest point within ``floor_r``. None when fewer
    than ``min_sectors`` sectors hold an annulus point or no point is on the floor."""
    ann = (r >= annulus[0]) & (r <= annulus[1])
    floor = r <= floor_r
    sector = np.floor((az[ann] + np.pi) / (np.pi / 4)).astype(int) % 8
    rim = h[ann]
    maxima = [rim[sector == k].max() for k in range(8) if (sector == k).any()]
    if len(maxima) < min_sectors or not floor.any():
        return None
    return float(np.median(maxima) - h[floor].min())
