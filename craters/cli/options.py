"""The option kit of the ``latlong``, ``dem`` and ``craters`` commands: every option, its
help text (with default, unit and range), its TOML key, its ``--vary`` key and the flag a
library error is shown under come from one declaration, a
:class:`~craters._shared.settings.Setting`.

How to declare a command's options
----------------------------------
1. A setting of a library record is declared on the record's field, once::

       width_px: int = setting(1024, "picture width", unit="px", range=(16, 8192))

   and the record's ``__post_init__`` calls ``check_declared(self)`` (the range check;
   :mod:`craters._shared.settings`). ``declared_keys(Record)`` (or ``(group, Record)``
   pairs) lists them by key for a command; the record's defaults are the options'.
2. A command's own options (an input, outputs, ``--force``, ``--quiet``, switches that
   only the command line reads) are ``Setting`` records in a table of the command's
   module, with ``run=True``: the kit checks their values (declared range and choices;
   a config file's value type). Ready-made: :data:`FORCE`, :data:`QUIET`,
   :data:`REPORT`, :func:`batch_options`. A library function's default is read from its
   signature, :func:`default_of`, not written again.
3. One module a command registers its table, its ``--help`` line first in ``HELP`` (a
   literal dict, read from the source for the command list: :func:`command_help`)::

       HELP = {"render": "render a saved body"}
       OPTIONS = {"model": Setting(help="a .npz written by latlong build", flag="MODEL",
                                   required=True, run=True),
                  "output": Setting(help="PNG to write", flag="-o/--output",
                                    required=True, run=True),
                  **declared_keys(("render", PreviewSettings)), "force": FORCE,
                  "quiet": QUIET}

       def run(v: Values) -> int:      # v["width_px"] or v.width_px; v.given ...
           ...

       def register(sub) -> None:
           command(sub, "render", run, OPTIONS, prog="latlong",
                   groups={"render": "preview picture"}, help=HELP["render"])

:func:`command` adds one argparse option a setting: ``--key`` with dashes unless
``flag`` says otherwise (``-o/--output``; an upper-case word, ``MODEL``, is a positional
argument), a ``bool`` is a switch (``--no-key`` when its default is on), ``many`` makes it
repeatable (``append``) or a list (``+``), ``choices`` show in the usage and are checked
by the library (or the kit, ``run``); with ``config=True`` it adds ``--config TOML``, whose
keys are the option keys (unknown keys are errors). At run time the values (defaults <
config file < command line) reach ``run`` as :class:`Values`, and a library error about a
setting's key, or a parameter named in its ``also`` (``also=("fx", "fy")``), is one line
under the flag, or under the file's key when the value came from the file. Batches read
``--vary KEY=V1,V2`` with the same parsers (:func:`parse_vary`; ``commas=True`` for a
setting whose one value holds commas).
"""

from __future__ import annotations

import argparse
import ast
import contextlib
import dataclasses
import importlib
import importlib.util
import math
from collections.abc import Callable, Iterator, Mapping
from pathlib import Path

from .._shared.files import load_toml
from .._shared.outputs import waiting
from .._shared.settings import Setting, by_key, default_of
from .._shared.validation import ParameterError, ParameterTypeError, parameter_of
from .kit import CliError

__all__ = ["CONFIG", "FORCE", "QUIET", "REPORT", "Setting", "Values", "add_commands",
           "add_options", "batch_error", "batch_options", "command", "command_modules",
           "declared_keys", "default_of", "flag_of", "help_text", "main_parser", "parse_vary",
           "read_config", "shown_value", "values_of"]


# --------------------------------------------------------------------------- text -> value
def _number(text) -> float:
    try:
        value = float(text)
    except (TypeError, ValueError):
        raise argparse.ArgumentTypeError(f"expected a number; got {text!r}") from None
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"must be finite; got {text!r}")
    return value


def _integer(text) -> int:
    try:
        return int(str(text), 10)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected an integer; got {text!r}") from None


def _text_parser(s: Setting) -> Callable[[str], object]:
    """The argparse type of a setting: its ``parse`` (a ValueError's rule becomes the
    message) or the parser of its kind."""
    if s.parse is None:
        parsers: dict[type | None, Callable[[str], object]] = {int: _integer, float: _number}
        return parsers.get(s.kind, str)
    parse = s.parse

    def parse_text(text):
        try:
            return parse(text)
        except (TypeError, ValueError) as exc:
            raise argparse.ArgumentTypeError(getattr(exc, "rule", None) or str(exc)) from None

    parse_text.__name__ = getattr(parse, "__name__", "value")
    return parse_text


