"""The numba blend of cached diffusion shapes against its numpy expression."""

from __future__ import annotations

import numpy as np

from craters._diffusion_kernels import _blend_tables


def test_blend_tables_matches_numpy_bit_for_bit():
    rng = np.random.default_rng(5)
    stack = rng.normal(size=(7, 9, 33)).astype(np.float32)
    n = 50
    a, b = rng.integers(0, 7, n), rng.integers(0, 7, n)
    j0 = rng.integers(0, 8, n)
    fd, ft, depth = rng.random(n), rng.random(n), rng.uniform(1, 1e3, n)
    out = np.empty((n, 33))
    _blend_tables(stack, a, b, j0, fd, ft, depth, out)
    f, t = fd[:, None], ft[:, None]
    want = ((1 - f) * ((1 - t) * stack[a, j0] + t * stack[a, j0 + 1])
            + f * ((1 - t) * stack[b, j0] + t * stack[b, j0 + 1])) * depth[:, None]
    np.testing.assert_array_equal(out, want)


def test_cached_shapes_do_not_depend_on_what_was_made_before():
    """The diffusion cache fills (D, tau) nodes on demand, in batches that depend on the
    calls before: a node's shape must be the same bits whatever batch made it, so a seed
    gives the same surface in any process."""
    from craters import diffusion as df
    from craters.targets import get_target

    moon = get_target("moon")
    fresh_cache = df._Cache(moon, 3.0)
    warmed = df._Cache(moon, 3.0)
    warmed.stack(np.arange(150, 290, 7), np.full(20, 40))  # other nodes, fewer tau
    idx = np.arange(200, 240)
    upto = np.full(40, len(fresh_cache.tau_nodes))
    a, pa = fresh_cache.stack(idx, upto)
    b, pb = warmed.stack(idx, upto)
    np.testing.assert_array_equal(a[pa], b[pb])
