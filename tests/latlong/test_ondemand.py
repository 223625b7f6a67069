"""Terrain on demand (latlong.ondemand, craters.local): locality, refinement, the kernels
against numpy references, the cell-by-cell catalogue."""

from __future__ import annotations

import numpy as np
import pytest

from craters import CraterLayer
from craters.cells import cell_ids, cell_of, cell_solid_angle
from craters.kernels import fbm2, roughness_amp, table, table_value, tilted_root, warp_x
from craters.local import bins, draw_cells
from latlong import LatLongGrid, Scene, build
from latlong.ondemand import _field_kernels as K
from latlong.ondemand import heights_at, units_of
from latlong.ondemand.cellsets import unique_inverse, unique_sorted
from latlong.ondemand.field import (
    BLEND_EDGE,
    FIT,
    ROUGHNESS_OCTAVES,
    STENCIL_XY,
    CraterField,
    crater_field,
)
from latlong.ondemand.tile import tile, tile_mesh


@pytest.fixture(scope="module")
def scene():
    # a 100 m fBm body with 4-15 m craters (few enough for quick single-point queries)
    return Scene.from_settings({"preset": "fbm-cratered", "seed": 5, "on_demand": True,
                                "craters": ["c=0.5,k=-2,d_min_m=4,d_max_m=15"]})


# ----------------------------------------------------------------------------- catalogue
def _cells(level, n=60, face=2):
    i, j = np.meshgrid(np.arange(n) + 7, np.arange(n) + 11)
    return cell_ids(level, np.full(i.size, face), i.ravel(), j.ravel()), \
        cell_solid_angle(level, face, i.ravel(), j.ravel())


def test_cells_draw_the_expected_counts_in_their_cells_and_bins():
    la = CraterLayer(0.5, -2.0, 1.0, 8.0)
    ids, omega = _cells(12)
    area = omega * 20000.0**2  # ~32 000 craters
    got = draw_cells(la, 0, seed=3, b=1, level=12, cell_ids=ids, area_m2=area)
    expected = area.sum() * la.expected_count(1.0, 2.0, 4.0)
    assert abs(len(got["diameter_m"]) - expected) < 4 * np.sqrt(expected)
    d = got["diameter_m"]
    assert ((d >= 2.0) & (d < 4.0)).all()
    # a power law of slope -2 in [2, 4): median 2 * sqrt(8 / 5) = 2.53
    assert abs(np.median(d) - 2.0 * np.sqrt(8.0 / 5.0)) < 0.02  # 4 standard errors
    f, i, j = cell_of(got["unit"], 12)
    assert np.array_equal(cell_ids(12, f, i, j), got["cell"])
    assert np.allclose(np.linalg.norm(got["unit"], axis=1), 1.0)
    assert ((got["age_gyr"] >= 0.0) & (got["age_gyr"] < 3.5)).all()


def test_a_cell_mean_beyond_one_inversion_is_a_sum_of_poisson_counts():
    la = CraterLayer(0.5, -2.0, 1.0, 8.0)
    ids, omega = _cells(10, n=20)
    area = omega * 250000.0**2  # ~4 600 craters a cell: ten draws of a tenth each
    got = draw_cells(la, 0, seed=3, b=1, level=10, cell_ids=ids, area_m2=area)
    want = area * la.expected_count(1.0, 2.0, 4.0)
    assert want.min() > 1000
    assert abs(len(got["diameter_m"]) - want.sum()) < 4 * np.sqrt(want.sum())
    order = np.argsort(ids)
    count = np.bincount(order[np.searchsorted(ids[order], got["cell"])], minlength=len(ids))
    assert 0.72 < np.var(count - want) / want.mean() < 1.28  # Poisson: 1 (400 cells)
    assert len(np.unique(got["id"])) == len(got["id"])


def test_a_cell_draws_the_same_craters_whatever_else_is_drawn():
    la = CraterLayer(0.5, -2.0, 1.0, 8.0)
    ids, omega = _cells(10, n=30)
    area = omega * 5000.0**2
    every = draw_cells(la, 2, seed=11, b=0, level=10, cell_ids=ids, area_m2=area)
    pick = np.array([5, 400, 899])
    some = draw_cells(la, 2, seed=11, b=0, level=10, cell_ids=ids[pick[::-1]],
                      area_m2=area[pick[::-1]])
    for c in ids[pick]:
        a, b = every["cell"] == c, some["cell"] == c
        for key in ("unit", "diameter_m", "age_gyr", "rim_phases", "seed", "id"):
            assert every[key][a].tobytes() == some[key][b].tobytes()
    other = draw_cells(la, 2, seed=12, b=0, level=10, cell_ids=ids, area_m2=area)
    assert not np.array_equal(other["id"][:10], every["id"][:10])


def test_bins_cover_the_layer_without_an_empty_top_bin():
    assert bins(CraterLayer(0.5, -2.0, 1.0, 8.0)).tolist() == [0, 1, 2]
    assert bins(CraterLayer(0.5, -2.0, 0.3, 9.0)).tolist() == [-2, -1, 0, 1, 2, 3]