# --------------------------------------------------------------------------- declarations
def declared_keys(*sources, **overrides) -> dict[str, Setting]:
    """{key: setting} of the declared fields of the records ``sources`` (or tables of
    settings by key; a ``(group, source)`` pair puts them in a group), one a key: the
    declaration with the help; another record's field of that key (help None) with a
    different default and a ``when`` adds its default to the help (``default: 10; 6 with
    a shape base``). ``overrides``: key -> attributes to change (``output={"required":
    True}``)."""
    out: dict[str, Setting] = {}
    extra: dict[str, list[Setting]] = {}
    for source in sources:
        group, source = source if isinstance(source, tuple) else (None, source)
        for key, s in by_key(source).items():
            if s.help is None:
                extra.setdefault(key, []).append(s)
            elif key in out:
                raise ValueError(f"setting {key!r} is declared twice")
            else:
                out[key] = dataclasses.replace(s, group=s.group or group)
    for key, s in out.items():
        shown = [f"{_shown_default(o)} {o.when}" for o in extra.get(key, ())
                 if o.when and o.default != s.default]
        if shown:
            s = dataclasses.replace(s, default_text="; ".join([_shown_default(s), *shown]))
        out[key] = dataclasses.replace(s, **overrides.get(key, {}))
    return out


def _shown_default(s: Setting) -> str:
    shown = s.default_text() if callable(s.default_text) else s.default_text
    return shown_value(s.default) if shown is None else shown


def flag_of(key: str, s: Setting) -> str:
    """How a message names the option: ``--radius-m``, ``-o/--output``, ``MODEL``."""
    return s.flag or f"--{'no-' if _negated(s) else ''}{key.replace('_', '-')}"


def _negated(s: Setting) -> bool:
    return s.kind is bool and s.default is True


def shown_value(value) -> str:
    """A default for people: ``5.0`` -> ``5``, ``(1.0, 1.0, 1.0)`` -> ``1,1,1``."""
    if isinstance(value, bool):
        return "on" if value else "off"
    if isinstance(value, float):
        return f"{value:g}"
    if isinstance(value, tuple | list):
        return ",".join(shown_value(v) for v in value) or "none"
    return "none" if value is None else str(value)


def _range_text(s: Setting) -> str | None:
    rule = s.range
    if rule is None or rule == "finite":
        return None
    if rule in (">0", ">=0"):
        return {">0": "> 0", ">=0": ">= 0"}[rule]
    lo, hi = (("-inf", "inf")[i] if v is None else str(v) if isinstance(v, int) else f"{v:g}"
              for i, v in enumerate(rule))
    return f"in [{lo}, {hi}]"


def help_text(s: Setting) -> str:
    """The help of an option: what it is, its unit and range, then ``(default: ...)`` or
    ``(required)``."""
    text = s.help or ""
    if s.unit:  # after the first clause: "surface gravity, m/s^2: transition ..."
        cut = min((i for i in (text.find(": "), text.find(" (")) if i > 0), default=len(text))
        text = f"{text[:cut]}, {s.unit}{text[cut:]}"
    if _range_text(s):
        text += f"; {_range_text(s)}"
    if _negated(s):
        text += "; this switch turns it off"
    if s.required:
        return f"{text} (required)"
    return f"{text} (default: {_shown_default(s)})"


def add_options(parser, options: Mapping[str, Setting],
                groups: Mapping[str, str] | None = None) -> None:
    """Add one argparse option a setting (module notes); ``groups``: group name -> title
    of the setting groups that get their own section; nothing given stays None."""
    used = {s.group for s in options.values()}
    sections: dict[str | None, argparse._ActionsContainer] = {
        g: parser.add_argument_group(title) for g, title in (groups or {}).items()
        if g in used}
    for key, s in options.items():
        where = sections.get(s.group, parser)
        kw: dict = {"help": help_text(s).replace("%", "%%"), "default": None}  # argparse
        flag = flag_of(key, s)
        if flag.isupper():  # a positional argument
            names = [key]
            kw.update(metavar=flag, nargs=None if s.required else "?")
        else:
            names = flag.split("/")
            kw.update(dest=key, required=s.required, metavar=s.metavar)
            if s.kind is bool and not s.many:
                kw["action"] = "store_false" if _negated(s) else "store_true"
                del kw["metavar"]
        if "action" not in kw:  # choices are the library's (or the kit's) to check
            kw["type"] = _text_parser(s)
            if s.choices and not s.metavar:
                kw["metavar"] = "{" + ",".join(s.choices) + "}"
            if s.many:
                kw.update({"action": "append"} if s.many == "append" else {"nargs": "+"})
        where.add_argument(*names, **kw)


