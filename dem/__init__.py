r"""dem: digital elevation models: I/O, RMD expansion, gap filling, layer stacks, meshes.

::

    GeoTIFF, PDS3 --io.read--> Dem (core: heights, NaN = unknown, transform, CRS, metres)
      -> fill_gaps (gaps, gapcraters), fill_crater_gaps / replace_crater (craterfill)
      -> detect_craters, crater_density, resolved_diameter_m (craterdensity)
      -> expand (expansion: RMD, 2x per level)                              -> Dem
      -> enhance (EnhanceConfig in config, the plan in planning)            -> Stack
         batch (seeds x varied keys on dask.distributed)          -> stack folders
    Stack (stack: consistent layers + catalogs; write, read_stack)
      -> to_mesh (mesh: PLY/VTP) | slope, power_spectrum (terrain), fractal_fit (fractal)
      -> DemSurface (surface: a DEM or a stack as a latlong surface, what the camera and
         the LIDAR of latlong.sensors see)

Beside them: ``frame`` (local metric frames), ``boulders`` (boulders on rasters),
``_*kernels`` (numba) and ``cli/`` (the
``dem`` command line, which imports the library, never the reverse; ``dem --help``).

Martin et al. (lunar crater model and DEM enhancement, IV): random-midpoint-displacement
expansion of real DEMs, fractal gap filling (conditioned on the gaps' rims, with craters
at the density around large gaps), crater gap filling and crater
replacement, boulders (:func:`stamp_boulders`), multi-resolution layer stacks with
craters and boulders per layer (:func:`enhance`) and their stitched meshes
(:func:`to_mesh`), on a :class:`Dem` that keeps the georeferencing.

The ``dem`` command
-------------------
The commands of this docstring run as written, in order, from the repository's folder
(later ones read what earlier ones wrote), into ``out/dem/``;
``tests/test_readme_commands.py`` runs them at small sizes. Every ``dem`` command takes
its input as its argument; every option is also a key of a TOML file given with
``--config`` (``input`` too; options on the command line win), ``-q`` silences every
command and ``--help`` shows every default.

.. code-block:: bash

    mkdir -p out/dem
    # describe a DEM: size, CRS, pixel size in metres, heights, fractal dimension (the
    # bundled LOLA LDEM_4 crop: 257^2 pixels of 7.6 km around 0 N 180 E, tests/data/README.md)
    dem info tests/data/ldem4_crop.lbl                # PDS3 .lbl/.img or any GeoTIFF
    dem convert tests/data/ldem4_crop.lbl -o out/dem/moon.tif   # -> cloud-optimised GeoTIFF
    # PDS3 through GDAL's PDS driver: polar stereographic products too (a 64^2 LOLA south pole)
    dem convert tests/data/ldem4_spole.lbl -o out/dem/spole.tif
    dem info out/dem/moon.tif  # a geographic CRS needs the body radius: the file's tags give
                               # it here, else --body-radius-m 1737400 (or --body moon)

    # fill NoData with fractal terrain meeting the gaps' rims (craters in large gaps at the
    # density around them: --craters auto|none|SPEC), then double the resolution twice
    # (examples/data/ldem4_gappy.tif: the same crop with three holes, examples/data/README.md)
    dem fill examples/data/ldem4_gappy.tif -o out/dem/filled.tif --seed 1
    dem expand out/dem/filled.tif -o out/dem/fine.tif --levels 2 --seed 1 --region 0,0,257

    # a 4x expansion of the LOLA crop in 16 tiles of 257^2 output pixels, the tiles as tasks
    # on a local dask cluster of two worker processes, written into a Zarr store (the same
    # heights as tile after tile in this process)
    dem expand tests/data/ldem4_crop.lbl --levels 2 --seed 1 --tile-px 257 --workers 2 \
        -o out/dem/crop4x.zarr
    dem info out/dem/crop4x.zarr

Expansion (random midpoint displacement, Martin et al. IV.A) keeps every input pixel
exactly, puts new pixel centres on the old ones and, by default, continues the input's
own roughness statistics (fractal dimension and local relief). Regions must be squares
of 2^n + 1 pixels, given as ROW,COL,SIZE in pixels or LEFT,BOTTOM,RIGHT,TOP in CRS units,
on the command line or in Python (``dem.expand(d, region=(0, 0, 257))`` or
``region="0,0,257"``). Same seed, same bytes; expanding tiles gives the same pixels as
expanding the whole.

Every GeoTIFF written is a cloud-optimised GeoTIFF (COG: tiles, overviews); ``dem
convert``, ``fill`` and ``expand`` write a Zarr store instead for a ``.zarr`` output
(format 2, zlib chunks of 512^2, the CRS and tags as attributes; GDAL, rasterio,
zarr-python and xarray read it, and so does every ``dem`` command).

DEMs bigger than memory
-----------------------
``dem.read(path, window=(row, col, rows, cols))`` reads a part. ``dem expand``
(:func:`expand_to_file`) writes its output tile by tile, in this process or with the
tiles as dask tasks (``--workers N``: a local cluster; ``--scheduler tcp://HOST:8786``:
an existing one whose workers see the same paths): a 1025^2 base by 4 levels (16385^2,
0.94 GB) peaks at 0.34 GB of memory (4.5 GB in one piece). ``dem fill`` of a DEM whose
whole-raster fill would need more than ``--max-memory-gb`` (default 0.8 x this machine's
memory) fills it from the file hole by hole (:func:`fill_to_file`: holes found tile by
tile across tile edges, the fractal dimension by a streamed reduction that gives the
very same number, each hole read with its neighbourhood), the same bytes as the
whole-raster fill; a gap too large to fill within the limit is refused, naming it.
``dem enhance`` makes and writes one layer at a time (below). Each gives the same bytes
as the whole-raster computation.

Layer stacks around a landing site: ``dem enhance``, ``dem mesh``
-----------------------------------------------------------------
.. code-block:: bash

    # 11 layers of 129^2, 7.6 km -> 7.4 m: ~3 s
    dem enhance --config examples/site.toml --seed 2014 -o out/dem/site
    dem mesh out/dem/site/manifest.json -o out/dem/site.ply   # or .vtp; a DEM meshes too
    dem slopes out/dem/site/manifest.json --plot out/dem/slopes.png  # every layer
    dem spectrum out/dem/fine.tif --plot out/dem/psd.png             # the expanded DEM

``examples/site.toml`` (every key is also an option: ``--layers``, ``--craters ...``,
``--target X,Y``; ``-o`` on the command line wins over its ``output``):

.. code-block:: toml

    input = "tests/data/ldem4_crop.lbl"  # LOLA LDEM_4 crop, 257^2 at 7.6 km/px, 0 N 180 E
    output = "out/site"                  # layer_NN.tif, craters_NN.csv/.geojson/.scc, manifest.json
    target = [180.0, 0.0]                # the site, in the DEM's CRS units (lon, lat degrees)
    layers = 11                          # layer k has pixels 2^k finer: 7.6 km ... 7.4 m
    size = 129                           # pixels per side of every layer, 2^n + 1
    craters = ["npf=moon,age_gyr=3.9,d_min_m=10,d_max_m=300000,equilibrium=trask",
               "c=0.079,k=-2,d_min_m=0.5,d_max_m=10,kind=equilibrium"]

A 3.9 Gyr highland surface: the Moon's production function and chronology (Neukum et
al. 2001) capped at the Trask equilibrium below ~0.6 km, and the equilibrium continued
below 10 m, the production function's limit (N_cum = 0.079 D^-2 per m²). Craters wider
than ``source_crater_px`` = 4 pixels of the source (here 30 km) are left to the source
DEM, whose real craters are the truth; set it to 0 on a synthetic or smoothed base. The
crater layer ``source[,d_min_m=..]`` instead continues the source's *own* crater density
below its resolution: :func:`crater_density` counts the source's craters of 6 pixels and
up (a rim-over-floor detector; a lower bound, it misses shallow and overlapping craters)
as N = c D^-2, here c = 0.055 from 100 craters of 45-490 km, and the stack's manifest
records it. The craters take the body the CRS names (here the Moon; ``--body``,
``--gravity-m-s2`` to override): fresh morphology by size and degradation by diffusion
for each crater's age (:mod:`craters`). ``python examples/plot_dem_enhance.py`` draws
this stack's layers with their height ranges and median slopes: layer 0's median Horn
slope is 3.4° against LOLA's 3.3° on the same pixels, and on the same ground each finer
layer is steeper than the coarser one (3.4° at 7.6 km/px to 6.2° at 7.4 m/px), as real
lunar slopes steepen at shorter baselines. Layers of ``size = 1025`` need a base of at
least 1025 x 1025 pixels (``dem fill`` first if it has NoData).

Each layer is the RMD expansion of the central half of the previous one (centred on the
target), so the stack spans 2^(layers-1) in resolution at a fixed cost per layer.
Craters come from **one** population for the area of layer 0, split so that each crater
goes into the finest layer that contains it entirely (ejecta edge 1.5 D, one pixel clear
of the border) if that layer resolves it (D >= 2 pixels); the others are counted as
rejected; a crater inside the rim of a larger, younger one (of any layer) was erased by
it and is dropped (``manifest.json``: drawn = stamped + erased on steep ground + erased
by a younger crater + rejected). It is
drawn band by band in diameter over the area where each band can be kept (the same
Poisson law, without generating the ~1e11 craters too small to keep). A layer's craters
are stamped before the next layer is expanded, and the coarser layers are then
re-synchronised, so the stack is **consistent**: inside its footprint a finer layer's
even pixels equal the coarser layer exactly (``Stack.is_consistent()``, also for the
float32 files). Catalogs list each stamped crater once, in its layer, with its
as-stamped depth, rim height, degradation and seed, in the stack's local frame (metres
from the target: x east, y north; equirectangular at the target for a geographic CRS)
and in world coordinates. Each layer also gets ``craters_NN.scc``, its crater count for
craterstats (``Stack.crater_count(k)``): every crater of the stack centred in the layer
and at least ``min_crater_px`` of its pixels wide, over the layer's area, with longitude
and latitude on the CRS's body. Crater layers are power laws or model ages
(``npf=moon,age_gyr=3.8,d_min_m=..,d_max_m=..``, :mod:`craters.chronology`), drawn band
by band through each layer's own law. The mesh uses the same frame, leaves a hole in
each layer where the next sits and fans the ring of coarse cells around it to the finer
layer's border vertices, so there are no cracks or T-junctions. ``dem enhance`` makes
the layers one after the other and writes each as soon as it is made
(``dem.enhancefile.enhance_to_folder``; the re-synchronisation is written at the end,
finest first): the same files as ``dem.enhance(...).write(...)``, with memory for about
two layers whatever their number.

Boulders on DEMs: ``dem enhance --boulders ...`` stamps each boulder (the shapes of
:mod:`craters.boulders`) as a heightfield maximum into the finest layer that holds it and
resolves it (>= 2 pixels), and ``dem mesh`` appends their meshes;
``dem.stamp_boulders(d, catalog)`` does the same on one DEM. Many stacks at once:
``dem batch`` (:mod:`latlong.parallel`).

From Python
-----------
.. code-block:: python

    import craters, dem

    d = dem.read("examples/data/ldem4_gappy.tif")  # metres, NaN = unknown (or a PDS .lbl)

    # a shadowed crater floor: fill it with a warped synthetic crater, then the other gaps
    frame = dem.local_frame(d)                       # metres around the DEM's centre pixel
    x, y = frame.to_local(179.4, -5.9)               # Daedalus (93 km) at 179.4 E, 5.9 S
    d = dem.fill_crater_gaps(d, [craters.Crater(float(x), float(y), 93000.0)], rng=1)
    d = dem.fill_gaps(d, rng=1)
    fine = dem.expand(d, levels=2, region=(0, 0, 257), rng=1)   # ROW,COL,SIZE: 1025^2 px
    dem.write(fine, "out/dem/daedalus_fine.tif")     # cloud-optimised GeoTIFF: float32, tags

    # 14 layers around Daedalus's centre, 7.6 km down to 0.93 m pixels, and a fresh 30 km
    # crater on its floor (the stack stays consistent)
    stack = dem.enhance({"layers": 14, "size": 129, "target": [179.4, -5.9], "seed": 1,
                         "craters": ["c=0.05,k=-2,d_min_m=2,d_max_m=150000"]}, dem=d)
    stack = dem.replace_crater(stack, craters.Crater(0.0, 0.0, 30000.0), rng=1)
    stack.write("out/dem/daedalus_site"); dem.to_mesh(stack, "out/dem/daedalus_site.vtp")

    # boulders of 2-10 m (N_cum = 0.01 D^-3 per m^2, ~15) on the finest layer, 120 m across
    floor = stack.layers[-1]
    rocks = dem.boulder_population(floor, "c=0.01,k=-3,d_min_m=2,d_max_m=10", rng=1)
    floor, placed = dem.stamp_boulders(floor, rocks, return_catalog=True)
"""

