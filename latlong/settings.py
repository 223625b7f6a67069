"""The parts of a :class:`latlong.Scene`: body, base shapes, crater and boulder layers,
the implicit backend (the faulting and fBm bases are :class:`latlong.FaultingParams` and
:class:`latlong.FbmParams`). Frozen, slotted records that validate themselves when made
(errors name the field); :mod:`latlong.scene` checks how they fit together.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from pathlib import Path
from typing import cast

import craters as _craters
from craters._shared import ParameterError, ParameterTypeError, physical_memory_bytes
from craters._shared.settings import check_declared, default_of, setting

from .memory import MEMORY_SHARE, RADII_ON_DISK, check_memory
from .shapes import SIZE_RANGE_M, ShapeModel, as_shape_model

__all__ = ["BASES", "DEFAULT_RADIUS_M", "NO_STRETCH", "SURFACES", "BodySettings", "BoulderSettings",
           "CraterSettings", "GaborExample", "ImplicitSettings", "ShapeBase", "SphereBase"]

#: Names of the base shapes (``shape`` takes a model file).
BASES = ("sphere", "faulting", "fbm", "shape")
#: Mean radius a body may have, metres: the range of shape models (a boulder to a gas
#: giant), so radii, areas and volumes stay finite in float64.
RADIUS_RANGE_M = SIZE_RANGE_M
#: The reference radius of a body without a shape base when none is given, metres.
DEFAULT_RADIUS_M = 50.0
#: The stretch of a body when none is given (the faulting presets have their own).
NO_STRETCH = (1.0, 1.0, 1.0)
CROSSINGS = ("error", "outermost", "innermost")
#: Where a shape base is cratered: the lat/long grid or the model's own mesh.
SURFACES = ("latlong", "mesh")


def _set(obj, name, value) -> None:
    object.__setattr__(obj, name, value)


def parse_stretch(value) -> tuple[float, float, float]:
    """Three factors X,Y,Z from ``"2,1,1"`` or a sequence; finite and > 0."""
    parts = value.split(",") if isinstance(value, str) else value
    try:
        vals = tuple(float(p) for p in parts)
    except (TypeError, ValueError):
        raise ParameterTypeError("stretch", f"must be three factors X,Y,Z; got {value!r}") \
            from None
    if len(vals) != 3:
        raise ParameterError("stretch", f"must be three factors X,Y,Z; got {value!r}")
    if any(not math.isfinite(v) or v <= 0 for v in vals):
        raise ParameterError("stretch", f"factors must be finite and > 0; got {vals}")
    return vals


@dataclass(frozen=True, slots=True)
class BodySettings:
    """The lat/long body: grid, size and stretch."""

    magnitude: int = setting(200, "grid magnitude M (6M^2+2 vertices)", range=(1, 10**9))
    """Grid magnitude M >= 1 (6M^2+2 vertices); refused up front if it cannot fit."""
    radius_m: float | None = setting(
        None, "reference radius", unit="m", range=RADIUS_RANGE_M,
        default_text=f"{DEFAULT_RADIUS_M:g}; a shape base: the model's")
    """Reference radius, metres; default 50 m (a shape base sets its own)."""
    stretch: tuple[float, float, float] | None = setting(
        None, "scale factors X,Y,Z applied to the body (e.g. 2,1,1)", parse=parse_stretch,
        commas=True, metavar="X,Y,Z",
        default_text=",".join(f"{x:g}" for x in NO_STRETCH) + "; a faulting preset's: 2,1,1")
    """Scale factors along x, y, z; default 1, 1, 1 (a shape base sets its own)."""
    target: str = setting(
        "small-body", "what kind of body the craters are on (morphology, transition "
        "diameters, diffusivity): small-body (gravity from its size and density) or a named "
        "body", key="body", choices=(*_craters.TARGETS, "small-body"))
    """The body's kind for crater morphology and diffusivity: ``small-body`` (its gravity
    from its size and ``density_kg_m3``) or a name of :data:`craters.TARGETS`."""
    gravity_m_s2: float | None = setting(
        None, "surface gravity: crater transition diameters scale as 1/g", unit="m/s^2",
        range=">0", default_text="the body's")
    """Surface gravity, m/s^2 (default: the target's; a small body's from its size)."""
    density_kg_m3: float = setting(2000.0, "bulk density of a small body (its gravity from "
                                   "its size)", unit="kg/m^3", range=(10.0, 30_000.0))
    """Bulk density of a small body, kg/m^3."""
    crater_depth_ratio: float | None = setting(
        None, "fresh crater depth/diameter on a small body", range=(0.01, 0.5),
        default_text=f"{default_of(_craters.small_body, 'depth_ratio'):g}, Marchi et al. "
        "2015; Bennu's measured 0.10")
    """Fresh crater depth/diameter of a small body, [0.01, 0.5]; default 0.2 (Marchi et
    al. 2015); e.g. Bennu 0.10 (Daly et al. 2020). With ``crater_depth_exponent`` != 1,
    the d/D of a 10 m crater."""
    crater_depth_exponent: float | None = setting(
        None, "exponent b of a small body's fresh crater depth d = ratio D (D / 10 m)^(b - 1) "
        "(b < 1: larger craters relatively shallower)", range=(0.5, 1.5),
        default_text="1, d/D the same at all sizes")
    """Exponent of a small body's fresh depth law, [0.5, 1.5]; default 1 (d/D the same at
    all sizes); the Bennu preset's 0.756 gives Daly et al.'s (2020) 0.13 below 10 m and 0.10
    above."""
    max_memory_gb: float | None = setting(
        None, "memory the build may use (1e9 bytes): a magnitude whose estimate (radii and "
        "bounded buffers, written as .npz) is larger is refused up front, or built with its "
        "radii on disk (radii_on_disk auto)", unit="GB", range=">0",
        default_text=lambda: f"{MEMORY_SHARE:g} x this machine's memory, "
        f"{MEMORY_SHARE * physical_memory_bytes() / 1e9:.3g} GB")
    """Memory the build may use, GB (1e9 bytes); a magnitude whose estimate
    (:func:`check_memory`) is larger is refused up front. Default: :data:`MEMORY_SHARE`
    of this machine's memory."""
    radii_on_disk: str = setting(
        "auto", "keep the body's radii in a memory-mapped scratch file beside the first "
        "output (bodies bigger than memory; the same bytes): auto = when the in-memory "
        "estimate exceeds max_memory_gb (sphere and fbm bases), yes, no",
        choices=RADII_ON_DISK)
    """Keep the radii in a memory-mapped scratch file (:mod:`latlong.scratch`; bodies
    bigger than memory, the same bytes): ``auto`` when the in-memory estimate exceeds
    ``max_memory_gb`` (sphere and fbm bases), ``yes``, ``no``."""

    def __post_init__(self):
        check_declared(self)
        for key in ("crater_depth_ratio", "crater_depth_exponent"):
            if getattr(self, key) is not None and self.target != "small-body":
                raise ParameterError(key, f"applies to small-body only (the {self.target}'s "
                                     "crater depths follow its published laws)")
        check_memory(self.magnitude, self.max_memory_gb, radii_on_disk=self.radii_on_disk)
        if self.stretch is not None:
            _set(self, "stretch", parse_stretch(self.stretch))