# --------------------------------------------------------------------------- config files
_TOML_KINDS: dict[type | None, str] = {str: "a file name", bool: "true or false",
                                       list: "a list of strings"}


def _good_toml(s: Setting, value) -> bool:
    if s.many == "append" and isinstance(value, str):
        return bool(value)
    if s.many:
        return isinstance(value, list) and all(isinstance(v, str) for v in value)
    if s.kind is bool:
        return isinstance(value, bool)
    return isinstance(value, str) and bool(value) if s.kind is str else True


def read_config(path, options: Mapping[str, Setting], command: str) -> dict:
    """The keys of a TOML file given with ``--config`` (the option keys of ``command``):
    unknown keys are errors; the values of run options are checked here (a repeatable
    one may be one string), the others by the library."""
    out = {}
    for key, value in load_toml(path).items():
        s = options.get(key)
        if s is None:
            raise CliError(f"config {str(path)!r}: unknown key {key!r} for `{command}`; "
                           f"allowed: {', '.join(sorted(options))}")
        if s.run and not _good_toml(s, value):
            what = _TOML_KINDS[list if s.many and s.many != "append" else s.kind]
            if s.many == "append":
                what += " or a list of them"
            raise CliError(f"config {str(path)!r}: key {key!r} must be {what}; got {value!r}")
        out[key] = [value] if s.run and s.many == "append" and isinstance(value, str) \
            else value
    return out


class Values(dict):
    """The values of a command's options (key -> value; ``values.key`` too): defaults,
    then the config file, then the command line; knows which were ``given`` (by the file
    or the line), which came ``from_config`` and the file (``config_file``)."""

    def __init__(self, command: str, options: Mapping[str, Setting], values: dict,
                 config=None, from_config=frozenset(), given=frozenset()):
        super().__init__(values)
        self.command, self.options, self.config_file = command, options, config
        self.from_config, self.given = set(from_config), set(given)

    def __getattr__(self, key: str):
        """``values.csv`` for ``values["csv"]``."""
        try:
            return self[key]
        except KeyError:
            raise AttributeError(key) from None

    def where(self, parameter: str | None) -> str | None:
        """How to name the option that sets a library ``parameter`` (None: none does)."""
        for key, s in self.options.items():
            if parameter in (key, *s.also):
                if key in self.from_config:
                    return f"config {str(self.config_file)!r}: key {key!r}"
                return flag_of(key, s)
        return None

    @contextlib.contextmanager
    def named_errors(self) -> Iterator[None]:
        """A library error about an option's parameter is one line under the option's
        name (its own name first, then the tag of a caller, :func:`parameter_of`)."""
        try:
            yield
        except (TypeError, ValueError, OSError) as exc:
            if isinstance(exc, ParameterError | ParameterTypeError) \
                    and (where := self.where(exc.name)):
                raise CliError(exc.shown_as(where,
                                            lambda k: self.where(k) or f"`{k}`")) from None
            where = self.where(parameter_of(exc))
            if where is None:
                raise
            raise CliError(f"{where}: {exc}") from None


def values_of(args: argparse.Namespace, command: str, options: Mapping[str, Setting], *,
              config_file: bool = False) -> Values:
    """Defaults, then the config file (``args.config`` with ``config_file``), then the
    command line; run options checked against their declared kind, range and choices."""
    values = {key: s.default for key, s in options.items()}
    config = getattr(args, "config", None) if config_file else None
    from_file = read_config(config, options, command) if config else {}
    typed = {key for key in options if getattr(args, key, None) is not None}
    values.update(from_file)
    values.update({key: getattr(args, key) for key in typed})
    out = Values(command, options, values, config, set(from_file) - typed,
                 set(from_file) | typed)
    with out.named_errors():
        for key, s in options.items():
            if s.run and values[key] is not None and not s.many:
                out[key] = s.check(key, values[key])
    return out


