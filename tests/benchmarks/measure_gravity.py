"""Issue 16 item 4 acceptance: M = 1000 gravitational slopes (time, RMS vs direct
evaluations at 10 000 sample vertices) and the sphere/ellipsoid closed forms at M = 1000.
Run: python tests/benchmarks/measure_gravity.py (needs the gravity extra; ~1 min)"""

import math
import time

import numpy as np
from scipy.special import elliprd

from latlong import Body, LatLongGrid, gravity, slopes_and_areas
from latlong.gravity import GRAVITATIONAL_CONSTANT as G
from latlong.gravity import polyhedron_gravity


def main() -> None:
    RHO, R = 2670.0, 10000.0

    def angle(a, b):
        return np.degrees(
            np.arctan2(np.linalg.norm(np.cross(a, b), axis=1), np.einsum("ij,ij->i", a, b))
        )

    # ---------------------------------------------------------------- M = 1000 body
    g = LatLongGrid(1000)
    lat, lon = g.latitudes(), g.longitudes()
    radii = R * (
        1
        + 0.06 * np.sin(2 * lon) * np.cos(lat) ** 2
        + 0.04 * np.sin(3 * lat)
        + 0.004 * np.sin(23 * lon) * np.sin(17 * lat)
        + 0.001 * np.sin(97 * lon + 3 * lat)
    )
    body = Body(g, radii, stretch=(1.7, 1.0, 0.8))
    t0 = time.perf_counter()
    field = gravity(body, RHO, 5.27)
    t1 = time.perf_counter()
    s, area = slopes_and_areas(body, 3.0, gravity=field)
    t2 = time.perf_counter()
    print(
        f"M=1000 ({g.n_vertices} vertices): gravity {t1 - t0:.1f} s (LOD {field.source_facets} "
        f"facets at {field.evaluated_points} points), slopes {t2 - t1:.1f} s, total "
        f"{t2 - t0:.1f} s; median gravitational slope {np.median(s):.2f} deg"
    )
    geo, _ = slopes_and_areas(body, 3.0)
    rng = np.random.default_rng(16)
    sample = np.sort(rng.choice(g.n_vertices, 10000, replace=False))
    pos = body.vertices()
    omega = 2 * math.pi / (5.27 * 3600)
    down = -field.effective_m_s2[sample]

    def effective(acc, centre):
        x = pos[sample] - centre
        return acc + omega**2 * (x * [1, 1, 0])

    def grav_slope(eff):
        # the slope is the angle between the cap-averaged normal and -g_eff; the normal is
        # recovered from the field's slope: compare fields directly (slope error <= angle)
        return angle(-eff, down)

    centre = pos.mean(axis=0) * 0
    for mref in (field.evaluated_points and int(round(math.sqrt(field.evaluated_points / 6))), 64):
        cg = LatLongGrid(mref)
        cr = g.surface_radii(radii, np.pi / 2 - cg.latitudes(), cg.longitudes())
        cv = cg.unit_vectors() * (cr[:, None] * body.stretch)
        cf = cg.triangles()
        a = cv[cf[:, 0]]
        vol = np.einsum("ij,ij->i", a, np.cross(cv[cf[:, 1]], cv[cf[:, 2]]))
        centre = ((a + cv[cf[:, 1]] + cv[cf[:, 2]]) * vol[:, None]).sum(0) / (4 * vol.sum())
        t = time.perf_counter()
        _, acc = polyhedron_gravity(cv, cf, RHO, pos[sample] * (1 + 1e-7))
        err = angle(effective(acc, centre), -down)
        print(
            f"direct evaluation at the 10000 sample vertices, source M={mref} ({len(cf)} "
            f"facets, {time.perf_counter() - t:.0f} s): RMS field-direction (= slope) error "
            f"{np.sqrt(np.mean(err**2)):.3f} deg, max {err.max():.3f} deg"
        )
    # the full M = 1000 polyhedron (12 M facets) at 24 of the sample vertices
    v = pos
    f = g.triangles()
    few = sample[:: len(sample) // 24][:24]
    t = time.perf_counter()
    _, acc = polyhedron_gravity(v, f, RHO, v[few] * (1 + 1e-7), chunk=8)
    x = v[few] - centre
    err = angle(acc + omega**2 * (x * [1, 1, 0]), field.effective_m_s2[few])
    print(
        f"full M=1000 polyhedron ({len(f)} facets) at 24 sample vertices "
        f"({time.perf_counter() - t:.0f} s): RMS {np.sqrt(np.mean(err**2)):.3f} deg, "
        f"max {err.max():.3f} deg"
    )
    del v, f

    # ---------------------------------------------------------------- closed forms, M = 1000
    for stretch in ((1.0, 1.0, 1.0), (1.5, 1.0, 0.8)):
        sb = Body.sphere(LatLongGrid(1000), 1000.0, stretch=stretch)
        v, f = sb.vertices(), sb.grid.triangles()
        idx = np.linspace(0, len(v) - 1, 6).astype(int)[1:-1]
        pts = v[idx] * (1 + 1e-9)
        t = time.perf_counter()
        _, acc = polyhedron_gravity(v, f, RHO, pts, chunk=4)
        axes = 1000.0 * np.asarray(stretch)
        a2 = axes**2
        coef = [
            np.prod(axes) * 2 / 3 * elliprd(a2[(i + 1) % 3], a2[(i + 2) % 3], a2[i])
            for i in range(3)
        ]
        want = -2 * math.pi * G * RHO * np.asarray(coef) * pts
        rel = np.linalg.norm(acc - want, axis=1) / np.linalg.norm(want, axis=1)
        print(
            f"{'sphere' if stretch[0] == 1 else 'ellipsoid 1.5:1:0.8'} M=1000 polyhedron "
            f"({len(f)} facets, {time.perf_counter() - t:.0f} s) vs closed form at 4 surface "
            f"points: max relative error {rel.max():.2e}"
        )
        del v, f


if __name__ == "__main__":
    main()
