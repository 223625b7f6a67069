"""Named scenes: the paper's bodies and asteroid-like presets, as scene settings.

A preset is a set of scene settings (the keys of :meth:`latlong.Scene.from_settings`,
which are also the ``latlong build`` option names and the TOML keys) plus, for Perlin
bases, the fBm amplitude as a fraction of the radius. Settings given explicitly override
the preset's.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from pathlib import Path

from .faulting import FAULTING_PRESETS
from .perlin import FBM_PRESETS

__all__ = ["DEFAULT_PRESET", "PRESETS", "RENAMED_PRESETS", "SHAPES_DIR", "Preset",
           "preset_table"]

#: Folder of the bundled shape models (provenance in its README.md).
SHAPES_DIR = Path(__file__).resolve().parent / "data" / "shapes"


def _faulting(name: str) -> dict:
    """The flat settings of a faulting parameter set (stretch included)."""
    p = FAULTING_PRESETS[name]
    return {"faults_1": p.n_faults_1, "max_fault_1_m": p.max_fault_1_m,
            "smooth_width_m": p.smooth_width_m, "smooth_passes": p.smooth_passes,
            "faults_2": p.n_faults_2, "max_fault_2_m": p.max_fault_2_m,
            "stretch": tuple(p.stretch)}


def _fbm(name: str) -> dict:
    """The flat settings of a Perlin parameter set (its amplitude is a fraction)."""
    p = FBM_PRESETS[name]
    return {"frequency": p.frequency, "octaves": p.octaves, "persistence": p.persistence,
            "lacunarity": p.lacunarity}


@dataclass(frozen=True, slots=True)
class Preset:
    """A named scene."""

    description: str
    """What it reproduces, with its source."""
    base: str
    """Base shape: ``sphere``, ``faulting``, ``fbm`` or ``shape`` (a bundled model)."""
    settings: dict = dataclasses.field(default_factory=dict)
    """Scene settings (flat keys), the base's parameters included."""
    amplitude_fraction: float | None = None
    """fBm amplitude as a fraction of the radius (``fbm`` base; ``amplitude_m`` wins)."""
    model: str | None = None
    """Bundled shape model file (``shape`` base; in ``latlong/data/shapes``)."""
    density_kg_m3: float | None = None
    """The real body's bulk density, kg/m^3 (for gravitational slopes)."""
    period_h: float | None = None
    """The real body's rotation period, hours (for gravitational slopes)."""

    @property
    def model_path(self) -> Path | None:
        """Path of the bundled shape model, or None."""
        return None if self.model is None else SHAPES_DIR / self.model


_FIG5A = FBM_PRESETS["fig5a"].amplitude

