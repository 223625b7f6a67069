"""Named scenes: the paper's bodies and asteroid-like presets, as scene settings.

A preset is a set of scene settings (the keys of :meth:`latlong.Scene.from_settings`,
which are also the ``latlong build`` option names and the TOML keys) plus, for Perlin
bases, the fBm amplitude as a fraction of the radius. Settings given explicitly override
the preset's.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

from .faulting import FAULTING_PRESETS
from .perlin import FBM_PRESETS

__all__ = ["DEFAULT_PRESET", "PRESETS", "Preset", "preset_table"]


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
    """Base shape: ``sphere``, ``faulting`` or ``fbm``."""
    settings: dict = dataclasses.field(default_factory=dict)
    """Scene settings (flat keys), the base's parameters included."""
    amplitude_fraction: float | None = None
    """fBm amplitude as a fraction of the radius (``fbm`` base; ``amplitude_m`` wins)."""


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
    "eros-like": Preset(
        "433 Eros-like: 8 km radius stretched to ~34 x 11 x 11 km, lumpy fBm base, a "
        "saturated crater population near equilibrium (N_cum = 0.1 D^-2, 40 m-1.5 km), "
        "asteroid d/D = 0.2 (magnitude >= 700 resolves it)", "fbm",
        {"radius_m": 8000.0, "stretch": (2.15, 0.7, 0.7), "frequency": 1.2, "octaves": 8,
         "persistence": 0.45, "lacunarity": 2.0,
         "craters": ["c=0.1,k=-2,d_min_m=40,d_max_m=1500"]}, 0.12),
    "itokawa-like": Preset(
        "25143 Itokawa-like rubble pile: 165 m radius, elongated (535 x 294 x 209 m), "
        "rough low-frequency fBm, few and degraded craters (N_cum = 0.005 D^-2, 2-20 m)",
        "fbm",
        {"radius_m": 165.0, "stretch": (1.6, 0.9, 0.65), "frequency": 1.0, "octaves": 10,
         "persistence": 0.55, "lacunarity": 2.0,
         "craters": ["c=0.005,k=-2,d_min_m=2,d_max_m=20,age_min_gyr=0.5,age_max_gyr=3"]}, 0.15),
    "bennu-like": Preset(
        "101955 Bennu-like: 245 m radius, slightly flattened, gentle fBm, craters as Li "
        "et al. 2022 Fig. A.3 (B = 3, ~19 % saturation: N_cum = 0.9 D^-3, 10-70 m)", "fbm",
        {"radius_m": 245.0, "stretch": (1.0, 1.0, 0.92), "frequency": 2.0, "octaves": 8,
         "persistence": 0.5, "lacunarity": 2.0,
         "craters": ["c=0.9,k=-3,d_min_m=10,d_max_m=70"]}, 0.05),
}

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
        s = {"base": p.base, **p.settings}
        if p.amplitude_fraction is not None:
            s["amplitude_fraction"] = p.amplitude_fraction
        rows.append((name, p.description, s))
    return rows
