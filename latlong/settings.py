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

import craters as _craters
from craters._shared import (
    ParameterError,
    ParameterTypeError,
    check_choice,
    check_finite,
    check_int,
    check_positive,
    check_range,
    physical_memory_bytes,
)

from .grid import BUILD_BASE_BYTES, LatLongGrid, build_bytes_per_vertex
from .shapes import SIZE_RANGE_M, ShapeModel, read_shape_model

__all__ = ["BASES", "MEMORY_SHARE", "RADII_ON_DISK", "BodySettings", "BoulderSettings",
           "CraterSettings", "ImplicitSettings", "SURFACES", "ShapeBase", "SphereBase",
           "check_memory", "expected_counts"]

#: Peak memory of a build per crater of its catalog (the catalog, the stamping profile
#: tables, the wave schedule), bytes. Measured (/usr/bin/time -v, 2 threads): M = 100,
#: R = 50 m, c=0.5,k=-2,d_max_m=15: 0.71 GB with 8.9e4 craters, 3.54 GB with 8.9e5,
#: 3.5 kB a crater; rounded up.
BUILD_BYTES_PER_CRATER = 4.0e3
#: ... per boulder (catalog, rock meshes' bookkeeping), bytes. Measured the same way:
#: M = 40, R = 50 m sphere, c=0.5,k=-2,d_max_m=2: 0.71 GB with 8.9e4 boulders, 0.97 GB
#: with 8.9e5, 0.33 kB a boulder; rounded up.
BUILD_BYTES_PER_BOULDER = 0.4e3
#: Names of the base shapes (``shape`` takes a model file).
BASES = ("sphere", "faulting", "fbm", "shape")
#: The share of this machine's memory a build may use unless ``max_memory_gb`` is given.
MEMORY_SHARE = 0.8
#: Where a lat/long build keeps its radii (:func:`check_memory`, :mod:`latlong.scratch`).
RADII_ON_DISK = ("auto", "yes", "no")
#: The radii's share of :func:`~latlong.grid.build_bytes_per_vertex` (one float64).
RADII_BYTES_PER_VERTEX = 8.0
#: Mean radius a body may have, metres: the range of shape models (a boulder to a gas
#: giant), so radii, areas and volumes stay finite in float64.
RADIUS_RANGE_M = SIZE_RANGE_M
CROSSINGS = ("error", "outermost", "innermost")
#: Where a shape base is cratered: the lat/long grid or the model's own mesh.
SURFACES = ("latlong", "mesh")


def check_memory(magnitude: int, max_memory_gb: float | None = None, *,
                 n_craters: float = 0.0, n_boulders: float = 0.0,
                 radii_on_disk: str = "auto", disk_ok: bool = True) -> bool:
    """Refuse up front a build that would need more than ``max_memory_gb`` GB (1e9
    bytes; default :data:`MEMORY_SHARE` of this machine's memory), with the estimate:
    the grid's (:meth:`LatLongGrid.estimate_bytes`), then with the expected numbers of
    craters and boulders (:data:`BUILD_BYTES_PER_CRATER`, :data:`BUILD_BYTES_PER_BOULDER`)
    refused under ``craters`` / ``boulders``.

    ``radii_on_disk`` (:data:`RADII_ON_DISK`): ``"yes"`` counts the radii (8 B a vertex)
    as kept in a scratch file (:mod:`latlong.scratch`), ``"no"`` in memory, ``"auto"`` in
    memory when that fits, else on disk if ``disk_ok`` (the base can be made on disk).
    Returns whether the radii go on disk."""
    check_choice("radii_on_disk", radii_on_disk, RADII_ON_DISK)
    if radii_on_disk == "yes" and not disk_ok:
        raise ParameterError("radii_on_disk", "= yes needs a sphere or fbm base on the "
                             "lat/long grid")
    bpv = build_bytes_per_vertex()
    if max_memory_gb is None:
        have = physical_memory_bytes()
        limit = MEMORY_SHARE * have
        whose = f" (the default: {MEMORY_SHARE:g} x this machine's {have / 1e9:.3g} GB)"
    else:
        limit, whose = max_memory_gb * 1e9, ""
    counts = n_craters * BUILD_BYTES_PER_CRATER + n_boulders * BUILD_BYTES_PER_BOULDER
    on_disk = radii_on_disk == "yes"
    if radii_on_disk == "auto" and disk_ok:
        on_disk = LatLongGrid.estimate_bytes(magnitude, bpv) + counts > limit
    if on_disk:
        bpv -= RADII_BYTES_PER_VERTEX
    need = LatLongGrid.estimate_bytes(magnitude, bpv)
    if need > limit:
        n = 6 * magnitude * magnitude + 2
        where = " with the radii on disk" if on_disk else ""
        raise ParameterError(
            "magnitude", f"{magnitude} needs about {need / 1e9:.3g} GB of memory{where} "
            f"({n:.3g} vertices x {bpv:g} B + {BUILD_BASE_BYTES / 1e9:.3g} GB), more than "
            f"{{}} = {limit / 1e9:.3g} GB{whose}", see=("max_memory_gb",))
    for name, count, each in (("craters", n_craters, BUILD_BYTES_PER_CRATER),
                              ("boulders", n_boulders, BUILD_BYTES_PER_BOULDER)):
        if need + count * each > limit:
            raise ParameterError(
                name, f": about {count:.3g} {name} need about {count * each / 1e9:.3g} GB of "
                f"memory ({each / 1e3:g} kB each) besides the {need / 1e9:.3g} GB of "
                f"magnitude {magnitude} and what comes before: more than {{}} = "
                f"{limit / 1e9:.3g} GB{whose}; raise d_min_m or lower c",
                see=("max_memory_gb",))
        need += count * each
    return on_disk


