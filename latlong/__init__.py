r"""latlong: asteroid bodies on the evenly spaced 6M^2+2 latitude/longitude sphere mesh.

Martin et al. 2014: the lat/long mesh, two-phase Poisson faulting and Perlin fBm base
shapes, crater stamping via local DEM mapping, boulders, slopes, renderer export and
previews; and the implicit backend of Li et al. 2020/2022 (metaballs over a sphere
packing, LCSN craters, Gabor noise, marching cubes).

::

    grid (LatLongGrid) -> base radii: faulting | perlin | shapes (real models)
                       -> body (Body: radii + stretch + catalogs; .npz)
                       -> cratering (catalog on the true surface: surface; stamping)
                       -> boulders (populations, placement)
                       -> export (PLY/OBJ/STL/VTP/VTK) | gltf + strips (patches, LODs)
                          | slopes, preview
    scene (Scene: settings, presets) -> build(scene) -> Body   (writes nothing)
                                     -> outputs (write_outputs) | batch (seeds x settings, dask)
    implicit/ (packing, metaballs, LCSN layers, Gabor, marching cubes) -> to_body
    ondemand/ (terrain on demand: heights_at any points, tile windows, descents, bodies
               in patches; craters drawn by cells, each height from the craters near it)
    loader (load_surface: a body .npz or a mesh file -> a surface, what sensors/ see)
    sensors/ (ray engine over Embree, cameras, LIDAR, photometry: frames + ground truth of
              any surface; they use only latlong.geometry and latlong.meshio)
    cli/ (the `latlong` command; the library never imports it)

Imports point down that picture and into ``craters`` (never ``dem``). ``latlong build
--help`` describes the command line. More in the subpackages' docstrings:
:mod:`latlong.mesh` (cratering shape models that are not star-shaped),
:mod:`latlong.implicit` (``--backend implicit``), :mod:`latlong.sensors` (``latlong
camera``, ``latlong lidar``), :mod:`latlong.parallel` (``latlong batch``, clusters),
:mod:`latlong.ondemand` (``latlong tile``, ``latlong descent``, ``--on-demand``).

Building bodies: ``latlong build``
----------------------------------
The commands of this docstring run as written, in order, from the repository's folder
(later ones read what earlier ones wrote), into ``out/latlong/``;
``tests/test_readme_commands.py`` runs them at small sizes. Timings are warm runs on
2 cores.

.. code-block:: bash

    mkdir -p out/latlong
    # a crater-saturated asteroid (Martin 2014 Fig. 8): Perlin base, N_cum = 0.5 D^-2
    # craters of 1-15 m, the ground-truth crater catalog and a preview
    latlong build --preset fbm-cratered --magnitude 400 --seed 1 -o out/latlong/a.npz \
        --catalog out/latlong/a.csv --preview out/latlong/a.png

    # the paper's two-phase faulting asteroid (IV.A): 1000 faults <= 5 m, 3 x 20 m
    # smoothing, 20 000 faults <= 0.03 m, 100 m radius stretched x2 along x, plus two
    # crater layers
    latlong build --preset paper --magnitude 400 --seed 7 -o out/latlong/body.ply \
        --craters c=0.1,k=-2,d_min_m=1,d_max_m=10 \
        --craters c=0.02,k=-3,d_min_m=10,d_max_m=20,age_max_gyr=1

    # Gaspra at a model age of 1 Gyr: crater sizes from its production function, ages
    # from its chronology (Schmedemann et al. 2014); the catalog as a craterstats count
    latlong build --magnitude 200 --base fbm --radius-m 6100 --seed 1 \
        --craters npf=gaspra,age_gyr=1.0,d_min_m=100,d_max_m=2000 \
        -o out/latlong/gaspra.npz --catalog out/latlong/gaspra.scc

    latlong presets     # paper, fig4, fig5a-c, fbm-cratered, faulted-cratered,
                        # eros, itokawa, bennu: with parameters and sources

    # real bodies: the bundled shape model with the published crater and boulder counts
    # (Eros near-saturated above 0.2 km and depleted below, Itokawa's boulders b = -3.1,
    # Bennu's craters d/D 0.10 and boulders b = -2.9; ~20-30 s each)
    latlong build --preset eros --seed 1 -o out/latlong/eros.npz -o out/latlong/eros.ply \
        --catalog out/latlong/eros.csv --preview out/latlong/eros.png
    latlong build --preset bennu --seed 1 -o out/latlong/bennu.ply \
        --boulder-catalog out/latlong/bennu_rocks.csv

    # a whole scene from a TOML file (keys = option names; the command line wins)
    latlong build --config examples/scene.toml --seed 1 -o out/latlong/scene.npz \
        --catalog out/latlong/scene.csv
    latlong info out/latlong/a.npz
    latlong render out/latlong/a.npz -o out/latlong/views.png --views 6 \
        --sun-azimuth-deg 70 --sun-elevation-deg 15

Crater layers are power laws, N_cum = c D^k (D in metres, N per m²; ages uniform in
[age_min_gyr, age_max_gyr] Gyr), or surfaces of a model age,
``npf=BODY,age_gyr=T,d_min_m=..,d_max_m=..[,equilibrium=trask|hartmann]`` (a body's
production function and chronology, :mod:`craters.chronology`); counts come from the
body's actual surface area and positions are uniform on it; each crater takes the shape
of its size on the body (a small body's gravity follows from its radius and
``--density-kg-m3``, default 2000; ``--body moon`` etc. for a planet) and is degraded by
topographic diffusion for its age (:mod:`craters`). The same keys make a ``[[craters]]``
table of a scene file. The catalog (``--catalog``, and inside the ``.npz``) lists every
stamped crater with its latitude/longitude, 3-D centre, diameter, age, degradation, rim
radius, depth and rim height as stamped; ``--catalog x.scc`` writes it as a craterstats
spatial crater count instead (the body's area in km², its semi-axes, diameter in km,
lon/lat) and ``--catalog-columns robbins`` a CSV with the Robbins crater database's
column names. Outputs are chosen by suffix: ``.npz`` (lossless, reloadable with
:func:`load`), ``.ply`` (binary, with a per-vertex ``height_m``), ``.obj``, ``.stl``,
``.vtp``, ``.vtk``, ``.glb`` (see renderer export). Same seed and parameters give
byte-identical files whatever the thread count: craters whose regions cannot overlap are
stamped together on all cores, in waves that keep the age order wherever it matters.
Existing files are only replaced with ``--force``; every write is atomic.

Real shape models
-----------------
``--base shape:PATH`` starts from a shape model. The default ``--surface latlong``
ray-casts OBJ, PDS plate (``.tab``/``.plt``), PLY and STL models from their centre onto
the lat/long mesh (``.npz`` bodies and everything that reads them); a model that is not
star-shaped from the centre is refused with the share of directions that cross it more
than once and a pointer to ``--surface mesh`` (:mod:`latlong.mesh`; or keep one crossing
with ``--shape-crossings outermost|innermost``). Fewer than one grid direction in 10⁴ (a
pinhole in a plate model, e.g. one direction of Eros's 7790-plate model at magnitude
300) is accepted with a warning that counts them.

.. code-block:: bash

    # a star-shaped model (Bennu's radar model) ray-cast onto the lat/long grid, with
    # craters younger than 10 Myr
    latlong build --base shape:tests/data/bennu_radar_sbgat.obj --shape-units km \
        --magnitude 300 --craters c=0.05,k=-2,d_min_m=2,d_max_m=20,age_max_gyr=0.01 \
        --seed 1 -o out/latlong/bennu_radar.npz

Boulders
--------
.. code-block:: bash

    # boulders N_cum = c D^k per m^2 (D in metres) on the body, 30 % of them around
    # crater rims; at most half of each boulder's height buried; the catalog as placed
    latlong build --preset fbm-cratered --magnitude 400 --seed 1 \
        --boulders c=0.002,k=-3,d_min_m=1,d_max_m=20,burial_max=0.5,near=0.3 \
        -o out/latlong/rocky.npz -o out/latlong/rocky.ply -o out/latlong/rocky.glb \
        --boulder-catalog out/latlong/rocks.csv --preview out/latlong/rocky.png

Boulders are Martin's procedural rocks: a flattened, elongated icosahedron refined by
edge subdivision with random midpoint displacement (``--boulder-flatten``,
``--boulder-elongation``, ``--boulder-roughness``), kept at four nested levels (12, 42,
162, 642 vertices; each level's vertices are the first ones of the next). Each boulder's
up axis follows the surface normal, it turns by a random azimuth, and it sinks until its
deepest point is its burial below the triangle mesh a renderer draws (never floating).
PLY/OBJ/STL/VTP outputs merge the boulders into the body mesh (PLY and VTP with a
per-vertex ``boulder_id``, -1 on the body: ground truth for hazard detection); ``.glb``
has one node per boulder (translation, rotation, scale) with all four levels. On DEMs,
``dem enhance --boulders ...`` stamps them into the layers (:mod:`dem`).

Slopes, spectra and renderer export
-----------------------------------
.. code-block:: bash

    latlong slopes out/latlong/rocky.npz --compare tests/data/itokawa_32.obj \
        --shape-units km --plot out/latlong/slopes.png --csv out/latlong/slopes.csv
    latlong spectrum out/latlong/rocky.npz --plot out/latlong/spectrum.png
    # slopes against the effective gravity (constant-density polyhedron + rotation) as
    # planetary scientists use them: Eros 2670 kg/m^3, 5.27 h (median ~9 deg at 350 m).
    # The polyhedron's field comes from the polyhedral-gravity package (GPL-3.0, so an
    # optional extra of this BSD project; the test extra includes it)
    pip install ".[gravity]"
    latlong slopes out/latlong/eros.npz --density-kg-m3 2670 --period-h 5.27 \
        --plot out/latlong/eros_slopes.png

    # patched triangle strips for renderers: glTF binary + JSON manifest, 3 nested LODs
    latlong export out/latlong/rocky.npz -o out/latlong/rocky_strips.glb --patch-k 64 --lod 2

Slopes are area-weighted 3-degree bins (Martin's Fig. 9 method: surface normals averaged
over a cap against the local radial direction); DEM slopes use Horn's method with the
true ground size of every row on geographic rasters. The ``.glb`` has one scene per level
of detail, one node per patch of the paper's patch tree (triangle strips, bounding
spheres in the node extras and the manifest) and switches to external ``.bin`` buffers
beyond glTF's 4 GiB limit.

Bodies bigger than memory
-------------------------
A lat/long build holds one float64 radius per vertex plus bounded buffers (the base is
computed in chunks straight into the radii, craters are stamped into them in place),
about 0.45 GB + 11 B per vertex on 2 threads: ``latlong build --preset fbm-cratered
--magnitude 4096 -o x.npz`` (101 M vertices) peaked at 1.5 GB resident, so M = 8192
(403 M vertices) needs about 5 GB and M = 13 000 (1 G vertices) about 12 GB. When that
estimate is over ``--max-memory-gb`` (default 0.8 x the machine's memory), a sphere or
fbm body keeps its radii in a memory-mapped scratch file beside the first output instead
(``--radii-on-disk auto``; ``yes`` forces it): the same kernels in the same order, so the
same bytes, with about 3 B a vertex in memory and the rest in the page cache and the file
(unlinked at once: a killed run leaves nothing). Measured: M = 2048 PLY + glTF
byte-identical either way, 0.83 GB peak on disk against 1.03 GB in memory. Other bases,
or a build that does not fit even so, are refused up front.

Outputs are written streaming (:mod:`latlong.meshio`): the ``.npz``, the PLY records in
1 M-vertex chunks, and the glTF patches ring window by ring window (positions and normals
never held for the whole body; past 4 GiB the data goes to ``<stem>.lod<k>.bin`` beside
the ``.glb``). Measured on a 2-core, 24 GB machine: ``latlong build --preset
fbm-cratered --magnitude 8192 --seed 1 -o x.ply -o x.glb`` (403 M vertices, 806 M
triangles, 67 968 craters) peaked at 6.0 GB resident and took 18 min 52 s, writing the
16.9 GB PLY at 222 MB/s and the 13.9 GB glTF at 163 MB/s (more than the page cache holds:
the disk's own speed, ``dd`` 150-240 MB/s); ``latlong build --preset fbm-cratered
--magnitude 13000 --seed 1 -o x13.ply`` (1.01 G vertices, 68 107 craters, radii in
memory) took 44 min 33 s on the quiet machine, peaked at 11.4 GB and wrote the 42.6 GB
PLY at 645 MB/s. With ``--radii-on-disk yes`` the same build stamped 20 craters/s instead
of 30 (the kernel writes the changed pages back to the scratch file): keep the radii in
memory when they fit. Mind the disk: about 42 B a vertex for PLY, 34 B for glTF.

From Python
-----------
A whole body from a typed scene, in memory (nothing is written until you say so):

.. code-block:: python

    import craters, latlong
    from latlong import BodySettings, BoulderSettings, CraterSettings, Scene

    scene = Scene(
        body=BodySettings(magnitude=100, radius_m=100.0),              # 60 002 vertices
        base=latlong.FAULTING_PRESETS["paper"],  # Martin 2014 IV.A: two-phase faulting
        craters=CraterSettings([craters.CraterLayer(c=0.1, k=-2.0, d_min_m=4.0,
                                                    d_max_m=15.0)]),
        boulders=BoulderSettings(["c=0.01,k=-3,d_min_m=2,d_max_m=5"]),  # ~300 rocks
        seed=7)
    body = latlong.build(scene)          # body.craters, body.boulders: the ground truth
    body.save("out/latlong/paper_body.npz"); body.export("out/latlong/paper_body.ply")

    # the same from flat settings (the option names of `latlong build`, the keys of a
    # TOML scene file), presets included
    body = latlong.build(latlong.Scene.from_settings(
        {"preset": "fbm-cratered", "magnitude": 60, "seed": 1,
         "craters": ["c=0.5,k=-2,d_min_m=4,d_max_m=15"]}))

The steps are functions too: :func:`two_phase_faulting`, :func:`perlin_fbm`,
:func:`body_population`, :func:`stamp_craters`, :func:`boulder_population`,
:func:`place_boulders` (``Body.replace`` recomputes nothing: new radii on a body with
boulders need its boulders placed again).
"""

