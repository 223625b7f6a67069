"""Craters on the body: local DEM mapping, ground truth, stretched bodies, populations."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import stats

import craters
from latlong import (
    Body,
    LatLongGrid,
    Scene,
    body_population,
    build,
    load,
    perlin_fbm,
    stamp_craters,
    surface_positions,
)
from latlong._crater_kernels import (
    _cholesky_solve6,
    _fill_holes,
    _fit_plane_points,
    _fit_quadric_points,
    _gather_kernel,
    _local_coordinates,
)

PROFILE_TOL = 0.02  # of the depth
AZIMUTH_STD_TOL = 0.005  # of the depth
RIM_TOL = 0.05


def unit(lat_deg, lon_deg):
    la, lo = np.radians(lat_deg), np.radians(lon_deg)
    return np.array([np.cos(la) * np.cos(lo), np.cos(la) * np.sin(lo), np.sin(la)])


@pytest.fixture(scope="module")
def sphere():
    return Body.sphere(LatLongGrid(160), 1000.0)


@pytest.mark.parametrize("lat,lon", [(0.0, 0.0), (45.0, 100.0), (80.0, 200.0),
                                     (10.0, 359.9), (-3.0, 0.05), (-89.0, 10.0)])
def test_single_crater_on_sphere_follows_profile(sphere, lat, lon):
    g = sphere.grid
    d = 20 * g.spacing(1000.0)
    cat = craters.make_catalog(lat_deg=[lat], lon_deg=[lon], diameter_m=[d])
    out = stamp_craters(sphere, cat, roughness=False)
    c = unit(lat, lon)
    u = g.unit_vectors()
    dist = 1000.0 * np.arctan2(np.linalg.norm(np.cross(u, c), axis=1), u @ c)
    h = out.radii_m - 1000.0
    want = craters.radial_profile(dist / (d / 2), d)
    depth = float(craters.fresh_morphometry(d)["depth_m"])
    assert np.abs(h - want).max() <= PROFILE_TOL * depth
    # azimuthal spread of the residual at fixed distance: no radial artifacts
    resid = h - want
    bins = np.digitize(dist, np.linspace(0, 1.6 * d, 33))
    for b in np.unique(bins[dist < 1.6 * d]):
        sel = bins == b
        if sel.sum() > 3:
            assert resid[sel].std() <= AZIMUTH_STD_TOL * depth
    # outside the ejecta nothing moved
    assert (h[dist > 1.5 * d * 1.001] == 0).all()


def test_rim_radius_matches_catalog_on_rough_body():
    """Rim radius measured on the mesh: the radial scale of the best-fitting crater
    profile (all vertices within 1.3 R, old terrain's plane removed). The highest vertex
    per azimuth is not used: a sharp rim's highest vertex is usually the first one
    outside the crest, a bias of up to a vertex spacing (10 % at 10 spacings across)."""
    g = LatLongGrid(200)
    radius = 1000.0
    base = Body.from_heights(g, radius, perlin_fbm(g, 1.5, 6, 0.5, 2.0, 20.0, rng=3))
    sp = g.spacing(radius)
    rng = np.random.default_rng(7)
    lats = np.array([-50.0, -20.0, 10.0, 40.0, 70.0, 0.0])
    lons = np.array([30.0, 150.0, 270.0, 60.0, 200.0, 330.0])
    diam = rng.uniform(10, 30, len(lats)) * sp
    cat = craters.make_catalog(lat_deg=lats, lon_deg=lons, diameter_m=diam)
    out = stamp_craters(base, cat, rng=1)
    p_new, p_old = out.vertices(), base.vertices()
    dirs = p_old / np.linalg.norm(p_old, axis=1, keepdims=True)
    for row in out.craters:
        centre = np.array([row["centre_x_m"], row["centre_y_m"], row["centre_z_m"]])
        rloc = np.linalg.norm(centre)
        a = centre / rloc
        dist = rloc * np.arctan2(np.linalg.norm(np.cross(dirs, a), axis=1), dirs @ a)
        r = row["rim_radius_m"]
        near = dist < 1.3 * r
        east = np.cross([0, 0, 1.0], a)
        east /= np.linalg.norm(east)
        north = np.cross(a, east)
        az = np.arctan2(dirs[near] @ north, dirs[near] @ east)
        x, y = dist[near] * np.cos(az), dist[near] * np.sin(az)
        design = np.stack([np.ones_like(x), x, y], 1)
        h_old = np.linalg.norm(p_old[near], axis=1) - rloc
        h_new = np.linalg.norm(p_new[near], axis=1) - rloc
        rel = h_new - design @ np.linalg.lstsq(design, h_old, rcond=None)[0]
        scales = np.linspace(0.85, 1.15, 121)
        errors = []
        for s in scales:
            model = craters.radial_profile(dist[near] / (s * r), row["diameter_m"])
            errors.append(np.var(rel - model))
        assert abs(scales[int(np.argmin(errors))] - 1.0) <= RIM_TOL


def test_stretched_body_no_spikes_or_holes():
    g = LatLongGrid(150)
    from latlong import FAULTING_PRESETS, two_phase_faulting

    p = FAULTING_PRESETS["paper"]
    h = two_phase_faulting(g, 100.0, p, rng=2)
    body = Body.from_heights(g, 100.0, h, stretch=p.stretch)
    rng = np.random.default_rng(5)
    lat, lon, _ = surface_positions(body, 60, rng=rng)
    diam = np.exp(rng.uniform(np.log(3.0), np.log(20.0), 60))
    verts, normals = body.vertices(), body.vertex_normals()
    for k in range(60):  # each crater alone: its own change, not its neighbours'
        cat = craters.make_catalog(lat_deg=lat[k:k + 1], lon_deg=lon[k:k + 1],
                                   diameter_m=diam[k:k + 1])
        for erosion in (False, True):
            stamped = stamp_craters(body, cat, rng=k, slope_erosion=erosion).craters
            for row in stamped:  # with erosion, craters on >= 45 deg ground are erased
                # an eroded crater still flattens the terrain inside its rim to the
                # fitted plane: bound the change by the fresh crater's relief, along the
                # surface normal; a vertex moves radially, so by up to 1 / cos(tilt)
                # of that on ground tilted from the radial (the base's frame, issue 36)
                fresh = craters.fresh_morphometry(row["diameter_m"], "moon")
                relief = float(fresh["depth_m"] + fresh["rim_height_m"])
                centre = np.array([row["centre_x_m"], row["centre_y_m"], row["centre_z_m"]])
                near = np.argmin(np.linalg.norm(verts - centre, axis=1))
                cos_tilt = abs(normals[near] @ verts[near]) / np.linalg.norm(verts[near])
                assert row["max_change_m"] <= 1.5 * relief / max(cos_tilt, 0.2)


def test_age_order_and_catalog_columns(sphere):
    cat = craters.make_catalog(lat_deg=[0.0, 20.0, 40.0], lon_deg=[0.0, 0.0, 0.0],
                               diameter_m=[100.0, 80.0, 60.0], age_gyr=[1.0, 3.0, 2.0],
                               degradation=[0.0, 0.5, 0.2])
    out = stamp_craters(sphere, cat, rng=0)
    assert out.craters["age_gyr"].tolist() == [3.0, 2.0, 1.0]
    for name in ("rim_radius_m", "depth_m", "rim_height_m", "slope_deg", "centre_x_m",
                 "seed", "max_change_m", "n_vertices"):
        assert name in out.craters.dtype.names
    assert np.allclose(np.linalg.norm(np.stack([out.craters["centre_x_m"],
                                                out.craters["centre_y_m"],
                                                out.craters["centre_z_m"]], 1), axis=1), 1000.0)
    # same seed, same body; the input body is untouched
    again = stamp_craters(sphere, cat, rng=0)
    assert np.array_equal(again.radii_m, out.radii_m)
    assert (sphere.radii_m == 1000.0).all()


def test_catalog_saved_with_the_body(sphere, tmp_path):
    cat = craters.make_catalog(lat_deg=[10.0], lon_deg=[20.0], diameter_m=[150.0])
    out = stamp_craters(sphere, cat, rng=0)
    out.save(tmp_path / "b.npz")
    back = load(tmp_path / "b.npz")
    assert np.array_equal(back.craters, out.craters)


def test_too_large_craters(sphere):
    big = craters.make_catalog(lat_deg=[0.0, 5.0], lon_deg=[0.0, 5.0],
                               diameter_m=[900.0, 50.0])
    with pytest.raises(ValueError, match="too large"):
        stamp_craters(sphere, big)
    out = stamp_craters(sphere, big, too_large="skip")
    assert len(out.craters) == 1 and out.craters["diameter_m"][0] == 50.0
    flat = craters.make_catalog(x_m=[0.0], y_m=[0.0], diameter_m=[5.0])
    with pytest.raises(ValueError, match="lat_deg"):
        stamp_craters(sphere, flat)
    with pytest.raises(TypeError, match="Body"):
        stamp_craters("body", big)


def reference_gather(g, colat, lon, ang):
    u = g.unit_vectors()
    c = np.array([np.sin(colat) * np.cos(lon), np.sin(colat) * np.sin(lon), np.cos(colat)])
    return set(np.flatnonzero(u @ c >= np.cos(min(ang, np.pi))).tolist())


@pytest.mark.parametrize("colat,lon,ang", [(0.0, 0.0, 0.1), (np.pi, 1.0, 0.3),
                                           (1.0, 6.27, 0.2), (0.05, 3.0, 0.2),
                                           (1.5, 0.0, 1.0), (2.0, 2.0, 3.2)])
def test_gather_is_a_superset_of_the_cap(colat, lon, ang):
    g = LatLongGrid(40)
    n = _gather_kernel(40, g.ring_offsets(), colat, lon, ang, np.empty(0, np.int64), True)
    out = np.empty(n, np.int64)
    _gather_kernel(40, g.ring_offsets(), colat, lon, ang, out, False)
    assert len(set(out.tolist())) == n  # no duplicates
    assert reference_gather(g, colat, lon, ang) <= set(out.tolist())
    # and it is local: not much more than the cap plus a ring of margin
    assert n <= min(g.n_vertices, len(reference_gather(g, colat, lon, ang + 4 * np.pi / 80)) + 2)


def test_fill_holes_matches_reference(rng):
    grid = rng.standard_normal((9, 9))
    known = rng.random((9, 9)) > 0.4
    got = _fill_holes(np.where(known, grid, 0.0), known)
    assert np.array_equal(got[known], grid[known])
    for i, j in zip(*np.nonzero(~known), strict=True):
        acc = wsum = 0.0
        for di in (-1, 0, 1):
            for dj in (-1, 0, 1):
                if di == dj == 0:
                    continue
                s = 1
                while 0 <= i + s * di < 9 and 0 <= j + s * dj < 9:
                    if known[i + s * di, j + s * dj]:
                        w = 1 / (s * np.hypot(di, dj))
                        acc += w * grid[i + s * di, j + s * dj]
                        wsum += w
                        break
                    s += 1
        assert got[i, j] == pytest.approx(acc / wsum)


def test_fit_plane_points_matches_lstsq(rng):
    x, y = rng.uniform(-5, 5, 200), rng.uniform(-5, 5, 200)
    h = 1.5 + 0.3 * x - 0.7 * y + 0.01 * rng.standard_normal(200)
    dist = np.hypot(x, y)
    p0, gx, gy = _fit_plane_points(x, y, h, dist, 200, 4.0)
    sel = dist <= 4.0
    want = np.linalg.lstsq(np.stack([np.ones(sel.sum()), x[sel], y[sel]], 1), h[sel],
                           rcond=None)[0]
    assert np.allclose([p0, gx, gy], want)


def test_surface_positions_uniform():
    body = Body.sphere(LatLongGrid(40), 10.0)
    lat, lon, area = surface_positions(body, 20000, rng=1)
    assert stats.kstest(np.sin(np.radians(lat)), "uniform", args=(-1, 2)).pvalue > 0.01
    assert stats.kstest(lon, "uniform", args=(0, 360)).pvalue > 0.01
    assert area == pytest.approx(4 * np.pi * 100, rel=0.01)
    # on a stretched body, points follow the actual area
    long_body = Body.sphere(LatLongGrid(40), 10.0, stretch=(3.0, 1.0, 1.0))
    lat, lon, _ = surface_positions(long_body, 20000, rng=2)
    x = np.cos(np.radians(lat)) * np.cos(np.radians(lon))
    tip = np.abs(x) > 0.9
    # the caps |x| > 0.9 of a 3:1:1 spheroid hold ~5.3 % of its area (vs 10 % of a sphere)
    assert 0.04 < tip.mean() < 0.07


def test_body_population_counts_the_actual_area():
    body = Body.sphere(LatLongGrid(40), 100.0, stretch=(2.0, 1.0, 1.0))
    cat = body_population(body, [craters.CraterLayer(0.5, -2.0, 5.0, 20.0)], rng=3)
    area = 4 * np.pi * 100.0**2 * 1.5  # a 2:1:1 prolate spheroid has ~1.48x the area
    mean = area * 0.5 * (5.0**-2 - 20.0**-2)
    assert abs(len(cat) - mean) < 0.05 * mean + 4 * np.sqrt(mean)


def test_cholesky_solve6_matches_numpy(rng):
    for _ in range(20):
        a = rng.standard_normal((30, 6))
        ata = a.T @ a
        b = rng.standard_normal(6)
        lo, x = ata.copy(), b.copy()
        assert _cholesky_solve6(lo, x, 0.0)
        assert np.allclose(x, np.linalg.solve(ata, b), rtol=1e-10, atol=1e-12)
    singular = np.ones((6, 6))  # rank 1: the second pivot falls to rounding
    assert not _cholesky_solve6(singular.copy(), np.ones(6), 1e-15 * 6)


def test_fit_quadric_points_matches_lstsq(rng):
    x, y = rng.uniform(-5, 5, 300), rng.uniform(-5, 5, 300)
    h = 1.5 + 0.3 * x - 0.7 * y + 0.02 * x * x - 0.05 * x * y + 0.01 * y * y \
        + 0.01 * rng.standard_normal(300)
    dist = np.hypot(x, y)
    got = _fit_quadric_points(x, y, h, dist, 300, 4.0)
    sel = dist <= 4.0
    a = np.stack([np.ones(sel.sum()), x[sel], y[sel], x[sel] ** 2, x[sel] * y[sel],
                  y[sel] ** 2], 1)
    assert np.allclose(got, np.linalg.lstsq(a, h[sel], rcond=None)[0], rtol=1e-8, atol=1e-10)
    # collinear points: the regularised system still gives the line, nothing wild
    xs = np.linspace(-3, 3, 40)
    got = _fit_quadric_points(xs, 0 * xs, 2.0 + xs, np.abs(xs), 40, 4.0)
    assert np.allclose(got, [2.0, 1.0, 0.0, 0.0, 0.0, 0.0], atol=1e-9)


@pytest.mark.parametrize("lat,lon,stretch", [(10.0, 30.0, (1.0, 1.0, 1.0)),
                                             (-70.0, 359.0, (1.3, 1.0, 0.8)),
                                             (89.5, 120.0, (1.0, 1.0, 1.0))])
def test_local_coordinates_match_numpy(rng, lat, lon, stretch):
    """The kernel's local coordinates (longitudes by rotation along each ring, the
    azimuth's cos and sin from its components) against the direct numpy formulas."""
    g = LatLongGrid(60)
    radii = 1000.0 * (1.0 + 0.01 * rng.standard_normal(g.n_vertices))
    st = np.array(stretch)
    la, lo = np.radians(lat), np.radians(lon)
    cand_n = _gather_kernel(60, g.ring_offsets(), np.pi / 2 - la, lo, 0.4,
                            np.empty(0, np.int64), True)
    cand = np.empty(cand_n, np.int64)
    _gather_kernel(60, g.ring_offsets(), np.pi / 2 - la, lo, 0.4, cand, False)
    pc = st * 1000.0 * unit(lat, lon)
    rloc = np.linalg.norm(pc)
    a = pc / rloc
    e = np.cross([0.0, 0.0, 1.0], a)
    e = e / np.linalg.norm(e) if np.linalg.norm(e) > 1e-12 else np.array([1.0, 0.0, 0.0])
    n = np.cross(a, e)
    reach, limit = 150.0, 250.0
    out = [np.empty(cand_n) for _ in range(7)]
    out[0] = np.empty(cand_n, np.int64)
    keep, inside = _local_coordinates(cand, 60, np.array(g.ring_offsets()), radii, st, *a,
                                      *e, *n, rloc, reach, limit, *out)
    p = st * radii[cand, None] * g.unit_vectors()[cand]
    pm = np.linalg.norm(p, axis=1)
    b = p / pm[:, None]
    d = rloc * np.arctan2(np.linalg.norm(np.cross(b, a), axis=1), b @ a)
    sel = d <= limit
    az = np.arctan2(b @ n, b @ e)
    assert keep == sel.sum() and inside == (d <= reach).sum()
    idx, pmag, dist, azk, xl, yl, hgt = (o[:keep] for o in out)
    assert np.array_equal(idx, cand[sel])
    assert np.allclose(pmag, pm[sel], rtol=1e-14, atol=0)
    assert np.allclose(dist, d[sel], rtol=0, atol=1e-9)
    near = (dist > 1e-6) & (dist <= reach)  # beyond reach the stamp reads no azimuth
    assert np.allclose(azk[near], az[sel][near], rtol=0, atol=1e-9)
    assert (azk[dist > reach * (1 + 1e-12)] == 0).all()
    assert np.allclose(xl, d[sel] * np.cos(az[sel]), rtol=0, atol=1e-9)
    assert np.allclose(yl, d[sel] * np.sin(az[sel]), rtol=0, atol=1e-9)
    assert np.allclose(hgt, pm[sel] - rloc, rtol=0, atol=1e-9)


def _steep_craters_measure():
    """``measure`` of tests/benchmarks/measure_steep_craters.py (one home for it)."""
    import importlib.util
    from pathlib import Path

    path = Path(__file__).parents[1] / "benchmarks" / "measure_steep_craters.py"
    spec = importlib.util.spec_from_file_location("measure_steep_craters", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module.measure


def test_craters_on_steep_ground_are_made_in_the_base_frame():
    # issue 36: on the flank of a 3:1:1 spheroid, 53 deg from the radial, the radial
    # frame stretched a crater 1.64x along the dip and made it 40 % shallower (a streak);
    # in its base's frame it has the rim and depth of the same crater where the ground
    # faces the radial (the tip, 0 deg)
    measure = _steep_craters_measure()
    body = Body.sphere(LatLongGrid(150), 1000.0, stretch=(3.0, 1.0, 1.0))
    got = {lon: measure(body, lon) for lon in (40.0, 90.0)}
    _, dip, across, floor, _ = got[40.0]
    assert dip / across == pytest.approx(1.0, abs=0.06), got
    assert floor == pytest.approx(got[90.0][3], rel=0.1), got


def test_tilted_frame_is_orthonormal_with_the_base_normal():
    from craters.kernels import tilted_frame as _tilted_frame

    for gx, gy in ((0.0, 0.0), (0.7, 0.0), (-0.3, 1.2)):
        fr = np.zeros(10)
        tilt = _tilted_frame(gx, gy, fr)
        e, m, n = fr[0:3], fr[3:6], fr[6:9]
        want_n = np.array([-gx, -gy, 1.0]) / np.sqrt(1 + gx * gx + gy * gy)
        assert np.allclose(n, want_n) and fr[9] == pytest.approx(want_n[2])
        assert np.allclose(np.array([e, m, n]) @ np.array([e, m, n]).T, np.eye(3), atol=1e-12)
        # E' is east projected on the base: in the plane of east and N, on east's side
        assert np.allclose(np.cross(n, e), m) and e[0] > 0
        assert np.cross(n, [1.0, 0.0, 0.0]) @ e == pytest.approx(0.0, abs=1e-12)
        assert tilt == pytest.approx(np.degrees(np.arccos(want_n[2])))


def test_a_tilted_crater_replaces_the_terrain_inside_its_rim_whatever_its_height():
    # the build's tilted stamp (issue 36) decides inside and outside at the vertex's foot
    # on the base plane, as the field does: inside the rim a vertex lands where its radial
    # line meets the crater's surface over the base plane (plus the base's curvature,
    # radially), whatever its height before; outside the ejecta add along the normal.
    # Deciding at the vertex itself caught vertices far off a poorly fitted base
    from craters.kernels import table_value
    from craters.kernels import tilted_frame as _tilted_frame
    from latlong._tilt_kernels import _tilted_change

    gx, gy, p0, qa, qb, qc = 0.9, -0.2, 3.0, 1e-3, -5e-4, 2e-3
    fr = np.zeros(10)
    assert _tilted_frame(gx, gy, fr) > 40.0
    radius, xe, n = 10.0, 3.0, 600
    xs = np.linspace(0.0, xe, 97)
    tab = np.where(xs < 1.0, 2.0 * xs * xs - 1.5, 0.5 / np.maximum(xs, 1.0) ** 3)  # bowl, ejecta
    rim, delta, rough = np.zeros(64), np.zeros(64), np.zeros(4)
    rng = np.random.default_rng(3)
    xl, yl = rng.uniform(-20.0, 20.0, (2, n))
    foot = np.stack([xl, yl, gx * xl + gy * yl])  # the radial line meets the base plane
    x_foot = np.hypot(fr[0:3] @ foot, fr[3:6] @ foot) / radius
    inside, outside = x_foot <= 1.0, (x_foot > 1.0) & (x_foot < xe)
    assert inside.sum() > 50 and outside.sum() > 200
    news = []
    for hgt in (p0 + foot[2] + rng.normal(0.0, 1.0, n), p0 + rng.normal(0.0, 30.0, n)):
        got = np.array([_tilted_change(q, xl, yl, hgt, radius, tab, 1.0, 1.0, xe, rim, delta,
                                       p0, qa, qb, qc, rough, 1, radius, 0, 0.5, fr)
                        for q in range(n)], dtype=object)
        hit = got[:, 0].astype(bool)
        dh = got[:, 1].astype(float)
        assert np.array_equal(hit, x_foot < xe)
        want = np.array([table_value(tab, x, xe) for x in x_foot[outside]]) / fr[9]
        assert np.allclose(dh[outside], want, rtol=0, atol=1e-12)
        news.append(hgt + dh)
        # inside: on the crater's surface over the base plane, in the plane's frame
        v = np.stack([xl, yl, hgt + dh - p0 - (qa * xl * xl + qb * xl * yl + qc * yl * yl)])
        u1, u2, w = fr[0:3] @ v, fr[3:6] @ v, fr[6:9] @ v
        xv = np.minimum(np.hypot(u1, u2) / radius, 1.0)
        surface = np.array([table_value(tab, x, xe) for x in xv])
        assert np.allclose(w[inside], surface[inside], rtol=0, atol=1e-7)
    # whatever the height before (1 m or 30 m off the base), inside the rim: the same
    assert np.allclose(news[0][inside], news[1][inside], rtol=0, atol=1e-7)


def test_a_tilted_crater_moves_no_vertex_farther_than_a_level_one():
    # examples/plot_slope_study.py's small run (fig5c, M = 40): 13 m craters on 44 deg
    # ground moved vertices up to 40 m while craters on level ground moved them at most
    # 6.8 m (each replaces the terrain inside its rim by its fitted base)
    scene = Scene.from_settings({"preset": "fig5c", "magnitude": 40, "radius_m": 100.0,
                                 "craters": ["c=0.5,k=-2,d_min_m=9.817,d_max_m=15"],
                                 "seed": 9})
    cat = build(scene).craters
    level = cat["slope_deg"] < 10.0
    assert level.sum() >= 10 and (~level).sum() >= 100
    moved = np.abs(cat["max_change_m"])
    assert moved[~level].max() <= 2.0 * moved[level].max(), (moved[~level].max(),
                                                             moved[level].max())