# ----------------------------------------------------------------------------- kernels
@pytest.mark.parametrize("angle", [0.0, 1e-12, 3e-7, 1e-4, 0.0099, 0.0101, 0.3, 2.5])
def test_the_distance_from_a_centre_is_the_arc(angle):
    # below sin(angle) = 0.01 the kernel sums asin's series instead of calling arctan2
    fc = np.zeros((1, K.N_COLS))
    fc[0, K.C2], fc[0, K.E0], fc[0, K.N1], fc[0, K.RHO] = 1.0, 1.0, 1.0, 1000.0
    az = 0.7
    p = np.array([np.sin(angle) * np.cos(az), np.sin(angle) * np.sin(az), np.cos(angle)])
    c, dist, x, y, east, north = K._local(fc, 0, *p)
    want = np.arctan2(np.hypot(p[0], p[1]), p[2]) * 1000.0
    assert dist == pytest.approx(want, rel=4e-16, abs=0.0)
    assert (east, north) == (p[0], p[1])
    assert np.hypot(x, y) == pytest.approx(dist, rel=4e-16, abs=0.0)


def test_the_fit_operator_reproduces_a_quadric_exactly():
    x, y = STENCIL_XY[:, 0], STENCIL_XY[:, 1]
    coef = np.array([0.3, -1.2, 0.7, 2.0, -0.5, 1.5])
    h = coef[0] + coef[1] * x + coef[2] * y + coef[3] * x * x + coef[4] * x * y + coef[5] * y * y
    assert np.allclose(FIT @ h, coef, atol=1e-12)
    assert FIT.shape == (6, len(STENCIL_XY))


def _step_reference(fc, k, tabs, rims, seeds, rough, gain, xe, p):
    """The affine step of crater k at direction p, in numpy (module notes of field)."""
    c = fc[k, 0:3] @ p
    xe_, xn_ = fc[k, 3:6] @ p, fc[k, 6:9] @ p
    s = np.hypot(xe_, xn_)
    dist = np.arctan2(s, c) * fc[k, K.RHO]
    x, y = (dist * xe_ / s, dist * xn_ / s) if s > 0 else (0.0, 0.0)
    az = np.arctan2(xn_, xe_) if s > 0 else 0.0
    if np.sum((p - fc[k, 0:3]) ** 2) > fc[k, K.CHORD2]:
        return False, 1.0, 0.0
    if fc[k, K.TILT_CZ] > 0.0:
        return _tilted_step_reference(fc, k, tabs, rims, seeds, rough, gain, xe, x, y)
    xr = dist / (fc[k, K.RAD] * (1.0 + table.py_func(rims[k], az)))
    if not xr < xe:
        return False, 1.0, 0.0
    xw = warp_x.py_func(xr, x, y, fc[k, K.RAD], fc[k, K.WARP], seeds[k]) if xr < 1.0 else xr
    prof = fc[k, K.SCALE] * table_value.py_func(tabs[k], xw, xe)
    amp = roughness_amp.py_func(xr, xe, *rough) * fc[k, K.DEPTH] * fc[k, K.SCALE]
    if amp > 1e-6 * fc[k, K.RAD]:
        prof += amp * fbm2.py_func(seeds[k], x, y, fc[k, K.RAD], ROUGHNESS_OCTAVES, gain)
    q = fc[k, K.RHO] + (fc[k, K.P0] + fc[k, K.GX] * x + fc[k, K.GY] * y + fc[k, K.QA] * x * x
                        + fc[k, K.QB] * x * y + fc[k, K.QC] * y * y)
    if xr <= 1.0:
        return True, 0.0, q + prof
    w = 1.0 - ((BLEND_EDGE - xr) / (BLEND_EDGE - 1.0)) ** 2 if xr < BLEND_EDGE else 1.0
    return True, w, (1.0 - w) * q + prof


def _tilted_step_reference(fc, k, tabs, rims, seeds, rough, gain, xe, x, y):
    """The step of a crater made in its tilted base's frame, in numpy: the point's foot on
    the base plane in the frame (E', N', N), the rim in that plane; inside it the
    radial line's meeting with the crater's surface over the base plane (the sequential
    stamp's root finder) plus the quadric's curvature radially, outside the profile along
    the normal over N_z, blended into the base quadric."""
    fr = fc[k, K.TILT:K.TILT + 10]
    foot = np.array([x, y, fc[k, K.GX] * x + fc[k, K.GY] * y])
    u1, u2, w0 = foot @ fr[0:3], foot @ fr[3:6], foot @ fr[6:9]
    az = np.arctan2(u2, u1)
    radius = fc[k, K.RAD]
    xr = np.hypot(u1, u2) / (radius * (1.0 + table.py_func(rims[k], az)))
    if not xr < xe:
        return False, 1.0, 0.0
    scale, depth = fc[k, K.SCALE], fc[k, K.DEPTH]
    has_rough = max(rough) * depth * scale > 1e-6 * radius
    q = fc[k, K.RHO] + (fc[k, K.P0] + fc[k, K.GX] * x + fc[k, K.GY] * y + fc[k, K.QA] * x * x
                        + fc[k, K.QB] * x * y + fc[k, K.QC] * y * y)
    if xr <= 1.0:
        t = tilted_root.py_func(u1, u2, w0, radius, tabs[k], scale, depth, xe, rims[k], rough,
                                fc[k, K.WARP], has_rough, seeds[k], radius, ROUGHNESS_OCTAVES,
                                gain, fr)
        return True, 0.0, q + t
    add = scale * table_value.py_func(tabs[k], xr, xe)
    if has_rough:
        add += (roughness_amp.py_func(xr, xe, *rough) * depth * scale
                * fbm2.py_func(seeds[k], u1, u2, radius, ROUGHNESS_OCTAVES, gain))
    w = 1.0 - ((BLEND_EDGE - xr) / (BLEND_EDGE - 1.0)) ** 2 if xr < BLEND_EDGE else 1.0
    return True, w, (1.0 - w) * q + add / fr[9]


