"""The settings kit: one declaration on a record's field gives the range check, the option,
its help (default, unit, range), the TOML key, the ``--vary`` key and the flag an error is
shown under (craters._shared.settings, craters.cli.options)."""

from __future__ import annotations

from dataclasses import dataclass

import pytest

from craters._shared.settings import Setting, by_key, check_declared, declared, setting
from craters.cli.kit import CliError, run_cli
from craters.cli.options import (
    FORCE,
    Values,
    command,
    declared_keys,
    help_text,
    main_parser,
    parse_vary,
    read_config,
)


@dataclass(frozen=True, slots=True)
class Grid:
    magnitude: int = setting(200, "grid magnitude M", range=(1, 10**9))
    radius_m: float | None = setting(None, "reference radius", unit="m", range=(1e-3, 1e9),
                                     default_text="50")
    width_m: float = setting(2.0, "width", unit="m", range=">0", key="grid_width_m")
    roughness: bool = setting(True, "fractal overlay (off: smooth)")
    surface: str = setting("latlong", "where", choices=("latlong", "mesh"))
    stretch: str | None = setting(None, "X,Y,Z factors", commas=True)
    layers: tuple = setting((), "a layer spec (repeatable)", many="append")
    amplitude: float = setting(0.4, range=">=0")  # checked, no option of its own

    def __post_init__(self):
        check_declared(self)


@dataclass(frozen=True, slots=True)
class Detail:
    octaves: int = setting(6, key="magnitude", range=(1, 30), when="as detail")


def test_check_declared_checks_and_cleans_every_declared_field():
    g = Grid(magnitude=3.0, radius_m=2, width_m=1)
    assert (g.magnitude, g.radius_m, g.width_m) == (3, 2.0, 1.0)
    assert type(g.magnitude) is int and type(g.radius_m) is float
    assert Grid().radius_m is None  # None where the default is None: not given
    for kw, text in (({"magnitude": 0}, "`magnitude` must be an integer in [1, 1000000000]"),
                     ({"radius_m": 1e10}, "`radius_m` must be in [0.001, 1e+09]"),
                     ({"width_m": 0.0}, "`width_m` must be finite and > 0"),
                     ({"amplitude": -1.0}, "`amplitude` must be finite and >= 0"),
                     ({"surface": "disk"}, "`surface` must be one of latlong, mesh"),
                     ({"roughness": 1}, "`roughness` must be true or false")):
        with pytest.raises((TypeError, ValueError), match=text.replace("[", r"\[").replace(
                "+", r"\+")) as info:
            Grid(**kw)
        assert info.value.name == next(iter(kw))


def test_keys_and_aliases():
    assert set(by_key(Grid)) == {"magnitude", "radius_m", "grid_width_m", "roughness",
                                 "surface", "stretch", "layers", "amplitude"}
    assert declared(Grid)["width_m"].key == "grid_width_m"
    options = declared_keys(("body", Grid), Detail)
    assert "amplitude" not in options  # no help: a checked field, not an option
    assert options["magnitude"].group == "body"
    assert help_text(options["magnitude"]) == (
        "grid magnitude M; in [1, 1000000000] (default: 200; 6 as detail)")
    with pytest.raises(ValueError, match="declared twice"):
        declared_keys(Grid, {"surface": Setting("x", "again")})


def test_help_shows_unit_range_default_and_switches():
    options = declared_keys(Grid)
    assert help_text(options["radius_m"]) == ("reference radius, m; in [0.001, 1e+09] "
                                              "(default: 50)")
    assert help_text(options["grid_width_m"]) == "width, m; > 0 (default: 2)"
    assert help_text(options["roughness"]).endswith("this switch turns it off (default: on)")
    assert help_text(Setting(help="file", required=True)) == "file (required)"


def _toy(tmp_path):
    """A command whose options are Grid's fields plus --force; returns (main, runs)."""
    runs = []
    parser, sub = main_parser("toy", "Toy.")
    options = {**declared_keys(Grid), "force": FORCE}

    def run(v: Values) -> int:
        runs.append(v)
        Grid(**{name: v[s.key] for name, s in declared(Grid).items() if s.key in options})
        return 0

    command(sub, "make", run, options, help="make a grid", config=True, prog="toy")

    def main(argv):
        args = parser.parse_args(argv)
        return run_cli(lambda: args.func(args), atomic=False)

    return main, runs


def test_one_declaration_makes_the_flag_the_toml_key_and_the_error_names(tmp_path, capsys):
    main, runs = _toy(tmp_path)
    assert main(["make", "--grid-width-m", "3", "--no-roughness", "--layers", "a",
                 "--layers", "b"]) == 0
    v = runs[-1]
    assert (v["grid_width_m"], v["roughness"], v["layers"]) == (3.0, False, ["a", "b"])
    assert v.given == {"grid_width_m", "roughness", "layers"} and v["magnitude"] == 200
    assert main(["make", "--magnitude", "0"]) == 2
    assert capsys.readouterr().err == ("error: --magnitude must be an integer in [1, "
                                       "1000000000]; got 0\n")
    cfg = tmp_path / "c.toml"
    cfg.write_text("magnitude = 0\nsurface = 'mesh'\n")
    assert main(["make", "--config", str(cfg)]) == 2  # the file's key is named
    assert capsys.readouterr().err == (f"error: config {str(cfg)!r}: key 'magnitude' must be "
                                       "an integer in [1, 1000000000]; got 0\n")
    assert main(["make", "--config", str(cfg), "--magnitude", "7"]) == 0  # the line wins
    assert runs[-1]["magnitude"] == 7 and runs[-1]["surface"] == "mesh"
    assert runs[-1].from_config == {"surface"}
    cfg.write_text("colour = 'red'\n")
    assert main(["make", "--config", str(cfg)]) == 2
    err = capsys.readouterr().err
    assert "unknown key 'colour' for `toy make`; allowed:" in err and "grid_width_m" in err
    cfg.write_text("force = 'yes'\n")  # a run option's value is the command line's to check
    assert main(["make", "--config", str(cfg)]) == 2
    assert "key 'force' must be true or false; got 'yes'" in capsys.readouterr().err


def test_read_config_turns_a_run_option_string_into_a_list(tmp_path):
    cfg = tmp_path / "c.toml"
    cfg.write_text("out = 'a.npz'\nlayers = 'x'\n")
    options = {"out": Setting(help="files", many="append", run=True),
               "layers": declared_keys(Grid)["layers"]}
    assert read_config(cfg, options, "toy") == {"out": ["a.npz"], "layers": "x"}


def test_vary_parses_each_value_as_its_option():
    options = declared_keys(Grid)
    vary = parse_vary(["magnitude=10,20", "stretch=2,1,1;1,1,1", "roughness=false",
                       "layers=c=1,k=-2", "grid-width-m=1.5"], options)
    assert vary == {"magnitude": [10, 20], "stretch": ["2,1,1", "1,1,1"],
                    "roughness": [False], "layers": [["c=1,k=-2"]], "grid_width_m": [1.5]}
    for item, text in (("seed=1,2", "--seeds"), ("colour=red", "unknown key 'colour'"),
                       ("magnitude=ten", "--vary magnitude=ten: expected an integer"),
                       ("surface=disk", "must be one of latlong, mesh"),
                       ("roughness=maybe", "expected true or false")):
        with pytest.raises(CliError, match=text):
            parse_vary([item], options)