import logging
from typing import TYPE_CHECKING

from craters._shared.lazy import lazy_package

if TYPE_CHECKING:  # at run time each name is imported on first use (lazy_package)
    from .batch import batch
    from .body import EXPORT_SUFFIXES, Body, load
    from .boulders import (
        BoulderLayer,
        BoulderNode,
        BoulderShape,
        boulder,
        boulder_meshes,
        boulder_population,
        boulder_world_meshes,
        place_boulders,
    )
    from .build import build
    from .cratering import body_population, crater_extents_deg, stamp_craters
    from .faulting import (
        FAULTING_PRESETS,
        FaultingParams,
        apply_faults,
        area_mean,
        poisson_faulting,
        random_faults,
        two_phase_faulting,
    )
    from .gltf import export_glb, export_vtp_strips
    from .gravity import GravityField, gravity
    from .grid import LatLongGrid
    from .implicit import (
        GaborNoise,
        GaborPatch,
        ImplicitSurface,
        LcsnLayer,
        fit_gabor,
        fit_metaballs,
        implicit_surface,
        sphere_packing,
    )
    from .loader import load_surface
    from .meshio.readers import MeshData
    from .ondemand import heights_at
    from .perlin import FBM_PRESETS, FbmParams, fbm3, perlin_fbm
    from .presets import PRESETS
    from .preview import PreviewSettings, render_preview
    from .scene import SETTING_DEFAULTS, SETTINGS, Scene
    from .sensors import render
    from .settings import (
        BodySettings,
        BoulderSettings,
        CraterSettings,
        ImplicitSettings,
        ShapeBase,
        SphereBase,
    )
    from .shapes import ShapeModel, cast_radii, from_shape_model, read_shape_model
    from .slopes import (
        facet_slopes,
        mesh_slopes,
        radius_spectrum,
        slope_summary,
        slopes,
        slopes_and_areas,
        vertex_normals,
    )
    from .smoothing import fwhm_to_sigma, heat_smooth, smooth
    from .surface import surface_positions

