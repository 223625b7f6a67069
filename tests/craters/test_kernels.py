"""The shared numba building blocks of ``craters.kernels`` against pure numpy/Python."""

from __future__ import annotations

import numpy as np
import pytest

import craters
from craters import kernels as K

MASK = 2**64 - 1


def reference_mix64(z: int) -> int:
    """splitmix64 finaliser (Steele, Lea & Flood) in Python integers."""
    z = ((z ^ (z >> 30)) * 0xBF58476D1CE4E5B9) & MASK
    z = ((z ^ (z >> 27)) * 0x94D049BB133111EB) & MASK
    return z ^ (z >> 31)


def reference_hash_normal(a: int) -> float:
    b = reference_mix64((a + 0x9E3779B97F4A7C15) & MASK)
    u1 = ((a >> 11) + 1) * 2.0**-53
    u2 = (b >> 11) * 2.0**-53
    return float(np.sqrt(-2.0 * np.log(u1)) * np.cos(2.0 * np.pi * u2))


@pytest.mark.parametrize("z", [0, 1, 12345, 2**63 - 1, 2**64 - 1, 0x9E3779B97F4A7C15])
def test_mix64_splitmix64_hash_normal_match_python(z):
    u = np.uint64(z)
    assert int(K.mix64(u)) == reference_mix64(z)
    assert int(K.splitmix64(u)) == reference_mix64((z + 0x9E3779B97F4A7C15) & MASK)
    assert K.hash_normal(u) == pytest.approx(reference_hash_normal(z), rel=1e-14, abs=1e-14)


def reference_bilinear(h, fy, fx, blend):
    """Pure numpy: NaN outside the cell centres, else the two-step linear blend."""
    ny, nx = h.shape
    if not (0 <= fy <= ny - 1 and 0 <= fx <= nx - 1):
        return np.nan
    i0, j0 = min(int(np.floor(fy)), max(ny - 2, 0)), min(int(np.floor(fx)), max(nx - 2, 0))
    i1, j1 = min(i0 + 1, ny - 1), min(j0 + 1, nx - 1)
    ty, tx = fy - i0, fx - j0
    if blend:
        a = (1 - tx) * h[i0, j0] + tx * h[i0, j1]
        b = (1 - tx) * h[i1, j0] + tx * h[i1, j1]
        return (1 - ty) * a + ty * b
    a = h[i0, j0] + tx * (h[i0, j1] - h[i0, j0])
    b = h[i1, j0] + tx * (h[i1, j1] - h[i1, j0])
    return a + ty * (b - a)


@pytest.mark.parametrize("shape", [(1, 1), (1, 5), (4, 1), (6, 7)])
@pytest.mark.parametrize("blend", [False, True])
def test_bilinear_matches_reference(rng, shape, blend):
    h = rng.normal(size=shape)
    pts = rng.uniform(-1.0, max(shape) + 0.5, size=(300, 2))
    pts[:10] = [[0, 0], [shape[0] - 1, shape[1] - 1], [np.nan, 0], [0, np.nan],
                [-1e-300, 0], [0, shape[1] - 1 + 1e-12], [0.5, 0.5], [shape[0] - 1, 0],
                [0, shape[1] - 1], [0.25, 0]]
    for fy, fx in pts:
        got = K.bilinear(h, fy, fx, blend)
        want = reference_bilinear(h, fy, fx, blend)
        assert got == want or (np.isnan(got) and np.isnan(want))
    # both forms are the same interpolation; exact at the cell centres and on a plane
    i, j = np.mgrid[: shape[0], : shape[1]]
    plane = 2.0 + 0.5 * i - 0.25 * j
    for fy, fx in pts[10:]:
        if 0 <= fy <= shape[0] - 1 and 0 <= fx <= shape[1] - 1:
            assert K.bilinear(plane, fy, fx, blend) == pytest.approx(2.0 + 0.5 * fy - 0.25 * fx)


def plane_sums(x, y, h):
    s = K.PLANE_SUMS0
    for xq, yq, hq in zip(x, y, h, strict=True):
        s = K.plane_sums_add(s, xq, yq, hq)
    return s


def test_plane_sums_and_solve_match_lstsq(rng):
    x, y = rng.uniform(-5, 5, 40), rng.uniform(-5, 5, 40)
    h = 1.5 + 0.3 * x - 0.7 * y + 0.01 * rng.standard_normal(40)
    s = plane_sums(x, y, h)
    np.testing.assert_allclose(s, [40, x.sum(), y.sum(), (x * x).sum(), (y * y).sum(),
                                   (x * y).sum(), h.sum(), (h * x).sum(), (h * y).sum()])
    ok, p0, gx, gy = K.plane_solve(s, 1.0)
    want = np.linalg.lstsq(np.stack([np.ones(40), x, y], 1), h, rcond=None)[0]
    assert ok
    np.testing.assert_allclose([p0, gx, gy], want, rtol=1e-10, atol=1e-12)


