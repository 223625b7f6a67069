"""The lat/long body's writer of a crater made in the frame of its tilted base (split
from :mod:`latlong._crater_kernels`; the frame and the root: :mod:`craters.kernels`,
``tilted_frame``, ``tilted_coords``, ``tilted_root``; issue 36: on steep ground the
radial frame squeezed craters along the dip into streaks)."""

from __future__ import annotations

from numba import njit

from craters.kernels import outer_weight, table, tilted_coords, tilted_ejecta, tilted_root


@njit(cache=True)
def _tilted_change(q, xl, yl, hgt, radius, tab, scale, depth, xe, rim_tab, delta, p0, qa, qb,
                   qc, rough, seed, wavelength, octaves, gain, fr):
    """(inside the ejecta edge?, radial height change) of point ``q`` for a crater stamped
    in the frame ``fr`` of its tilted base (:func:`craters.kernels.tilted_frame`; issue 36: on steep
    ground the radial frame squeezes a crater along the dip into a streak).

    The point is taken at its foot on the base plane (where its radial line meets it),
    which has in-plane coordinates u: the crater is the same function of u as
    :func:`_height_change` is of (x, y), and the field's (``latlong.ondemand``): inside
    the rim the terrain is replaced by the base plane plus the profile and roughness (the
    quadric's curvature added radially), outside the profile (over N_z: the ejecta are
    thin), the rim offset fading to the edge and roughness are added. The vertex can only
    move radially (the lat/long mesh), which also moves it along the base by
    ``t (E'_z, N'_z)``: inside the rim the radial change t from the foot solves
    ``t N_z = W(u(t))`` (bracketed, then false position). Deciding inside and outside at
    the vertex's own position instead caught vertices far off a poorly fitted base (its
    radial line meeting the crater's surface beyond the rim) and moved them up to 40 m at
    a 13 m crater on 44 deg ground."""
    cz = fr[9]
    r0, r1 = xl[q], yl[q]
    r2 = -(fr[6] * r0 + fr[7] * r1) / fr[8]  # the foot on the base plane (N = (-gx, -gy, 1) / l)
    u1, u2, w0, az, x = tilted_coords(r0, r1, r2, fr, radius, rim_tab)
    if not x < xe:
        return False, 0.0
    has_rough = rough[0] > 0.0 or rough[1] > 0.0 or rough[2] > 0.0
    if x > 1.0:
        return True, (tilted_ejecta(x, xe, u1, u2, tab, scale, depth, rough, has_rough, seed,
                                    wavelength, octaves, gain, cz)
                      + table(delta, az) * outer_weight(x, xe))
    # the crater over its base plane in the plane's frame, and the base's curvature (the
    # quadric's quadratic part) radially, as outside the rim (where the rim offset takes
    # the terrain to the quadric): the rim is continuous whatever the curvature (with the
    # curvature along the normal, 37 m apart at a 663 m crater in a larger one's bowl)
    t = tilted_root(u1, u2, w0, radius, tab, scale, depth, xe, rim_tab, rough, rough[3],
                    has_rough, seed, wavelength, octaves, gain, fr)
    return True, (p0 + r2 + (qa * r0 * r0 + qb * r0 * r1 + qc * r1 * r1) + t) - hgt[q]