# --------------------------------------------------------------------------- bases
def _read_shape(record, name: str, what: str) -> None:
    """The field ``name`` of ``record``: a ShapeModel, or a path read in ``record.units``
    (``what`` names the file in messages; errors named by the field)."""
    value = getattr(record, name)
    if isinstance(value, str | Path) and record.units not in ("km", "m"):
        raise ParameterError("units", f"must be km or m with a {what} file; got "
                             f"{record.units!r}")
    if not isinstance(value, str | Path | ShapeModel):
        raise ParameterTypeError(name, f"must be a ShapeModel or a path; got "
                                 f"{type(value).__name__}")
    try:
        _set(record, name, as_shape_model(value, units=record.units, what=what, name=name))
    except FileNotFoundError as exc:  # kept (Python), tagged (a command's flag)
        exc.parameter = name  # type: ignore[attr-defined]  # a tag (parameter_of)
        raise
    except ValueError as exc:
        raise ParameterError(name, f"{value}: {exc}") from None


@dataclass(frozen=True, slots=True)
class SphereBase:
    """A plain sphere (craters and boulders only)."""

    name = "sphere"


@dataclass(frozen=True, slots=True)
class ShapeBase:
    """A real shape model ray-cast onto the grid (:func:`latlong.from_shape_model`),
    with optional fBm detail below its resolution. The model is read once, here."""

    model: ShapeModel | str | Path
    """The model, or its file (OBJ, PDS plate .tab/.plt, PLY, STL; needs ``units``)."""
    units: str | None = setting(
        None, "units of the shape model file (required with --base shape:PATH and "
        "--backend implicit)", key="shape_units", choices=("km", "m"))
    """Units of the file: ``km`` or ``m``."""
    center: str | tuple[float, float, float] = setting(
        "volume-centroid", "ray origin: volume-centroid, area-centroid, origin or X,Y,Z in "
        "metres", key="shape_center", commas=True)
    """Ray origin: volume-centroid, area-centroid, origin or (x, y, z) metres."""
    crossings: str = setting("error", "where a ray crosses the surface more than once",
                             key="shape_crossings", choices=CROSSINGS)
    """Where a ray crosses the surface more than once: error, outermost, innermost."""
    smooth: str = setting(
        "butterfly", "subdivision before casting: butterfly (interpolating), linear (keep "
        "the facets), loop, none (--surface mesh: butterfly or linear)", key="shape_smooth",
        choices=("butterfly", "linear", "loop", "none"))
    """Subdivision before casting: butterfly, linear, loop, none."""
    detail_frequency: float | None = setting(
        None, key="frequency", range=">0", when="with a shape base",
        default_text="wavelength = the model's resolution")
    """fBm detail frequency on the unit sphere; default: wavelength = the resolution."""
    detail_octaves: int = setting(6, key="octaves", range=(1, 30), when="with a shape base")
    """fBm detail octaves."""
    detail_persistence: float = setting(0.5, key="persistence", range=">0",
                                        when="with a shape base")
    """fBm detail amplitude ratio per octave."""
    detail_lacunarity: float = setting(2.0, key="lacunarity", range=(1.0, None),
                                       when="with a shape base")
    """fBm detail frequency ratio per octave."""
    detail_amplitude_m: float = setting(0.0, key="amplitude_m", range=">=0",
                                        when="with a shape base")
    """fBm detail height scale, metres (0 = no detail)."""
    surface: str = setting(
        "latlong", "where a shape model is cratered: latlong (ray-cast onto the lat/long "
        "grid; the model must be star-shaped from its centre) or mesh (its own refined "
        "triangle mesh: any closed shape, e.g. Itokawa; outputs .ply .obj .stl .vtp .vtk "
        ".glb)", choices=SURFACES)
    """``latlong``: ray-cast onto the lat/long grid (the body must be star-shaped from
    the centre); ``mesh``: cratered on the model's own refined mesh (:mod:`latlong.mesh`;
    any closed shape, e.g. Itokawa's neck)."""
    spacing_m: float | None = setting(
        None, "mean edge of the refined mesh with --surface mesh", unit="m", range=">0",
        default_text="the lat/long spacing at --magnitude, (pi/2) R / M")
    """Mean edge of the refined mesh with ``surface="mesh"``, metres; default: the
    lat/long grid's spacing at the scene's magnitude, (pi / 2) R / M."""
    name = "shape"

    def __post_init__(self):
        check_declared(self)
        _read_shape(self, "model", "shape model")
        if self.surface == "mesh" and self.smooth not in ("butterfly", "linear"):
            raise ParameterError("smooth", f"must be butterfly or linear with {{}} mesh; got "
                                 f"{self.smooth!r}", see=("surface",))
        if self.spacing_m is not None and self.surface != "mesh":
            raise ParameterError("spacing_m", "applies to {} mesh", see=("surface",))
        _set(self, "center", _center(self.center))
        if self.detail_frequency is None:
            _set(self, "detail_frequency", self.radius_m / self.model.mean_edge_m)

    @property
    def radius_m(self) -> float:
        """Volume-equivalent radius of the model, metres."""
        model = cast(ShapeModel, self.model)  # __post_init__ read the file
        return (3.0 * model.volume_m3 / (4.0 * math.pi)) ** (1.0 / 3.0)