def _reference_tables(field):
    """(profile tables, rim perturbations) of the craters of the field's last call."""
    from craters.catalog import make_catalog
    from craters.stamp import rim_perturbations_from_phases, stamping_profiles

    cr = field.last["craters"]
    n = len(cr)
    fixed = np.array([np.nan if la.degradation is None else la.degradation
                      for la in field.layers])
    prof = stamping_profiles(make_catalog(lat_deg=np.zeros(n), lon_deg=np.zeros(n),
                                          diameter_m=cr.diameter_m, age_gyr=cr.age_gyr,
                                          degradation=fixed[cr.layer]),
                             field.target, ejecta_edge=field.xe)
    return prof.tables, rim_perturbations_from_phases(cr.rim_phases, field.irregularity)


def _compose_reference(field, tables, p, base_radius, keep=lambda j: True):
    """The height at direction p over ``base_radius`` from the craters of the field's last
    call that ``keep`` (youngest first, stopping at the first rim), in numpy; ``tables``:
    :func:`_reference_tables`."""
    fc, rank, cr = field.last["fc"], field.last["rank"], field.last["craters"]
    tabs, rims = tables
    a, b = 1.0, 0.0
    for k in np.argsort(rank):
        if fc[k, K.ACTIVE] == 0.0 or not keep(k):
            continue
        with np.errstate(over="ignore"):  # the hash's uint64 arithmetic wraps
            hit, ak, bk = _step_reference(fc, k, tabs, rims, cr.seed, field.rough,
                                          field.gain, field.xe, p)
        if hit:
            b += a * bk
            a *= ak
            if a == 0.0:
                break
    return b + a * base_radius


def test_the_point_kernel_matches_a_numpy_composition(scene):
    field = crater_field(scene)
    units = units_of(np.linspace(-20, 20, 40), np.linspace(100, 130, 40))
    got = field.radii(units, 4.0)
    base = field.base.radius(units)
    tables = _reference_tables(field)
    for i, p in enumerate(units):
        want = _compose_reference(field, tables, p, base[i])
        assert got[i] == pytest.approx(want, abs=1e-9), i


def _steep_scene(degradation="degradation=0"):
    # fresh 140-180 m craters on a 3:1:1 spheroid of 1 km: ground tilted up to ~50 deg from
    # the radial where the long axis meets the others
    return Scene.from_settings({
        "base": "sphere", "radius_m": 1000.0, "stretch": [3, 1, 1], "magnitude": 300,
        "seed": 2, "crater_roughness": False, "boulders": [], "on_demand": True,
        "craters": [f"c=0.02,k=-2,d_min_m=140,d_max_m=180,{degradation}"]})


def _steep_craters(field):
    """(direction, base radius, normal, dip, across, tilt deg, radius) of each crater of
    the field's last call: the stretched sphere's normal and the dip (the radial's
    direction in the tangent plane)."""
    fc = field.last["fc"]
    s = np.array([3.0, 1.0, 1.0])
    for k in range(len(fc)):
        w = fc[k, K.C0:K.C2 + 1]
        rc = field.base.radius(w[None])[0]
        nrm = w * rc / s**2
        nrm /= np.linalg.norm(nrm)
        dip = w - (w @ nrm) * nrm
        dip /= np.linalg.norm(dip)
        tilt = np.degrees(np.arccos(nrm @ w))
        yield k, w, rc, nrm, dip, np.cross(nrm, dip), tilt, fc[k, K.RAD]


def test_a_crater_on_steep_ground_on_demand_has_the_shape_of_one_on_level_ground():
    # issue 36 for terrain on demand: made in the radial frame, a crater on ground tilted
    # 49 deg had its rim crest 1.50 R from the centre along the dip and 1.01 R across
    # (measured before the tilted frame); in its tilted base's frame 0.96-1.01 R both ways
    field = CraterField(_steep_scene())
    g = np.random.default_rng(0).normal(size=(20000, 3))
    field.radii(g / np.linalg.norm(g, axis=1)[:, None], 100.0)
    craters = list(_steep_craters(field))
    assert (field.last["fc"][:, K.TILT_CZ] > 0).sum() >= 8
    phis = np.linspace(-np.pi, np.pi, 32, endpoint=False)
    along = np.abs(np.cos(phis)) > np.cos(np.radians(20))
    across = np.abs(np.sin(phis)) > np.cos(np.radians(20))
    steep = 0
    for _, w, rc, nrm, dip, e2, tilt, radius in craters:
        if tilt < 35.0:
            continue
        rho = np.linspace(0.3, 1.7, 141) * radius
        p = w * rc + rho[None, :, None] * (np.cos(phis)[:, None, None] * dip
                                           + np.sin(phis)[:, None, None] * e2)
        u = p.reshape(-1, 3) / np.linalg.norm(p.reshape(-1, 3), axis=1)[:, None]
        # height above the ground before the crater, along the normal
        h = ((field.radii(u, 100.0) - field.base.radius(u)) * (u @ nrm)).reshape(p.shape[:2])
        crest = rho[np.argmax(h, axis=1)] / radius
        assert 0.93 < crest[along].mean() / crest[across].mean() < 1.05, tilt
        steep += 1
    assert steep >= 6


