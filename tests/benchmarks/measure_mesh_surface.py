"""Acceptance of a --surface mesh output: closed 2-manifold, Euler characteristic, no flip
against the refined (uncratered) model. usage: python
tests/benchmarks/measure_mesh_surface.py OUT.ply MODEL SPACING_M"""

import sys

import numpy as np
import pyvista as pv

from latlong.mesh import mesh_checks, mesh_surface
from latlong.shapes import read_shape_model


def main() -> None:
    out, model, spacing = sys.argv[1], sys.argv[2], float(sys.argv[3])
    base = mesh_surface(read_shape_model(model, units="km"), spacing)
    m = pv.read(out)
    v = np.asarray(m.points, dtype=np.float64)
    f = np.asarray(m.faces).reshape(-1, 4)[:, 1:]
    nv, nf = base.n_vertices, len(base.faces)
    whole = mesh_checks(v, f)
    body = mesh_checks(v[:nv], f[:nf])
    print("whole file (body + boulders):", whole)
    print("body:", body)
    assert np.array_equal(f[:nf], base.faces)

    def fn(p, t):
        return np.cross(p[t[:, 1]] - p[t[:, 0]], p[t[:, 2]] - p[t[:, 0]])

    dots = np.einsum("ij,ij->i", fn(base.vertices, base.faces), fn(v[:nv], f[:nf]))
    cosang = (
        dots
        / np.linalg.norm(fn(base.vertices, base.faces), axis=1)
        / np.linalg.norm(fn(v[:nv], f[:nf]), axis=1)
    )
    print(
        "flipped triangles (normal dot before/after <= 0):",
        int((dots <= 0).sum()),
        "of",
        nf,
        f"; smallest cos(turn) {cosang.min():.3f}, "
        f"largest turn {np.degrees(np.arccos(cosang.min())):.1f} deg",
    )
    moved = np.linalg.norm(v[:nv] - base.vertices, axis=1)
    print(
        f"vertices moved: {100 * (moved > 1e-3).mean():.1f} %, "
        f"largest move {moved.max():.2f} m (float32 PLY)"
    )


if __name__ == "__main__":
    main()
