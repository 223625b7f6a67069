"""Age round trip: surfaces of a known model age, fitted by craterstats, give their age back.

Each case draws a crater population from a chronology system (``craters.ModelAgeLayer``:
``npf`` at ``age_gyr``, diameters 0.5-40 km so that the fitted range is complete) on an
area where at least 300 craters fall in 1-20 km, writes it as a craterstats spatial
crater count (``craters.write_scc``) and fits it with craterstats' own command line: a
cumulative fit (``type=c-fit``) over 1-20 km with the chronology system that made it
(``-cs "Moon, Neukum et al. (2001)"``, ``"Mars, Neukum-Ivanov (2001)"``). Acceptance
(issue 21): the Moon at 1.0 Gyr within +-10 %, at 3.8 Gyr within +-0.1 Gyr, Mars at 3.5
Gyr within +-0.1 Gyr. A fourth case caps the craters below the saturation diameter at
the Trask equilibrium (0.1-40 km drawn) and fits above it.

craterstats 3.x imports ``scipy.integrate.simps`` and ``numpy.Inf``, so it needs numpy < 2
and scipy < 1.14: it runs in a virtual environment of its own, made in a temporary
folder (``python -m venv``; ``pip install craterstats 'numpy<2' 'scipy<1.14'``, about a
minute) or the one given with ``--venv`` / ``CRATERFORM_CRATERSTATS_VENV``.

    python tests/benchmarks/bench_age_roundtrip.py [--seeds 1 2 3] [--venv DIR]

``tests/craters/test_craterstats_roundtrip.py`` runs the same (opt-in:
``CRATERFORM_CRATERSTATS=1``).
"""

from __future__ import annotations

import argparse
import csv
import dataclasses
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import craters


@dataclasses.dataclass(frozen=True)
class Case:
    npf: str
    age_gyr: float
    area_m2: float
    tolerance_gyr: float
    d_min_m: float = 500.0
    equilibrium: str | None = None

    @property
    def label(self) -> str:
        eq = f", {self.equilibrium} equilibrium" if self.equilibrium else ""
        return f"{self.npf} {self.age_gyr:g} Gyr{eq}"


FIT_RANGE_KM = (1.0, 20.0)
CASES = (
    Case("moon", 1.0, 2.5e12, 0.10),    # +-10 %; ~2100 craters in 1-20 km
    Case("moon", 3.8, 2.5e10, 0.10),    # ~450
    Case("mars", 3.5, 1.5e11, 0.10),    # ~420
    Case("moon", 3.8, 2.5e10, 0.10, d_min_m=100.0, equilibrium="trask"),
)


def craterstats_venv(folder: Path) -> Path:
    """A virtual environment with craterstats in ``folder``; returns its ``craterstats``."""
    exe = folder / "bin" / "craterstats"
    if not exe.exists():
        subprocess.run([sys.executable, "-m", "venv", str(folder)], check=True)
        subprocess.run([str(folder / "bin" / "python"), "-m", "pip", "install", "-q",
                        "craterstats", "numpy<2", "scipy<1.14"], check=True)
    return exe


def write_surface(case: Case, seed: int, folder: Path) -> tuple[Path, int]:
    """The case's crater count as ``.scc``; returns its path and the craters in the fit
    range."""
    layer = craters.ModelAgeLayer(case.npf, case.age_gyr, case.d_min_m, 40000.0,
                                  equilibrium=case.equilibrium)
    cat = craters.population(layer, area_m2=case.area_m2, rng=seed)
    age = f"{case.age_gyr:g}".replace(".", "p")     # craterstats takes a dot as a suffix
    path = folder / f"{case.npf}_{age}_{case.equilibrium or 'pf'}_{seed}.scc"
    system = craters.get_chronology_system(case.npf)
    craters.write_scc(cat, path, area_m2=case.area_m2, body_radius_m=system.body_radius_m,
                      note=f"bench_age_roundtrip: {case.label}, seed {seed}")
    d_km = cat["diameter_m"] / 1000.0
    return path, int(((d_km >= FIT_RANGE_KM[0]) & (d_km <= FIT_RANGE_KM[1])).sum())


