"""Scenes: a typed, frozen, validated description of a whole build.

A :class:`Scene` holds everything that makes a body (no output paths): the body (grid
magnitude, reference radius, stretch), the base shape (:class:`SphereBase`,
:class:`~latlong.FaultingParams`, :class:`~latlong.FbmParams`, :class:`ShapeBase`), the
crater and boulder layers, or the implicit backend (:class:`ImplicitSettings`) instead of a base and
craters, the preview picture's camera and light, and the seed. Each part validates
itself when it is made (:mod:`latlong.settings`) and the scene checks how they fit
together, once; :func:`latlong.build` turns a scene into a body and writes nothing.

Scenes are made in Python, or from flat *settings* (:meth:`Scene.from_settings`,
:meth:`Scene.from_toml`) whose keys are the ``latlong build`` option names with
underscores (``magnitude``, ``radius_m``, ``faults_1``, ``craters`` ...; the list is
:data:`SETTINGS`). Precedence: defaults < preset < the given settings. Errors are
``ValueError`` / ``TypeError`` naming the setting (a command line shows its flag).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import cast

import numpy as np

import craters as _craters
from craters._shared import (
    ParameterError,
    ParameterTypeError,
    check_choice,
    load_toml,
    package_version,
)
from craters._shared.settings import Setting, by_key, check_declared, declared, setting

from .faulting import FaultingParams
from .memory import check_memory, expected_counts
from .perlin import FbmParams
from .presets import DEFAULT_PRESET, PRESETS, RENAMED_PRESETS
from .preview import PreviewSettings
from .settings import (
    DEFAULT_RADIUS_M,
    NO_STRETCH,
    BodySettings,
    BoulderSettings,
    CraterSettings,
    GaborExample,
    ImplicitSettings,
    ShapeBase,
    SphereBase,
)
from .shapes import ShapeModel, read_shape_model

#: What the bodies built from scenes record as their maker.
GENERATOR = "craterform latlong build"

__all__ = ["SETTINGS", "SETTING_DEFAULTS", "SETTING_PARTS", "Scene"]

#: The settings that choose what a scene is made of (no record field holds them as given).
_CHOICES = {
    "base": Setting(None, "base shape: sphere, faulting, fbm or shape:PATH (a real shape "
                    "model: OBJ, PDS plate .tab/.plt, PLY, STL)",
                    default_text=f"fbm (preset {DEFAULT_PRESET['fbm']})"),
    "backend": Setting("latlong", "latlong (the lat/long mesh) or implicit (Li et al.: "
                       "metaballs over a sphere packing of --shape, LCSN craters, Gabor "
                       "detail, marching cubes)", choices=("latlong", "implicit")),
}
_BOULDER_HELP = {"flatten": "boulder up-axis scale relative to its width",
                 "elongation": "boulder length relative to its width",
                 "roughness": "boulder midpoint-displacement amplitude (fraction of the edge "
                              "length)"}
#: The boulders' shape (:class:`craters.BoulderShape`, whose fields check themselves) as
#: settings ``boulder_<field>``.
_BOULDER_SHAPE = {f"boulder_{f.name}": Setting(f.default, _BOULDER_HELP[f.name])
                  for f in dataclasses.fields(_craters.BoulderShape) if f.name in _BOULDER_HELP}

def _ellipsoid_area(body: BodySettings) -> float:
    """The stretched sphere's area (Knud Thomsen's formula, within 1.1 %)."""
    assert body.radius_m is not None and body.stretch is not None  # a scene's body
    a, b, c = (body.radius_m * f for f in body.stretch)
    p = 1.6075
    return 4 * math.pi * (((a * b) ** p + (a * c) ** p + (b * c) ** p) / 3) ** (1 / p)


@dataclass(frozen=True, slots=True)
class Scene:
    """A whole build, validated once (module notes).

    Examples
    --------
    >>> s = Scene(BodySettings(magnitude=16, radius_m=100.0), FbmParams(octaves=4), seed=1)
    >>> s.body.radius_m, s.body.stretch, s.base.amplitude_m
    (100.0, (1.0, 1.0, 1.0), 40.0)
    >>> Scene.from_settings({"preset": "paper", "magnitude": 20, "seed": 3}).base.n_faults_2
    20000
    """

    body: BodySettings = dataclasses.field(default_factory=BodySettings)
    """Grid magnitude, reference radius and stretch."""
    base: SphereBase | FaultingParams | FbmParams | ShapeBase | None = None
    """Base shape; default :class:`FbmParams` (None with the implicit backend)."""
    craters: CraterSettings = dataclasses.field(default_factory=CraterSettings)
    """Crater layers and how they are stamped."""
    boulders: BoulderSettings = dataclasses.field(default_factory=BoulderSettings)
    """Boulder layers and shape."""
    implicit: ImplicitSettings | None = None
    """The implicit backend (Li et al.) instead of the lat/long base and craters."""
    preview: PreviewSettings = dataclasses.field(default_factory=PreviewSettings)
    """Camera and light of a preview picture."""
    seed: int | None = setting(None, "random seed (non-negative integer)",
                               range=(0, 2**63 - 1),
                               default_text="a fresh one, recorded in the model")
    """Seed of everything random, [0, 2**63); None draws a fresh one (kept here)."""
    preset: str | None = setting(None, "named scene (see `latlong presets`): sets the base "
                                 "and its parameters, the body and crater layers")
    """The preset the scene came from (recorded in the body's metadata)."""
    on_demand: bool = setting(False, "terrain on demand (latlong.ondemand): craters drawn "
                              "cell by cell, every height a function of its position, "
                              "memory bounded by the region asked, not the whole body")
    """Terrain on demand (:mod:`latlong.ondemand`): no whole-body memory estimate (what
    is made is bounded by the region asked); needs a lat/long body (stretched or not)."""

    def __post_init__(self):
        check_declared(self)
        if self.seed is None:
            object.__setattr__(self, "seed", int(np.random.SeedSequence().entropy % (2**63)))
        for name, kind in (("body", BodySettings), ("craters", CraterSettings),
                           ("boulders", BoulderSettings), ("preview", PreviewSettings)):
            if not isinstance(getattr(self, name), kind):
                raise ParameterTypeError(name, f"must be a {kind.__name__}; got "
                                         f"{type(getattr(self, name)).__name__}")
        if self.implicit is not None:
            if not isinstance(self.implicit, ImplicitSettings):
                raise ParameterTypeError("implicit", "must be an ImplicitSettings; got "
                                         f"{type(self.implicit).__name__}")
            for name, empty in (("base", None), ("craters", CraterSettings()),
                                ("boulders", BoulderSettings())):
                if getattr(self, name) != empty:
                    raise ParameterError(name, "does not apply to the implicit backend")
            return
        base = FbmParams() if self.base is None else self.base
        if not isinstance(base, SphereBase | FaultingParams | FbmParams | ShapeBase):
            raise ParameterTypeError("base", "must be a SphereBase, FaultingParams, FbmParams or "
                                     f"ShapeBase; got {type(base).__name__}")
        body, resolution = self.body, None
        if isinstance(base, ShapeBase):
            own = {"radius_m": base.radius_m, "stretch": NO_STRETCH}
            for key, value in own.items():
                if getattr(body, key) not in (None, value):
                    raise ParameterError(key, "does not apply to a shape base (the model "
                                         "sets the size and shape)")
            body = dataclasses.replace(body, **own)
            resolution = base.model.mean_edge_m
        else:
            stretch = body.stretch
            if stretch is None:  # a faulting set carries its body's stretch (the paper's 2,1,1)
                stretch = base.stretch if isinstance(base, FaultingParams) else NO_STRETCH
            body = dataclasses.replace(
                body, radius_m=DEFAULT_RADIUS_M if body.radius_m is None else body.radius_m,
                stretch=stretch)
        if isinstance(base, FaultingParams):
            base = dataclasses.replace(base, stretch=body.stretch)
        if isinstance(base, FbmParams) and base.amplitude_m is None:
            base = dataclasses.replace(base, amplitude_m=base.amplitude * body.radius_m)
        object.__setattr__(self, "base", base)
        object.__setattr__(self, "body", body)
        smallest = body.radius_m * min(body.stretch)
        try:
            self.craters.check_fits(smallest, resolution)
        except ParameterError as exc:
            raise exc.renamed("craters") from None
        try:
            self.boulders.check_fits(smallest)
        except ParameterError as exc:
            raise exc.renamed("boulders") from None
        if self.on_demand:
            if isinstance(base, ShapeBase) and base.surface != "latlong":
                raise ParameterError("surface", "must be latlong for terrain on demand")
            return
        if isinstance(base, ShapeBase):
            area = base.model.area_m2
        else:
            area = _ellipsoid_area(body)
        self._check_memory(area)

    def _check_memory(self, area_m2: float) -> bool:
        """:func:`check_memory` of this scene; whether its radii go on disk."""
        body, base = self.body, self.base
        n_craters, n_boulders = expected_counts(self.craters, self.boulders, area_m2)
        disk_ok = self.implicit is None and isinstance(base, SphereBase | FbmParams)
        return check_memory(body.magnitude, body.max_memory_gb, n_craters=n_craters,
                            n_boulders=n_boulders, radii_on_disk=body.radii_on_disk,
                            disk_ok=disk_ok)

    def radii_on_disk(self) -> bool:
        """Whether :func:`latlong.build` keeps this scene's radii in a scratch file
        (``body.radii_on_disk``: ``yes``, or ``auto`` and the in-memory estimate exceeds
        ``max_memory_gb``; :mod:`latlong.scratch`)."""
        if self.implicit is not None or not isinstance(self.base, SphereBase | FbmParams):
            return False
        return self._check_memory(_ellipsoid_area(self.body))

    def target(self) -> _craters.Target:
        """The craters' target (:func:`craters.get_target`): a named body, or a small body
        of this size (volume-equivalent radius) and density."""
        b = self.body
        if b.target != "small-body":
            return _craters.get_target(b.target, gravity_m_s2=b.gravity_m_s2)
        assert b.radius_m is not None and b.stretch is not None  # __post_init__ set them
        radius = b.radius_m * float(np.prod(b.stretch)) ** (1.0 / 3.0)
        return _craters.get_target("small-body", radius_m=radius, density_kg_m3=b.density_kg_m3,
                                   gravity_m_s2=b.gravity_m_s2,
                                   depth_ratio=b.crater_depth_ratio,
                                   depth_exponent=b.crater_depth_exponent)

    def body_metadata(self, params: dict) -> dict:
        """The metadata a body built from this scene records (``params``: the base's)."""
        craters, boulders, target = self.craters, self.boulders, self.target()
        assert self.base is not None  # a lat/long or mesh build: __post_init__ set it
        return {
            "generator": GENERATOR,
            "version": package_version(),
            "seed": self.seed,
            "base": self.base.name,
            "preset": self.preset,
            "parameters": params,
            "craters": [dataclasses.asdict(la) for la in craters.layers],
            "body": self.body.target,
            "gravity_m_s2": target.gravity_m_s2,
            "crater_roughness": craters.roughness,
            "boulders": [dataclasses.asdict(la) for la in boulders.layers],
            "boulder_shape": dataclasses.asdict(boulders.shape) if boulders.layers else None,
        }

    @property
    def backend(self) -> str:
        """``latlong`` (the lat/long mesh) or ``implicit``."""
        return "latlong" if self.implicit is None else "implicit"

    @classmethod
    def from_settings(cls, settings: Mapping) -> Scene:
        """A scene from flat settings (:data:`SETTINGS`; module notes), e.g.
        ``{"preset": "fbm-cratered", "magnitude": 300, "seed": 1}``. Values as in a TOML
        file: numbers, strings, lists; crater and boulder layers as spec strings or
        tables. ``None`` means "not given"."""
        if not isinstance(settings, Mapping):
            raise ParameterTypeError("settings", f"must be a mapping; got "
                                     f"{type(settings).__name__}")
        given = {k: v for k, v in settings.items() if v is not None}
        unknown = sorted(set(given) - set(SETTINGS))
        if unknown:
            raise ParameterError(unknown[0], f"is not a scene setting; allowed: "
                                 f"{', '.join(SETTINGS)}")
        backend = check_choice("backend", given.pop("backend", "latlong"),
                               ("latlong", "implicit"))
        if backend == "implicit":
            return _implicit_scene(cls, given)
        return _latlong_scene(cls, given)

    @classmethod
    def from_toml(cls, path) -> Scene:
        """A scene from a TOML file whose keys are settings (:meth:`from_settings`)."""
        return cls.from_settings(load_toml(Path(path)))


#: (group, record or table of settings) of every flat setting, in the order of
#: :data:`SETTINGS`: the records :meth:`Scene.from_settings` makes and the group each
#: setting is listed in by ``latlong build --help``.
SETTING_PARTS = (
    ("body", {"preset": declared(Scene)["preset"], "base": _CHOICES["base"],
              "seed": declared(Scene)["seed"], "on_demand": declared(Scene)["on_demand"]}),
    ("implicit", {"backend": _CHOICES["backend"]}), ("body", BodySettings),
    ("faulting", FaultingParams), ("fbm", FbmParams), ("shape", ShapeBase),
    ("craters", CraterSettings), ("boulders", BoulderSettings), ("boulders", _BOULDER_SHAPE),
    ("implicit", ImplicitSettings), ("implicit", GaborExample), ("render", PreviewSettings))
_OWN = {k: s for _, part in SETTING_PARTS for k, s in by_key(part).items() if s.help is not None}

#: Every setting of :meth:`Scene.from_settings` (the TOML keys of a scene file).
SETTINGS: tuple[str, ...] = tuple(_OWN)

#: The default of every setting without a preset (None: none, or it depends on the
#: preset or base); the faulting and fBm values are the paper's / Fig. 5a's.
SETTING_DEFAULTS: dict[str, object] = {**{k: s.default for k, s in _OWN.items()},
                                       "radius_m": DEFAULT_RADIUS_M, "stretch": NO_STRETCH}


def _keys(kind) -> tuple[str, ...]:
    return tuple(by_key(kind))


def _names(kind) -> dict[str, str]:
    """Setting -> field of a record's declared fields."""
    return {cast(str, s.key): name for name, s in declared(kind).items()}  # keys filled in


def _part(factory, values: dict, names: dict | None = None, **fixed):
    """``factory(**fixed, **{field: values[key]})`` for the settings of ``names`` (setting
    -> field; default: the record's declared fields) present in ``values``; an error of a
    field is shown under its setting."""
    names = _names(factory) if names is None else names
    kwargs = {field: values[key] for key, field in names.items() if key in values}
    try:
        return factory(**fixed, **kwargs)
    except (ParameterError, ParameterTypeError) as exc:
        key = next((k for k, f in names.items() if f == exc.name), exc.name)
        raise exc.renamed(key) from None
    except FileNotFoundError as exc:  # a file setting's: kept, its tag renamed
        tag = getattr(exc, "parameter", None)
        # a tag (parameter_of)
        exc.parameter = next(  # type: ignore[attr-defined]
            (k for k, f in names.items() if f == tag), tag)
        raise


_IMPLICIT, _EXAMPLE, _PREVIEW = _keys(ImplicitSettings), _keys(GaborExample), _keys(PreviewSettings)
_SHAPE_ONLY = tuple(k for k in _keys(ShapeBase) if k not in _keys(FbmParams))
_GROUPS = {"faulting": _keys(FaultingParams), "fbm": _keys(FbmParams), "shape:PATH": _SHAPE_ONLY}
_GROUPS_OF_BASE = {"faulting": ("faulting",), "fbm": ("fbm",), "sphere": (),
                   "shape": ("fbm", "shape:PATH")}


def _latlong_scene(cls, given: dict) -> Scene:
    stray = [k for k in given if k in (*_IMPLICIT, *_EXAMPLE) and k not in _SHAPE_ONLY]
    if stray:
        raise ParameterError(stray[0], "applies to {} implicit", see=("backend",))
    preset, base = given.get("preset"), given.get("base")
    if preset in RENAMED_PRESETS:
        raise ParameterError("preset", f"{preset!r} is now {RENAMED_PRESETS[preset]!r} (built "
                             "from the real body's bundled shape model)")
    if preset is not None and preset not in PRESETS:
        raise ParameterError("preset", f"must be one of {', '.join(PRESETS)}; got {preset!r}")
    shape_path: str | ShapeModel | None = None
    if isinstance(base, str) and base.startswith("shape:"):
        shape_path, base = base[len("shape:"):], "shape"
        if preset is not None:
            raise ParameterError("preset", "and {} shape:PATH cannot be combined",
                                 see=("base",))
        if not shape_path:
            raise ParameterError("base", "shape:PATH needs a path after 'shape:'")
    elif base is not None and base not in ("sphere", "faulting", "fbm"):
        raise ParameterError("base", f"must be one of sphere, faulting, fbm or shape:PATH; "
                             f"got {base!r}")
    if preset is not None and base is not None and PRESETS[preset].base != base:
        raise ParameterError("preset", f"{preset} has {{}} {PRESETS[preset].base}, not {base}",
                             see=("base",))
    if preset is None:
        base = base or "fbm"
        preset = DEFAULT_PRESET.get(base)
    p = PRESETS[preset] if preset else None
    base = p.base if p else base
    assert base is not None  # the preset's, or the given one (default fbm)
    if p is not None and p.model is not None:
        # the bundled model, recorded by its place in the package (not this machine's path)
        units = {**p.settings, **given}.get("shape_units", "km")
        model = read_shape_model(p.model_path, units=units)
        shape_path = dataclasses.replace(model, source=f"latlong/data/shapes/{p.model}")
    for group, keys in _GROUPS.items():
        for key in keys:
            if key in given and group not in _GROUPS_OF_BASE[base]:
                raise ParameterError(key, f"applies to {{}} {group}, not {{}} {base}",
                                     see=("base", "base"))
    merged = {**(p.settings if p else {}), **given}
    body = _part(BodySettings, merged)
    if base == "faulting":
        part = _part(FaultingParams, merged)
    elif base == "fbm":  # a preset's height scale is a fraction of the radius
        fraction = {} if p is None or p.amplitude_fraction is None else {
            "amplitude": p.amplitude_fraction}
        part = _part(FbmParams, {**fraction, **merged})
    elif base == "sphere":
        part = SphereBase()
    else:
        part = _part(ShapeBase, {**merged, "base": shape_path},
                     {**_names(ShapeBase), "base": "model"})
    shape = _part(_craters.BoulderShape, merged,
                  {k: k[len("boulder_"):] for k in _BOULDER_SHAPE})
    return cls(body=body, base=part, craters=_part(CraterSettings, merged),
               boulders=_part(BoulderSettings, merged, shape=shape),
               preview=_part(PreviewSettings, given), seed=given.get("seed"), preset=preset,
               on_demand=given.get("on_demand", False))


def _implicit_scene(cls, given: dict) -> Scene:
    allowed = {*_IMPLICIT, *_EXAMPLE, *_PREVIEW, "magnitude", "max_memory_gb", "seed"}
    for key in given:
        if key not in allowed:
            raise ParameterError(key, "does not apply to {} implicit", see=("backend",))
    if "shape" not in given:
        raise ParameterError("backend", "implicit needs {} (the constraint mesh)",
                             see=("shape",))
    gabor = given.get("gabor")
    example = given.get("gabor_example")
    if gabor is not None and example is not None:
        raise ParameterError("gabor", "and {} cannot be combined: give one",
                             see=("gabor_example",))
    for key in ("gabor_pixel_m", "gabor_amplitude_m"):
        if key in given and example is None:
            raise ParameterError(key, "applies to {}", see=("gabor_example",))
    settings = _part(ImplicitSettings, given)
    if example is not None:
        settings = dataclasses.replace(settings, gabor=_part(GaborExample, given).fit())
    body = _part(BodySettings, given)
    return cls(body=body, implicit=settings, preview=_part(PreviewSettings, given),
               seed=given.get("seed"))