@pytest.mark.parametrize("n", [0, 1, 2])
def test_plane_solve_refuses_too_few_points(n):
    s = plane_sums(np.arange(n, dtype=float), np.zeros(n), np.ones(n))
    assert K.plane_solve(s, 0.0) == (False, 0.0, 0.0, 0.0)


def test_plane_solve_refuses_collinear_points():
    x = np.arange(6, dtype=float)
    s = plane_sums(x, 2.0 * x, x)
    assert not K.plane_solve(s, s[0] * (s[3] + s[4]) ** 2)[0]


def test_fit_plane_matches_lstsq_and_falls_back(rng):
    h = 3.0 + 0.2 * np.arange(15)[:, None] - 0.1 * np.arange(12)[None, :]
    h = h + 0.01 * rng.standard_normal(h.shape)
    cy, cx, r_px, pixel = 7.3, 5.6, 4.2, 2.0
    p0, gx, gy, n = K.fit_plane(h, cy, cx, r_px, pixel)
    i, j = np.mgrid[: h.shape[0], : h.shape[1]]
    sel = (j - cx) ** 2 + (i - cy) ** 2 <= r_px**2
    a = np.stack([np.ones(sel.sum()), j[sel] - cx, i[sel] - cy], 1)
    want = np.linalg.lstsq(a, h[sel], rcond=None)[0]
    assert n == sel.sum()
    np.testing.assert_allclose([p0, gx * pixel, gy * pixel], want, rtol=1e-10)
    # too few pixels: flat at the (clamped) bilinear height of the centre
    p0, gx, gy, n = K.fit_plane(h, -3.5, 40.0, 0.4, pixel)
    assert (p0, gx, gy, n) == (h[0, -1], 0.0, 0.0, 0.0)


def reference_idw8(z, known, r, c, step_len, empty):
    acc = wsum = 0.0
    for d, (dr, dc) in enumerate(zip((-1, -1, -1, 0, 0, 1, 1, 1),
                                     (-1, 0, 1, -1, 1, -1, 0, 1), strict=True)):
        k = 1
        while 0 <= r + k * dr < z.shape[0] and 0 <= c + k * dc < z.shape[1]:
            if known[r + k * dr, c + k * dc]:
                w = 1.0 / (k * step_len[d])
                acc += w * z[r + k * dr, c + k * dc]
                wsum += w
                break
            k += 1
    return acc / wsum if wsum > 0 else empty


@pytest.mark.parametrize("frac", [0.0, 0.1, 0.6, 1.0])
def test_idw8_matches_reference(rng, frac):
    z = rng.normal(size=(7, 9))
    known = rng.random(z.shape) < frac
    step = np.array([1.5, 1.2, 1.5, 0.9, 0.9, 1.5, 1.2, 1.5])
    np.testing.assert_array_equal(K.DR8, [-1, -1, -1, 0, 0, 1, 1, 1])
    np.testing.assert_array_equal(K.DC8, [-1, 0, 1, -1, 1, -1, 0, 1])
    for r in range(z.shape[0]):
        for c in range(z.shape[1]):
            got = K.idw8(z, known, r, c, step, -7.0)
            assert got == pytest.approx(reference_idw8(z, known, r, c, step, -7.0), rel=1e-14)


@pytest.mark.parametrize("slope", [0.0, 10.0, 20.0, 30.0, 44.9, 60.0])
def test_slope_factor_is_linear_in_slope(slope):
    frac = np.clip((slope - 20.0) / 25.0, 0.0, 1.0)
    assert K.slope_factor(slope, 20.0, 45.0) == pytest.approx(1.0 - frac)
    # the relief kept: degradation d becomes d + (1 - d) frac, as craters.slope_erosion
    kept = (1.0 - 0.2) * K.slope_factor(slope, 20.0, 45.0)
    assert 1.0 - kept == pytest.approx(float(craters.slope_erosion(0.2, slope)))


