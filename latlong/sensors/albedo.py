"""Per-vertex albedo from the crater catalog: the bright ejecta of fresh craters.

Fresh ejecta is brighter than the space-weathered terrain around it and darkens as it
matures (lunar optical maturity of crater ejecta falls with age: Grier, McEwen, Lucey,
Milazzo & Strom 2001, "Optical maturity of ejecta from large rayed lunar craters", JGR
106(E12), 32847; on asteroids, fresh crater walls and ejecta on Eros and Itokawa are
the bright, less weathered units). :func:`ejecta_albedo` gives each vertex the factor

    1 + contrast * w * g(rho),   w = 1 - degradation / fresh_degradation (>= 0),
    g = 1 inside the rim (rho = distance / R <= 1), rho^-3 outside, 0 beyond reach_radii,

(the ejecta thickness law rho^-3 of McGetchin et al. 1973 as the share of fresh material),
the largest over the craters that reach the vertex; craters at or above
``fresh_degradation`` leave the terrain as it is. Pass it to
:func:`latlong.render` as ``vertex_albedo``.

:func:`regolith_albedo` is the regolith's own mottling below the craters: a factor
``exp(contrast * f / MOTTLE_RMS)`` from a non-repeating 3-D fBm ``f`` of the body-fixed
position (value noise hashed from the lattice, octaves from ``wavelength_max_m`` halving
down to two pixels, amplitudes 0.7^k: a frame shows the same coarse mottling as a coarser
frame, plus finer detail), so ``contrast`` is the RMS of the log albedo at full detail.
Its default, 0.05 (about +-5 %), is set against LROC NAC pictures at 0.5 m a pixel (with
the relief below the pixels, :func:`regolith_normals`; :mod:`latlong.ondemand.descent`'s
notes): 0.1 put 0.18 / 0.22 of a frame's image power in its second and third finest
octaves, the NAC crops hold 0.08-0.16 / 0.14-0.17; 0.05 gives 0.13 / 0.15. No published
small-scale albedo spectrum of the regolith is used.
Multiply the two factors for a frame's albedo.

:func:`regolith_normals` is the relief below a frame's smallest stamped craters (3
pixels), as shading: vertex normals tilted by the gradient of a 3-D fBm height field of the
body-fixed position on the fixed ladder of wavelengths 2^-k m, the octaves within a factor
2 of 2.83 pixels weighted so that a frame shows the same texture at the same places as
the frames before and after it (a descent's features stay put; with octaves tied to each
frame's pixels, PnP between frames missed by up to 4.9 %), tilt ~ pixel^(H - 1). Beside
LROC NAC frames at 0.5 m a pixel the soil between stamped craters was smooth where the
real regolith is granular; the geometry (depth, LIDAR ranges, labels) keeps the stamped
terrain.
"""

from __future__ import annotations

import numpy as np

from craters._shared import ParameterError, check_int, check_positive, check_range

from ..geometry.meshes import bounds
from .scene_geometry import SceneGeometry

__all__ = ["MOTTLE_GAIN", "MOTTLE_RMS", "RELIEF_CENTRE_PX", "VALUE_GRAD_RMS", "ejecta_albedo",
           "regolith_albedo", "regolith_normals", "relief_octaves"]

#: Octave gain of the regolith mottling (amplitude ratio of successive octaves).
MOTTLE_GAIN = 0.7
#: RMS of the mottling fBm with all octaves (0.1681-0.1684 over three sets of 10^6
#: random points, 24 octaves; tests/latlong/test_albedo.py checks it), so that
#: ``contrast`` is the RMS of the log albedo.
MOTTLE_RMS = 0.168
_MOTTLE_SALT = 0x5DEECE66D2545F49
#: Centre of the wavelengths of :func:`regolith_normals`, pixels (craters from 3 pixels
#: are stamped; its octaves lie within a factor 2 of 2^1.5 = 2.83 pixels).
RELIEF_CENTRE_PX = 2.0 ** 1.5
#: RMS of the gradient across a random plane of one octave of the value noise at a unit
#: wavelength (1.0807-1.0825 over three sets of 10^6 random points and planes;
#: tests/latlong/test_albedo.py checks it).
VALUE_GRAD_RMS = 1.081
_RELIEF_SALT = 0x2545F4914F6CDD1D


def _positions(points_m) -> np.ndarray:
    """``points_m`` as finite (n, 3) float64 positions (a one-line error otherwise)."""
    pts = np.ascontiguousarray(points_m, dtype=np.float64)
    if pts.ndim != 2 or pts.shape[1] != 3 or not np.isfinite(pts).all():
        raise ParameterError("points_m", f"must be finite (n, 3) positions; got shape "
                                         f"{pts.shape}")
    return pts