def command(sub, name: str, run: Callable[[Values], int | None],
            options: Mapping[str, Setting], *, help: str, description: str | None = None,
            groups: Mapping[str, str] | None = None, config: bool = False, prog: str = ""):
    """Register the command ``name`` with its options (:func:`add_options`) on the
    sub-command parser ``sub``; ``run(values)`` does the work, its library errors named
    by the options (:meth:`Values.named_errors`). A command that writes outputs (it has
    ``force``) also gets :data:`WAIT`: with it, an output another run is writing is
    waited for (:func:`~craters._shared.outputs.waiting`), not refused."""
    if "force" in options and "wait" not in options:
        options = {**options, "wait": WAIT}
    p = sub.add_parser(name, help=help, description=description or help[0].upper() + help[1:]
                       + ".")
    add_options(p, {**options, **({"config": CONFIG} if config else {})}, groups)
    label = f"{prog} {name}".strip()

    def call(args: argparse.Namespace) -> int:
        values = values_of(args, label, options, config_file=config)
        with values.named_errors(), waiting(bool(values.get("wait"))):
            return int(run(values) or 0)

    # the table of the flags and config keys, for tests (an attribute of the function)
    call.options = dict(options)  # type: ignore[attr-defined]
    p.set_defaults(func=call)
    return p


# --------------------------------------------------------------------------- vary
def parse_vary(items, options: Mapping[str, Setting]) -> dict[str, list]:
    """``--vary KEY=V1,V2`` options -> {key: [values]}: the key (one of ``options``) with
    dashes or underscores, each value parsed as its option parses it (a repeatable
    option's value: a list of one; a switch: true or false); values separated by ``;``
    when the text holds one, else by ``,`` (but a setting whose one value holds commas,
    ``Setting.commas``, takes the whole text)."""
    out: dict[str, list] = {}
    for item in items or ():
        key, sep, text = item.partition("=")
        key = key.strip().lstrip("-").replace("-", "_")
        if not sep or not text.strip():
            raise CliError(f"--vary {item!r}: expected KEY=V1,V2,...")
        if key == "seed":
            raise CliError("--vary seed: give the seeds with --seeds")
        if key not in options:
            raise CliError(f"--vary {item!r}: unknown key {key!r}; allowed: "
                           f"{', '.join(sorted(options))}")
        if key in out:
            raise CliError(f"--vary {key} is given twice; give its values in one --vary")
        s = options[key]
        if ";" in text:
            texts = text.split(";")
        else:
            texts = [text] if s.commas or s.many == "append" else text.split(",")
        out[key] = [_vary_value(key, s, t.strip()) for t in texts]
    return out


def _vary_value(key: str, s: Setting, text: str):
    try:
        if s.kind is bool and not s.many:
            if text.lower() not in ("true", "false"):
                raise ValueError(f"expected true or false; got {text!r}")
            return text.lower() == "true"
        value = _text_parser(s)(text)
        if s.choices and value not in s.choices:
            raise ValueError(f"must be one of {', '.join(s.choices)}; got {text!r}")
    except (argparse.ArgumentTypeError, ValueError) as exc:
        raise CliError(f"--vary {key}={text}: {exc}") from None
    return [value] if s.many == "append" else value


def batch_error(exc: Exception, v: Values, config) -> CliError:
    """A library error of a batch as one line: under its option, else under the key of
    the file ``config`` it is about."""
    def name_of(key):
        return v.where(key) or f"key {key!r}"

    def where(key):
        return v.where(key) or f"config {str(config)!r}: key {key!r}"

    if isinstance(exc, ParameterError | ParameterTypeError):
        return CliError(exc.shown_as(where(exc.name), name_of))
    if parameter_of(exc) is not None:
        return CliError(f"{where(parameter_of(exc))}: {exc}")
    return CliError(str(exc))


# --------------------------------------------------------------------------- run options
#: ``--config``: a TOML file of option keys.
CONFIG = Setting(help="TOML file whose keys are the option names; options given here "
                 "override it", metavar="TOML", run=True)
#: ``--force``: overwrite existing outputs.
FORCE = Setting(False, "overwrite existing outputs", run=True)
#: ``-q/--quiet``: no progress bars or messages.
QUIET = Setting(False, "no progress bars or messages", flag="-q/--quiet", run=True)
#: ``--wait``: every command with ``--force`` has it (:func:`command`).
WAIT = Setting(False, "when another run is writing one of the outputs, wait for it to end "
               "instead of failing at once", run=True)