def catmull_rom_table(tab, x, xe):
    """numpy reference of the stamping kernels' profile lookup (``craters.kernels.
    table_value``): the Catmull-Rom spline through the table's samples over [0, xe], even
    about 0, zeros beyond the last sample, 0 at and beyond ``xe``."""
    tab = np.asarray(tab, dtype=np.float64)
    x = np.asarray(x, dtype=np.float64)
    n = len(tab)
    ext = np.concatenate([[tab[1]], tab, [0.0, 0.0]])  # ext[j + 1] = tab[j]
    f = x / xe * (n - 1)
    i = np.clip(np.floor(f).astype(np.int64), 0, n - 2)
    t = f - i
    p0, p1, p2, p3 = ext[i], ext[i + 1], ext[i + 2], ext[i + 3]
    # the cardinal (tension 0.5) Hermite form: tangents (p2 - p0) / 2, (p3 - p1) / 2
    h00, h10 = 2 * t**3 - 3 * t**2 + 1, t**3 - 2 * t**2 + t
    h01, h11 = -2 * t**3 + 3 * t**2, t**3 - t**2
    v = h00 * p1 + h10 * 0.5 * (p2 - p0) + h01 * p2 + h11 * 0.5 * (p3 - p1)
    return np.where(f >= n - 1, 0.0, v)


def test_table_value_is_the_c1_catmull_rom_spline(rng):
    from craters._stamp_kernels import _table_kernel

    tabs = rng.normal(size=(3, 256))
    grid = np.linspace(0.0, 3.0, 256)
    x = np.concatenate([rng.uniform(0.0, 3.2, 500), grid[:7], [3.0, 3.0 - 1e-12, 5.0]])
    out = np.empty((3, len(x)))
    _table_kernel(tabs, x, 3.0, out)
    for c in range(3):
        assert np.allclose(out[c], catmull_rom_table(tabs[c], x, 3.0), rtol=0,
                           atol=1e-12)
    # through the samples, and C1: the slope on both sides of a sample agrees
    assert np.array_equal(out[0, 500:507], tabs[0, :7])
    h = 1e-7
    at = grid[10:200:7]
    left, mid, right = (np.empty((3, len(at))) for _ in range(3))
    for arr, dx in ((left, -h), (mid, 0.0), (right, h)):
        _table_kernel(tabs, at + dx, 3.0, arr)
    slope_l, slope_r = (mid - left) / h, (right - mid) / h
    assert np.allclose(slope_l, slope_r, rtol=0, atol=1e-4 * np.abs(slope_l).max())
    # zero slope on the axis
    near0 = np.empty((3, 1))
    _table_kernel(tabs, np.array([1e-9]), 3.0, near0)
    assert np.allclose(near0[:, 0], tabs[:, 0], rtol=0, atol=1e-9)


def test_table_row_value_is_table_value_of_the_row(rng):
    from craters._stamp_kernels import _table_kernel, _table_rows_kernel

    tabs = rng.normal(size=(3, 256))
    x = np.concatenate([rng.uniform(0.0, 3.2, 500), np.linspace(0.0, 3.0, 256)[:7],
                        [3.0, 3.0 - 1e-12, 5.0, 0.0]])
    by_view, in_place = np.empty((3, len(x))), np.empty((3, len(x)))
    _table_kernel(tabs, x, 3.0, by_view)
    _table_rows_kernel(tabs, x, 3.0, in_place)
    assert by_view.tobytes() == in_place.tobytes()


def test_azimuth_table_row_is_the_periodic_interpolation_of_the_row(rng):
    from numba import njit

    from craters._stamp_kernels import _table, _table_row

    @njit
    def both(tabs, theta, by_view, in_place):
        for c in range(tabs.shape[0]):
            for i in range(theta.shape[0]):
                by_view[c, i] = _table(tabs[c], theta[i])
                in_place[c, i] = _table_row(tabs, c, theta[i])

    tabs = rng.normal(size=(3, 64))
    theta = np.concatenate([rng.uniform(-np.pi, np.pi, 500), [-np.pi, 0.0, np.pi - 1e-12,
                                                              np.pi, 4.0, -4.0]])
    by_view, in_place = np.empty((3, len(theta))), np.empty((3, len(theta)))
    both(tabs, theta, by_view, in_place)
    assert by_view.tobytes() == in_place.tobytes()
    # numpy: linear between the 64 samples at -pi + 2 pi k / 64, periodic
    grid = -np.pi + 2.0 * np.pi * np.arange(65) / 64.0
    for c in range(3):
        want = np.interp(np.mod(theta + np.pi, 2.0 * np.pi) - np.pi, grid,
                         np.append(tabs[c], tabs[c, 0]))
        np.testing.assert_allclose(in_place[c], want, rtol=0, atol=1e-12)


@pytest.mark.parametrize(("wavelength", "spacing"), [(1.0, 1.0), (8.0, 1.0), (9.0, 1.0),
                                                     (1e6, 1.0), (100.0, 3.0)])
def test_roughness_octaves(wavelength, spacing):
    want = 1
    while want < 10 and wavelength / 2.0**want >= 2.0 * spacing:
        want += 1
    assert K.roughness_octaves(wavelength, spacing) == want
    assert 1 <= want <= 10


