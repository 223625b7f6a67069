r"""The implicit backend (Li et al. 2020, 2022): metaballs over a sphere packing, LCSN
craters on a multi-level 3-D grid, Gabor micro-detail, marching cubes.

Pipeline (:func:`implicit_surface`):

1. **Sphere packing** (:func:`sphere_packing`) of a closed constraint mesh: the mesh is
   voxelised by ray parity along x (a numba scan of every grid column), the inside is
   distance-transformed (``scipy.ndimage.distance_transform_edt``; the boundary lies half
   a voxel beyond the last inside voxel), and balls are placed greedily, the largest
   free ball first (inside the shape, not overlapping the balls already placed: a
   non-uniform packing in the spirit of Weller & Zachmann's (2010) ProtoSphere), down to
   a minimum radius. Coverage = packed volume / mesh volume.
2. **Metaballs** (:func:`fit_metaballs`): the soft-object kernel of Wyvill, McPheeters &
   Wyvill 1986, ``(1 - d^2/R^2)^3`` (compact support R = blend x ball radius, so every
   ball's own iso-surface sits at the same fraction of its radius) summed over the balls;
   the blend factor and the iso-value T are *fitted to the constraint*: on 20 000 points
   uniform on the constraint surface, T is the median of f weighted by 1/|grad f|,
   which minimises the mean first-order distance |f - T| / |grad f| of those points to
   the iso-surface, and the blend factor with the smallest such mean is kept.
3. **Field**: on a grid of spacing ``voxel_m`` the signed distance (> 0 inside) to the
   coarse surface: ``constraint_weight`` x that of the constraint itself + (1 - weight)
   x that of the metaball surface (:func:`~latlong.implicit.metaballs.metaball_distance`,
   from the first-order ``(f - T) / |grad f|`` next to the surface). The constraint's
   distance (:func:`~latlong.implicit.distance.mesh_distance`) is taken to the
   constraint after a butterfly subdivision to the voxel (a smooth surface through its
   vertices). With the default weight 1 the body follows the constraint: the metaballs
   alone leave one dome per packed ball (Eros, Itokawa, Bennu: slope against a 5 %-of-axis
   smoothed copy, KS distance 0.51-0.58 from the constraint's, median 13-14 degrees for
   3.5-4.7; with the constraint's field 0.02-0.04 and a mean distance of 0.02-0.08 % of
   the long axis, :func:`~latlong.implicit.fidelity.shape_fidelity`). Weight 0 gives
   Li et al.'s (2020) bare metaball surface.
4. **Craters** (:class:`LcsnLayer`): the multi-level grid has cells of ``cell_m / 2^l``
   at level l (each cell holds 2^3 cells of the next level); a layer uses the finest
   level whose cells hold its largest crater. Every cell of that level that the coarse
   surface passes through (a triangle of the base mesh has its centroid in it) receives
   one impulse with the layer's probability, at a uniform random point of the surface
   inside the cell (a Poisson point conditioned on the cell); its diameter is drawn by
   inversion sampling in [d_min, d_max] (Li 2022 eq. 17-21,
   :func:`craters.sample_power_law_diameters`). The layer's kernel
   (:mod:`craters.lcsn`) is scaled self-similarly to that diameter (rim-crest diameter,
   or apparent diameter for kernels without a rim), its heights times the layer weight
   omega (eq. 2) and optionally set to a random depth/diameter ratio, and added to d in
   the impulse's tangent frame: r = distance from the surface normal through the
   impulse, z = height along it; the kernel fades to 0 over the last 20 % of its
   support radius (where it is < 1e-3 of its extreme) and beyond ``|z|`` = its
   largest height + a quarter of its support (C1 smoothstep over as much again: room
   for the surface to curve away from the tangent plane), so it does not reach the
   far side of the body unless that is closer.
5. **Gabor noise** (:mod:`~latlong.implicit.gabor`) is added near the surface.
6. **Marching cubes** (VTK flying edges) on the zero level gives a closed, outward
   oriented triangle mesh; only its largest connected piece is kept (how much area was
   dropped is recorded). The crater catalog lists every impulse (position on the
   coarse surface, normal, diameter and as-added depth / rim height).

For star-shaped results :meth:`ImplicitSurface.to_body` casts the mesh onto a
:class:`~latlong.LatLongGrid` (:func:`latlong.shapes.from_shape_model`), so slopes,
strips, boulders and exports of the lat/long toolkit apply.

Modules (none imports the lat/long grid; ``surface`` meets it in ``to_body`` only)::

    build      implicit_surface                                   (the build: steps 1-6)
    surface    ImplicitSurface: the mesh and catalog it returns
    packing    sphere_packing, SpherePacking                      (step 1)
    metaballs  fit_metaballs, Metaballs, metaball_distance        (steps 2-3)
    distance   mesh_distance, smoothed_constraint                 (step 3)
    fidelity   shape_fidelity, ShapeFidelity: the coarse surface against the constraint
    layers     LcsnLayer, parse_lcsn_spec, the crater impulses    (step 4)
    gabor      GaborNoise, GaborPatch, fit_gabor, gabor_image ... (step 5)
    grid       VoxelGrid: index boxes, bins, sampling, marching cubes
    _kernels   the numba kernels (craters.kernels.lcsn_height for the LCSN formulas)

From the command line: ``latlong build --backend implicit``
-----------------------------------------------------------
The commands run as written from the repository's folder, into ``out/implicit/``
(``tests/test_readme_commands.py`` runs them at small sizes):

.. code-block:: bash

    mkdir -p out/implicit
    # Eros-like: metaballs fitted to the 7790-plate NEAR model, three LCSN crater layers on
    # the multi-level 3-D grid, about 200 000 triangles (~8 s warm on 2 cores with the
    # preview)
    latlong build --backend implicit --shape tests/data/eros007790.tab --shape-units km \
        --lcsn kernel=table-a1-3km-0gyr,d_min_m=2000,d_max_m=4000 \
        --lcsn kernel=table-a1-1km-0gyr,d_min_m=1000,d_max_m=2000 \
        --lcsn kernel=fig6-kernel1,d_min_m=500,d_max_m=1000,depth_ratio=0.1:0.2 \
        --gabor frequency=0.0025,bandwidth=0.00125,amplitude_m=10 --seed 1 \
        -o out/implicit/eros.ply --catalog out/implicit/eros.csv --preview out/implicit/eros.png

    # a star-shaped result can also be cast onto the lat/long mesh (.npz, then slopes,
    # strips ...)
    latlong build --backend implicit --shape tests/data/bennu_radar_sbgat.obj --shape-units km \
        --lcsn kernel=table-a1-300m-0gyr,d_min_m=30,d_max_m=60,probability=0.3 \
        --magnitude 300 --shape-crossings outermost --seed 2 \
        -o out/implicit/bennu.npz -o out/implicit/bennu.obj

Alone, the metaball surface shows one dome per ball (Itokawa, Bennu and Eros: mean
distance 0.5 % of the long axis, and a distribution of slopes against a 5 %-of-axis
smoothed copy 0.51-0.58 KS distance from the constraint's). So the coarse shape the body
is built on blends in the constraint's own signed distance with ``--constraint-weight``
(default 1: mean distance 0.02-0.08 %, 99th percentile <= 0.35 %, slope KS <= 0.04; 0
gives the bare metaballs; :func:`~latlong.implicit.fidelity.shape_fidelity` measures
both). Craters are Li et al.'s LCSN kernels (:func:`craters.lcsn_kernel`, kinds 1-4;
presets ``table-a1-<D>-<age>gyr`` and ``fig6-kernel1..4`` in ``craters.LCSN_PRESETS``),
one impulse per surface cell of a grid level with probability ``p``, diameters by
inversion sampling of N(>D) ~ D^-exponent in [d_min_m, d_max_m], the kernel scaled to
each diameter and added along the local normal; each layer sits on the finest level
whose cells hold its largest crater (``--cell-m`` = level-0 cell, default the largest
d_max_m; each level has 2^3 finer cells). ``--gabor`` adds 3-D Gabor noise (frequency in
cycles/m, bandwidth in 1/m, rms in m, orientation from local east, default random),
``--gabor-example Z.npy --gabor-pixel-m 50`` fits it to the power spectrum of an example
(NNLS over Gaussian patches). The surface is extracted by marching cubes (VTK flying
edges) at ``--voxel-m`` or about ``--polygons`` triangles; outputs by suffix are meshes
(``.ply .obj .stl .vtp .vtk``), ``.npz`` (the mesh cast onto a lat/long grid of
``--magnitude``; refused with the share of folded directions unless the surface is
star-shaped or ``--shape-crossings outermost|innermost``), and the crater catalog
(``--catalog``: centre, normal, rim-crest diameter, as-added depth, rim height, central
uplift, level). Same seed, same bytes, whatever the thread count.

From Python:

.. code-block:: python

    from latlong.implicit import LcsnLayer, implicit_surface

    surf = implicit_surface("tests/data/eros007790.tab",
                            [LcsnLayer("fig6-kernel3", 500, 1000)],
                            units="km", target_polygons=20_000, rng=1)
    surf.save("out/implicit/eros_implicit.ply")
    print(len(surf.catalog), "craters")
    body = surf.to_body(60, crossings="outermost")   # on the lat/long mesh
"""

from .build import implicit_surface
from .distance import mesh_distance, smoothed_constraint
from .fidelity import ShapeFidelity, shape_fidelity
from .gabor import (
    GaborNoise,
    GaborPatch,
    fit_gabor,
    gabor_image,
    parse_gabor_spec,
    power_spectrum,
    read_example,
)
from .grid import VoxelGrid
from .layers import LcsnLayer, parse_lcsn_spec
from .metaballs import Metaballs, fit_metaballs
from .packing import SpherePacking, sphere_packing
from .surface import MESH_SUFFIXES, ImplicitSurface

__all__ = ["MESH_SUFFIXES", "GaborNoise", "GaborPatch", "ImplicitSurface", "LcsnLayer",
           "Metaballs", "ShapeFidelity", "SpherePacking", "VoxelGrid", "fit_gabor", "fit_metaballs",
           "gabor_image", "implicit_surface", "mesh_distance", "parse_gabor_spec",
           "parse_lcsn_spec", "power_spectrum", "read_example", "shape_fidelity",
           "smoothed_constraint", "sphere_packing"]
