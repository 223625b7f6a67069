"""The typed description of a layer stack: :class:`EnhanceConfig` (what :func:`dem.enhance`
builds; the keys of a ``dem enhance`` TOML scene but the run options ``output``,
``force`` and ``quiet``, which are the command line's or :meth:`dem.Stack.write`'s).

It is validated once, where it is made (from command-line options, a TOML file or
Python): every field is checked, every crater and boulder spec parsed (the parsed layers
are :attr:`EnhanceConfig.crater_layers` and :attr:`EnhanceConfig.boulder_layers`). An
error names the field (``exc.parameter``, see ``craters._shared.parameter_of``).
"""

from __future__ import annotations

import dataclasses
import math
import numbers

from craters import (
    LAYER_TYPES,
    TARGETS,
    BoulderLayer,
    CraterLayer,
    ModelAgeLayer,
    parse_boulder_specs,
    parse_layer_spec,
)
from craters._shared import (
    ParameterError,
    ParameterTypeError,
    about,
    check_int,
    check_positive,
    check_range,
    parse_spec,
)
from craters._shared.settings import check_declared, setting

from .crscode import check_crs
from .fractal import MAX_ROUGHNESS
from .terrains import TERRAINS

__all__ = ["EnhanceConfig", "SourceCraterLayer", "parse_source_spec", "parse_xy"]


@dataclasses.dataclass(frozen=True, slots=True)
class SourceCraterLayer:
    """Craters at the source DEM's own density, continued below what it resolves.

    :func:`dem.enhance` measures the density of the source's craters with
    :func:`dem.crater_density` (craters of 6 source pixels and up, N_cum = c D^-2, the
    equilibrium slope; a lower bound, as the detector misses shallow and overlapping
    craters) and draws a power law with that ``c`` and ``k`` from ``d_min_m`` up to the
    source's resolution (``source_crater_px``); ages uniform in [``age_min_gyr``,
    ``age_max_gyr``]. Spec: ``source[,d_min_m=..,age_min_gyr=..,age_max_gyr=..,
    degradation=..,kind=..]``.
    """

    d_min_m: float = 1.0
    """Smallest diameter, metres."""
    age_min_gyr: float = 0.0
    """Youngest age, Gyr."""
    age_max_gyr: float = 3.5
    """Oldest age, Gyr (ages uniform in between)."""
    degradation: float | None = None
    """Fixed degradation for every crater; None = from its age."""
    kind: str = "source"
    """Label in the catalogs."""

    def __post_init__(self):
        check_positive("d_min_m", self.d_min_m)
        check_range("age_min_gyr", self.age_min_gyr, 0.0, 4.6)
        check_range("age_max_gyr", self.age_max_gyr, 0.0, 4.6)
        if self.age_max_gyr < self.age_min_gyr:
            raise ParameterError("age_max_gyr", f"must be >= age_min_gyr "
                                 f"({self.age_min_gyr}); got {self.age_max_gyr}")
        if self.degradation is not None:
            check_range("degradation", self.degradation, 0.0, 1.0)

    def layer(self, c: float, k: float, d_max_m: float) -> CraterLayer:
        """The power-law layer at the measured ``c`` and ``k`` up to ``d_max_m``."""
        return CraterLayer(c, k, self.d_min_m, d_max_m, self.age_min_gyr, self.age_max_gyr,
                           self.degradation, self.kind)


def parse_source_spec(spec: str) -> SourceCraterLayer:
    """``source[,d_min_m=..,age_min_gyr=..,age_max_gyr=..,degradation=..,kind=..]``.

    Examples
    --------
    >>> parse_source_spec("source,d_min_m=2").d_min_m
    2.0
    """
    head, _, rest = spec.strip().partition(",")
    if head.strip() != "source":
        raise ValueError(f"a source crater layer spec starts with 'source'; got {spec!r}")
    fields = {f.name: (str if f.name == "kind" else float)
              for f in dataclasses.fields(SourceCraterLayer)}
    values = parse_spec(rest, fields, (), "source crater layer") if rest.strip() else {}
    return SourceCraterLayer(**values)


def _parse_crater_spec(spec: str):
    if spec.strip().split(",")[0].strip() == "source":
        return parse_source_spec(spec)
    return parse_layer_spec(spec)

# keys of ``dem enhance`` that are not part of a stack's description
_RUN_KEYS = ("output", "force", "quiet")
#: Fields the manifest records as given (a TOML integer stays an integer), checked only.
_AS_GIVEN = ("fractal_dimension", "roughness", "seed", "band", "pixel_size_m", "body_radius_m",
             "crs", "gravity_m_s2", "body")