__all__ = [
    "EXPORT_SUFFIXES",
    "FAULTING_PRESETS",
    "FBM_PRESETS",
    "GravityField",
    "PRESETS",
    "SETTINGS",
    "SETTING_DEFAULTS",
    "Body",
    "BodySettings",
    "BoulderSettings",
    "CraterSettings",
    "ImplicitSettings",
    "PreviewSettings",
    "Scene",
    "ShapeBase",
    "SphereBase",
    "BoulderLayer",
    "BoulderNode",
    "BoulderShape",
    "FaultingParams",
    "FbmParams",
    "GaborNoise",
    "GaborPatch",
    "ImplicitSurface",
    "LatLongGrid",
    "LcsnLayer",
    "MeshData",
    "ShapeModel",
    "apply_faults",
    "area_mean",
    "batch",
    "body_population",
    "boulder",
    "boulder_meshes",
    "boulder_population",
    "boulder_world_meshes",
    "build",
    "cast_radii",
    "crater_extents_deg",
    "export_glb",
    "export_vtp_strips",
    "facet_slopes",
    "gravity",
    "fbm3",
    "heights_at",
    "fit_gabor",
    "fit_metaballs",
    "from_shape_model",
    "fwhm_to_sigma",
    "heat_smooth",
    "implicit_surface",
    "load",
    "load_surface",
    "mesh_slopes",
    "perlin_fbm",
    "place_boulders",
    "poisson_faulting",
    "radius_spectrum",
    "random_faults",
    "read_shape_model",
    "render",
    "render_preview",
    "slope_summary",
    "slopes",
    "slopes_and_areas",
    "smooth",
    "sphere_packing",
    "stamp_craters",
    "surface_positions",
    "vertex_normals",
    "two_phase_faulting",
]

lazy_package(__name__)

logging.getLogger(__name__).addHandler(logging.NullHandler())