def test_the_point_kernel_matches_numpy_on_craters_made_in_a_tilted_frame():
    field = CraterField(_steep_scene("age_max_gyr=2"))
    g = np.random.default_rng(0).normal(size=(2000, 3))
    field.radii(g / np.linalg.norm(g, axis=1)[:, None], 100.0)
    k, w, rc, nrm, dip, e2, tilt, radius = max(_steep_craters(field), key=lambda c: c[6])
    assert tilt > 40.0 and field.last["fc"][k, K.TILT_CZ] > 0
    # points across the crater and its ejecta: inside the rim, the blend and beyond
    s = np.linspace(-2.5, 2.5, 15) * radius
    p = w * rc + s[:, None, None] * dip + s[None, :, None] * e2
    units = p.reshape(-1, 3) / np.linalg.norm(p.reshape(-1, 3), axis=1)[:, None]
    got = field.radii(units, 100.0)
    base = field.base.radius(units)
    tables = _reference_tables(field)
    for i, q in enumerate(units):
        assert got[i] == pytest.approx(_compose_reference(field, tables, q, base[i]),
                                       abs=1e-9), i


def _rim_jumps(fc, k, tables, field, n_az=16):
    """Height just inside minus just outside crater k's rim (its tilted step, the height
    before it taken as the base quadric) at ``n_az`` azimuths of the crater's plane."""
    tabs, rims = tables
    cr = field.last["craters"]
    seeds = np.ascontiguousarray(cr.seed)
    out = []
    for phi in np.linspace(-np.pi, np.pi, n_az, endpoint=False):
        def step(d, phi=phi):
            x, y = d * np.cos(phi), d * np.sin(phi)
            hit, a, b = K._tilted_step(fc, k, tabs, rims, seeds, field.rough, field.gain,
                                       ROUGHNESS_OCTAVES, field.xe, BLEND_EDGE, x, y)
            q = fc[k, K.RHO] + (fc[k, K.P0] + fc[k, K.GX] * x + fc[k, K.GY] * y
                                + fc[k, K.QA] * x * x + fc[k, K.QB] * x * y + fc[k, K.QC] * y * y)
            return a, b + a * q
        lo, hi = 0.3 * fc[k, K.RAD], 1.5 * fc[k, K.RAD]
        for _ in range(60):  # the rim: where the step stops replacing the terrain
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if step(mid)[0] == 0.0 else (lo, mid)
        out.append(step(lo)[1] - step(hi)[1])
    return np.array(out)


def test_a_tilted_craters_rim_does_not_move_with_its_bases_curvature():
    # a crater in a larger crater's bowl sits on a strongly curved base: over the LOLA
    # site a 663 m crater had 110 m of curvature over its radius, and with the curvature
    # taken along the tilted normal inside the rim (radially outside) its rim was a 37 m
    # cliff. Taken radially on both sides the jump at the rim is the curvature's none
    field = CraterField(_steep_scene())
    g = np.random.default_rng(0).normal(size=(2000, 3))
    field.radii(g / np.linalg.norm(g, axis=1)[:, None], 100.0)
    k, *_, tilt, radius = max(_steep_craters(field), key=lambda c: c[6])
    tables = tuple(np.ascontiguousarray(t) for t in _reference_tables(field))
    flat = field.last["fc"].copy()
    flat[k, K.QA:K.QC + 1] = 0.0
    curved = flat.copy()
    curved[k, K.QA], curved[k, K.QC] = 1.5e-3, 1.5e-3  # 11 m over its 85 m radius
    a, b = _rim_jumps(flat, k, tables, field), _rim_jumps(curved, k, tables, field)
    assert tilt > 40.0 and np.abs(a - b).max() < 1e-6 * radius, np.abs(a - b).max()


def test_a_layer_with_a_fixed_degradation_keeps_it_on_demand():
    field = CraterField(_steep_scene("degradation=0.6"))
    g = np.random.default_rng(0).normal(size=(2000, 3))
    cat = field.catalog(g / np.linalg.norm(g, axis=1)[:, None], 100.0)
    flat = cat["slope_factor"] == 1.0
    assert flat.sum() >= 3
    # the catalogue's degradation is what the craters were made with (depth lost)
    assert np.allclose(cat["degradation"][flat], 0.6, atol=0.05)


# ----------------------------------------------------------------------------- locality
def test_a_height_is_the_same_alone_in_a_batch_and_in_the_whole_body(scene):
    grid = LatLongGrid(60)
    res = grid.spacing(crater_field(scene).base.radius_m)
    units = grid.unit_vectors()
    every = crater_field(scene).radii(units, 3.0 * res)
    pick = np.random.default_rng(1).choice(len(units), 40, replace=False)
    batch = crater_field(scene).radii(units[pick], 3.0 * res)
    assert batch.tobytes() == every[pick].tobytes()
    for i in pick[:2]:
        alone = crater_field(scene).radii(units[i:i + 1], 3.0 * res)
        assert alone.tobytes() == every[i:i + 1].tobytes()
    # the library call and the on-demand build give the same values
    lat, lon = grid.latitudes(), grid.longitudes()
    r = heights_at(scene, np.degrees(lat[pick[:5]]), np.degrees(lon[pick[:5]]),
                   resolution_m=res)
    assert np.allclose(r, every[pick[:5]], rtol=0, atol=1e-9)
    body = build(Scene.from_settings({"preset": "fbm-cratered", "seed": 5, "on_demand": True,
                                      "magnitude": 60,
                                      "craters": ["c=0.5,k=-2,d_min_m=4,d_max_m=15"]}))
    assert body.radii_m.tobytes() == every.tobytes()
    assert len(body.craters) > 100


