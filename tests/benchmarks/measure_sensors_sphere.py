"""Measure: the camera against a sphere's closed forms (issue 17's first acceptance item).

A sphere of radius 1 km tessellated by lat/long meshes of magnitude M (``python
tests/benchmarks/measure_sensors_sphere.py [M ...]``, default 150 500 1000), seen from
2.7 km by a 320 x 240 camera (45 deg), sun from the side, Lambert and Lommel-Seeliger.
Prints, for the lit pixels away from the terminator and the limb (incidence and
emission < 80 deg) and for all lit pixels:

* the largest and median relative error of the image against the analytic sphere's
  (exact ray-sphere point and radial normal) and against the closed form evaluated at
  the rendered mesh point (the renderer's own error),
* the depth error against the analytic ray-sphere distance, in m per km of range,
  against the facets' sag (a mesh lies inside its sphere by up to edge^2 / 8R),
* the terminator: the largest |cos i| of the closed form where the lit state differs.
"""

from __future__ import annotations

import math
import sys

import numpy as np


def analytic(camera, pose, sun, radius):
    o, d = camera.rays(pose)
    d = d.reshape(-1, 3)
    od = d @ o
    disc = od**2 - (o @ o - radius * radius)
    t = np.where(disc > 0, -od - np.sqrt(np.maximum(disc, 0.0)), np.nan)
    n = (o + t[:, None] * d) / radius
    return t, n @ sun, -(n * d).sum(axis=1), -(d @ sun), d


def main():
    from latlong import LatLongGrid
    from latlong.sensors import Camera, Lambert, LommelSeeliger, Pose, RayMesh, radiance_factor
    from latlong.sensors.render import render

    radius = 1000.0
    cam = Camera.from_fov(45.0, 320, 240)
    pose = Pose.look_at([2600.0, 500.0, 300.0], [0.0, 0.0, 0.0])
    sun = np.array([0.3, 1.0, 0.4]) / np.linalg.norm([0.3, 1.0, 0.4])
    t, mu0, mu, cg, d = analytic(cam, pose, sun, radius)
    for m in [int(a) for a in sys.argv[1:]] or [150, 500, 1000]:
        g = LatLongGrid(m)
        verts = g.unit_vectors() * radius
        mesh = RayMesh(verts, g.triangles())
        edge = np.linalg.norm(np.diff(verts[g.triangles()[:2000]], axis=1), axis=2).max()
        print(f"M = {m}: {len(verts):,} vertices, longest edge {edge:.2f} m, sag "
              f"{edge**2 / (8 * radius) * 1e3:.3f} mm")
        for model in (Lambert(), LommelSeeliger()):
            fr = render(mesh, cam, pose, sun, reflectance=model, normals=verts / radius)
            img = fr.reflectance.ravel()
            lit = fr.sunlit.ravel() > 0
            an = radiance_factor(model, mu0, mu, cg)
            p = fr.position_m.reshape(-1, 3)
            n = p / np.linalg.norm(p, axis=1, keepdims=True)
            dd = (p - pose.position_m) / np.linalg.norm(p - pose.position_m, axis=1,
                                                        keepdims=True)
            own = radiance_factor(model, n @ sun, -(n * dd).sum(axis=1), -(dd @ sun))
            ok = lit & (mu0 > math.cos(math.radians(80))) & (mu > math.cos(math.radians(80)))
            rel = np.abs(img[ok] / an[ok] - 1)
            rel_all = np.abs(img[lit & (an > 0)] / an[lit & (an > 0)] - 1)
            pos_own = lit & (own > 0)
            rel_own = np.abs(img[pos_own] / own[pos_own] - 1)
            print(f"  {type(model).__name__}: vs analytic sphere (i, e < 80 deg) max "
                  f"{rel.max():.2e} median {np.median(rel):.2e}; all lit pixels max "
                  f"{rel_all.max():.2e}; vs the closed form at the rendered point max "
                  f"{rel_own.max():.2e}")
        both = np.isfinite(t) & (fr.face.ravel() >= 0)
        dz = fr.range_m.ravel().astype(np.float64)[both] - t[both]
        per_km = np.abs(dz) / (t[both] / 1000.0)
        print(f"  range vs analytic: max {per_km.max():.2e} m per km of range (median "
              f"{np.median(per_km):.2e}); inside i, e < 80 deg: "
              f"{per_km[(mu[both] > 0.17)].max():.2e}")
        differ = both & (lit != (mu0 > 0))
        print(f"  terminator: {int(differ.sum())} pixels differ from the closed form, all "
              f"within |cos i| <= {np.abs(mu0[differ]).max() if differ.any() else 0:.2e} "
              f"(a facet's angle: {edge / radius:.2e} rad)")


if __name__ == "__main__":
    main()
