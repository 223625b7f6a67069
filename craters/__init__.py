r"""craters: crater science shared by the body (latlong) and raster (dem) pipelines.

Science only, pure functions over numpy arrays: fresh crater shapes on any target body
(simple bowls, flat floors, terraces, central peaks, peak rings; Pike 1977 and the
bodies' published laws), degradation by topographic diffusion (Fassett & Thomson 2014),
irregular rims and roughness (lunar paper III), stamping into 2-D height grids, crater
populations (power laws, or production functions and chronologies at a model age with
equilibrium) and catalogs (CSV, GeoJSON, craterstats .scc), the locally controlled
spot-noise (LCSN) crater kernels of Li et al. 2022 with their morphometry, procedural
boulders.
Imports neither ``latlong`` nor ``dem``.

::

    targets -> morphology (fresh), diffusion (ageing) -> profile -> stamp
      (numba: _stamp_kernels primitives, _raster_stamp_kernels writers, _tilt_kernels
      craters on steep ground in their base's frame)
    chronology/ (production functions, chronologies, equilibrium; model-age sampling)
      -> layers (power-law and model-age layers) -> population (positions, ages)
      -> catalog (CSV, GeoJSON, craterstats .scc)
    lcsn/ (kernel, morphometry, inverse, presets; numba: _lcsn_kernels)
    boulders/ (meshes, placement)
    kernels: the numba building blocks latlong and dem compile against

The plumbing every package needs (checks, RNG, atomic files, progress, ``key=value``
specs, reports, the mesh-writer registry) is the private ``craters._shared``, and the
command line ``craters.cli``; neither is crater science. More in the subpackages'
docstrings: :mod:`craters.chronology` (populations by model age), :mod:`craters.lcsn`
(Li et al.'s kernels), :mod:`craters.boulders`.

The ``craters`` command
-----------------------
The commands of this docstring run as written, in order, from the repository's folder,
into ``out/craters/``; ``tests/test_readme_commands.py`` runs them at small sizes.

.. code-block:: bash

    mkdir -p out/craters
    craters profile --diameter-m 1000 --age-gyr 3 --csv out/craters/p.csv \
        --plot out/craters/p.png
    craters profile --diameter-m 100000 --body moon  # 4.2 km deep, 59 km flat floor, 2 km peak
    craters profile --diameter-m 20000 --body mars --plot out/craters/mars.png
    craters population --body mars \
        --craters npf=mars,age_gyr=3.5,d_min_m=5000,d_max_m=100000 -o out/craters/mars_all.csv
    craters population --craters c=0.5,k=-2,d_min_m=5,d_max_m=800 --radius-m 2000 --seed 1 \
        -o out/craters/cat.csv --plot out/craters/sfd.png

    # a 3.8 Gyr lunar surface on 10 000 km^2 (Neukum et al. 2001), capped at the Trask
    # equilibrium below its saturation diameter (printed: 420 m); craterstats reads the .scc
    craters population \
        --craters npf=moon,age_gyr=3.8,d_min_m=100,d_max_m=40000,equilibrium=trask \
        --area-m2 1e10 --seed 1 -o out/craters/moon.scc --plot out/craters/moon_sfd.png
    # Mars at 3.5 Gyr (Ivanov 2001 production function, Hartmann & Neukum 2001 chronology),
    # CSV with the Robbins database's columns (LAT_CIRC_IMG, LON_CIRC_IMG, DIAM_CIRC_IMG, km)
    craters population --craters npf=mars,age_gyr=3.5,d_min_m=1000,d_max_m=40000 \
        --area-m2 1e11 --seed 1 -o out/craters/mars.csv --columns robbins

Crater shapes by body, size and age
-----------------------------------
A fresh crater's shape follows its target body (:data:`TARGETS`: ``moon``, ``mars``,
``mercury``, ``earth``, ``ceres``, ``vesta``, and :func:`small_body` (radius_m,
density_kg_m3) for an asteroid, whose gravity follows from its size; ``--body``,
``--gravity-m-s2`` on every command). Below the body's simple/complex transition (Moon
~15 km; Mars 7 km, Garvin, Sakimoto & Frawley 2003; Mercury 10.3 km, Pike 1988; measured
where published, else scaled as 1/g from the Moon's) a crater is a bowl with its body's
fresh depth law (Moon: Pike's (1977) simple depth 0.196 D^1.010 and rim 0.036 D^1.014, D
in km, from 400 m; below, shallower in a weak regolith: d/D 0.13 at 40-100 m, 0.15 at
100-200 m, 0.17 at 200-400 m, Stopar et al. 2017; Mars 0.21 D^0.81) and Fassett & Thomson's
(2014) fresh interior; above it, continuously through a transitional range (0.8–1.6
D_t), a flat floor that widens with D, terraced walls, a central peak (height
0.032 D^0.9 km, base 0.22 D) and Pike's complex depth 1.044 D^0.301 and rim 0.236
D^0.399; beyond the peak-ring onset (Moon ~200 km, Baker et al. 2011) a peak ring; the
ejecta thins as r^-3 (McGetchin et al. 1973). Ageing is topographic diffusion
(Fassett & Thomson 2014: κ = 5.5 m²/Myr at 1 km, ∝ D^0.9): a crater of age T is its
fresh profile diffused for κT, solved exactly in Hankel space and cached per (D, κT) for
stamping, so old craters are shallow and rimless (a 1 km lunar crater: d/D 0.196 fresh,
0.174 at 1 Gyr, 0.103 at 3.5 Gyr, 0.011 at 3.9 Gyr: diffusion is paced by the impact
flux, :func:`diffusion_age_gyr`) and ``degradation`` (the share of the fresh depth
removed, an explicit override) = 1 leaves no relief. Catalogs list each crater's
``morphology`` (simple, transitional, complex, peak-ring), its depth, rim height, floor
diameter, peak height and κt as stamped. ``python examples/plot_crater_morphology.py``
draws them; ``craters.stamp_many(heights, pixel_size_m, catalog, target=...)`` stamps a
catalog into any 2-D height grid, with Martin et al.'s irregular rims and fractal
roughness, on all cores: craters whose boxes cannot overlap are stamped together, in
waves that keep the age order wherever it matters (the same bytes for any thread count).

Catalogs crater-counting tools read
-----------------------------------
``-o cat.scc`` writes a craterstats spatial crater count (:func:`write_scc`: ellipsoid
axes, ``Total_area`` in km², one row per crater with diameter in km, fraction,
longitude and latitude; :func:`read_scc` reads it and CraterTools' files). craterstats
fits a synthetic surface's age back: with ``pip install craterstats 'numpy<2'
'scipy<1.14'`` in a virtual environment of its own, ``craterstats -cs "Moon, Neukum et
al. (2001)" -p source=out/craters/moon.scc,type=c-fit,range=[1,20] -f csv`` gives
3.8 Gyr. ``python tests/benchmarks/bench_age_roundtrip.py`` runs the whole round trip
(it makes that environment; the opt-in test ``CRATERFORM_CRATERSTATS=1 python -m pytest
tests/craters/test_craterstats_roundtrip.py`` does the same): Moon 1.0 Gyr → 0.96–1.02,
Moon 3.8 → 3.79–3.81, Mars 3.5 → 3.49–3.53 Gyr over five seeds, 400–2100 craters in
1–20 km each.

.. code-block:: python

    import craters

    layer = craters.ModelAgeLayer("moon", 3.8, d_min_m=100.0, d_max_m=40000.0,
                                  equilibrium="trask")
    cat = craters.population([layer], area_m2=1e10, rng=1)  # sizes, ages, positions ...
    craters.write_scc(cat, "out/craters/moon_lib.scc", area_m2=1e10,
                      body_radius_m=1737400.0)
    print(layer.saturation_diameter_m, layer.expected_count(1e10),
          layer.cumulative_m2(1000.0))
"""