def test_a_model_age_scene_on_demand_is_local_too():
    sc = Scene.from_settings({"base": "sphere", "radius_m": 1737400.0, "body": "moon",
                              "seed": 2, "on_demand": True,
                              "craters": ["npf=moon,age_gyr=3.5,d_min_m=20,d_max_m=2000"]})
    t = tile(sc, 1.0, 2.0, size_m=3000.0, pixel_m=30.0)
    assert t.n_craters > 100 and np.ptp(t.heights_m) > 10.0
    u = units_of(np.linspace(0.99, 1.01, 30), np.linspace(1.99, 2.01, 30))
    every = crater_field(sc).radii(u, 90.0)
    assert crater_field(sc).radii(u[7:8], 90.0).tobytes() == every[7:8].tobytes()


def test_a_finer_resolution_changes_heights_only_where_the_added_craters_reach(scene):
    field = crater_field(scene)
    units = units_of(*np.meshgrid(np.linspace(30, 36, 70), np.linspace(40, 46, 70)))
    coarse = field.radii(units, 12.0)
    fine = field.radii(units, 6.0)
    cr, fc = field.last["craters"], field.last["fc"]
    added = (cr.diameter_m >= 6.0) & (cr.diameter_m < 12.0)
    reach = np.zeros(len(units), bool)
    for k in np.flatnonzero(added):
        reach |= units @ fc[k, 0:3] >= fc[k, K.COS_FAR]
    changed = fine != coarse
    assert changed.any()
    assert not (changed & ~reach).any()


def test_no_older_crater_shows_inside_a_younger_rim(scene):
    field = crater_field(scene)
    field.radii(LatLongGrid(30).unit_vectors(), 4.0)  # every crater of the body
    fc, rank, cr = field.last["fc"], field.last["rank"], field.last["craters"]
    ang = np.arccos(np.clip(fc[:, 0:3] @ fc[:, 0:3].T, -1.0, 1.0))
    rim = 0.97 * fc[:, K.RAD] / fc[:, K.RHO]  # inside the rim at every azimuth
    # j older than k, j's centre inside k's rim: nothing of j shows there
    inside = (rank[:, None] > rank[None, :]) & (ang < rim[None, :]) \
        & (fc[None, :, K.ACTIVE] > 0)
    js = np.flatnonzero(inside.any(axis=1))
    assert len(js) >= 3
    for j in js[:8]:
        k = np.flatnonzero(inside[j])[0]
        # j's centre and points on the way to k's centre
        t = np.linspace(0.0, 1.0, 4)[:, None]
        pts = (1.0 - t) * fc[j, 0:3] + t * fc[k, 0:3]
        pts /= np.linalg.norm(pts, axis=1, keepdims=True)
        with_j = field.radii(pts, 0.999 * cr.diameter_m[j])
        without = field.radii(pts, 1.001 * cr.diameter_m[j])
        assert with_j.tobytes() == without.tobytes(), j


# ----------------------------------------------------------------------------- tiles
def test_a_tile_has_its_pixels_and_projection(scene):
    t = tile(scene, 10.0, 20.0, size_m=8.0, pixel_m=0.5)
    assert t.heights_m.shape == (16, 16)
    assert "+proj=gnom" in t.crs_proj4 and "+lat_0=10.0" in t.crs_proj4
    assert t.transform[:2] == (-4.0, 0.5)
    verts, faces = tile_mesh(t)
    assert verts.shape == (256, 3) and faces.shape == (2 * 15 * 15, 3)
    # outward: the triangles' normals point away from the centre
    a, b, c = verts[faces[:, 0]], verts[faces[:, 1]], verts[faces[:, 2]]
    assert (np.einsum("ij,ij->i", np.cross(b - a, c - a), a) > 0).all()
    with pytest.raises(ValueError, match="size_m"):
        tile(scene, 10.0, 20.0, size_m=1e9, pixel_m=0.5)
    with pytest.raises(ValueError, match="pixel_m"):
        tile(scene, 10.0, 20.0, size_m=8.0, pixel_m=-1.0)


def test_descent_frames_label_the_craters_of_their_own_terrain(scene):
    from latlong.ondemand.descent import descent

    frames = list(descent(scene, 10.0, 40.0, [60.0, 20.0], width_px=64))
    for f in frames:
        ids = f.frame.crater_id
        hit = ids >= 0
        assert hit.mean() > 0.1 and ids.max() < len(f.craters)
        assert (f.craters["slope_factor"] > 0).all()  # craters erased by slope show nothing
        # each labelled pixel lies inside the rim of the crater it names
        cat = f.craters[ids[hit]]
        c = np.stack([cat["centre_x_m"], cat["centre_y_m"], cat["centre_z_m"]], axis=1)
        p = f.frame.position_m[hit]
        cos = np.einsum("ij,ij->i", p, c) / np.linalg.norm(p, axis=1) / np.linalg.norm(c, axis=1)
        arc = np.linalg.norm(c, axis=1) * np.arccos(np.clip(cos, -1.0, 1.0))
        assert (arc <= cat["rim_radius_m"] * (1.0 + 1e-6)).all()
    # the craters are the window's, not those of the single point asked after it
    assert len(frames[0].craters) > 20


