"""Declared settings: one declaration per setting, on the field of its record, holding the
default, the unit, the allowed values, the help text and the names (the key of a TOML
file and of flat settings, the command-line flag), so that each lives once::

    @dataclass(frozen=True, slots=True)
    class Grid:
        magnitude: int = setting(200, "grid magnitude M (6M^2+2 vertices)", range=(1, 10**9))
        radius_m: float = setting(50.0, "reference radius", unit="m", range=">0")

        def __post_init__(self):
            check_declared(self)  # every declared range and choice, named by the field

The library uses the checks (:func:`check_declared`) and the keys (:func:`declared`);
the command lines (:mod:`craters.cli.options`) make of the same declarations the options,
the help texts with default, unit and range, the TOML keys, the ``--vary`` keys and the
flag an error is shown under. This module loads neither argparse nor numpy.
"""

from __future__ import annotations

import dataclasses
import functools
from collections.abc import Callable
from typing import Any, cast

from .validation import (
    ParameterTypeError,
    check_choice,
    check_finite,
    check_int,
    check_positive,
    check_range,
)

__all__ = ["Setting", "by_key", "check_declared", "declared", "default_of", "setting"]

_KINDS = {"bool": bool, "int": int, "float": float, "str": str}


@dataclasses.dataclass(frozen=True, slots=True)
class Setting:
    """One setting: its meaning, unit, allowed values and names (module notes)."""

    default: Any = None
    """The value when none is given (None: not given; the record or command decides)."""
    help: str | None = None
    """What it is, without default, unit or range (help texts add them); None: the same
    setting as another record's field of this ``key``, or a field without an option."""
    unit: str | None = None
    """Unit of the value (``m``, ``deg``, ``kg/m^3`` ...)."""
    range: tuple | str | None = None
    """``(lo, hi)`` (None open; integers for ``int``), ``">0"``, ``">=0"`` or ``"finite"``."""
    choices: tuple[str, ...] | None = None
    """The allowed words."""
    kind: type | None = None
    """``bool``, ``int``, ``float`` or ``str`` (default: the default's or field's type)."""
    key: str | None = None
    """The flat / TOML key (default: the field's name)."""
    flag: str | None = None
    """The flag (default ``--key`` with dashes; ``-o/--output``; ``MODEL``: positional)."""
    parse: Callable[[str], Any] | None = None
    """Command-line text -> value (default: by ``kind``); ValueError for bad text."""
    many: str | None = None
    """``append``: the flag repeats (a list); ``+``: one or more values after the flag."""
    commas: bool = False
    """One value holds commas (X,Y,Z, a spec): ``--vary`` separates values by ``;``."""
    required: bool = False
    """The command line needs it."""
    run: bool = False
    """A command's own option (a file, a switch): checked by the command line."""
    metavar: str | None = None
    """The value's name in help texts."""
    default_text: str | Callable[[], str] | None = None
    """How help texts say the default when the value does not."""
    when: str | None = None
    """Where this field's default applies, for a key that several records share."""
    also: tuple[str, ...] = ()
    """Other library parameters the value sets (errors about them name this setting)."""
    group: str | None = None
    """The group of options it is listed in."""

    def __post_init__(self):
        if self.kind is None and isinstance(self.default, bool | int | float | str):
            object.__setattr__(self, "kind", type(self.default))

    def check(self, name: str, value):
        """``value`` checked against the declared kind, range and choices; the cleaned
        value (a ``ParameterError``/``ParameterTypeError`` naming ``name``)."""
        if self.kind is bool and not isinstance(value, bool):
            raise ParameterTypeError(name, f"must be true or false; got {value!r}")
        if self.choices is not None:
            return check_choice(name, value, self.choices)
        rule = self.range
        if rule is None:
            return value
        if rule == "finite":
            return check_finite(name, value)
        if rule in (">0", ">=0"):
            return check_positive(name, value, allow_zero=rule == ">=0")
        if self.kind is int:
            return check_int(name, value, *rule)
        return check_range(name, value, *rule)


def setting(default=None, help: str | None = None, **kw) -> Any:
    """A dataclass field with its declaration (:class:`Setting`; ``kw`` its attributes);
    ``dataclasses.MISSING``: a field without a default."""
    decl = Setting(None if default is dataclasses.MISSING else default, help, **kw)
    return dataclasses.field(default=default, metadata={"setting": decl})


def default_of(func, parameter: str):
    """The default of a function's ``parameter``: a setting's default written once, in the
    library function's signature."""
    import inspect

    return inspect.signature(func).parameters[parameter].default


def _kind(field: dataclasses.Field, decl: Setting) -> type | None:
    if decl.kind is not None:
        return decl.kind
    names = [t.strip() for t in str(field.type).split("|")]
    return next((_KINDS[t] for t in names if t in _KINDS), None)


@functools.cache
def declared(cls) -> dict[str, Setting]:
    """{field name: its :class:`Setting`, ``key`` and ``kind`` filled in} of the declared
    fields of the dataclass ``cls``, in field order (do not change the dict)."""
    out = {}
    for f in dataclasses.fields(cls):
        decl = f.metadata.get("setting")
        if decl is not None:
            out[f.name] = dataclasses.replace(decl, key=decl.key or f.name,
                                              kind=_kind(f, decl))
    return out


def by_key(source) -> dict[str, Setting]:
    """{key: setting} of a record's declared fields (:func:`declared`) or of a table of
    settings by key (their ``key`` filled in)."""
    if isinstance(source, dict):
        return {k: dataclasses.replace(s, key=k) for k, s in source.items()}
    return {cast(str, s.key): s for s in declared(source).values()}  # declared() fills keys


def check_declared(obj, *, keep: tuple[str, ...] = ()) -> None:
    """Check every declared field of the dataclass ``obj`` (None passes where the field's
    type or default allows it) and store the cleaned value (an integer ``3.0`` as ``3``,
    a number as a float) but in the fields of ``keep`` (kept as given)."""
    types = {f.name: str(f.type) for f in dataclasses.fields(obj)}
    # a class is hashable; mypy reads type[Any] as not Hashable
    for name, decl in declared(type(obj)).items():  # type: ignore[arg-type]
        value = getattr(obj, name)
        if value is None and (decl.default is None or "None" in types[name]):
            continue
        clean = decl.check(name, value)
        if name not in keep:
            object.__setattr__(obj, name, clean)
