"""Issue 21 acceptance figures for crater shapes (plain script, from the repository's top).

Fresh lunar depth and rim height through ``craters profile`` against Pike (1977) at
0.5-100 km (Pike's law holds from 400 m), the largest jump between neighbouring
diameters across the simple->complex transition, the flat floor and central peak of 30
and 100 km craters, Mars (Garvin & Sakimoto & Frawley 2003) and Mercury (Pike 1988)
transitions and simple and complex depths, fresh 40-400 m lunar craters stamped on a
raster against Stopar et al. 2017, diffusion of a 1 km crater against the test suite's
independent finite-difference solve, and what
``degradation=1`` leaves. Usage: ``python tests/benchmarks/measure_crater_morphology.py``.
"""

import os
import re
import subprocess
import sys
import tempfile

import numpy as np
from crater_depth import rim_minus_floor

import craters

PIKE = {"simple": ((0.196, 1.010), (0.036, 1.014)), "complex": ((1.044, 0.301), (0.236, 0.399))}
# body: source, fresh simple (a, b), complex (a, b) (d = a D^b, km), transition range (km),
# simple diameters (km, below where the two laws cross)
FITS = {"mars": ("Garvin, Sakimoto & Frawley 2003", (0.21, 0.81), (0.36, 0.49), (6.0, 8.0),
                 (1, 2, 4)),
        "mercury": ("Pike 1988", (0.199, 0.995), (0.353, 0.496), (9.0, 12.0), (1, 2, 3))}
STOPAR = ((40, 100, 0.13), (100, 200, 0.15), (200, 400, 0.17))  # Stopar et al. 2017


def cli(d: float, body: str = "moon") -> tuple[dict, np.ndarray]:
    """``craters profile``'s header figures and its table for diameter ``d`` metres."""
    with tempfile.TemporaryDirectory() as t:
        p = os.path.join(t, "p.csv")
        subprocess.run(["craters", "profile", "--diameter-m", str(d), "--body", body,
                        "--csv", p, "-q"], check=True)
        with open(p) as f:
            head = f.readline()
        pairs = re.findall(r"(depth_m|rim_height_m)=([0-9.eE+-]+)", head)
        return {k: float(v) for k, v in pairs}, np.loadtxt(p, delimiter=",", skiprows=2)


def lunar() -> None:
    print("Fresh lunar craters vs Pike (1977):")
    for dkm, kind in ((0.5, "simple"), (1, "simple"), (5, "simple"), (30, "complex"),
                      (100, "complex")):
        m, _ = cli(dkm * 1000)
        (a, b), (c, e) = PIKE[kind]
        dl, rl = 1000 * a * dkm**b, 1000 * c * dkm**e
        print(f"  {dkm:5g} km {kind:8s} depth {m['depth_m']:8.1f} m (Pike {dl:8.1f}, "
              f"{100 * (m['depth_m'] / dl - 1):+5.1f} %)  rim {m['rim_height_m']:7.1f} m "
              f"(Pike {rl:7.1f}, {100 * (m['rim_height_m'] / rl - 1):+5.1f} %)")
    ds = np.exp(np.linspace(np.log(3e3), np.log(60e3), 120))  # 2.5 % steps
    dep = np.array([craters.crater_morphometry(d)["depth_m"] for d in ds])
    rim = np.array([craters.crater_morphometry(d)["rim_height_m"] for d in ds])
    print(f"Transition: largest jump between neighbours (2.5 % apart, 3-60 km): depth "
          f"{100 * np.abs(np.diff(dep) / dep[:-1]).max():.2f} %, rim "
          f"{100 * np.abs(np.diff(rim) / rim[:-1]).max():.2f} %")
    for dkm in (30, 100):
        _, data = cli(dkm * 1000)
        x, h = data[:, 0], data[:, 2]
        m = craters.fresh_morphometry(dkm * 1000.0)
        xf = float(m["floor_diameter_m"]) / (dkm * 1000.0)
        floor = (x > 0.25) & (x < 0.9 * xf)
        peak = h[x < 0.02].max() - np.median(h[floor])
        print(f"  {dkm} km: floor from r/R 0.25 to {0.9 * xf:.2f} spans {np.ptp(h[floor]):.1f} m "
              f"(depth {m['depth_m']:.0f} m); central peak {peak:.0f} m above the floor "
              f"(published fit 0.032 D^0.9 km = {32 * dkm**0.9:.0f} m)")