PRESETS: dict[str, Preset] = {
    "paper": Preset("Martin 2014 IV.A two-phase faulting: 1000 faults <= 5 m, 3 x 20 m "
                    "smoothing, 20 000 faults <= 0.03 m; 100 m radius stretched 2x on x",
                    "faulting", {"radius_m": 100.0, **_faulting("paper")}),
    "fig4": Preset("Martin 2014 Fig. 4: as 'paper' with 500 phase-2 faults <= 0.5 m",
                   "faulting", {"radius_m": 100.0, **_faulting("fig4")}),
    "fig5a": Preset("Martin 2014 Fig. 5 Perlin set: f 1.5, persistence 0.5, lacunarity "
                    "1.75, 10 octaves", "fbm", _fbm("fig5a"), FBM_PRESETS["fig5a"].amplitude),
    "fig5b": Preset("Martin 2014 Fig. 5 Perlin set: f 2.5, persistence 0.5, lacunarity 1.5",
                    "fbm", _fbm("fig5b"), FBM_PRESETS["fig5b"].amplitude),
    "fig5c": Preset("Martin 2014 Fig. 5 Perlin set: f 4.0, persistence 0.3, lacunarity 2.5",
                    "fbm", _fbm("fig5c"), FBM_PRESETS["fig5c"].amplitude),
    "fbm-cratered": Preset(
        "Martin 2014 Fig. 8: Perlin base (fig5a) on a 100 m body with N_cum = 0.5 D^-2 "
        "craters, 1-15 m (resolved from magnitude ~400)", "fbm",
        {**_fbm("fig5a"), "radius_m": 100.0, "craters": ["c=0.5,k=-2,d_min_m=1,d_max_m=15"]},
        _FIG5A),
    "faulted-cratered": Preset(
        "Martin 2014 Fig. 8: two-phase faulting (paper), stretch 2 on x, with N_cum = "
        "0.1 D^-2 craters, 1-20 m", "faulting",
        {**_faulting("paper"), "radius_m": 100.0, "craters": ["c=0.1,k=-2,d_min_m=1,d_max_m=20"]}),
    "eros": Preset(
        "433 Eros from the NEAR 7790-plate shape model (34 x 11 x 11 km; Thomas et al., "
        "PDS). Craters: near empirical saturation above 0.2 km (Veverka et al. 2000 Science "
        "289, 2088; Chapman 2002 Asteroids III), between the Hartmann (1984) and Trask (1966) "
        "equilibria (1.38-1.99 per km^2 >= 0.2 km, slopes -1.83 to -2): N_cum = 0.0377 "
        "D^-1.9 (1.6 per km^2 >= 0.2 km), 0.2-1.18 km (the model holds larger ones); "
        "depleted below 0.2 km at R = 0.08 (Berthoud, Thomas & Veverka 2001, BAAS 33, 59.04, "
        "counted down to 50 m): N_cum = 0.04 D^-2, 50-200 m; strongly depleted below 100 m "
        "(Chapman 2002): about 40 per km^2 >= 20 m instead of the ~400 of saturation (NEAR "
        "MSI counts as reported by the NEAR team), N_cum = 7.8e-4 D^-1, 20-50 m (40 per km^2 "
        ">= 20 m with the larger layers). Craters below the mesh's resolution are in the "
        "catalogue and on demand (a magnitude-700 vertex is ~19 m apart). "
        "Boulders: 6760 >= 15 m on 1125 km^2 (Thomas et al. "
        "2001, Nature 413, 394) with cumulative exponent -3.25 +- 0.14 (Michikami & Hagermann "
        "2021, Icarus 357, 114282): N_cum = 0.0397 D^-3.25, 40-100 m at magnitude 700. "
        "Bulk 2670 kg/m^3 (Yeomans et al. 2000); spin 5.27 h", "shape",
        {"magnitude": 700, "shape_units": "km", "density_kg_m3": 2670.0,
         "craters": ["c=0.0377,k=-1.9,d_min_m=200,d_max_m=1180,age_max_gyr=2",
                     "c=0.04,k=-2,d_min_m=50,d_max_m=200,age_max_gyr=0.5",
                     "c=7.8e-4,k=-1,d_min_m=20,d_max_m=50,age_max_gyr=0.1"],
         "boulders": ["c=0.0397,k=-3.25,d_min_m=40,d_max_m=100,near=0.3"]},
        model="eros007790.tab", density_kg_m3=2670.0, period_h=5.27),
    "itokawa": Preset(
        "25143 Itokawa from the Hayabusa shape model (535 x 294 x 209 m; q = 32), cratered on "
        "its own mesh (not star-shaped) at 2 m. Craters: few and shallow (Saito et al. 2006 "
        "Science 312, 1341; Hirata et al. 2009 Icarus 200, 486); N_cum = 0.006 D^-2 (15 per "
        "km^2 >= 20 m: the named craters' lower bound), 6-19 m, younger than 10 Myr (Michel et "
        "al. 2009 Icarus 200, 503: surface ages of Myr). Boulders: 373 >= 5 m on 0.393 km^2, "
        "exponent -3.1 +- 0.1 (Michikami et al. 2008, Earth Planets Space 60, 13): N_cum = "
        "0.1395 D^-3.1, 4-20 m. Bulk 1900 kg/m^3 (Fujiwara et al. 2006); spin 12.132 h",
        "shape",
        {"shape_units": "km", "surface": "mesh", "spacing_m": 2.0, "density_kg_m3": 1900.0,
         "craters": ["c=0.006,k=-2,d_min_m=6,d_max_m=19,age_max_gyr=0.01"],
         "boulders": ["c=0.1395,k=-3.1,d_min_m=4,d_max_m=20,near=0.3"]},
        model="itokawa_32.obj", density_kg_m3=1900.0, period_h=12.132),
    "bennu": Preset(
        "101955 Bennu from the radar shape model (Nolan et al. 2013; spinning top, 246 m "
        "mean radius). Craters: >= 108 craters >= 10 m with d/D = 0.10 +- 0.03 (Daly et al. "
        "2020, GRL 47, e2020GL089672: the sample with altimetry; ~1500 craters in all, "
        "Bierhaus et al. 2022): N_cum = 0.018 D^-2 (180 per km^2 >= 10 m), 4-50 m (the "
        "model holds larger ones), younger than 50 Myr (Walsh et al. 2019, Nature Geosci. "
        "12, 242). Depths: the measured d/D, 0.13 +- 0.04 below 10 m and 0.10 +- 0.03 above "
        "(Daly et al. 2020), as d/D = 0.118 (D / 10 m)^-0.244, fitted so that the craters as "
        "stamped on the mesh have the two means (as formed, 6-9 % deeper at this "
        "population's median diameters, 5.3 and 13.9 m: the mesh takes 4-6 % off), stamped "
        "as measured (no lunar diffusion: on this surface it "
        "would leave d/D 0.03-0.06). Magnitude 500: 0.75 m spacing, 4 m craters 5 vertices "
        "across. The model is Loop-subdivided before casting (the interpolating butterfly "
        "kept its 15 m facets and a dark crease along the equatorial ridge). "
        "Boulders: > 200 >= 10 m, exponent -2.9 +- 0.3 (DellaGiustina et al. "
        "2019, Nature Astron. 3, 341; Walsh et al. 2019): N_cum = 0.238 D^-2.9 (300 per km^2 "
        ">= 10 m), 4-40 m. Bulk 1190 kg/m^3 (Scheeres et al. 2019); spin 4.296 h", "shape",
        {"magnitude": 500, "shape_units": "km", "shape_smooth": "loop",
         "density_kg_m3": 1190.0,
         "crater_depth_ratio": 0.118, "crater_depth_exponent": 0.756,
         "craters": ["c=0.018,k=-2,d_min_m=4,d_max_m=50,age_max_gyr=0.05,degradation=0"],
         "boulders": ["c=0.238,k=-2.9,d_min_m=4,d_max_m=40,near=0.3"]},
        model="bennu_radar_sbgat.obj", density_kg_m3=1190.0, period_h=4.296),
}

#: Former preset names and what replaced them.
RENAMED_PRESETS = {"eros-like": "eros", "itokawa-like": "itokawa", "bennu-like": "bennu"}

#: The preset a base gets when none is named (its parameter set).
DEFAULT_PRESET: dict[str, str | None] = {"faulting": "paper", "fbm": "fig5a", "sphere": None}


def preset_table() -> list[tuple[str, str, dict]]:
    """(name, description, settings) of every preset, for listings.

    Examples
    --------
    >>> name, _, settings = preset_table()[0]
    >>> name, settings["base"], settings["faults_1"]
    ('paper', 'faulting', 1000)
    """
    rows = []
    for name, p in PRESETS.items():
        s = {"base": p.base if p.model is None else f"shape:{p.model}", **p.settings}
        if p.amplitude_fraction is not None:
            s["amplitude_fraction"] = p.amplitude_fraction
        if p.period_h is not None:
            s["period_h (for latlong slopes)"] = p.period_h
        rows.append((name, p.description, s))
    return rows