def test_azimuth_table_is_periodic_linear_interpolation_at_any_angle(rng):
    """``table`` (the rim and offset tables) against numpy's periodic ``interp``, over
    [-pi, pi) where no integer division is taken, at its ends, and outside it."""
    tab = rng.normal(size=K.N_RIM)
    samples = -np.pi + 2.0 * np.pi * np.arange(K.N_RIM) / K.N_RIM
    inside = np.concatenate([rng.uniform(-np.pi, np.pi, 400), samples,
                             [-np.pi, np.nextafter(np.pi, 0.0), np.pi]])
    outside = np.concatenate([rng.uniform(-9.0, -np.pi, 50), rng.uniform(np.pi, 9.0, 50)])
    for theta in np.concatenate([inside, outside]):
        want = np.interp(theta, samples, tab, period=2.0 * np.pi)
        assert K.table(tab, theta) == pytest.approx(want, abs=1e-12)
    assert K.table(tab, -np.pi) == tab[0]


GRAD8 = [(1.0, 0.0), (0.70710678118654752, 0.70710678118654752), (0.0, 1.0),
         (-0.70710678118654752, 0.70710678118654752), (-1.0, 0.0),
         (-0.70710678118654752, -0.70710678118654752), (0.0, -1.0),
         (0.70710678118654752, -0.70710678118654752)]


def reference_noise2(seed: int, x: float, y: float) -> float:
    """The roughness noise in Python integers: each corner's key from its own lattice
    index (the kernel adds the key step instead of multiplying again)."""
    ix, iy = int(np.floor(x)), int(np.floor(y))
    fx, fy = x - np.floor(x), y - np.floor(y)

    def corner(cx, cy, dx, dy):
        key = ((cx * 0x9E3779B97F4A7C15) & MASK) ^ ((cy * 0xC2B2AE3D27D4EB4F) & MASK)
        g = GRAD8[reference_mix64(((seed ^ key) * 0x9E3779B97F4A7C15) & MASK) & 7]
        return g[0] * dx + g[1] * dy

    u = fx * fx * fx * (fx * (fx * 6.0 - 15.0) + 10.0)
    v = fy * fy * fy * (fy * (fy * 6.0 - 15.0) + 10.0)
    n00, n10 = corner(ix, iy, fx, fy), corner(ix + 1, iy, fx - 1.0, fy)
    n01, n11 = corner(ix, iy + 1, fx, fy - 1.0), corner(ix + 1, iy + 1, fx - 1.0, fy - 1.0)
    a = n00 + u * (n10 - n00)
    b = n01 + u * (n11 - n01)
    return a + v * (b - a)


def test_fbm2_matches_python_integers_bit_for_bit(rng):
    # one octave is the noise itself (divided by a norm of 1); negative lattice indices
    # and seeds with the top bit set included
    for _ in range(300):
        seed = int(rng.integers(0, 2**63)) * 2 + int(rng.integers(0, 2))
        x, y = rng.uniform(-1e4, 1e4, 2)
        got = K.fbm2(np.uint64(seed), x, y, 1.0, 1, 0.5)
        assert got == reference_noise2(seed, x, y)


def test_azimuth_is_atan2_within_two_ulp(rng):
    from craters._angle_kernels import _azimuth_kernel

    for scale in (1.0, 1e-300, 1e300, 1e-9):
        y = rng.normal(size=200_000) * scale
        x = rng.normal(size=200_000) * scale
        x[:500] = 0.0  # the axes
        y[500:1000] = 0.0
        y[1000:1500] = x[1000:1500]  # the diagonals
        y[1500:2000] = -x[1500:2000]
        got = np.empty_like(y)
        _azimuth_kernel(y, x, got)
        want = np.arctan2(y, x)
        ulp = np.abs(got - want) / np.spacing(np.abs(want).clip(np.finfo(float).tiny))
        assert ulp.max() <= 2.0, (scale, ulp.max())
    t = np.linspace(-np.pi, np.pi, 100_001)  # every reduction's boundary crossed
    got = np.empty_like(t)
    _azimuth_kernel(np.sin(t), np.cos(t), got)
    assert np.abs(got - np.arctan2(np.sin(t), np.cos(t))).max() <= 2 * np.spacing(np.pi)
    special = np.array([[0.0, 0.0], [0.0, -0.0], [-0.0, 0.0], [1.0, 0.0], [-1.0, 0.0],
                        [0.0, -1.0], [1e-320, 1.0], [1.0, 1e-320], [np.inf, 1.0]])
    got = np.empty(len(special))
    _azimuth_kernel(special[:, 0].copy(), special[:, 1].copy(), got)
    assert got.tolist() == [0.0, 0.0, 0.0, np.pi / 2, -np.pi / 2, np.pi, 1e-320,
                            np.pi / 2, np.pi / 2]