import logging
from typing import TYPE_CHECKING

from craters._shared.lazy import lazy_package

if TYPE_CHECKING:  # at run time each name is imported on first use (lazy_package)
    from .analysis import band_power, laplacian
    from .batch import batch
    from .boulders import boulder_population, stamp_boulders
    from .config import EnhanceConfig, SourceCraterLayer
    from .core import Dem
    from .craterdensity import CraterDensity, crater_density, detect_craters, resolved_diameter_m
    from .craterfill import fill_crater_gaps, replace_crater
    from .enhance import enhance
    from .expandfile import ExpandedFile, expand_to_file
    from .expansion import (
        displacement_scales,
        expand,
        expansion_sizes,
        local_relief,
    )
    from .fractal import (
        FractalFit,
        SpectralFit,
        dimension_warning,
        expansion_fit,
        fractal_dimension,
        fractal_fit,
        local_roughness,
        variogram,
    )
    from .frame import LocalFrame, local_frame
    from .gaps import fill_gaps
    from .io import WindowWriter, read, write
    from .mesh import to_mesh
    from .stack import Stack, read_stack
    from .surface import DemSurface
    from .terrain import (
        pixel_sizes_by_row,
        power_spectrum,
        roughness,
        slope,
        slope_distribution,
        spectral_exponent,
        spectral_fit,
    )
    from .tiledfill import FilledFile, fill_to_file

__all__ = [
    "CraterDensity",
    "Dem",
    "DemSurface",
    "EnhanceConfig",
    "ExpandedFile",
    "FilledFile",
    "SourceCraterLayer",
    "FractalFit",
    "LocalFrame",
    "SpectralFit",
    "Stack",
    "WindowWriter",
    "band_power",
    "batch",
    "boulder_population",
    "crater_density",
    "detect_craters",
    "dimension_warning",
    "displacement_scales",
    "enhance",
    "expand",
    "expand_to_file",
    "expansion_fit",
    "expansion_sizes",
    "fill_crater_gaps",
    "fill_gaps",
    "fill_to_file",
    "fractal_dimension",
    "fractal_fit",
    "laplacian",
    "local_frame",
    "local_relief",
    "local_roughness",
    "read",
    "read_stack",
    "replace_crater",
    "resolved_diameter_m",
    "pixel_sizes_by_row",
    "power_spectrum",
    "roughness",
    "slope",
    "slope_distribution",
    "spectral_exponent",
    "spectral_fit",
    "stamp_boulders",
    "to_mesh",
    "variogram",
    "write",
]

lazy_package(__name__)

logging.getLogger(__name__).addHandler(logging.NullHandler())
