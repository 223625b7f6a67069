"""The blocks of the on-demand field (``latlong.ondemand.cellsets.block_pairs``) against a
brute-force reference: every crater and rock that reaches a point is listed for the
point's block, also for millimetre craters on a Moon-sized body, whose reach (~1e-9 rad)
has a cosine that rounds to 1 (they were listed in their centre's block only, and cut
off along its edges: one-pixel steps in a 1 m descent frame)."""

from __future__ import annotations

import numpy as np
import pytest

from latlong import Scene
from latlong.ondemand import _field_kernels as K
from latlong.ondemand import _rock_kernels as R
from latlong.ondemand import units_of
from latlong.ondemand.field import crater_field


@pytest.fixture(scope="module")
def moon():
    return Scene.from_settings({"base": "sphere", "radius_m": 1737400.0, "body": "moon",
                                "seed": 4, "on_demand": True,
                                "craters": ["c=0.002,k=-2,d_min_m=0.002,d_max_m=0.05"],
                                "boulders": ["c=0.002,k=-2,d_min_m=0.002,d_max_m=0.05"]})


def _missed(units, block_of, start, lst, centres, chord2):
    """(point, record) pairs where the record reaches the point (by the chord, as the
    field's kernels test it) but is not listed for the point's block."""
    listed = np.zeros((len(start) - 1, len(centres)), dtype=bool)
    blk = np.repeat(np.arange(len(start) - 1), np.diff(start))
    listed[blk, lst] = True
    d2 = ((units[:, None, :] - centres[None, :, :]) ** 2).sum(axis=2)
    reach = d2 <= chord2[None, :]
    missed = reach & ~listed[block_of]
    return int(reach.sum()), int(missed.sum())


def test_every_crater_and_rock_reaching_a_point_is_listed_for_its_block(moon, monkeypatch):
    seen = {}

    def spy(name, kernel):
        def call(*args):
            seen[name] = args
            return kernel(*args)
        return call

    monkeypatch.setattr(K, "_points_kernel", spy("craters", K._points_kernel))
    monkeypatch.setattr(R, "_rocks_kernel", spy("rocks", R._rocks_kernel))
    # 100 x 100 points 1 cm apart, craters and rocks from 2 mm: blocks of ~20 cm (level 24)
    half = np.degrees(0.5 / 1737400.0)
    lat, lon = np.meshgrid(np.linspace(0.01 - half, 0.01 + half, 100),
                           np.linspace(0.01 - half, 0.01 + half, 100))
    field = crater_field(moon)
    field.radii(units_of(lat.ravel(), lon.ravel()), 0.002)
    units, block_of, start, lst, _, fc = seen["craters"][:6]
    assert len(start) > 20 and len(fc) > 300 and len(seen["rocks"][4]) > 100
    pairs, missed = _missed(units, block_of, start, lst, fc[:, K.C0:K.C2 + 1],
                            fc[:, K.CHORD2])
    assert pairs > 500 and missed == 0, (pairs, missed)
    units, block_of, start, lst, rc = seen["rocks"][:5]
    pairs, missed = _missed(units, block_of, start, lst, rc[:, 0:3], rc[:, R.CHORD2])
    assert pairs > 50 and missed == 0, (pairs, missed)


def test_serial_below_runs_small_work_on_one_thread_and_restores_the_pool():
    numba = pytest.importorskip("numba")
    from latlong.parallel.backends import PARALLEL_MIN_ITEMS, serial_below

    before = numba.get_num_threads()
    with serial_below(10):
        assert numba.get_num_threads() == 1
    assert numba.get_num_threads() == before
    with serial_below(PARALLEL_MIN_ITEMS):
        assert numba.get_num_threads() == before
    with pytest.raises(KeyError), serial_below(0, minimum=1):
        raise KeyError("inside")
    assert numba.get_num_threads() == before


@pytest.mark.parametrize("minimum", [0, 10**9])
def test_cell_set_work_gives_the_same_bytes_on_one_thread_or_all(moon, monkeypatch, minimum):
    """The crater lookup's small kernels (cells, neighbourhoods, reach, dependency pairs)
    run on the calling thread below ``PARALLEL_MIN_ITEMS`` items: the heights are the
    same bytes with every one of them in parallel (minimum 0) or serial (10**9)."""
    from latlong.ondemand.field import CraterField
    from latlong.parallel import backends

    half = np.degrees(0.5 / 1737400.0)
    lat, lon = np.meshgrid(np.linspace(0.01 - half, 0.01 + half, 64),
                           np.linspace(0.01 - half, 0.01 + half, 64))
    units = units_of(lat.ravel(), lon.ravel())
    want = CraterField(moon).radii(units, 0.002)
    monkeypatch.setattr(backends, "PARALLEL_MIN_ITEMS", minimum)
    got = CraterField(moon).radii(units, 0.002)
    assert got.tobytes() == want.tobytes()