import logging
import os
from typing import TYPE_CHECKING

from ._shared.lazy import lazy_package

#: How many times a numba OpenMP thread that ran out of work spins before it sleeps
#: (``GOMP_SPINCOUNT``; libgomp's default is 300 000): :func:`_short_thread_spins`.
THREAD_SPIN_COUNT = "1000"


def _short_thread_spins() -> None:
    """Let numba's OpenMP threads (its default threading layer on Linux) sleep soon after
    they run out of work: ``GOMP_SPINCOUNT`` = :data:`THREAD_SPIN_COUNT` in this process
    and the processes it starts, unless ``GOMP_SPINCOUNT`` or ``OMP_WAIT_POLICY`` is set.
    ``craters`` is imported before any kernel runs (``latlong``
    and ``dem`` import it), and libgomp reads the variable when numba starts its threads.

    A thread that finished its share of a parallel loop spins ~300 000 times by default,
    and the stamping waits at the end of each of its waves: where another process (or the
    VM's host) holds a core, the spinning thread takes time from the one still working.
    Measured (``tests/benchmarks/bench_body_craters.py``, 2 threads / 1 thread,
    2026-12-07, alternating runs): with a busy-loop process beside it, M = 330 x0.77-1.05
    with libgomp's default and x1.05-1.13 with 1000 spins (10 repetitions a run), M = 1000
    x1.02-1.03 and x1.34-1.35; alone, M = 330 x1.58-1.68 and x1.87-2.29, M = 1000
    x1.96-2.04 and x1.81-1.92. No result depends on it."""
    if "GOMP_SPINCOUNT" not in os.environ and "OMP_WAIT_POLICY" not in os.environ:
        os.environ["GOMP_SPINCOUNT"] = THREAD_SPIN_COUNT