def expected_counts(craters: CraterSettings, boulders: BoulderSettings,
                    area_m2: float) -> tuple[float, float]:
    """The mean numbers of craters and boulders the layers draw on ``area_m2``."""
    n_craters = sum(float(la.expected_count(area_m2)) for la in craters.layers)
    n_boulders = sum(area_m2 * la.c * (la.d_min_m ** la.k - la.d_max_m ** la.k)
                     for la in boulders.layers)
    return n_craters, n_boulders


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

    magnitude: int = 200
    """Grid magnitude M >= 1 (6M^2+2 vertices); refused up front if it cannot fit."""
    radius_m: float | None = None
    """Reference radius, metres; default 50 m (a shape base sets its own)."""
    stretch: tuple[float, float, float] | None = None
    """Scale factors along x, y, z; default 1, 1, 1 (a shape base sets its own)."""
    target: str = "small-body"
    """The body's kind for crater morphology and diffusivity: ``small-body`` (its gravity
    from its size and ``density_kg_m3``) or a name of :data:`craters.TARGETS`."""
    gravity_m_s2: float | None = None
    """Surface gravity, m/s^2 (default: the target's; a small body's from its size)."""
    density_kg_m3: float = 2000.0
    """Bulk density of a small body, kg/m^3."""
    crater_depth_ratio: float | None = None
    """Fresh crater depth/diameter of a small body, [0.01, 0.5]; default 0.2 (Marchi et
    al. 2015); e.g. Bennu 0.10 (Daly et al. 2020)."""
    max_memory_gb: float | None = None
    """Memory the build may use, GB (1e9 bytes); a magnitude whose estimate
    (:func:`check_memory`) is larger is refused up front. Default: :data:`MEMORY_SHARE`
    of this machine's memory."""
    radii_on_disk: str = "auto"
    """Keep the radii in a memory-mapped scratch file (:mod:`latlong.scratch`; bodies
    bigger than memory, the same bytes): ``auto`` when the in-memory estimate exceeds
    ``max_memory_gb`` (sphere and fbm bases), ``yes``, ``no``."""

    def __post_init__(self):
        _set(self, "magnitude", check_int("magnitude", self.magnitude, 1, 10**9))
        check_choice("target", self.target, (*_craters.TARGETS, "small-body"))
        if self.gravity_m_s2 is not None:
            _set(self, "gravity_m_s2", check_positive("gravity_m_s2", self.gravity_m_s2))
        _set(self, "density_kg_m3", check_range("density_kg_m3", self.density_kg_m3,
                                                10.0, 30_000.0))
        if self.crater_depth_ratio is not None:
            if self.target != "small-body":
                raise ParameterError("crater_depth_ratio", f"applies to small-body only (the "
                                     f"{self.target}'s crater depths follow its published laws)")
            _set(self, "crater_depth_ratio", check_range("crater_depth_ratio",
                                                         self.crater_depth_ratio, 0.01, 0.5))
        if self.max_memory_gb is not None:
            _set(self, "max_memory_gb", check_positive("max_memory_gb", self.max_memory_gb))
        check_memory(self.magnitude, self.max_memory_gb, radii_on_disk=self.radii_on_disk)
        if self.radius_m is not None:
            _set(self, "radius_m", check_range("radius_m", self.radius_m, *RADIUS_RANGE_M))
        if self.stretch is not None:
            _set(self, "stretch", parse_stretch(self.stretch))


# --------------------------------------------------------------------------- bases
@dataclass(frozen=True, slots=True)
class SphereBase:
    """A plain sphere (craters and boulders only)."""

    name = "sphere"


