"""Issue 36: a crater on steep ground has the shape of one on level ground (plain script).

One 160 m crater (no roughness, no slope erosion) is stamped at 0 N on a 3:1:1 spheroid
of 1 km (magnitude M, default 300) at longitudes where the surface is tilted from the
radial by 28.5 deg (12 E), 52.7 deg (40 E) and 0 deg (90 E). In the surface's own
tangent frame it prints the rim-crest radius (the highest point of each of 16 azimuth
sectors) along the dip and across it, and the floor and rim height along the surface
normal relative to a quadric fitted to the surface before stamping. Radial stamping
(before issue 36's fix) gave along-dip / across 1.14 and 1.64 and floors 0.116 / 0.077 D.

The same crater stamped into a DEM raster (``craters.stamp_many``, 1 m pixels) on planes
tilted by 0, 28.5 and 45 deg, measured the same way in the plane's frame (before the
raster's stamp followed the tilted base it stamped along z, as bodies did).
Usage, from the top folder: ``python tests/benchmarks/measure_steep_craters.py [M]``.
"""

import sys

import numpy as np

import craters
import latlong
from latlong import Body, LatLongGrid

DIAMETER_M = 160.0
LONGITUDES_DEG = (12.0, 40.0, 90.0)


def measure(body: Body, lon_deg: float) -> tuple[float, float, float, float, float]:
    """(tilt deg, rim along dip / R, across / R, floor / D, rim height / D)."""
    cat = craters.make_catalog(lat_deg=np.array([0.0]), lon_deg=np.array([lon_deg]),
                               diameter_m=np.array([DIAMETER_M]))
    new = latlong.stamp_craters(body, cat, roughness=False, rng=1, slope_erosion=False)
    lam = np.radians(lon_deg)
    s = np.asarray(body.stretch)
    c = body.radius_m * s * np.array([np.cos(lam), np.sin(lam), 0.0])
    nrm = c / s**2
    nrm /= np.linalg.norm(nrm)
    tilt = float(np.degrees(np.arccos(nrm @ c / np.linalg.norm(c))))
    e1 = np.cross([0.0, 0.0, 1.0], nrm)
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(nrm, e1)
    r_c = 0.5 * DIAMETER_M

    def local(p):
        rel = p - c
        return rel @ e1, rel @ e2, rel @ nrm

    def quad(a, b):
        return np.c_[np.ones(len(a)), a, b, a * a, a * b, b * b]

    x0, y0, h0 = local(body.vertices())
    s0 = (np.hypot(x0, y0) < 2.5 * r_c) & (np.abs(h0) < r_c)
    coef = np.linalg.lstsq(quad(x0[s0], y0[s0]), h0[s0], rcond=None)[0]
    x, y, h = local(new.vertices())
    near = (np.hypot(x, y) < 2 * r_c) & (np.abs(h) < r_c)
    return (tilt, *rim_and_floor(x, y, h, h - quad(x, y) @ coef, near))


def rim_and_floor(x, y, h, above, near) -> tuple[float, float, float, float]:
    """(rim along dip / R, across / R, floor / D, rim height / D) from the points (x, y)
    of the surface's frame (x along the dip), their heights ``h`` (the rim: each of 16
    sectors' highest) and ``above`` the surface before stamping."""
    r_c = 0.5 * DIAMETER_M
    r, az = np.hypot(x, y), np.arctan2(y, x)
    rims, tops = [], []
    for a0 in np.linspace(-np.pi, np.pi, 16, endpoint=False):
        sel = near & (np.abs(np.angle(np.exp(1j * (az - a0)))) < np.pi / 16) & (r > 0.4 * r_c)
        rims.append(r[sel][np.argmax(h[sel])] / r_c)
        tops.append(above[sel & (r < 1.4 * r_c)].max())
    rims = np.array(rims)
    floor = -above[near & (r < 0.3 * r_c)].min()
    return (float(rims[[0, 8]].mean()), float(rims[[4, 12]].mean()), floor / DIAMETER_M,
            float(np.mean(tops)) / DIAMETER_M)


def measure_dem(tilt_deg: float, pixel_m: float = 1.0) -> tuple[float, float, float, float]:
    """(rim along dip / R, across / R, floor / D, rim height / D) of the crater stamped at
    the centre of a plane DEM dipping ``tilt_deg`` towards -x, in the plane's frame."""
    n = int(round(4.0 * DIAMETER_M / pixel_m)) | 1
    x = (np.arange(n) - n // 2) * pixel_m
    xx, yy = np.meshgrid(x, x)
    g = np.tan(np.radians(tilt_deg))
    plane = g * xx
    c = n // 2 * pixel_m  # the centre of pixel n // 2 (x_m / pixel: the column)
    cat = craters.make_catalog(x_m=np.array([c]), y_m=np.array([c]),
                               diameter_m=np.array([DIAMETER_M]))
    h = craters.stamp_many(plane, pixel_m, cat, roughness=False, rng=1, slope_erosion=False)
    nrm = np.array([-g, 0.0, 1.0]) / np.hypot(g, 1.0)
    e1 = np.array([1.0, 0.0, g]) / np.hypot(g, 1.0)   # along the dip, in the plane
    pts = np.c_[xx.ravel(), yy.ravel(), h.ravel()]
    u, v, w = pts @ e1, pts[:, 1], pts @ nrm
    return rim_and_floor(u, v, w, w, np.hypot(u, v) < DIAMETER_M)


def main() -> None:
    m = int(sys.argv[1]) if len(sys.argv) > 1 else 300
    body = Body.sphere(LatLongGrid(m), 1000.0, stretch=(3.0, 1.0, 1.0))
    print(f"{DIAMETER_M:g} m crater on a 3:1:1 spheroid of 1 km, magnitude {m}")
    print("  tilt deg  rim along dip / R  across / R  floor / D  rim / D")
    for lon in LONGITUDES_DEG:
        tilt, dip, across, floor, rim = measure(body, lon)
        print(f"  {tilt:8.1f}  {dip:17.2f}  {across:10.2f}  {floor:9.3f}  {rim:7.3f}")
    print(f"{DIAMETER_M:g} m crater on a tilted plane DEM (1 m pixels)")
    print("  tilt deg  rim along dip / R  across / R  floor / D  rim / D")
    for tilt in (28.5, 45.0, 0.0):
        dip, across, floor, rim = measure_dem(tilt)
        print(f"  {tilt:8.1f}  {dip:17.2f}  {across:10.2f}  {floor:9.3f}  {rim:7.3f}")


if __name__ == "__main__":
    main()