def _center(value):
    named = ("volume-centroid", "area-centroid", "origin")
    if isinstance(value, str) and value in named:
        return value
    parts = value.split(",") if isinstance(value, str) else value
    try:
        xyz = tuple(float(v) for v in parts)
    except (TypeError, ValueError):
        xyz = ()
    if len(xyz) != 3 or not all(math.isfinite(v) for v in xyz):
        raise ParameterError("center", f"must be volume-centroid, area-centroid, origin or "
                             f"X,Y,Z in metres; got {value!r}")
    return xyz


# --------------------------------------------------------------------------- layers
def _layers(value, kind, parse, name: str, *, table=None) -> tuple:
    """A tuple of layer records (``kind``: a record type or a tuple of them) from
    records, spec strings (``parse``) or TOML tables (``table(dict)``, default the
    record ``kind(**table)`` with unknown keys refused)."""
    kinds = kind if isinstance(kind, tuple) else (kind,)
    items = [value] if isinstance(value, (str, dict, *kinds)) else list(value)
    out = []
    for item in items:
        if isinstance(item, kinds):
            out.append(item)
        elif isinstance(item, str):
            try:
                got = parse(item)
            except ValueError as exc:
                raise ParameterError(name, f": {exc}") from None
            out.extend(got if isinstance(got, tuple) else (got,))  # a spec of several
        elif isinstance(item, dict):
            if table is None:
                allowed = {f.name for f in dataclasses.fields(kinds[0])}
                unknown = set(item) - allowed
                if unknown:
                    raise ParameterError(name, f": unknown key(s) {', '.join(sorted(unknown))}; "
                                         f"allowed: {', '.join(sorted(allowed))}")
            try:
                out.append(kinds[0](**item) if table is None else table(item))
            except (TypeError, ValueError) as exc:
                raise ParameterError(name, f": {exc}") from None
        else:
            names = " or ".join(k.__name__ for k in kinds)
            raise ParameterTypeError(name, f"must be {names}s, spec strings or "
                                     f"tables; got {item!r}")
    return tuple(out)