def _check_fbm(obj, prefix: str = "") -> None:
    """frequency > 0, octaves in [1, 30], persistence > 0, lacunarity >= 1 (the fields of
    an fBm record whose names start with ``prefix``)."""
    key = prefix + "frequency"
    if getattr(obj, key) is not None:
        _set(obj, key, check_positive(key, getattr(obj, key)))
    key = prefix + "octaves"
    _set(obj, key, check_int(key, getattr(obj, key), 1, 30))
    key = prefix + "persistence"
    _set(obj, key, check_positive(key, getattr(obj, key)))
    key = prefix + "lacunarity"
    lac = check_finite(key, getattr(obj, key))
    if lac < 1:
        raise ParameterError(key, f"must be >= 1; got {lac!r}")
    _set(obj, key, lac)


@dataclass(frozen=True, slots=True)
class ShapeBase:
    """A real shape model ray-cast onto the grid (:func:`latlong.from_shape_model`),
    with optional fBm detail below its resolution. The model is read once, here."""

    model: ShapeModel | str | Path
    """The model, or its file (OBJ, PDS plate .tab/.plt, PLY, STL; needs ``units``)."""
    units: str | None = None
    """Units of the file: ``km`` or ``m``."""
    center: str | tuple[float, float, float] = "volume-centroid"
    """Ray origin: volume-centroid, area-centroid, origin or (x, y, z) metres."""
    crossings: str = "error"
    """Where a ray crosses the surface more than once: error, outermost, innermost."""
    smooth: str = "butterfly"
    """Subdivision before casting: butterfly, linear, loop, none."""
    detail_frequency: float | None = None
    """fBm detail frequency on the unit sphere; default: wavelength = the resolution."""
    detail_octaves: int = 6
    """fBm detail octaves."""
    detail_persistence: float = 0.5
    """fBm detail amplitude ratio per octave."""
    detail_lacunarity: float = 2.0
    """fBm detail frequency ratio per octave."""
    detail_amplitude_m: float = 0.0
    """fBm detail height scale, metres (0 = no detail)."""
    surface: str = "latlong"
    """``latlong``: ray-cast onto the lat/long grid (the body must be star-shaped from
    the centre); ``mesh``: cratered on the model's own refined mesh (:mod:`latlong.mesh`;
    any closed shape, e.g. Itokawa's neck)."""
    spacing_m: float | None = None
    """Mean edge of the refined mesh with ``surface="mesh"``, metres; default: the
    lat/long grid's spacing at the scene's magnitude, (pi / 2) R / M."""
    name = "shape"

    def __post_init__(self):
        if isinstance(self.model, str | Path):  # a file: read it
            if self.units not in ("km", "m"):
                raise ParameterError("units", f"must be km or m with a shape model file; "
                                     f"got {self.units!r}")
            try:
                _set(self, "model", read_shape_model(self.model, units=self.units))
            except FileNotFoundError as exc:  # kept (Python), tagged (a command's flag)
                exc.parameter = "model"
                raise
            except ValueError as exc:
                raise ParameterError("model", f"{self.model}: {exc}") from None
        elif not isinstance(self.model, ShapeModel):
            raise ParameterTypeError("model", f"must be a ShapeModel or a path; got "
                                     f"{type(self.model).__name__}")
        check_choice("crossings", self.crossings, CROSSINGS)
        check_choice("smooth", self.smooth, ("butterfly", "linear", "loop", "none"))
        check_choice("surface", self.surface, SURFACES)
        if self.surface == "mesh" and self.smooth not in ("butterfly", "linear"):
            raise ParameterError("smooth", f"must be butterfly or linear with {{}} mesh; got "
                                 f"{self.smooth!r}", see=("surface",))
        if self.spacing_m is not None:
            if self.surface != "mesh":
                raise ParameterError("spacing_m", "applies to {} mesh", see=("surface",))
            _set(self, "spacing_m", check_positive("spacing_m", self.spacing_m))
        _set(self, "center", _center(self.center))
        if self.detail_frequency is None:
            _set(self, "detail_frequency", self.radius_m / self.model.mean_edge_m)
        _check_fbm(self, "detail_")
        _set(self, "detail_amplitude_m", check_positive("detail_amplitude_m",
                                                        self.detail_amplitude_m,
                                                        allow_zero=True))

    @property
    def radius_m(self) -> float:
        """Volume-equivalent radius of the model, metres."""
        return (3.0 * self.model.volume_m3 / (4.0 * math.pi)) ** (1.0 / 3.0)


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
                out.append(parse(item))
            except ValueError as exc:
                raise ParameterError(name, f": {exc}") from None
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

    layers: tuple[_craters.CraterLayer | _craters.ModelAgeLayer, ...] = ()
    """Crater layers: power laws (:class:`craters.CraterLayer`) or model ages
    (:class:`craters.ModelAgeLayer`), as records, spec strings or tables."""
    roughness: bool = True
    """Fractal overlay and irregular rims (False: ideal craters)."""
    max_extent_deg: float = 60.0
    """Largest angular size of a crater's ejecta blanket, degrees of arc, (0, 180]."""

    def __post_init__(self):
        _set(self, "layers", _layers(self.layers, _craters.LAYER_TYPES,
                                     _craters.parse_layer_spec, "layers",
                                     table=_craters.as_crater_layer))
        if not isinstance(self.roughness, bool):
            raise ParameterTypeError("roughness", f"must be true or false; got "
                                     f"{self.roughness!r}")
        ext = check_positive("max_extent_deg", self.max_extent_deg)
        if ext > 180:
            raise ParameterError("max_extent_deg", f"must be <= 180; got {ext!r}")
        _set(self, "max_extent_deg", ext)

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

    layers: tuple[_craters.BoulderLayer, ...] = ()
    """Power-law layers (:class:`craters.BoulderLayer`, spec strings or tables)."""
    shape: _craters.BoulderShape = dataclasses.field(default_factory=_craters.BoulderShape)
    """Flattening, elongation and roughness of the procedural rocks."""

    def __post_init__(self):
        _set(self, "layers", _layers(self.layers, _craters.BoulderLayer,
                                     _craters.parse_boulder_spec, "layers"))
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

    shape: ShapeModel | str | Path
    """The constraint mesh, or its file (needs ``units``)."""
    units: str | None = None
    """Units of the constraint file: ``km`` or ``m``."""
    layers: tuple = ()
    """LCSN crater layers (:class:`latlong.LcsnLayer` or spec strings)."""
    gabor: object | None = None
    """Gabor micro-detail (:class:`latlong.GaborNoise` or a spec string)."""
    polygons: int = 200_000
    """About how many triangles the mesh has (when ``voxel_m`` is not given)."""
    voxel_m: float | None = None
    """Marching-cubes spacing, metres."""
    packing_voxels: int = 128
    """Voxels along the constraint's longest side for the sphere packing, [8, 1024]."""
    min_sphere_m: float | None = None
    """Smallest packed sphere, metres (default 2 packing voxels)."""
    constraint_weight: float = 1.0
    """Weight of the constraint's own signed distance in the coarse field, [0, 1]: 1
    follows the constraint, 0 is the bare metaball surface (one dome per packed ball)."""
    cell_m: float | None = None
    """Cell size of grid level 0, metres (default: the largest d_max_m); >= every d_max_m."""
    crossings: str = "error"
    """Casting onto a lat/long grid where a ray crosses twice: error, outermost, innermost."""

    def __post_init__(self):
        from .implicit import GaborNoise, LcsnLayer, parse_gabor_spec, parse_lcsn_spec

        if isinstance(self.shape, str | Path):  # a file: read it
            if self.units not in ("km", "m"):
                raise ParameterError("units", f"must be km or m with a constraint file; "
                                     f"got {self.units!r}")
            try:
                _set(self, "shape", read_shape_model(self.shape, units=self.units))
            except FileNotFoundError as exc:  # kept (Python), tagged (a command's flag)
                exc.parameter = "shape"
                raise
            except ValueError as exc:
                raise ParameterError("shape", f"{self.shape}: {exc}") from None
        elif not isinstance(self.shape, ShapeModel):
            raise ParameterTypeError("shape", f"must be a ShapeModel or a path; got "
                                     f"{type(self.shape).__name__}")
        _set(self, "layers", _layers(self.layers, LcsnLayer, parse_lcsn_spec, "layers"))
        if isinstance(self.gabor, str):
            try:
                _set(self, "gabor", parse_gabor_spec(self.gabor))
            except ValueError as exc:
                raise ParameterError("gabor", f": {exc}") from None
        elif self.gabor is not None and not isinstance(self.gabor, GaborNoise):
            raise ParameterTypeError("gabor", f"must be a GaborNoise or a spec string; got "
                                     f"{type(self.gabor).__name__}")
        _set(self, "polygons", check_int("polygons", self.polygons, 100, 10**9))
        _set(self, "packing_voxels", check_int("packing_voxels", self.packing_voxels, 8, 1024))
        _set(self, "constraint_weight",
             check_range("constraint_weight", self.constraint_weight, 0.0, 1.0))
        for key in ("voxel_m", "min_sphere_m", "cell_m"):
            if getattr(self, key) is not None:
                _set(self, key, check_positive(key, getattr(self, key)))
        check_choice("crossings", self.crossings, CROSSINGS)
        if self.layers and self.cell_m is not None:
            biggest = max(la.d_max_m for la in self.layers)
            if self.cell_m < biggest:
                raise ParameterError("cell_m", f"{self.cell_m:g} is smaller than the largest "
                                     f"crater (d_max_m {biggest:g} m): level-0 cells must hold it")