def planets() -> None:
    print("Mars and Mercury:")
    for body, (src, simple, complex_, rng, simple_km) in FITS.items():
        t = craters.get_target(body)
        print(f"  {body}: transition {t.transition_m / 1e3:.1f} km (published "
              f"{rng[0]}-{rng[1]} km, {src})")
        for dkm, (a, b) in [(d, simple) for d in simple_km] + [(d, complex_)
                                                             for d in (20, 50, 100)]:
            m, _ = cli(dkm * 1000, body)
            law = 1000 * a * dkm**b
            print(f"    D {dkm} km: depth {m['depth_m']:.0f} m vs {src} {law:.0f} m "
                  f"({100 * (m['depth_m'] / law - 1):+.1f} %)")


def stopar(n: int = 200, pixel_m: float = 0.5) -> None:
    """Fresh 40-400 m lunar craters (N_cum ~ D^-2) stamped one by one on a flat raster of
    ``pixel_m`` with the default roughness; d/D = ``crater_depth.rim_minus_floor`` (rim at
    0.8-1.2 R, floor within R/2) / D, median per Stopar et al. 2017 bin."""
    rng = np.random.default_rng(2017)
    print(f"Fresh small lunar craters stamped at {pixel_m} m/px vs Stopar et al. 2017:")
    for lo, hi, ref in STOPAR:
        u = rng.random(n)
        d = 1.0 / (1.0 / lo - u * (1.0 / lo - 1.0 / hi))     # N_cum ~ D^-2 in [lo, hi]
        ratios = []
        for dm in d:
            size = int(np.ceil(1.6 * dm / pixel_m)) | 1
            c = (size // 2) * pixel_m
            cat = np.zeros(1, dtype=[("x_m", "f8"), ("y_m", "f8"), ("diameter_m", "f8")])
            cat[0] = (c, c, dm)
            h = craters.stamp_many(np.zeros((size, size)), pixel_m, cat,
                                   rng=int(rng.integers(1 << 30)))
            yy, xx = (np.mgrid[:size, :size] * pixel_m - c)
            depth = rim_minus_floor(h, np.hypot(xx, yy) / (dm / 2), np.arctan2(yy, xx))
            ratios.append(depth / dm)
        med = float(np.median(ratios))
        print(f"  {lo:3d}-{hi:3d} m: median d/D {med:.4f} (Stopar {ref}, "
              f"{100 * (med / ref - 1):+.1f} %) over {n} craters")


def depth_ratio(r: np.ndarray, h: np.ndarray, d: float) -> float:
    return float((h[r <= 1.5].max() - h[r <= 1.2].min()) / d)


def diffusion() -> None:
    sys.path.insert(0, "tests/craters")
    from test_profile import explicit_radial_diffusion

    print("Diffusion of a 1 km lunar crater vs explicit finite differences (same kappa t):")
    d = 1000.0
    r = np.linspace(0.0, 6.0, 1201)
    for age in (1.0, 3.5):
        tau = float(craters.tau_from_age(d, age))
        ref = depth_ratio(r, explicit_radial_diffusion(r, craters.fresh_profile(r, d), tau), d)
        got = depth_ratio(r, craters.radial_profile(r, d, age_gyr=age), d)
        print(f"  {age} Gyr (kappa t = {tau * 500**2:.0f} m^2): d/D exact {got:.4f}, "
              f"FD {ref:.4f} ({100 * (got / ref - 1):+.2f} %)")
    x = np.linspace(0, 3, 601)
    gone = np.ptp(craters.radial_profile(x, d, degradation=1.0))
    fresh = np.ptp(craters.fresh_profile(x, d))
    print(f"degradation = 1: relief left {gone:.3g} m of the fresh {fresh:.1f} m "
          f"({100 * gone / fresh:.3f} %)")


if __name__ == "__main__":
    lunar()
    stopar()
    planets()
    diffusion()
