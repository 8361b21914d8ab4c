"""Checking one key's value with pydantic, and saying in words what the key allows.

Each key's type and constraints are declared once, as a field of the models in
:mod:`.schema`; :func:`key_of` turns such a field into a :class:`Key` whose checker
validates with a pydantic ``TypeAdapter`` and, on failure, raises :class:`_Invalid` with
``expected <allowed>, got <value>``, where ``<allowed>`` is written from the field's JSON
Schema (:func:`allowed`), e.g. "an integer >= 1 and <= 7" or "an array of 3 numbers
[fx, fy, fz]".
"""

from __future__ import annotations

import re
import types
from dataclasses import dataclass
from typing import Annotated, Any, Callable, Literal, Union, get_args, get_origin

from pydantic import TypeAdapter, ValidationError
from pydantic.fields import FieldInfo

from .locate import _describe


class _Invalid(Exception):
    """A value is not allowed; the message says what was given and what is allowed.

    ``sub`` locates the offending element inside the value (``"[2]"``).
    """

    def __init__(self, message: str, sub: str = "") -> None:
        super().__init__(message)
        self.sub = sub


_REQUIRED = object()


@dataclass(frozen=True)
class Key:
    """One documented key: its checker, default (or required) and meaning."""

    check: Callable[[Any], Any]
    default: Any = _REQUIRED
    doc: str = ""
    shown_default: str | None = None    # the default as documented, when not the value itself

    @property
    def required(self) -> bool:
        return self.default is _REQUIRED

    @property
    def allowed(self) -> str:
        return getattr(self.check, "allowed", "")


def _bound(x: float) -> str:
    return f"{x:g}"


def allowed(schema: dict[str, Any], title: str = "") -> str:
    """What a JSON Schema allows, in words ("a number > 0", 'one of "a", "b"', …)."""
    if "anyOf" in schema:
        return " or ".join(allowed(s, title) for s in schema["anyOf"] if s.get("type") != "null")
    if "enum" in schema:
        return "one of " + ", ".join(f'"{o}"' for o in schema["enum"])
    if "const" in schema:
        return f'"{schema["const"]}"'
    kind = schema.get("type")
    if kind in ("number", "integer"):
        parts = [f"{op} {_bound(schema[k])}" for k, op in
                 (("minimum", ">="), ("exclusiveMinimum", ">"), ("maximum", "<="),
                  ("exclusiveMaximum", "<")) if k in schema]
        return ("a number" if kind == "number" else "an integer") + \
            ("" if not parts else " " + " and ".join(parts))
    if kind == "string":
        return "a string"
    if kind == "object":
        names = schema.get("propertyNames", {}).get("enum", [])
        return "an inline table" + (" {" + ", ".join(f"{k} = …" for k in names) + "}"
                                    if names else "")
    if kind == "array" and "prefixItems" in schema:
        items = schema["prefixItems"]
        return f"an array of {len(items)} {_plural(allowed(items[0]))}" + \
            (f" {title}" if title else "")
    if kind == "array":
        text = f"an array of {title or _plural(allowed(schema.get('items', {})))}"
        return text + (f" (at least {schema['minItems']})" if schema.get("minItems") else "")
    return "a value"


def _plural(text: str) -> str:
    for one, many in (("a number", "numbers"), ("an integer", "integers"),
                      ("an array", "arrays"), ("a string", "strings"), ("one of", "names among")):
        if text.startswith(one):
            return many + text[len(one):]
    return text


def _without_none(annotation: Any) -> Any:
    if get_origin(annotation) in (Union, types.UnionType):
        args = tuple(a for a in get_args(annotation) if a is not type(None))
        return args[0] if len(args) == 1 else Union[args]
    return annotation


def _frozen(value: Any) -> Any:
    return tuple(_frozen(v) for v in value) if isinstance(value, (list, tuple)) else value