def test_descent_frames_light_their_shadows_with_bounced_light_when_asked(scene):
    from latlong.ondemand.descent import descent

    alts = [60.0, 20.0]
    direct = list(descent(scene, 10.0, 40.0, alts, width_px=64, sun_elevation_deg=8.0))
    lit = list(descent(scene, 10.0, 40.0, alts, width_px=64, sun_elevation_deg=8.0,
                       bounces=1))
    for a, b in zip(direct, lit, strict=True):
        np.testing.assert_array_equal(a.frame.depth_m, b.frame.depth_m)  # the same terrain
        seen = a.frame.face >= 0
        shadow = seen & (a.frame.sunlit == 0)
        assert shadow.mean() > 0.01
        assert (a.frame.reflectance[shadow] == 0).all()
        # the terrain lights its own shadows (where lit ground rises above a shadowed point's
        # horizon: ~40 % of them on this 100 m convex body at 8 deg sun), and adds to the rest
        assert (b.frame.reflectance[shadow] > 0).mean() > 0.2
        assert (b.frame.reflectance[seen] >= a.frame.reflectance[seen]).all()
    with pytest.raises(ValueError, match="bounces"):
        next(descent(scene, 10.0, 40.0, alts, width_px=64, bounces=3))


def test_descent_lidar_sees_the_frames_terrain_as_the_camera_does(scene):
    from latlong.ondemand.descent import descent
    from latlong.sensors import LidarSettings

    # a flash LIDAR with the camera's pixels as beams: the same rays on the same mesh
    lidar = LidarSettings(beams=(48, 48), fov_deg=30.0)
    frames = list(descent(scene, 10.0, 40.0, [60.0, 20.0], width_px=48, lidar=lidar))
    for f in frames:
        r = f.lidar.range_image
        assert np.isfinite(r).all() and len(f.lidar) == 48 * 48
        assert np.allclose(r, f.frame.range_m, rtol=1e-6, atol=0.0)
        # returns name the craters the camera's label image names at the same pixel
        assert np.array_equal(f.lidar.crater_id, f.frame.crater_id.ravel()[f.lidar.beam])
    with pytest.raises(ValueError, match="lidar"):
        next(descent(scene, 10.0, 40.0, [60.0], width_px=48,
                     lidar=LidarSettings(fov_deg=80.0)))


def test_a_stretched_body_on_demand_is_its_stretched_surface():
    from latlong.ondemand import heights_at_units

    def stretched(craters):
        return Scene.from_settings({"base": "sphere", "radius_m": 100.0, "seed": 3,
                                    "stretch": [2.0, 1.0, 0.8], "magnitude": 40,
                                    "on_demand": True, "craters": craters})

    v = build(stretched([])).vertices()
    assert np.allclose((v[:, 0] / 200) ** 2 + (v[:, 1] / 100) ** 2 + (v[:, 2] / 80) ** 2, 1.0,
                       rtol=0, atol=1e-12)
    sc = stretched(["c=0.5,k=-2,d_min_m=4,d_max_m=15"])
    body = build(sc)
    v = body.vertices()
    r = np.linalg.norm(v, axis=1)
    pick = np.random.default_rng(2).choice(len(v), 200, replace=False)
    # a vertex lies where heights_at puts the surface along its direction
    got = heights_at_units(sc, v[pick] / r[pick, None],
                           resolution_m=body.grid.spacing(crater_field(sc).base.radius_m))
    assert np.allclose(got, r[pick], rtol=1e-13, atol=0)
    assert len(body.craters) > 50 and np.abs(r - np.linalg.norm(
        build(stretched([])).vertices(), axis=1)).max() > 0.5
    # slopes are measured against the stretched sphere's normal, as the sequential stamp
    u = units_of([30.0], [40.0])
    up = crater_field(sc).base.up(u)[0]
    n = u[0] / np.array([4.0, 1.0, 0.64])
    assert np.allclose(up, n / np.linalg.norm(n), atol=1e-15)


def test_stencil_points_match_numpy(scene):
    from latlong.ondemand.field import _stencil_points

    field = crater_field(scene)
    field.radii(units_of([0.0], [0.0]), 4.0)
    fc = field.last["fc"]
    t = STENCIL_XY[None, :, :] * (fc[:, K.RAD] / fc[:, K.RHO])[:, None, None]
    ang = np.hypot(t[..., 0], t[..., 1])
    safe = np.where(ang > 0, ang, 1.0)
    ce, cn = t[..., 0] / safe, t[..., 1] / safe
    want = np.cos(ang)[..., None] * fc[:, None, 0:3] + np.sin(ang)[..., None] * (
        ce[..., None] * fc[:, None, 3:6] + cn[..., None] * fc[:, None, 6:9])
    assert np.allclose(_stencil_points(fc), want, rtol=0, atol=1e-15)


