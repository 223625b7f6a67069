"""The memory a lat/long build needs, estimated before any work: a build that cannot fit
is refused up front with the estimate (:func:`check_memory`), or its radii go into a
memory-mapped scratch file (:mod:`latlong.scratch`)."""

from __future__ import annotations

from craters._shared import ParameterError, check_choice, physical_memory_bytes

from .grid import BUILD_BASE_BYTES, LatLongGrid, build_bytes_per_vertex

__all__ = ["BUILD_BYTES_PER_BOULDER", "BUILD_BYTES_PER_CRATER", "MEMORY_SHARE",
           "RADII_ON_DISK", "check_memory", "expected_counts"]

#: Peak memory of a build per crater of its catalog (the catalog, the stamping profile
#: tables, the wave schedule), bytes. Measured (/usr/bin/time -v, 2 threads): M = 100,
#: R = 50 m, c=0.5,k=-2,d_max_m=15: 0.71 GB with 8.9e4 craters, 3.54 GB with 8.9e5,
#: 3.5 kB a crater; rounded up.
BUILD_BYTES_PER_CRATER = 4.0e3
#: ... per boulder (catalog, rock meshes' bookkeeping), bytes. Measured the same way:
#: M = 40, R = 50 m sphere, c=0.5,k=-2,d_max_m=2: 0.71 GB with 8.9e4 boulders, 0.97 GB
#: with 8.9e5, 0.33 kB a boulder; rounded up.
BUILD_BYTES_PER_BOULDER = 0.4e3
#: The share of this machine's memory a build may use unless ``max_memory_gb`` is given.
MEMORY_SHARE = 0.8
#: Where a lat/long build keeps its radii (:func:`check_memory`, :mod:`latlong.scratch`).
RADII_ON_DISK = ("auto", "yes", "no")
#: The radii's share of :func:`~latlong.grid.build_bytes_per_vertex` (one float64).
RADII_BYTES_PER_VERTEX = 8.0


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
    need: float = LatLongGrid.estimate_bytes(magnitude, bpv)
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


def expected_counts(craters, boulders, area_m2: float) -> tuple[float, float]:
    """The mean numbers of craters and boulders the layers of a scene's
    :class:`~latlong.CraterSettings` and :class:`~latlong.BoulderSettings` draw on
    ``area_m2``."""
    n_craters = sum(float(la.expected_count(area_m2)) for la in craters.layers)
    n_boulders = sum(area_m2 * la.c * (la.d_min_m ** la.k - la.d_max_m ** la.k)
                     for la in boulders.layers)
    return n_craters, n_boulders
