"""``dem enhance`` layer by layer (issue 18, deliver 3): the stack folder
:func:`dem.enhancefile.enhance_to_folder` writes holds the bytes of ``dem.enhance`` +
``Stack.write``, file for file, while it keeps about two layers in memory."""

from __future__ import annotations

import numpy as np
import pytest

from dem import Dem, enhance
from dem.enhancefile import enhance_to_folder
from dem.stack import read_stack

CRATERS = "c=0.05,k=-2,d_min_m=20,d_max_m=800"
BOULDERS = "c=0.5,k=-3,d_min_m=3,d_max_m=40"


@pytest.mark.parametrize("cfg", [
    {"layers": 4, "size": 17, "seed": 1, "craters": [CRATERS]},
    {"layers": 3, "size": 33, "seed": 2, "craters": [CRATERS], "boulders": [BOULDERS]},
    {"layers": 5, "size": 17, "seed": 3, "target": [4.0, 36.0], "craters": [CRATERS],
     "smooth_craters": True},
    {"layers": 1, "size": 33, "seed": 4},
    {"layers": 3, "size": 17, "seed": 5, "roughness": 0.05, "fractal_dimension": 2.3},
])
def test_layer_by_layer_is_the_whole_stack(tmp_path, cfg):
    z = np.random.default_rng(0).normal(0, 5, (41, 47)).cumsum(0)
    base = Dem(z, pixel_size_m=100.0)
    stack, manifest = enhance_to_folder(cfg, tmp_path / "a", dem=base)
    whole = enhance(cfg, dem=base)
    whole.write(tmp_path / "b")
    names = sorted(p.name for p in (tmp_path / "b").iterdir())
    assert sorted(p.name for p in (tmp_path / "a").iterdir()) == names
    for name in names:
        assert (tmp_path / "a" / name).read_bytes() == (tmp_path / "b" / name).read_bytes(), name
    assert stack.info == whole.info and manifest == tmp_path / "a" / "manifest.json"
    assert read_stack(manifest).is_consistent()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a", "b"]  # no temporaries


def test_a_failure_leaves_nothing(tmp_path, monkeypatch):
    import dem.enhancefile as mod

    def boom(*args, **kw):
        raise RuntimeError("disk full")

    monkeypatch.setattr(mod, "write_stack", boom)
    base = Dem(np.random.default_rng(0).normal(0, 5, (33, 33)), pixel_size_m=100.0)
    with pytest.raises(RuntimeError, match="disk full"):
        enhance_to_folder({"layers": 3, "size": 17, "seed": 1}, tmp_path / "a", dem=base)
    assert list(tmp_path.iterdir()) == []


if __name__ == "__main__":  # pragma: no cover
    pytest.main([__file__, "-q"])
