"""Compare: the camera's smooth shading against Mitsuba 3's with Mitsuba's own vertex
normals (issue 33: "camera shading of a mesh equals Mitsuba's with Mitsuba's own normals
to the tolerance of the same-normals comparison").

Mesh: a rough body (magnitude ``--magnitude``, radius 100 m, +-8 % Perlin-like relief)
written as a PLY without normals, so Mitsuba computes its own. The same pixel-centre rays
are cast in both: Mitsuba's ``scene.ray_intersect`` gives its interpolated shading normal
(``si.sh_frame.n``), craterform's ``render`` its frame's ``normals``. Reported: the angle
between the two normals and the relative difference of Lambert's I/F (cos i) at those
points, for the camera's weighting (angle) and, for comparison, the area and Max (1999)
weightings the project used before (``render(normals=...)``).

Usage: ``python tests/benchmarks/compare_normals_mitsuba.py [--magnitude 60] [--size 96]``
(needs ``pip install mitsuba``).
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

import numpy as np

from latlong import LatLongGrid
from latlong.geometry.normals import vertex_normals
from latlong.sensors import Camera, Lambert, Pose, RayMesh
from latlong.sensors.render import render

sys.path.insert(0, str(Path(__file__).parent))
from compare_bounce_mitsuba import write_ply  # noqa: E402

SUN = np.array([0.6, -0.3, 0.75]) / np.linalg.norm([0.6, -0.3, 0.75])


def rough_body(m: int) -> tuple[np.ndarray, np.ndarray]:
    g = LatLongGrid(m)
    u = g.unit_vectors()
    r = 100.0 * (1.0 + 0.04 * np.sin(9 * u[:, 0] + 2) * np.cos(7 * u[:, 1])
                 + 0.04 * np.sin(11 * u[:, 2] + 1.3 * u[:, 0]))
    return u * r[:, None], g.triangles()


def mitsuba_normals(ply: Path, origin, dirs) -> tuple[np.ndarray, np.ndarray]:
    import mitsuba as mi

    mi.set_variant("scalar_rgb")
    scene = mi.load_dict({"type": "scene", "m": {"type": "ply", "filename": str(ply)}})
    n, hit = np.full((len(dirs), 3), np.nan), np.zeros(len(dirs), dtype=bool)
    o = mi.ScalarPoint3f(*[float(x) for x in origin])
    for k, d in enumerate(dirs):
        si = scene.ray_intersect(mi.Ray3f(o, mi.ScalarVector3f(*[float(x) for x in d])))
        if si.is_valid():
            hit[k] = True
            n[k] = [float(x) for x in si.sh_frame.n]
    return n, hit


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--magnitude", type=int, default=60)
    ap.add_argument("--size", type=int, default=96)
    args = ap.parse_args()
    v, f = rough_body(args.magnitude)
    mesh = RayMesh(v, f)
    cam = Camera.from_fov(40.0, args.size, args.size)
    pose = Pose.look_at([260.0, 90.0, 140.0], [0.0, 0.0, 0.0], up=(0.0, 0.0, 1.0))
    origin, dirs = cam.rays(pose)
    dirs = dirs.reshape(-1, 3)
    with tempfile.TemporaryDirectory() as tmp:
        ply = Path(tmp) / "body.ply"
        write_ply(ply, v, f)
        mn, mhit = mitsuba_normals(ply, origin.reshape(3), dirs)
    for label, normals in (("angle (the camera's)", "smooth"),
                           ("area", vertex_normals(v, f, "area")),
                           ("max", vertex_normals(v, f, "max"))):
        fr = render(mesh, cam, pose, SUN, reflectance=Lambert(0.3), normals=normals)
        ours = fr.normals.reshape(-1, 3).astype(np.float64)
        both = mhit & (fr.face.ravel() >= 0)
        # Mitsuba turns the shading normal to the geometric normal's side, as we do
        cos = np.clip((ours[both] * mn[both]).sum(axis=1), -1.0, 1.0)
        ang = np.degrees(np.arccos(np.abs(cos)))
        mu_m = mn[both] @ SUN * np.sign(cos)
        mu_o = ours[both] @ SUN
        lit = (mu_m > 0.05) & (mu_o > 0.05)
        rel = np.abs(mu_o[lit] / mu_m[lit] - 1.0)
        print(f"{label:22s} pixels {both.sum():6d}: normal angle median {np.median(ang):.2e} "
              f"deg, max {ang.max():.2e} deg; Lambert I/F relative difference median "
              f"{np.median(rel):.2e}, 99th percentile {np.percentile(rel, 99):.2e}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
