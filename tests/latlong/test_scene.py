"""latlong.Scene and latlong.build: a typed scene, validated once, built in memory."""

from __future__ import annotations

import dataclasses
import os

import numpy as np
import pytest

import craters
import latlong
from latlong import (
    SETTINGS,
    BodySettings,
    BoulderSettings,
    CraterSettings,
    FaultingParams,
    FbmParams,
    Scene,
    ShapeBase,
    SphereBase,
    build,
)

DATA = os.path.join(os.path.dirname(__file__), "..", "data")


def test_build_returns_a_body_and_writes_nothing(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    scene = Scene(BodySettings(magnitude=24, radius_m=100.0), SphereBase(),
                  CraterSettings([craters.CraterLayer(0.5, -2.0, 4.0, 20.0)]),
                  BoulderSettings(["c=0.002,k=-3,d_min_m=1,d_max_m=8"]), seed=4)
    body = build(scene)
    assert isinstance(body, latlong.Body) and body.magnitude == 24
    assert len(body.craters) > 10 and len(body.boulders) > 0
    assert body.metadata["seed"] == 4 and body.metadata["base"] == "sphere"
    assert list(tmp_path.iterdir()) == []


def test_python_and_settings_give_the_same_body():
    a = build(Scene(BodySettings(magnitude=20, radius_m=100.0),
                    dataclasses.replace(latlong.FAULTING_PRESETS["paper"], n_faults_1=50,
                                        n_faults_2=80), seed=3, preset="paper"))
    assert np.array_equal(a.stretch, [2.0, 1.0, 1.0])  # the paper's set carries its stretch
    b = build(Scene.from_settings({"base": "faulting", "magnitude": 20, "faults_1": 50,
                                   "faults_2": 80, "seed": 3}))
    assert np.array_equal(a.radii_m, b.radii_m) and a.metadata == b.metadata


def test_scene_is_frozen_and_defaults_are_resolved_once():
    s = Scene(BodySettings(magnitude=8), seed=1)
    assert Scene(BodySettings(magnitude=8, stretch=(1, 1, 3)), FaultingParams()).base.stretch \
        == (1.0, 1.0, 3.0)  # the body's stretch is the base's
    assert isinstance(s.base, FbmParams) and s.base.amplitude_m == pytest.approx(0.4 * 50.0)
    assert s.body.radius_m == 50.0 and s.body.stretch == (1.0, 1.0, 1.0)
    with pytest.raises(dataclasses.FrozenInstanceError):
        s.seed = 2
    again = dataclasses.replace(s)  # validation is idempotent
    assert again == s
    assert Scene(BodySettings(magnitude=8)).seed is not None  # a fresh seed, kept


def test_from_settings_applies_presets_then_the_given_values():
    s = Scene.from_settings({"preset": "fbm-cratered", "magnitude": 30, "octaves": 4,
                             "seed": 2})
    assert s.preset == "fbm-cratered" and s.body.radius_m == 100.0
    assert s.base.octaves == 4 and s.base.frequency == 1.5
    assert s.craters.layers[0].d_max_m == 15.0
    assert s.base.amplitude_m == pytest.approx(40.0)


def test_amplitude_is_a_fraction_of_the_radius_and_the_metres_win():
    s = Scene.from_settings({"base": "fbm", "magnitude": 8, "radius_m": 200, "amplitude": 0.1})
    assert s.base.amplitude_m == pytest.approx(20.0)
    s = Scene.from_settings({"magnitude": 8, "amplitude": 0.1, "amplitude_m": 3.0})
    assert s.base.amplitude_m == 3.0
    with pytest.raises(ValueError, match="applies to"):
        Scene.from_settings({"base": "sphere", "magnitude": 8, "amplitude": 0.1})


def test_a_toml_scene(tmp_path):
    path = tmp_path / "s.toml"
    path.write_text('magnitude = 16\nbase = "sphere"\nradius_m = 100\nseed = 5\n'
                    "[[craters]]\nc = 0.3\nk = -2.0\nd_min_m = 4\nd_max_m = 12\n")
    s = Scene.from_toml(path)
    assert s.craters.layers == (craters.CraterLayer(0.3, -2.0, 4.0, 12.0),)
    assert isinstance(s.body.radius_m, float)


def test_shape_base_reads_the_model_once_and_sets_the_body():
    base = ShapeBase(os.path.join(DATA, "eros001708.tab"), units="km")
    s = Scene(BodySettings(magnitude=20), base, seed=1)
    assert s.body.radius_m == pytest.approx(base.radius_m) and s.body.stretch == (1, 1, 1)
    assert s.base.model is base.model
    with pytest.raises(ValueError, match="radius_m"):
        Scene(BodySettings(magnitude=20, radius_m=3.0), base)


@pytest.mark.parametrize("settings,name,text", [
    ({"magnitude": 0}, "magnitude", "[1, 1000000000]"),
    ({"radius_m": -1}, "radius_m", "[0.001, 1e+09]"),
    ({"base": "fbm", "faults_1": 10}, "faults_1", "faulting"),
    ({"preset": "paper", "base": "fbm"}, "preset", "faulting"),
    ({"craters": ["c=0.1,k=-2,d_min_m=5,d_max_m=150"], "radius_m": 100}, "craters",
     "larger than the body"),
    ({"boulder_flatten": 9}, "boulder_flatten", "[0.1, 2]"),
    ({"sun_elevation_deg": 95}, "sun_elevation_deg", "[-90, 90]"),
    ({"colour": "red"}, "colour", "not a scene setting"),
    ({"polygons": 100}, "polygons", "backend"),
    ({"backend": "implicit"}, "backend", "shape"),
])
def test_errors_name_the_setting(settings, name, text):
    with pytest.raises((ValueError, TypeError)) as info:
        Scene.from_settings(settings)
    assert info.value.name == name and text in str(info.value)


def test_every_setting_is_an_option_and_a_toml_key():
    from latlong.cli.build import ON_DEMAND_RUN, OPTIONS
    from latlong.outputs import OUTPUT_SETTINGS

    assert set(OPTIONS) == set(SETTINGS) | set(OUTPUT_SETTINGS) | {"quiet", "force"} \
        | set(ON_DEMAND_RUN)


def test_help_shows_every_default(capsys):
    from latlong.cli import build_parser

    parser = build_parser()
    build_cmd = parser._subparsers._group_actions[0].choices["build"]
    for action in build_cmd._actions:
        if action.dest not in ("help",):
            assert "default" in (action.help or ""), action.dest
    assert "(default: 200)" in build_cmd.format_help()