def test_coarser_cells_are_the_points_cells_at_that_level():
    from latlong.ondemand.cellsets import cells_of, coarser

    u = np.random.default_rng(0).normal(size=(20000, 3))
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    fine = cells_of(u, 20)
    for level in (0, 3, 10, 19):
        assert np.array_equal(coarser(fine, 20, level), np.unique(cells_of(u, level)))


def test_distinct_cells_and_their_inverse_match_numpy_with_runs_and_without():
    rng = np.random.default_rng(3)
    runs = np.repeat(rng.integers(0, 50, 300, dtype=np.uint64) << np.uint64(40),
                     rng.integers(1, 9, 300))
    for x in (runs, rng.permutation(runs), runs[:1], runs[:0]):
        want, want_inv = np.unique(x, return_inverse=True)
        got, got_inv = unique_inverse(x)
        assert np.array_equal(got, want) and np.array_equal(unique_sorted(x), want)
        assert got.dtype == x.dtype and np.array_equal(got_inv, want_inv.ravel())


def test_a_neighbour_set_is_the_union_of_the_neighbourhoods():
    """``neighbour_set`` (distinct cells first, nine runs merged) against numpy's unique
    of every neighbourhood, with cells on a cube corner and edge and repeated cells."""
    from latlong.ondemand.cellsets import cells_of, neighbour_set, neighbours

    rng = np.random.default_rng(5)
    u = rng.normal(size=(3000, 3))
    corner = np.array([[1.0, 1.0, 1.0], [1.0, -1.0, 1e-9], [-1.0, 1e-9, 1e-9]])
    u = np.concatenate([u, corner, u[:500]])
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    for level in (0, 2, 7, 20):
        cells = cells_of(u, level)
        assert np.array_equal(neighbour_set(cells), np.unique(neighbours(cells)))
    assert len(neighbour_set(np.zeros(0, dtype=np.uint64))) == 0


def test_a_centimetre_crater_on_the_moon_reaches_its_whole_ejecta_blanket():
    # at 1e-8 rad (2 cm on the Moon) a cosine test cannot tell points apart: the reach
    # tests go by chords
    moon = Scene.from_settings({"base": "sphere", "radius_m": 1737400.0, "body": "moon",
                                "seed": 3, "on_demand": True,
                                "craters": ["c=1,k=-2,d_min_m=0.02,d_max_m=0.04,age_max_gyr=1e-6"]})
    field = crater_field(moon)
    field.radii(units_of([0.0], [0.0]), 0.02)
    fc, cr = field.last["fc"], field.last["craters"]
    k = int(np.argmax(cr.diameter_m))
    x = np.linspace(0.05, 0.95 * field.xe, 40)  # radii from its centre, to the east
    ang = x * fc[k, K.RAD] / fc[k, K.RHO]
    pts = np.cos(ang)[:, None] * fc[k, 0:3] + np.sin(ang)[:, None] * fc[k, 3:6]
    with_k = field.radii(pts, 0.999 * cr.diameter_m[k])
    without = field.radii(pts, 1.001 * cr.diameter_m[k])
    assert (with_k != without).all()


def test_parameters_kept_between_calls_give_the_same_bytes(scene):
    from latlong.ondemand.field import CraterField

    units = units_of(*np.meshgrid(np.linspace(-10, -4, 50), np.linspace(70, 76, 50)))
    warm = CraterField(scene)
    warm.radii(LatLongGrid(40).unit_vectors(), 4.0)  # parameters of every crater kept
    kept = len(warm._params)
    again = warm.radii(units, 4.0)
    assert kept > 100 and len(warm._params) == kept  # nothing new computed
    assert again.tobytes() == CraterField(scene).radii(units, 4.0).tobytes()


def test_reaching_keeps_every_crater_that_reaches_a_point_and_drops_far_ones():
    from latlong.ondemand.base import tangent_frame
    from latlong.ondemand.cellsets import cells_of, reaching, unique_sorted

    rng = np.random.default_rng(5)
    # points of a window near a cube corner and near a face centre
    for lat, lon in ((35.26, 45.0), (0.3, 0.2)):
        c = units_of([lat], [lon])
        e, n = tangent_frame(c)
        xy = rng.uniform(-0.01, 0.01, (4000, 2))
        pts = c + xy[:, :1] * e + xy[:, 1:] * n
        pts /= np.linalg.norm(pts, axis=1, keepdims=True)
        level = 12
        occ = unique_sorted(cells_of(pts, level))
        # caps of every size around the window, some far from it
        m = 3000
        off = rng.uniform(-0.05, 0.05, (m, 2))
        cu = c + off[:, :1] * e + off[:, 1:] * n
        cu /= np.linalg.norm(cu, axis=1, keepdims=True)
        rec = np.zeros((m, K.N_COLS))
        rec[:, K.C0:K.C2 + 1] = cu
        rec[:, K.FAR] = 10.0 ** rng.uniform(-5, -1.5, m)
        got = reaching(rec, level, occ)
        # by brute force: the angle from each cap's centre to its nearest point
        ang = np.arccos(np.clip(cu @ pts.T, -1, 1)).min(axis=1)
        assert not (ang <= rec[:, K.FAR])[~got].any()  # every cap holding a point kept
        # no point near: dropped (but where the box leaves its cube face, at the corner)
        far = ang > 5.0 * rec[:, K.FAR] + 0.002
        assert far.sum() > 300 and got[far].mean() < 0.05