def checker(annotation: Any, title: str = "", pair: bool = False) -> Callable[[Any], Any]:
    """Checker of one value of type ``annotation`` (with its constraints), via pydantic.

    Arrays come back as tuples; with ``pair`` a single value ``x`` becomes ``(x, x)``.
    """
    adapter = TypeAdapter(annotation)
    schema = adapter.json_schema()
    text = allowed(schema, title)
    listed = schema.get("type") == "array" and "prefixItems" not in schema

    def check(value: Any) -> Any:
        try:
            out = _frozen(adapter.validate_python(value))
        except ValidationError as exc:
            loc = exc.errors()[0]["loc"]
            if listed and isinstance(value, list) and loc and isinstance(loc[0], int):
                element = value[loc[0]]
                raise _Invalid(f"expected {allowed(schema['items'])}, got {_describe(element)}",
                               sub=f"[{loc[0] + 1}]") from None
            raise _Invalid(f"expected {text}, got {_describe(value)}") from None
        return (out, out) if pair and not isinstance(out, tuple) else out
    check.allowed = text  # type: ignore[attr-defined]
    return check


def key_of(field: FieldInfo, default: Any = _REQUIRED, pair: bool = False) -> Key:
    """The :class:`Key` of a model field: its checker, default and description.

    ``default`` overrides the field's (keys that are required only in some cases have
    the default None here and a cross-field rule in :mod:`.validate`).
    """
    annotation = _without_none(field.annotation)
    if field.metadata:
        annotation = Annotated[(annotation, *field.metadata)]
    if default is _REQUIRED and not field.is_required():
        default = _frozen(field.get_default(call_default_factory=True))
        if pair and default is not None and not isinstance(default, tuple):
            default = (default, default)
    extra = field.json_schema_extra if isinstance(field.json_schema_extra, dict) else {}
    return Key(checker(annotation, field.title or "", pair), default, field.description or "",
               extra.get("doc_default"))  # type: ignore[arg-type]


def choice(*options: str) -> Callable[[Any], str]:
    """Checker of one string among ``options`` (a discriminator such as ``shape``)."""
    return checker(Literal[options])


#: a union member's type label in a pydantic error location (``dict[str, …]``)
_UNION_MEMBER = re.compile(r"^[a-z][a-z-]*\[.*\]$")


def located_checker(annotation: Any, title: str = "") -> Callable[[Any], Any]:
    """Checker of a nested table: a problem is located at its key path inside the value
    (``.loops[2].circle.radius``, arrays counted from 1) and says pydantic's reason."""
    adapter = TypeAdapter(annotation)
    text = allowed(adapter.json_schema(), title)

    def check(value: Any) -> Any:
        try:
            return adapter.validate_python(value)
        except ValidationError as exc:
            # a union's members are tried in turn: the error that went deepest into the
            # value is the one meant (the first of those), located without the members'
            # type labels (``literal['free', …]``) pydantic puts in its path
            errors = [{**e, "loc": tuple(p for p in e["loc"] if not _UNION_MEMBER.match(str(p)))}
                      for e in exc.errors()]
            error = max(errors, key=lambda e: len(e["loc"]))
            sub = "".join(f"[{p + 1}]" if isinstance(p, int) else f".{p}"
                          for p in error["loc"])
            reason = error["msg"].removeprefix("Value error, ")
            given = "" if error["type"] == "value_error" else f"; got {_describe(error['input'])}"
            raise _Invalid(reason + given, sub=sub) from None
    check.allowed = text  # type: ignore[attr-defined]
    return check


def moving_points_mask(scenario: Any, points: Any, shape: tuple[int, int], key: str,
                       what: str) -> Any:
    """``fixed`` mask of a net of ``shape`` where only ``points`` (``[i, j]`` pairs) move; an
    index off the net names ``key[n]`` and ``what`` ("face 2: its net") has the points."""
    import numpy as np

    moving = np.zeros(shape, dtype=bool)
    for n, (i, j) in enumerate(points, start=1):
        if not (i < shape[0] and j < shape[1]):
            raise scenario.error(f"{key}[{n}]",
                                 f"[{i}, {j}] is not a control point of {what} has "
                                 f"{shape[0]} x {shape[1]} points, i in 0 .. {shape[0] - 1}"
                                 f", j in 0 .. {shape[1] - 1}")
        moving[i, j] = True
    return ~moving