#: The outputs of an analysis command (a table and a plot).
REPORT = {
    "csv": Setting(help="write the table (CSV, units in the header)", run=True),
    "plot": Setting(help="write the plot (PNG)", run=True),
    "force": FORCE,
    "quiet": Setting(False, "no progress bars or messages, the summary table included",
                     flag="-q/--quiet", run=True),
}

def batch_options(what: str) -> dict[str, Setting]:
    """The options of ``latlong batch`` and ``dem batch`` (``what``: a variant's output)."""
    return {
        "seeds": Setting(help="seeds: a range 1-1000, a list 1,5,9 or both 1-3,7",
                         metavar="SEEDS", required=True, run=True),
        "vary": Setting(help="build every value of a setting (a key of the file, dashes or "
                        "underscores); several --vary make a cartesian product; values that "
                        "hold commas (crater specs, X,Y,Z) are separated by ';' (repeatable)",
                        many="append", metavar="KEY=V1,V2,...", run=True),
        "output": Setting(help=f"batch folder: {what}, and index.csv", flag="-o/--output",
                          metavar="FOLDER", required=True, run=True, also=("out",)),
        "scheduler": Setting(help="a running dask scheduler, e.g. tcp://127.0.0.1:8786",
                             metavar="ADDRESS", run=True,
                             default_text="a local cluster on 127.0.0.1, one "
                             "single-threaded worker process per core"),
        "workers": Setting(help="worker processes of the local cluster", kind=int,
                           metavar="N", run=True, default_text="one per core"),
        "resume": Setting(False, "keep the variants index.csv lists as done whose files "
                          "still have their sha256; redo the others", run=True),
        "force": Setting(False, "redo every variant in a folder that holds a batch",
                         run=True),
        "quiet": Setting(False, "no progress bar, lines or summary; failures still "
                         "reported", flag="-q/--quiet", run=True),
    }


def command_modules(package: str, modules: Mapping[str, str],
                    argv: list[str] | None = None) -> list:
    """The modules of the command-line package ``package`` that ``argv`` needs, imported:
    ``modules`` maps each command to its module. When ``argv`` names a command first only
    its module, so a run does not load the libraries of the other commands (0.1-0.5 s a
    start); none when it names no command (``--help``, ``--version``, a typo:
    :func:`add_commands` lists them unloaded); all of them without ``argv``."""
    if argv is None:
        return [importlib.import_module(f"{package}.{module}")
                for module in dict.fromkeys(modules.values())]
    wanted = modules.get(argv[0]) if argv else None
    return [] if wanted is None else [importlib.import_module(f"{package}.{wanted}")]


def command_help(package: str, module: str) -> dict[str, str]:
    """The ``HELP`` table of the command module ``package.module`` ({command: its line in
    ``--help``}), read from its source: importing it would load its libraries."""
    spec = importlib.util.find_spec(f"{package}.{module}")
    source = Path(spec.origin).read_text("utf-8") if spec and spec.origin else ""
    for node in ast.parse(source).body:
        if isinstance(node, ast.Assign) and ast.unparse(node.targets[0]) == "HELP":
            return ast.literal_eval(node.value)
    raise ImportError(f"{package}.{module} has no HELP table", name=f"{package}.{module}")


def add_commands(sub, package: str, modules: Mapping[str, str],
                 argv: list[str] | None = None) -> None:
    """Register on the sub-command parser ``sub`` the commands of :func:`command_modules`
    (each module's ``register(sub)``); when ``argv`` names no command, every command by
    name and help line only (``latlong --help`` in a fraction of the time)."""
    loaded = command_modules(package, modules, argv)
    if argv is not None and not loaded:
        helps = {m: command_help(package, m) for m in dict.fromkeys(modules.values())}
        for name, module in modules.items():
            sub.add_parser(name, help=helps[module][name])
        return
    for module in loaded:
        module.register(sub)


def main_parser(prog: str, description: str):
    """(parser, sub-command parser) of the command ``prog``, with ``--version``."""
    from .._shared.system import package_version
    from .kit import OneLineParser

    parser = OneLineParser(prog=prog, description=description)
    parser.add_argument("--version", action="version", version=f"craterform {package_version()}")
    return parser, parser.add_subparsers(dest="command", required=True,
                                         parser_class=OneLineParser)