def test_window_directions_match_numpy():
    from latlong.ondemand.base import tangent_frame
    from latlong.ondemand.tile import tile_units

    got = tile_units(12.5, -40.0, 37, 3.0, 1000.0)
    c = units_of([12.5], [-40.0])
    e, n = tangent_frame(c)
    coords = (np.arange(37) + 0.5 - 0.5 * 37) * 3.0 / 1000.0
    v = c[0] + coords[None, :, None] * e[0] + (-coords[:, None])[..., None] * n[0]
    want = v / np.sqrt((v * v).sum(axis=-1, keepdims=True))
    assert got.tobytes() == want.tobytes()


def test_a_crater_base_is_the_fit_of_its_older_larger_craters_with_their_roughness(scene):
    # the params kernel against numpy: FIT @ (the older, larger craters' composition at
    # the crater's stencil points, roughness overlay included: at a small crater's scale a
    # large crater's overlay is a smooth offset, and leaving it out floated small craters'
    # floors metres off the ground on the Moon)
    from latlong.ondemand.field import CraterField, _stencil_points

    field = CraterField(scene)
    field.radii(units_of(np.linspace(-20, 20, 30), np.linspace(100, 130, 30)), 4.0)
    fc, rank, cr = field.last["fc"], field.last["rank"], field.last["craters"]
    stencil = _stencil_points(fc)
    tables = _reference_tables(field)
    checked = 0
    for k in np.argsort(-cr.diameter_m)[len(cr) // 3:][:12]:  # craters with larger ones
        def older_larger(j, k=k):
            return rank[j] > rank[k] and cr.diameter_m[j] > cr.diameter_m[k]

        h = [_compose_reference(field, tables, p, field.base.radius(p[None])[0], older_larger)
             - fc[k, K.RHO] for p in stencil[k]]
        coef = FIT @ np.array(h)
        radius = fc[k, K.RAD]
        want = [coef[0], coef[1] / radius, coef[2] / radius]
        assert np.allclose([fc[k, K.P0], fc[k, K.GX], fc[k, K.GY]], want, rtol=0,
                           atol=1e-6), k
        checked += 1
    assert checked == 12


def _dep_pairs_reference(owners, owner_cell, lo, hi, cand, fc, diam):
    """Every (owner, candidate) pair of the dependency kernel by brute force, in its order:
    owners as given, candidates by neighbour cell t then position."""
    pairs = []
    for o, c in zip(owners, owner_cell, strict=True):
        own = fc[o, K.RAD] / fc[o, K.RHO] * (1.0 + 1e-9)
        for t in range(9):
            for k in cand[lo[c, t]:hi[c, t]]:
                d2 = np.sum((fc[k, 0:3] - fc[o, 0:3]) ** 2)
                lim = np.sqrt(fc[k, K.CHORD2]) + 2.0 * np.sin(0.5 * own)
                if diam[k] > diam[o] and (fc[k, K.FAR] + own >= np.pi or d2 <= lim * lim):
                    pairs.append((o, k))
    return np.array(pairs, dtype=np.int64).reshape(-1, 2)


@pytest.mark.parametrize("spread", [1e-7, 1e-3, 0.3])
def test_dependency_pairs_match_brute_force(spread, rng):
    # owners clustered in three cells, candidates around them near and far, one reaching
    # everywhere
    n_own, n_cand = 300, 400
    centre = np.array([0.3, -0.2, 0.9]) / np.linalg.norm([0.3, -0.2, 0.9])
    u = centre + rng.normal(0.0, spread, (n_own + n_cand, 3))
    u[n_own:] = centre + rng.normal(0.0, 20.0 * spread, (n_cand, 3))  # spread wider
    u /= np.linalg.norm(u, axis=1)[:, None]
    fc = np.zeros((n_own + n_cand, K.N_COLS))
    fc[:, 0:3] = u
    fc[:, K.RHO] = 1000.0
    fc[:, K.RAD] = 1000.0 * spread * rng.uniform(0.01, 0.5, n_own + n_cand)
    fc[:, K.FAR] = np.minimum(3.0 * fc[:, K.RAD] / fc[:, K.RHO], np.pi)
    fc[-1, K.FAR] = np.pi
    fc[:, K.CHORD2] = (2.0 * np.sin(0.5 * fc[:, K.FAR])) ** 2
    diam = 2.0 * fc[:, K.RAD]
    diam[n_own:] += 1000.0 * spread  # candidates larger, but for a few
    diam[n_own:n_own + 20] = 0.0
    owners = rng.permutation(n_own).astype(np.int64)
    owner_cell = rng.integers(0, 3, n_own).astype(np.int64)
    cand = (np.arange(n_cand) + n_own).astype(np.int64)
    edges = np.sort(rng.integers(0, n_cand, (3, 10)), axis=1)
    lo, hi = edges[:, :9].copy(), edges[:, 1:].copy()
    o, d = K._dep_kernel(owners, owner_cell, lo, hi, cand, fc, diam)
    want = _dep_pairs_reference(owners, owner_cell, lo, hi, cand, fc, diam)
    assert 0 < len(want) < len(owners) * 0.5 * n_cand
    np.testing.assert_array_equal(np.stack([o, d], axis=1), want)
    # and the cells' candidate lists left out the candidates no owner of theirs reaches
    _, kept = K._cell_candidates(owners, owner_cell, lo, hi, cand, fc)
    assert len(kept) < (hi - lo).sum()