@dataclass(frozen=True, slots=True)
class CraterSettings:
    """Crater layers on the body and how they are stamped (:func:`latlong.stamp_craters`;
    their shapes and degradation follow the body's target, :class:`BodySettings`)."""

    layers: tuple[_craters.CraterLayer | _craters.ModelAgeLayer, ...] = setting(
        (), "crater layer: a power law c=0.5,k=-2,d_min_m=2,d_max_m=50[,age_min_gyr=0,"
        "age_max_gyr=3.5,degradation=0.2,kind=mare] (the fields of craters.CraterLayer): "
        "N_cum = c D^k per m^2, D in metres, ages in Gyr; or a model age npf=moon,age_gyr="
        "3.8,d_min_m=100,d_max_m=5000[,equilibrium=trask|hartmann,degradation,kind] "
        "(craters.ModelAgeLayer: the body's production function and chronology, npf one "
        "of craters.CHRONOLOGY_SYSTEMS) (repeatable)", key="craters", many="append",
        metavar="SPEC")
    """Crater layers: power laws (:class:`craters.CraterLayer`) or model ages
    (:class:`craters.ModelAgeLayer`), as records, spec strings or tables."""
    roughness: bool = setting(True, "fractal overlay and irregular rims (off: ideal "
                              "craters)", key="crater_roughness")
    """Fractal overlay and irregular rims (False: ideal craters)."""
    max_extent_deg: float = setting(60.0, "largest angular size of a crater's ejecta "
                                    "blanket, degrees of arc", key="max_crater_extent_deg",
                                    unit="deg", range=(0.0, 180.0))
    """Largest angular size of a crater's ejecta blanket, degrees of arc, [0, 180]."""

    def __post_init__(self):
        check_declared(self)
        _set(self, "layers", _layers(self.layers, _craters.LAYER_TYPES,
                                     _craters.parse_layer_spec, "layers",
                                     table=_craters.as_crater_layer))

    def check_fits(self, smallest_radius_m: float, resolution_m: float | None) -> None:
        """Refuse layers whose craters cannot fit on the body (ejecta 3 D across within
        ``max_extent_deg`` of arc at the smallest semi-axis) or that a shape model of
        mean edge ``resolution_m`` already holds."""
        for la in self.layers:
            span = math.degrees(3.0 * la.d_max_m * 1.02 / smallest_radius_m)
            if span > self.max_extent_deg:
                raise ParameterError(
                    "layers", f"d_max_m={la.d_max_m:g} m: the crater (ejecta {3 * la.d_max_m:g} m "
                    f"across) is larger than the body allows (radius {smallest_radius_m:g} m, "
                    f"limit {self.max_extent_deg:g} deg)")
            if resolution_m is not None and la.d_max_m > 2.0 * resolution_m:
                raise ParameterError(
                    "layers", f"d_max_m={la.d_max_m:g} m is above the shape model's resolution "
                    f"(mean edge {resolution_m:.3g} m): the model already holds craters that "
                    f"large; keep crater layers below {2 * resolution_m:.3g} m")