_short_thread_spins()

if TYPE_CHECKING:  # at run time each name is imported on first use (lazy_package)
    from .boulders import (
        BoulderLayer,
        BoulderNode,
        BoulderShape,
        boulder,
        boulder_meshes,
        golombek_layers,
        parse_boulder_spec,
        parse_boulder_specs,
    )
    from .catalog import (
        CATALOG_COLUMNS,
        make_catalog,
        read_catalog,
        read_scc,
        sort_oldest_first,
        validate_catalog,
        write_catalog,
        write_geojson,
        write_scc,
    )
    from .chronology import (
        CHRONOLOGY_SYSTEMS,
        EQUILIBRIUM_FUNCTIONS,
        ChronologySystem,
        cap_at_equilibrium,
        cumulative_density,
        formation_ages,
        get_chronology_system,
        sample_pf_diameters,
        saturation_diameter_m,
    )
    from .diffusion import (
        diffusion_age_gyr,
        kappa_m2_yr,
        profile_tables,
        tau_from_age,
        tau_from_degradation,
    )
    from .layers import LAYER_TYPES, ModelAgeLayer, as_crater_layer
    from .lcsn import (
        LCSN_PRESETS,
        LcsnParams,
        lcsn_degrade,
        lcsn_kernel,
        lcsn_morphometry,
        lcsn_raw,
        lcsn_scaled,
    )
    from .morphology import fresh_morphometry, fresh_profile, morphology_class
    from .population import (
        CraterLayer,
        expected_count,
        fit_power_law_exponent,
        parse_layer_spec,
        population,
        power_law_population,
        sample_power_law_diameters,
        uniform_sphere_directions,
    )
    from .profile import (
        DEFAULT_EJECTA_EDGE,
        crater_morphometry,
        crater_tau,
        radial_profile,
        slope_erosion,
    )
    from .references import REFERENCES, Reference, reference
    from .stamp import (
        Crater,
        Roughness,
        StampingProfiles,
        as_stamped,
        rim_perturbations,
        stamp,
        stamp_many,
        stamping_profiles,
    )
    from .targets import TARGETS, Target, get_target, small_body

__all__ = [
    "BoulderLayer",
    "CATALOG_COLUMNS",
    "BoulderNode",
    "BoulderShape",
    "CHRONOLOGY_SYSTEMS",
    "ChronologySystem",
    "DEFAULT_EJECTA_EDGE",
    "EQUILIBRIUM_FUNCTIONS",
    "LAYER_TYPES",
    "LCSN_PRESETS",
    "REFERENCES",
    "TARGETS",
    "Target",
    "Crater",
    "CraterLayer",
    "Reference",
    "LcsnParams",
    "ModelAgeLayer",
    "Roughness",
    "StampingProfiles",
    "as_crater_layer",
    "as_stamped",
    "boulder",
    "boulder_meshes",
    "cap_at_equilibrium",
    "crater_morphometry",
    "crater_tau",
    "cumulative_density",
    "expected_count",
    "fit_power_law_exponent",
    "fresh_morphometry",
    "fresh_profile",
    "golombek_layers",
    "parse_boulder_spec",
    "parse_boulder_specs",
    "parse_layer_spec",
    "formation_ages",
    "get_chronology_system",
    "get_target",
    "diffusion_age_gyr",
    "kappa_m2_yr",
    "lcsn_degrade",
    "lcsn_kernel",
    "lcsn_morphometry",
    "lcsn_raw",
    "lcsn_scaled",
    "make_catalog",
    "morphology_class",
    "population",
    "power_law_population",
    "profile_tables",
    "radial_profile",
    "reference",
    "read_catalog",
    "read_scc",
    "rim_perturbations",
    "sample_pf_diameters",
    "sample_power_law_diameters",
    "saturation_diameter_m",
    "slope_erosion",
    "small_body",
    "sort_oldest_first",
    "stamp",
    "stamp_many",
    "stamping_profiles",
    "tau_from_age",
    "tau_from_degradation",
    "uniform_sphere_directions",
    "validate_catalog",
    "write_catalog",
    "write_geojson",
    "write_scc",
]

lazy_package(__name__)

logging.getLogger(__name__).addHandler(logging.NullHandler())