def ejecta_albedo(geometry: SceneGeometry, *, contrast: float = 0.5,
                  fresh_degradation: float = 0.3, reach_radii: float = 3.0) -> np.ndarray:
    """(n,) float64 albedo factor per vertex of ``geometry`` (module notes).

    Parameters
    ----------
    geometry : SceneGeometry
        The model and its crater catalog (``centre_x_m, centre_y_m, centre_z_m``,
        ``rim_radius_m`` or ``diameter_m``, optional ``degradation``: 0 fresh .. 1 gone).
    contrast : float
        Brightening of the freshest ejecta at the rim, a fraction, [0, 10].
    fresh_degradation : float
        Degradation at which ejecta has matured to the terrain's albedo, (0, 1].
    reach_radii : float
        How far the bright ejecta reaches, in rim radii, [1, 20].

    Examples
    --------
    >>> import numpy as np, craters
    >>> cat = craters.make_catalog(x_m=[0.0], y_m=[0.0], diameter_m=[20.0],
    ...                            centre_x_m=[100.0], centre_y_m=[0.0], centre_z_m=[0.0])
    >>> geo = SceneGeometry(np.array([[100.0, 0, 0], [100.0, 20, 0], [100.0, 40, 0]]),
    ...                     np.array([[0, 1, 2]]), np.array([-1], np.int32), cat)
    >>> ejecta_albedo(geo, contrast=0.5).round(4).tolist()
    [1.5, 1.0625, 1.0]
    """
    import numba

    from ._albedo_kernels import _cube_keys_kernel, _ejecta_kernel  # numba loads here

    if not isinstance(geometry, SceneGeometry):
        raise TypeError(f"`geometry` must be a SceneGeometry; got {type(geometry).__name__}")
    contrast = check_range("contrast", contrast, 0.0, 10.0)
    fresh = check_range("fresh_degradation", fresh_degradation, 0.0, 1.0)
    if fresh == 0.0:
        raise ParameterError("fresh_degradation", "must be in (0, 1]; got 0")
    reach = check_range("reach_radii", check_positive("reach_radii", reach_radii), 1.0, 20.0)
    verts = geometry.vertices
    out = np.ones(len(verts))
    cat = geometry.craters
    if cat is None or not len(cat) or contrast == 0.0:
        return out
    names = cat.dtype.names
    centres = np.stack([cat["centre_x_m"], cat["centre_y_m"], cat["centre_z_m"]], 1) \
        .astype(np.float64)
    assert names is not None  # fields were read: a structured array
    radii = np.asarray(cat["rim_radius_m"] if "rim_radius_m" in names
                       else 0.5 * cat["diameter_m"], dtype=np.float64)
    deg = np.asarray(cat["degradation"], dtype=np.float64) if "degradation" in names \
        else np.zeros(len(cat))
    weight = 1.0 - deg / fresh
    rows = np.flatnonzero((weight > 0) & (radii > 0) & np.isfinite(centres).all(axis=1))
    if not len(rows):
        return out
    # a uniform grid of cubes as wide as the median crater's reach finds each crater's
    # vertices (a k-d tree of the vertices took ~4 s a 1024^2 descent frame); at most 2^20
    # cubes along an axis, so that a cube's key fits an int64 (the cube size changes the
    # time, not the result)
    verts = np.ascontiguousarray(verts, dtype=np.float64)
    lo, hi = bounds(verts)
    cell = max(float(np.median(reach * radii[rows])), float((hi - lo).max())
               / 2.0**20, 1e-9)
    # the largest vertex's cube is the last along each axis (floor and the arithmetic
    # before it are monotonic)
    dims = np.floor((hi - lo) / cell).astype(np.int64) + 1
    keys = np.empty(len(verts), dtype=np.int64)
    _cube_keys_kernel(verts, lo, cell, dims, keys)
    order = np.argsort(keys, kind="stable")
    _ejecta_kernel(verts, order,
                   np.ascontiguousarray(keys[order]), lo, cell, dims,
                   np.ascontiguousarray(centres[rows]), np.ascontiguousarray(radii[rows]),
                   contrast * weight[rows], float(reach),
                   min(numba.get_num_threads(), len(rows)), out)
    return out


def regolith_albedo(points_m, *, seed: int, contrast: float = 0.05, pixel_m: float,
                    wavelength_max_m: float = 2.0) -> np.ndarray:
    """(n,) float64 albedo factor of the regolith's mottling at ``points_m`` (n, 3),
    body-fixed metres (module notes), for a picture whose pixels are ``pixel_m`` on the
    ground.

    Parameters
    ----------
    points_m : (n, 3) array_like
        Positions, metres (finite).
    seed : int
        The texture's seed, [0, 2^63).
    contrast : float
        RMS of the log albedo with all octaves, [0, 2] (0: a factor of 1 everywhere).
    pixel_m : float
        Ground pixel of the picture (> 0): octaves end at two pixels.
    wavelength_max_m : float
        Wavelength of the coarsest octave, metres (> 0). The default, 2 m, keeps the
        mottling to close range: at 20 m a frame from 1 km looked cloudy, topography (the
        small craters) is what orbital pictures show.

    Examples
    --------
    >>> f = regolith_albedo([[0.0, 0.0, 1737e3], [0.5, 0.0, 1737e3]], seed=1, pixel_m=0.01)
    >>> f.shape, bool(((f > 0.5) & (f < 2.0)).all())
    ((2,), True)
    """
    from ._albedo_kernels import _mottle_kernel  # numba loads here
    pts = _positions(points_m)
    seed = check_int("seed", seed, 0, 2**63 - 1)
    contrast = check_range("contrast", contrast, 0.0, 2.0)
    pixel = check_positive("pixel_m", pixel_m)
    top = check_positive("wavelength_max_m", wavelength_max_m)
    out = np.ones(len(pts))
    octaves = 0
    while octaves < 48 and top / 2.0**octaves >= 2.0 * pixel:
        octaves += 1
    if contrast == 0.0 or octaves == 0 or not len(pts):
        return out
    _mottle_kernel(pts, np.uint64(seed ^ _MOTTLE_SALT), top, octaves, MOTTLE_GAIN, out)
    return np.exp((contrast / MOTTLE_RMS) * out)


