"""The cell hierarchy (craters.cells) and the portable atan it uses."""

import math

import numpy as np
import pytest

from craters.cells import MAX_LEVEL, cell_ids, cell_of, cell_parts, cell_points, cell_solid_angle


def test_portable_atan_is_within_one_ulp():
    from craters._counter_kernels import _atan_kernel

    rng = np.random.default_rng(1)
    x = np.concatenate([rng.uniform(-3, 3, 20000), np.exp(rng.uniform(-60, 60, 20000)),
                        -np.exp(rng.uniform(-60, 60, 2000)),
                        [0.0, -0.0, 0.4375, 0.6875, 1.1875, 2.4375, 1.0, -1.0, 1e300, -np.inf]])
    got = np.empty_like(x)
    _atan_kernel(x, got)
    ref = np.array([math.atan(v) for v in x])
    assert np.abs(got.view(np.int64) - ref.view(np.int64)).max() <= 1


@pytest.mark.parametrize("level", [0, 1, 3, 7])
def test_the_cells_of_a_level_tile_the_sphere(level):
    n = 1 << level
    face, i, j = np.meshgrid(np.arange(6), np.arange(n), np.arange(n), indexing="ij")
    omega = cell_solid_angle(level, face, i, j)
    assert omega.min() > 0
    assert math.isclose(omega.sum(), 4 * math.pi, rel_tol=1e-13)
    # a cell's solid angle is the sum of its four children's
    if level:
        parent = cell_solid_angle(level - 1, face[:, ::2, ::2], i[:, ::2, ::2] // 2,
                                  j[:, ::2, ::2] // 2)
        kids = sum(omega[:, a::2, b::2] for a in (0, 1) for b in (0, 1))
        np.testing.assert_allclose(kids, parent, rtol=1e-12)


def test_a_cell_holds_the_points_made_inside_it():
    rng = np.random.default_rng(2)
    level = 9
    n = 1 << level
    face = rng.integers(0, 6, 5000)
    i, j = rng.integers(0, n, 5000), rng.integers(0, n, 5000)
    p = cell_points(level, face, i, j, rng.uniform(0.01, 0.99, 5000),
                    rng.uniform(0.01, 0.99, 5000))
    np.testing.assert_allclose(np.linalg.norm(p, axis=1), 1.0, rtol=1e-15)
    f2, i2, j2 = cell_of(p, level)
    assert (f2 == face).all() and (i2 == i).all() and (j2 == j).all()
    # and the points of a finer level's cell lie in its parent
    f3, i3, j3 = cell_of(p, level - 3)
    assert (f3 == face).all() and (i3 == i >> 3).all() and (j3 == j >> 3).all()


def test_uniform_directions_fill_cells_by_solid_angle():
    rng = np.random.default_rng(3)
    p = rng.normal(size=(200_000, 3))
    face, i, j = cell_of(p, 2)
    counts = np.zeros((6, 4, 4))
    np.add.at(counts, (face, i, j), 1)
    f, ii, jj = np.meshgrid(np.arange(6), np.arange(4), np.arange(4), indexing="ij")
    expected = len(p) * cell_solid_angle(2, f, ii, jj) / (4 * math.pi)
    chi2 = ((counts - expected) ** 2 / expected).sum()
    assert chi2 < 150  # 95 degrees of freedom: p ~ 1e-3 at 135


def test_ids_pack_and_unpack():
    rng = np.random.default_rng(4)
    for level in (0, 5, MAX_LEVEL):
        n = 1 << level
        f, i, j = rng.integers(0, 6, 100), rng.integers(0, n, 100), rng.integers(0, n, 100)
        ids = cell_ids(level, f, i, j)
        assert ids.dtype == np.uint64 and len(np.unique(ids)) == len(np.unique(
            np.stack([f, i, j], 1), axis=0))
        lv, f2, i2, j2 = cell_parts(ids)
        assert (lv == level).all() and (f2 == f).all() and (i2 == i).all() and (j2 == j).all()


@pytest.mark.parametrize(("call", "message"), [
    (lambda: cell_of([[0.0, 0.0, 0.0]], 3), "non-zero"),
    (lambda: cell_of([[1.0, 0.0, 0.0]], 28), "level"),
    (lambda: cell_of([[1.0, 0.0, 0.0]], -1), "level"),
    (lambda: cell_ids(2, [0], [4], [0]), "`i`"),
    (lambda: cell_ids(2, [6], [0], [0]), "face"),
])
def test_bad_input_is_named(call, message):
    with pytest.raises(ValueError, match=message):
        call()
