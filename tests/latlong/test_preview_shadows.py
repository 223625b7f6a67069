"""Previews (``latlong render``, ``--preview``) cast shadows through the sensors' engine."""

from __future__ import annotations

import numpy as np
from PIL import Image

from latlong import LatLongGrid
from latlong.preview import (
    AMBIENT,
    SURFACE_RGB,
    camera_frame,
    preview_view,
    render_preview,
    sun_direction,
)


def _sphere(radius, centre, magnitude=40):
    g = LatLongGrid(magnitude)
    return g.unit_vectors() * radius + np.asarray(centre), g.triangles()


def _pixel(png, xy):
    img = np.asarray(Image.open(png))
    return img[int(xy[1]), int(xy[0])]


def test_a_second_body_casts_its_shadow_on_the_first(tmp_path):
    sun = sun_direction(60.0, 20.0)
    big_v, big_f = _sphere(100.0, [0.0, 0.0, 0.0])
    small_v, small_f = _sphere(20.0, 170.0 * sun)
    both = (np.concatenate([big_v, small_v]), np.concatenate([big_f, small_f + len(big_v)]))
    spot = 100.0 * sun  # the big sphere's sub-solar point: in the small one's shadow
    alone, pair = tmp_path / "alone.png", tmp_path / "pair.png"
    render_preview((big_v, big_f), alone, width_px=200, height_px=160)
    render_preview(both, pair, width_px=200, height_px=160)
    view = camera_frame(0.0, -90.0)
    cam, pose = preview_view(both[0], view, 200, 160)
    xy, z = cam.project(spot[None], pose)
    assert z[0] > 0 and 0 <= xy[0, 0] < 200 and 0 <= xy[0, 1] < 160
    shadowed = int(round(AMBIENT * SURFACE_RGB[0] * 255))
    assert abs(int(_pixel(pair, xy[0])[0]) - shadowed) <= 1  # ambient only
    cam1, pose1 = preview_view(big_v, view, 200, 160)
    xy1, _ = cam1.project(spot[None], pose1)
    assert _pixel(alone, xy1[0])[0] > 0.9 * 255 * SURFACE_RGB[0]  # lit, ~ head-on


def test_lit_pixels_follow_lambert(tmp_path):
    """On a lone sphere every lit pixel is colour x (ambient + cos i) within rounding and
    the smooth normal's facet error (M = 40)."""
    v, f = _sphere(100.0, [0.0, 0.0, 0.0])
    png = tmp_path / "s.png"
    render_preview((v, f), png, width_px=160, height_px=160, sun_azimuth_deg=30.0,
                   sun_elevation_deg=10.0)
    img = np.asarray(Image.open(png))[..., 0].astype(float)
    cam, pose = preview_view(v, camera_frame(0.0, -90.0), 160, 160)
    origin, dirs = cam.rays(pose)
    d = dirs.reshape(-1, 3)
    o = np.asarray(origin).reshape(-1, 3)[0]
    b = d @ o
    disc = b * b - (o @ o - 100.0**2)
    hit = disc > 0
    t = -b[hit] - np.sqrt(disc[hit])
    n = (o + t[:, None] * d[hit]) / 100.0
    sun = sun_direction(30.0, 10.0)
    expect = np.clip(AMBIENT + np.clip(n @ sun, 0, None), 0, None) * SURFACE_RGB[0] * 255
    got = img.reshape(-1)[hit]
    inner = (n @ -pose.rotation[:, 2]) > 0.3  # away from the limb's facets
    assert np.abs(got[inner] - expect[inner]).max() < 4.0


def test_extent_kernel_matches_numpy():
    from latlong._preview_kernels import _extent_kernel

    rng = np.random.default_rng(4)
    v = rng.normal(size=(500, 3)) * [300.0, 200.0, 100.0] + 50.0
    centre = 0.5 * (v.min(axis=0) + v.max(axis=0))
    view, right, up = camera_frame(20.0, 35.0)
    out = np.empty(3)
    _extent_kernel(v, centre, view, right, up, out)
    rel = v - centre
    np.testing.assert_allclose(out, [(rel @ view).max(), np.abs(rel @ right).max(),
                                     np.abs(rel @ up).max()], rtol=1e-14)
