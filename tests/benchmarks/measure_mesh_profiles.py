"""Single craters (no roughness, no slope erosion) on the refined Itokawa mesh (1 m request):
the crater as stamped = new height minus the base it was stamped on (inside the rim: the
quadric fitted to the old surface within the rim radius, as the kernel does; outside: the
old surface), compared with craters.radial_profile at the vertices' true in-plane distances.
Usage: python tests/benchmarks/measure_mesh_profiles.py sphere|itokawa N_SITES [D_SPACINGS]."""

import sys

import numpy as np
import pyvista as pv

import craters
from latlong.mesh import mesh_surface, stamp_mesh_craters
from latlong.shapes import read_shape_model


def main() -> None:
    which = sys.argv[1] if len(sys.argv) > 1 else "itokawa"
    if which == "itokawa":
        s = mesh_surface(read_shape_model("tests/data/itokawa_32.obj", units="km"), 1.0)
    else:  # a smooth closed mesh: an icosphere of 1 km (as the body test's sphere)
        from latlong.shapes import ShapeModel

        ico = pv.Icosphere(radius=1000.0, nsub=4)
        s = mesh_surface(
            ShapeModel(np.asarray(ico.points, float), np.asarray(ico.faces).reshape(-1, 4)[:, 1:]),
            8.0,
        )
    sp = s.mean_edge_m
    d = float(sys.argv[3]) * sp if len(sys.argv) > 3 else 20 * sp
    depth = float(craters.fresh_morphometry(d)["depth_m"])
    rng = np.random.default_rng(3)
    errs, errs_dh = [], []
    skipped = 0
    for k in rng.choice(s.n_vertices, int(sys.argv[2]) if len(sys.argv) > 2 else 12, replace=False):
        c = s.vertices[k]
        cat = craters.make_catalog(
            lat_deg=[0.0],
            lon_deg=[0.0],
            diameter_m=[d],
            centre_x_m=[c[0]],
            centre_y_m=[c[1]],
            centre_z_m=[c[2]],
        )
        out = stamp_mesh_craters(s, cat, roughness=False, slope_erosion=False)
        if len(out.craters) == 0:
            skipped += 1
            continue
        row = out.craters[0]
        up = np.array([row["normal_x"], row["normal_y"], row["normal_z"]])
        cen = np.array([row["centre_x_m"], row["centre_y_m"], row["centre_z_m"]])
        e = np.cross(up, [0, 0, 1.0] if abs(up[2]) < 0.9 else [1.0, 0, 0])
        e /= np.linalg.norm(e)
        n = np.cross(up, e)
        r = s.vertices - cen
        moved = out.heights_m != s.heights_m
        X, Y, H = r @ e, r @ n, r @ up
        dist = np.hypot(X, Y)
        A = np.stack([np.ones_like(X), X, Y, X * X, X * Y, Y * Y], 1)
        fit = moved & (dist <= d / 2)
        coef, *_ = np.linalg.lstsq(A[fit], H[fit], rcond=None)
        newH = (out.vertices - cen) @ up
        base = np.where(
            dist <= row["rim_radius_m"] if "rim_radius_m" in row.dtype.names else dist <= d / 2,
            A @ coef,
            H,
        )
        sel = moved | ((dist < 1.4 * d) & (np.abs(H) < d))
        sel &= dist < 1.4 * d
        want = craters.radial_profile(dist[sel] / (d / 2), d)
        ee = np.abs(newH[sel] - base[sel] - want) / depth
        ins = dist[sel] <= d / 2
        print(
            f"  inside {ee[ins].max():.4f} outside {ee[~ins].max():.4f}  "
            f"at x={dist[sel][np.argmax(ee)] / (d / 2):.2f}"
        )
        errs.append(ee.max())
        errs_dh.append(np.abs((out.heights_m - s.heights_m)[sel] - want).max() / depth)
    errs, errs_dh = np.array(errs), np.array(errs_dh)
    print(
        f"{which}: spacing {sp:.3f} m, D {d:.2f} m, depth {depth:.3f} m, "
        f"{len(errs)} sites stamped, {skipped} left out"
    )
    print(
        f"crater as stamped vs radial_profile, max |error| / depth: "
        f"median {np.median(errs):.4f}  max {errs.max():.4f}"
    )
    print(
        "height change vs radial_profile (includes the obliterated old relief), max |error| / "
        f"depth: median {np.median(errs_dh):.4f}  min {errs_dh.min():.4f} max {errs_dh.max():.4f}"
    )
    print(
        f"sites with height change within 2 % of the depth: {(errs_dh <= 0.02).sum()} of "
        f"{len(errs_dh)}"
    )
    print("inside the rim: see above")


if __name__ == "__main__":
    main()