@dataclass(frozen=True, slots=True)
class BoulderSettings:
    """Boulder layers and the boulders' shape (:func:`latlong.place_boulders`)."""

    layers: tuple[_craters.BoulderLayer, ...] = setting(
        (), "boulder layer c=0.05,k=-3,d_min_m=0.5,d_max_m=10[,burial_max=0.5,near=0.3] (the "
        "fields of craters.BoulderLayer): N_cum = c D^k per m^2, D in metres; burial_max = "
        "largest buried fraction of the height (<= 0.9); near = share around crater rims; or "
        "Golombek & Rapp's rock abundance golombek,k=..,d_min_m=..,d_max_m=..[,burial_max,near] "
        "(k = total rock area fraction) (repeatable)", key="boulders", many="append",
        metavar="SPEC")
    """Power-law layers (:class:`craters.BoulderLayer`, spec strings or tables)."""
    shape: _craters.BoulderShape = dataclasses.field(default_factory=_craters.BoulderShape)
    """Flattening, elongation and roughness of the procedural rocks."""

    def __post_init__(self):
        _set(self, "layers", _layers(self.layers, _craters.BoulderLayer,
                                     _craters.parse_boulder_specs, "layers"))
        if not isinstance(self.shape, _craters.BoulderShape):
            raise ParameterTypeError("shape", f"must be a craters.BoulderShape; got "
                                     f"{type(self.shape).__name__}")

    def check_fits(self, smallest_radius_m: float) -> None:
        """Refuse boulders larger than a fifth of the body's smallest semi-axis."""
        for la in self.layers:
            if la.d_max_m > 0.2 * smallest_radius_m:
                raise ParameterError("layers", f"d_max_m={la.d_max_m:g} m: boulders larger than "
                                     "a fifth of the body's radius are not boulders")


