"""Issue 36 acceptance: old lunar complex craters as deep as the real ones (plain script).

Real: 186 age-classified craters of the LPI Lunar Impact Crater Database (Losiak et al.
2009, revised by Ohman 2015; ages from Wilhelms 1987), a sample of its rows in
``tests/data/lpi_crater_ages_sample.csv`` (provenance in ``tests/data/README.md``), their
depths measured on LOLA LDEM_4 (``../shared/data/dems/lola_ldem4/LDEM_4.IMG``, 7.6 km
pixels; 40-100 km craters, 5-13 pixels across): rim = the median over 8 azimuth sectors
of the highest pixel at 0.8-1.2 radii, floor = the lowest within 0.6 radii, depth / Pike's
(1977) fresh complex depth 1.044 D^0.301 (km). The Copernican craters check the method
(it reads them at 1.10: the annulus maximum picks up neighbouring highs).
Model: ``craters.crater_morphometry`` (depth measured on the stamped profile) at the same
diameters and the age of each class (Copernican 0.4, Eratosthenian 2.0, Imbrian 3.7,
Nectarian 3.88, pre-Nectarian 4.2 Gyr), divided by the fresh depth. Usage, from the top
folder: ``python tests/benchmarks/measure_old_craters_lola.py``.
"""

import csv
from pathlib import Path

import numpy as np
from crater_depth import rim_minus_floor

import craters

R_MOON_KM = 1737.4
IMG = Path("../shared/data/dems/lola_ldem4/LDEM_4.IMG")
SAMPLE = Path("tests/data/lpi_crater_ages_sample.csv")
AGES_GYR = {"Copernican": 0.4, "Eratosthenian": 2.0, "Imbrian": 3.7, "Nectarian": 3.88,
            "pre-Nectarian": 4.2}


def lola_depth_km(dem_km: np.ndarray, lat0: float, lon0: float, d_km: float) -> float | None:
    """Rim-to-floor depth of the crater at (lat0, lon0) (module notes), km."""
    lat_c = 90.0 - (np.arange(720) + 0.5) / 4.0
    lon_c = (np.arange(1440) + 0.5) / 4.0
    r_km = d_km / 2.0
    rows = np.flatnonzero(np.abs(lat_c - lat0) <= np.degrees(1.3 * r_km / R_MOON_KM) + 0.25)
    la, lo = np.radians(lat_c[rows])[:, None], np.radians(lon_c)[None, :]
    la0, lo0 = np.radians(lat0), np.radians(lon0)
    a = (np.sin((la - la0) / 2) ** 2
         + np.cos(la0) * np.cos(la) * np.sin((lo - lo0) / 2) ** 2)
    r = 2 * R_MOON_KM * np.arcsin(np.sqrt(np.clip(a, 0, 1))) / r_km
    az = np.arctan2(np.sin(lo - lo0) * np.cos(la),
                    np.cos(la0) * np.sin(la) - np.sin(la0) * np.cos(la) * np.cos(lo - lo0))
    return rim_minus_floor(dem_km[rows], r, az, floor_r=0.6)


def main() -> None:
    dem_km = np.fromfile(IMG, dtype="<i2").reshape(720, 1440).astype(np.float64) * 0.5e-3
    rows = list(csv.DictReader(SAMPLE.open(encoding="utf-8")))
    real: dict[str, list[float]] = {k: [] for k in AGES_GYR}
    model: dict[str, list[float]] = {k: [] for k in AGES_GYR}
    for row in rows:
        age = "Imbrian" if "Imbrian" in row["age"] else row["age"].strip()
        d_km = float(row["D_km"])
        if age not in AGES_GYR or not 40.0 <= d_km < 100.0:
            continue
        depth = lola_depth_km(dem_km, float(row["lat"]), float(row["elon"]) % 360.0, d_km)
        if depth is None:
            continue
        real[age].append(depth / (1.044 * d_km**0.301))
        d_m = d_km * 1000.0
        fresh = float(craters.fresh_morphometry(d_m)["depth_m"])
        model[age].append(float(craters.crater_morphometry(d_m, age_gyr=AGES_GYR[age])
                                ["depth_m"]) / fresh)
    print("40-100 km lunar craters: depth / fresh depth, median [quartiles]")
    print(f"{'class':14s} {'age Gyr':>7s} {'N':>4s}  {'LOLA (LPI ages)':>22s}  {'craterform':>22s}")
    for age, t in AGES_GYR.items():
        if not real[age]:
            continue
        q = np.percentile(real[age], [25, 50, 75])
        m = np.percentile(model[age], [25, 50, 75])
        print(f"{age:14s} {t:7.2f} {len(real[age]):4d}  {q[1]:6.2f} [{q[0]:.2f}, {q[2]:.2f}]"
              f"       {m[1]:6.2f} [{m[0]:.2f}, {m[2]:.2f}]")


if __name__ == "__main__":
    main()