def relief_octaves(pixel_m: float, tilt_1m_deg: float, hurst: float):
    """The octaves of :func:`regolith_normals` for a picture of ``pixel_m`` pixels:
    (wavelengths in metres, RMS tilt tangents, octave numbers k). The wavelengths are
    the fixed ladder 2^-k m, so consecutive frames of a descent share their octaves (the
    same texture at the same places); those within a factor 2 of RELIEF_CENTRE_PX pixels
    are weighted cos(pi/2 log2(lambda / centre)) (their squares sum to 1 wherever the
    centre falls), each with the tilt tan(tilt_1m_deg) (lambda / RELIEF_CENTRE_PX m)^(H-1)."""
    centre = RELIEF_CENTRE_PX * pixel_m
    k_lo = int(np.floor(-np.log2(2.0 * centre)))
    ks, lams, tilts = [], [], []
    for k in range(k_lo, k_lo + 3):
        lam = 2.0 ** -k
        x = np.log2(lam / centre)
        if abs(x) >= 1.0:
            continue
        ks.append(k)
        lams.append(lam)
        tilts.append(np.cos(0.5 * np.pi * x) * np.tan(np.radians(tilt_1m_deg))
                     * (lam / RELIEF_CENTRE_PX) ** (hurst - 1.0))
    return np.array(lams), np.array(tilts), np.array(ks, dtype=np.int64)


def regolith_normals(points_m, normals, *, seed: int, pixel_m: float, tilt_1m_deg: float,
                     hurst: float = 1.0) -> np.ndarray:
    """(n, 3) unit vertex normals ``normals`` at ``points_m`` tilted by the relief below a
    picture's resolved craters (module notes): about ``tan(tilt_1m_deg) p^(H - 1)`` RMS
    tangent of the tilt at pixels p metres wide (:func:`relief_octaves`).

    Parameters
    ----------
    points_m, normals : (n, 3) array_like
        Vertex positions (body-fixed metres) and their unit normals.
    seed : int
        The relief's seed, [0, 2^63).
    pixel_m : float
        Ground pixel of the picture (> 0).
    tilt_1m_deg : float
        RMS tilt at 1 m pixels, [0, 45] degrees; 0 returns the normals as given.
    hurst : float
        Hurst exponent of the relief, [0, 1] (1: the same tilt at every pixel size).

    Examples
    --------
    >>> n = regolith_normals([[0.0, 0.0, 1737e3]] * 2, [[0.0, 0.0, 1.0]] * 2, seed=1,
    ...                      pixel_m=0.5, tilt_1m_deg=2.5)
    >>> n.shape, bool(np.allclose(np.linalg.norm(n, axis=1), 1.0))
    ((2, 3), True)
    """
    from ._albedo_kernels import _OCTAVE, _bump_kernel  # numba loads here
    pts = _positions(points_m)
    nrm = np.ascontiguousarray(normals, dtype=np.float64)
    if nrm.shape != pts.shape or not np.isfinite(nrm).all():
        raise ParameterError("normals", f"must be finite unit normals shaped like points_m "
                                        f"{pts.shape}; got {nrm.shape}")
    seed = check_int("seed", seed, 0, 2**63 - 1)
    pixel = check_positive("pixel_m", pixel_m)
    tilt = check_range("tilt_1m_deg", tilt_1m_deg, 0.0, 45.0)
    hurst = check_range("hurst", hurst, 0.0, 1.0)
    if tilt == 0.0 or not len(pts):
        return nrm.copy()
    lams, tilts, ks = relief_octaves(pixel, tilt, hurst)
    # an octave's RMS tangential gradient is amp VALUE_GRAD_RMS / lambda
    amps = tilts * lams / VALUE_GRAD_RMS
    seeds = np.array([((seed ^ _RELIEF_SALT) + (int(k) + 1024) * int(_OCTAVE)) % 2**64
                      for k in ks], dtype=np.uint64)
    out = np.empty_like(nrm)
    _bump_kernel(pts, nrm, seeds, np.ascontiguousarray(lams), np.ascontiguousarray(amps), out)
    return out