def craterstats_fit(exe: Path, scc: Path, system_title: str) -> dict:
    """craterstats' cumulative fit of ``scc`` over the fit range: its age and interval."""
    out = scc.with_suffix("")
    lo, hi = FIT_RANGE_KM
    cmd = [str(exe), "-cs", system_title, "-p",
           f"source={scc},type=c-fit,range=[{lo:g},{hi:g}]", "-o", str(out), "-f", "csv"]
    proc = subprocess.run(cmd, capture_output=True, text=True, cwd=scc.parent)
    table = out.with_suffix(".csv")
    if proc.returncode != 0 or not table.exists():
        raise RuntimeError(f"craterstats failed: {' '.join(cmd)}\n{proc.stdout}{proc.stderr}")
    rows = list(csv.reader(table.read_text(encoding="utf-8").splitlines()))
    head = next(r for r in rows if r and r[0] == "Name")
    row = {}
    for name, value in zip(head, rows[rows.index(head) + 1], strict=False):
        row.setdefault(name, value)     # the numbers; later columns repeat them formatted
    return {"age": float(row["Age"]), "age_minus": float(row["Age-"]),
            "age_plus": float(row["Age+"]), "n": float(row["N"]), "d_min": float(row["d_min"]),
            "d_max": float(row["d_max"])}


def run(venv: Path | None = None, seeds=(1,), cases=CASES, folder: Path | None = None):
    """Every case at every seed: list of result dicts (case, seed, counts, fit, error)."""
    with tempfile.TemporaryDirectory(prefix="craterstats-") as tmp:
        work = Path(folder) if folder else Path(tmp)
        exe = craterstats_venv(Path(venv) if venv else work / "venv")
        results = []
        for case in cases:
            title = craters.get_chronology_system(case.npf).title
            for seed in seeds:
                scc, n_range = write_surface(case, seed, work)
                fit = craterstats_fit(exe, scc, title)
                err = fit["age"] - case.age_gyr
                tol = case.tolerance_gyr * (case.age_gyr if case.age_gyr < 2 else 1.0)
                results.append({"case": case, "seed": seed, "n_1_20km": n_range, **fit,
                                "error_gyr": err, "tolerance_gyr": tol,
                                "ok": abs(err) <= tol})
        return results


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, nargs="+", default=[1, 2, 3, 4, 5])
    parser.add_argument("--venv", default=os.environ.get("CRATERFORM_CRATERSTATS_VENV"),
                        help="a virtual environment with craterstats (made if missing)")
    args = parser.parse_args(argv)
    t0 = time.perf_counter()
    results = run(args.venv, args.seeds)
    print(f"craterstats cumulative fits over {FIT_RANGE_KM[0]:g}-{FIT_RANGE_KM[1]:g} km "
          f"(the bins craterstats snaps to in the d_min/d_max columns)")
    print(f"{'surface':<34}{'seed':>5}{'N 1-20km':>9}{'fit N':>7}{'d_min':>7}{'d_max':>7}"
          f"{'age':>8}{'-':>8}{'+':>8}{'error':>9}{'tol':>7}  ok")
    for r in results:
        print(f"{r['case'].label:<34}{r['seed']:>5}{r['n_1_20km']:>9}{r['n']:>7.0f}"
              f"{r['d_min']:>7.3g}{r['d_max']:>7.3g}{r['age']:>8.3f}{r['age_minus']:>8.3f}"
              f"{r['age_plus']:>8.3f}{r['error_gyr']:>+9.3f}{r['tolerance_gyr']:>7.2f}  "
              f"{'yes' if r['ok'] else 'NO'}")
    print(f"{sum(r['ok'] for r in results)}/{len(results)} within tolerance; "
          f"{time.perf_counter() - t0:.0f} s (venv included)")
    return 0 if all(r["ok"] for r in results) else 1


if __name__ == "__main__":
    sys.exit(main())