def parse_xy(text) -> tuple[float, float]:
    """``X,Y``: two finite numbers (world coordinates, CRS units)."""
    parts = str(text).split(",")
    try:
        if len(parts) == 2:
            x, y = (float(p) for p in parts)
            if math.isfinite(x) and math.isfinite(y):
                return x, y
    except ValueError:
        pass
    raise ValueError(f"expected X,Y in world coordinates; got {text!r}")


@dataclasses.dataclass(frozen=True, slots=True)
class EnhanceConfig:
    """Everything that defines a layer stack; validated when made (module notes).

    Examples
    --------
    >>> cfg = EnhanceConfig(layers=3, size=17, craters=["c=0.05,k=-2,d_min_m=20,d_max_m=800"])
    >>> cfg.crater_layers[0].d_max_m, cfg.to_dict()["craters"]
    (800.0, ['c=0.05,k=-2,d_min_m=20,d_max_m=800'])
    >>> EnhanceConfig(size=100)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    craters._shared.validation.ParameterError: `size` must be 2^n + 1 pixels, 5..16385 (5, ...
    """

    input: str | None = setting(None, "input DEM (GeoTIFF, PDS .lbl/.img)", flag="INPUT",
                                default_text="none: the config file's `input`")
    """Base DEM file (GeoTIFF or PDS3 .lbl/.img); or pass the Dem to :func:`dem.enhance`."""
    target: tuple[float, float] | None = setting(
        None, "site in world coordinates (CRS units), X,Y", parse=parse_xy, commas=True,
        metavar="X,Y", default_text="the base DEM's centre")
    """Site in world coordinates (CRS units, X then Y); default: the base DEM's centre."""
    layers: int = setting(11, "number of layers, each 2x finer", range=(1, 24), metavar="N")
    """Number of layers, 1..24 (layer k has pixels 2^k finer than the base)."""
    size: int = setting(1025, "pixels per side of every layer, 2^n + 1", kind=int,
                        metavar="W")
    """Pixels per side of every layer: 2^n + 1, 5..16385."""
    craters: tuple[str | CraterLayer | ModelAgeLayer | SourceCraterLayer, ...] = setting(
        (), "crater layer: a power law c=..,k=..,d_min_m=..,d_max_m=..[,age_min_gyr=..,"
        "age_max_gyr=..,degradation=..,kind=..] (the fields of craters.CraterLayer; N_cum = "
        "c D^k per m^2, D in metres, ages in Gyr) or a model age npf=moon,age_gyr=..,"
        "d_min_m=..,d_max_m=..[,equilibrium=trask|hartmann,degradation=..,kind=..] "
        "(craters.ModelAgeLayer: the body's production function and chronology) or "
        "source[,d_min_m=..,age_min_gyr=..,age_max_gyr=..] (the source DEM's own crater "
        "density, measured, continued below what it resolves); repeat for several. Each "
        "layer's crater count is also written as craters_NN.scc (craterstats)",
        many="append", metavar="SPEC")
    """Crater layers: power laws ``c=..,k=..,d_min_m=..,d_max_m=..[,age_min_gyr,age_max_gyr,
    degradation,kind]`` (metres, Gyr; :class:`craters.CraterLayer`), model ages
    ``npf=moon,age_gyr=..,d_min_m=..,d_max_m=..[,equilibrium,degradation,kind]``
    (:class:`craters.ModelAgeLayer`) or the source's own density continued below its
    resolution, ``source[,d_min_m=..,...]`` (:class:`SourceCraterLayer`), as specs or
    records."""
    min_crater_px: float = setting(2.0, "smallest crater diameter a layer takes, in its "
                                   "pixels", unit="px", range=(1.0, 1e6), metavar="PX")
    """Smallest crater diameter a layer takes, in its pixels (>= 1)."""
    source_crater_px: float | None = setting(
        4.0, "synthetic craters stay below this many source (layer-0) pixels: the source's "
        "own craters are the truth above (0: no limit)", unit="px", range=(1.0, 1e6),
        metavar="PX")
    """Synthetic craters stay smaller than this many pixels of the source DEM (layer 0):
    larger craters are resolved by the source itself, whose real ones are the truth
    (Pike-style counts on DEMs need ~4 pixels across a crater). None or 0: no limit (a
    synthetic or smoothed base)."""
    boulders: tuple[str | BoulderLayer, ...] = setting(
        (), "boulder layer c=..,k=..,d_min_m=..,d_max_m=..[,burial_max=..] (N_cum = c D^k per "
        "m^2, D in metres; burial_max = largest buried fraction of the height) or Golombek & "
        "Rapp's rock abundance golombek,k=..,d_min_m=..,d_max_m=.. (k = total rock area "
        "fraction); stamped as a heightfield maximum in the finest layer holding each; "
        "repeat for several", many="append", metavar="SPEC")
    """Boulder layers: specs ``c=..,k=..,d_min_m=..,d_max_m=..[,burial,near]`` (metres; ``near``
    is ignored on DEMs), ``golombek,k=..,d_min_m=..,d_max_m=..`` (several power-law layers,
    :func:`craters.golombek_layers`) or :class:`craters.BoulderLayer` objects."""
    min_boulder_px: float = setting(2.0, "smallest boulder a layer takes, in its pixels",
                                    unit="px", range=(1.0, 1e6), metavar="PX")
    """Smallest boulder a layer takes, in its pixels (>= 1)."""
    smooth_craters: bool = setting(False, "ideal craters: no fractal overlay, circular rims")
    """Ideal craters: no fractal overlay, circular rims."""
    fractal_dimension: float | None = setting(None, "fractal dimension F", range=(2.0, 3.0),
                                              metavar="F", default_text="estimated from the "
                                              "input")
    """F in [2, 3] of the expansion; default: estimated on layer 0."""
    roughness: float | None = setting(
        None, "RMS slope between neighbouring pixels", unit="m/m", range=(0.0, MAX_ROUGHNESS),
        metavar="R", default_text="from the input; for expand and enhance the local relief "
        "of each input pixel")
    """Uniform RMS neighbour slope (m/m) of the expansion; default: local relief."""
    terrain: str | None = setting(
        None, "terrain type: the RMD detail follows its LOLA deviogram (median slope at 17 m, "
        "Hurst exponent, breakover; Rosenburg et al. 2011) below the source's pixels",
        choices=tuple(TERRAINS), metavar="NAME",
        default_text="the source's own relief continued with its own F")
    """Terrain type (:data:`dem.terrains.TERRAINS`) whose deviogram the RMD detail of every
    layer follows below the breakover (shaped in space by the source's local relief); not
    with ``roughness`` or ``fractal_dimension``. Default: the source's relief continued."""
    seed: int | None = setting(None, "random seed, a non-negative integer",
                               range=(0, 2**63 - 1), metavar="S", also=("rng",),
                               default_text="a fresh one, recorded in the outputs")
    """Seed of everything random, in [0, 2^63) (a fresh one is drawn and recorded if
    None)."""
    band: int = setting(1, "band of the input (1-based)", range=(1, None), metavar="B")
    """Band of the input file (1-based)."""
    pixel_size_m: float | None = setting(None, "pixel size (for inputs without a CRS)",
                                         unit="m", range=">0", metavar="M")
    """Pixel size in metres, for inputs without a CRS."""
    body_radius_m: float | None = setting(
        None, "body radius (for inputs with a geographic CRS, e.g. 1737400 for the Moon)",
        unit="m", range=">0", metavar="M", default_text="from the file's tags or PDS label")
    """Body radius in metres, for inputs with a geographic CRS."""
    body: str | None = setting(
        None, "the DEM's body: the craters' target (morphology, transition diameters, "
        "diffusivity) and, for a geographic CRS the file gives no radius for, its mean "
        "radius", choices=tuple(TARGETS), metavar="NAME",
        default_text="the body the DEM's CRS names, else moon")
    """The target body of the craters (:data:`craters.TARGETS`: morphology, transition
    diameters, diffusivity); default: the body the DEM's CRS names, else the Moon."""
    crs: str | None = setting(None, "the input's CRS instead of the file's: a code "
                              "(IAU_2015:30100, the Moon), a WKT or a PROJ string",
                              metavar="CRS", default_text="the file's")
    """The input's CRS instead of the file's (:func:`dem.read`'s ``crs``)."""
    gravity_m_s2: float | None = setting(
        None, "surface gravity: crater transition diameters scale as 1/g", unit="m/s^2",
        range=">0", metavar="G", default_text="the body's")
    """Surface gravity, m/s^2 (crater transition diameters scale as 1/g); default: the
    body's."""
    crater_layers: tuple[CraterLayer | ModelAgeLayer | SourceCraterLayer, ...] = dataclasses.field(
        init=False, repr=False, compare=False)
    """The parsed :attr:`craters` (set when the config is made)."""
    boulder_layers: tuple[BoulderLayer, ...] = dataclasses.field(init=False, repr=False,
                                                                  compare=False)
    """The parsed :attr:`boulders` (set when the config is made)."""

    def __post_init__(self):
        def put(name, value):
            object.__setattr__(self, name, value)

        if self.source_crater_px == 0:
            put("source_crater_px", None)
        check_declared(self, keep=_AS_GIVEN)
        if self.crs is not None:
            check_crs(self.crs)
        if self.terrain is not None:
            for other in ("roughness", "fractal_dimension"):
                if getattr(self, other) is not None:
                    raise ParameterError("terrain", f"sets the roughness and fractal dimension "
                                         f"of the expansion: give `terrain` or `{other}`, "
                                         f"not both")
        with about("input"):
            if self.input is not None and (not isinstance(self.input, str) or not self.input):
                raise ParameterTypeError("input", f"must be a file name; got {self.input!r}")
        with about("target"):
            t = self.target
            if t is not None:
                if (isinstance(t, str) or not hasattr(t, "__len__") or len(t) != 2
                        or not all(isinstance(v, numbers.Real) and not isinstance(v, bool)
                                   for v in t)):
                    raise ParameterTypeError("target", f"must be [x, y] in world coordinates "
                                             f"(CRS units); got {t!r}")
                if not all(math.isfinite(v) for v in t):
                    raise ParameterError("target", f"must be finite; got {t!r}")
                put("target", (float(t[0]), float(t[1])))
        with about("size"):
            size = check_int("size", self.size)
            if size < 5 or size > 16385 or (size - 1) & (size - 2):
                raise ParameterError("size", f"must be 2^n + 1 pixels, 5..16385 (5, 9, 17, "
                                     f"..., 1025, 2049, ...); got {size}")
            put("size", size)
        for name, parse, kind, example in (
                ("craters", _parse_crater_spec, (*LAYER_TYPES, SourceCraterLayer),
                 "c=0.05,k=-2,d_min_m=1,d_max_m=500"),
                ("boulders", parse_boulder_specs, (BoulderLayer,),
                 "c=0.01,k=-3,d_min_m=0.5,d_max_m=5")):
            with about(name):
                specs = getattr(self, name)
                if isinstance(specs, str) or not isinstance(specs, list | tuple):
                    raise ParameterTypeError(name, f"must be a list of {name[:-1]} layer specs "
                                             f"like '{example}'; got {specs!r}")
                parsed = []
                for spec in specs:
                    if not isinstance(spec, (str, *kind)):
                        records = " or ".join(f"{k.__module__.split('.')[0]}.{k.__name__}"
                                              for k in kind)
                        raise ParameterTypeError(name, f"must hold {name[:-1]} layer specs "
                                                 f"like '{example}' or {records}; got "
                                                 f"{spec!r}")
                    got = spec if isinstance(spec, kind) else parse(spec)
                    parsed.extend(got if isinstance(got, tuple) else (got,))
                put(name, tuple(specs))
                put(f"{name[:-1]}_layers", tuple(parsed))

    @classmethod
    def keys(cls) -> tuple[str, ...]:
        """The config keys, in order."""
        return tuple(f.name for f in dataclasses.fields(cls) if f.init)

    @classmethod
    def from_mapping(cls, config) -> EnhanceConfig:
        """Validate a dict (e.g. parsed TOML); unknown keys are errors."""
        if isinstance(config, cls):
            return config
        if not isinstance(config, dict):
            raise TypeError(f"`config` must be a dict of scene keys; got "
                            f"{type(config).__name__}")
        unknown = sorted(set(config) - set(cls.keys()))
        if unknown:
            run = [k for k in unknown if k in _RUN_KEYS]
            hint = (f" ({', '.join(run)}: how to write a stack, not what it is; use "
                    f"Stack.write(folder, force=...) and enhance(..., progress=...))"
                    if run else "")
            raise ValueError(f"unknown config key(s) {', '.join(map(repr, unknown))}; "
                             f"allowed: {', '.join(cls.keys())}{hint}")
        return cls(**config)

    def to_dict(self) -> dict:
        """JSON-ready values that define the stack (for the manifest): the specs as given
        (a layer object as a dict of its fields)."""
        d = {name: getattr(self, name) for name in self.keys()}
        for name in ("craters", "boulders"):
            d[name] = [s if isinstance(s, str) else dataclasses.asdict(s)
                       for s in getattr(self, name)]
        d["target"] = None if self.target is None else list(self.target)
        return d
