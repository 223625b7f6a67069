"""Every example runs (at a small size) and writes its picture."""

from __future__ import annotations

import os
import runpy
from pathlib import Path

import pytest

EXAMPLES = sorted((Path(__file__).parents[1] / "examples").glob("plot_*.py"))


@pytest.mark.parametrize("script", EXAMPLES, ids=lambda p: p.stem)
def test_example_runs(script, tmp_path, monkeypatch, capsys):
    monkeypatch.setenv("CRATERFORM_EXAMPLE_MAGNITUDE", "24")
    monkeypatch.setenv("CRATERFORM_EXAMPLE_SMALL", "1")
    monkeypatch.setenv("CRATERFORM_EXAMPLE_OUT", str(tmp_path))
    runpy.run_path(str(script), run_name="__main__")
    pngs = list(tmp_path.glob("*.png"))
    assert pngs, "the example wrote no picture"
    assert all(p.stat().st_size > 10_000 for p in pngs)
    assert "wrote" in capsys.readouterr().out
    assert os.environ["CRATERFORM_EXAMPLE_OUT"] == str(tmp_path)


def test_the_readme_names_every_example():
    readme = (Path(__file__).parents[1] / "README.md").read_text(encoding="utf-8")
    assert len(EXAMPLES) >= 10
    missing = [p.name for p in EXAMPLES if f"`{p.stem.removeprefix('plot_')}`" not in readme]
    assert not missing, missing