# --------------------------------------------------------------------------- implicit
@dataclass(frozen=True, slots=True)
class ImplicitSettings:
    """The implicit backend (Li et al.; :func:`latlong.implicit_surface`): metaballs over a
    sphere packing of a constraint mesh, LCSN craters, Gabor detail, marching cubes."""

    shape: ShapeModel | str | Path = setting(
        dataclasses.MISSING, "constraint mesh of --backend implicit (OBJ, PDS plate "
        ".tab/.plt, PLY, STL, VTK; units from --shape-units)", default_text="none")
    """The constraint mesh, or its file (needs ``units``)."""
    units: str | None = setting(None, key="shape_units", choices=("km", "m"))
    """Units of the constraint file: ``km`` or ``m``."""
    layers: tuple = setting(
        (), "LCSN crater layer kernel=NAME,d_min_m=M,d_max_m=M[,exponent=3,probability=0.5,"
        "weight=1,depth_ratio=LO:HI] (the fields of latlong.LcsnLayer): NAME of "
        "craters.LCSN_PRESETS scaled to D in [d_min_m, d_max_m] (metres), N(>D) ~ "
        "D^-exponent, probability = impulse chance per surface cell, depth_ratio = "
        "depth/diameter (repeatable)", key="lcsn", many="append", metavar="SPEC")
    """LCSN crater layers (:class:`latlong.LcsnLayer` or spec strings)."""
    gabor: object | None = setting(
        None, "Gabor micro-detail frequency=CYCLES_PER_M,bandwidth=PER_M,amplitude_m=RMS_M"
        "[,orientation_deg=DEG,density=N]", commas=True, metavar="SPEC")
    """Gabor micro-detail (:class:`latlong.GaborNoise` or a spec string)."""
    polygons: int = setting(200_000, "about how many triangles the implicit mesh has",
                            range=(100, 10**9))
    """About how many triangles the mesh has (when ``voxel_m`` is not given)."""
    voxel_m: float | None = setting(None, "marching-cubes spacing (instead of --polygons)",
                                    unit="m", range=">0")
    """Marching-cubes spacing, metres."""
    packing_voxels: int = setting(128, "voxels along the constraint's longest side for the "
                                  "sphere packing", range=(8, 1024))
    """Voxels along the constraint's longest side for the sphere packing, [8, 1024]."""
    min_sphere_m: float | None = setting(None, "smallest packed sphere", unit="m", range=">0",
                                         default_text="2 packing voxels")
    """Smallest packed sphere, metres (default 2 packing voxels)."""
    constraint_weight: float = setting(
        1.0, "weight of the constraint's own signed distance in the coarse field: 1 follows "
        "the constraint (smooth where it is smooth), 0 the bare metaballs over the packing "
        "(one dome per ball)", range=(0.0, 1.0))
    """Weight of the constraint's own signed distance in the coarse field, [0, 1]: 1
    follows the constraint, 0 is the bare metaball surface (one dome per packed ball)."""
    cell_m: float | None = setting(None, "cell size of grid level 0", unit="m", range=">0",
                                   default_text="the largest d_max_m")
    """Cell size of grid level 0, metres (default: the largest d_max_m); >= every d_max_m."""
    crossings: str = setting("error", key="shape_crossings", choices=CROSSINGS)
    """Casting onto a lat/long grid where a ray crosses twice: error, outermost, innermost."""

    def __post_init__(self):
        from .implicit import GaborNoise, LcsnLayer, parse_gabor_spec, parse_lcsn_spec

        check_declared(self)
        _read_shape(self, "shape", "constraint")
        _set(self, "layers", _layers(self.layers, LcsnLayer, parse_lcsn_spec, "layers"))
        if isinstance(self.gabor, str):
            try:
                _set(self, "gabor", parse_gabor_spec(self.gabor))
            except ValueError as exc:
                raise ParameterError("gabor", f": {exc}") from None
        elif self.gabor is not None and not isinstance(self.gabor, GaborNoise):
            raise ParameterTypeError("gabor", f"must be a GaborNoise or a spec string; got "
                                     f"{type(self.gabor).__name__}")
        if self.layers and self.cell_m is not None:
            biggest = max(la.d_max_m for la in self.layers)
            if self.cell_m < biggest:
                raise ParameterError("cell_m", f"{self.cell_m:g} is smaller than the largest "
                                     f"crater (d_max_m {biggest:g} m): level-0 cells must hold it")


@dataclass(frozen=True, slots=True)
class GaborExample:
    """Gabor micro-detail of the implicit backend fitted to an example
    (:func:`latlong.implicit.fit_gabor`): heights in metres (.npy) or a picture."""

    gabor_example: str = setting(
        dataclasses.MISSING, "fit the Gabor noise to an example (.npy heights in metres, or "
        "a .png/.jpg/.tif picture)", default_text="none")
    """The example file."""
    gabor_pixel_m: float | None = setting(None, "pixel size of --gabor-example on the body",
                                          unit="m", range=">0", default_text="none")
    """The example's pixel size on the body, metres (required)."""
    gabor_amplitude_m: float | None = setting(
        None, "rms of the fitted Gabor noise", unit="m", range=">=0",
        default_text="the .npy example's")
    """The rms of the fitted noise, metres (a picture's grey levels need it)."""

    def __post_init__(self):
        check_declared(self)
        if self.gabor_pixel_m is None:
            raise ParameterError("gabor_example", "needs {} (the example's pixel size on "
                                 "the body, metres)", see=("gabor_pixel_m",))

    def fit(self):
        """The :class:`~latlong.implicit.GaborNoise` fitted to the example."""
        from .implicit import fit_gabor, read_example

        try:
            image, is_heights = read_example(self.gabor_example)
            if not is_heights and self.gabor_amplitude_m is None:
                raise ParameterError("gabor_example", "is a picture (grey levels, not "
                                     "metres): give {}", see=("gabor_amplitude_m",))
            return fit_gabor(image, self.gabor_pixel_m, amplitude_m=self.gabor_amplitude_m)
        except ParameterError:
            raise
        except FileNotFoundError as exc:  # kept (Python), tagged (the command's flag)
            exc.parameter = "gabor_example"
            raise
        except ValueError as exc:
            raise ParameterError("gabor_example", f"{self.gabor_example}: {exc}") from None
