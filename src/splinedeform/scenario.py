"""Scenario files: one TOML file describes one simulation.

A scenario has the tables ``[surface]``, ``[material]``, ``[boundary]``, ``[[load]]``,
``[solve]`` and ``[output]`` (every key is documented in ``docs/scenario.md``). Reading is
two steps:

1. :func:`load_scenario` / :func:`parse_scenario` read the text with :mod:`tomllib` and
   validate **every** field before any work starts. All problems found are reported
   together in one :class:`~splinedeform.errors.ScenarioError` whose lines read
   ``file:line: key.path: what is wrong; what is allowed``. ``tomllib`` gives no
   positions, so the line of each key is found by scanning the text (:func:`key_lines`).
2. :func:`build` turns a :class:`Scenario` into library objects (surface, model, load),
   and :func:`run` solves it and writes the requested outputs.

Arrays of tables and array elements are counted from 1: ``load[2].force`` is the
``force`` of the second ``[[load]]`` table.
"""

from __future__ import annotations

import copy
import json
import math
import re
import tomllib
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Iterable, Iterator, Mapping

from .basis import KNOT_KINDS as KNOTS
from .boundary import EDGES, PRESETS
from .errors import InputError, ScenarioError
from .model import METHODS
from .shapes import FIT_METHODS

SHAPES = ("plane", "tile", "half_sphere", "cylinder", "torus", "saddle", "file")
LOAD_KINDS = ("point", "uniform", "pressure")
PROFILES = ("constant", "step", "piecewise", "harmonic")
SOLVE_KINDS = ("static", "modes", "dynamic")
IVP_METHODS = ("rk45", "dop853", "radau", "bdf")
MASS_MATRICES = ("consistent", "lumped")
FORMATS = ("obj", "stl", "ply", "vtu", "json", "npz", "report", "images", "gif", "mp4",
           "viewer")
#: shorthand names accepted in ``output.formats``
FORMAT_ALIASES = {"pvd": ("vtu",), "nets": ("json", "npz"), "animation": ("gif",),
                  "all": ("obj", "stl", "ply", "vtu", "json", "npz", "report", "images", "gif",
                          "viewer")}


# =====================================================================================
# Where keys are written: tomllib gives values, not positions
# =====================================================================================
_BARE = frozenset("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789_-")


class _KeyScanner:
    """Finds the line of every key, table header and array element of a TOML text.

    A small state machine over the characters: it skips strings and comments, follows
    ``[table]`` / ``[[array]]`` headers (counting array tables from 1), dotted keys,
    inline tables and arrays (counting elements from 1).
    """

    def __init__(self, text: str) -> None:
        self.text = text
        self.pos = 0
        self.line = 1
        self.lines: dict[str, int] = {}
        self.counts: dict[str, int] = {}

    def peek(self) -> str:
        return self.text[self.pos] if self.pos < len(self.text) else ""

    def advance(self, k: int = 1) -> None:
        k = max(1, k)
        self.line += self.text.count("\n", self.pos, self.pos + k)
        self.pos += k

    def at_end(self) -> bool:
        return self.pos >= len(self.text)

    def skip_blank(self, newlines: bool) -> None:
        while not self.at_end():
            c = self.peek()
            if c in " \t\r" or (newlines and c == "\n"):
                self.advance()
            elif c == "#":
                end = self.text.find("\n", self.pos)
                if end < 0:
                    end = len(self.text)
                if end == self.pos:
                    return
                self.advance(end - self.pos)
            else:
                return

    def skip_to_line_end(self) -> None:
        end = self.text.find("\n", self.pos)
        self.advance((len(self.text) if end < 0 else end) - self.pos)

    def string(self) -> str:
        """Skip the string starting here and return its raw content."""
        quote = self.peek()
        delim = quote * 3 if self.text.startswith(quote * 3, self.pos) else quote
        self.advance(len(delim))
        start = self.pos
        while not self.at_end():
            if quote == '"' and self.peek() == "\\":
                self.advance(2)
            elif self.text.startswith(delim, self.pos):
                content = self.text[start:self.pos]
                self.advance(len(delim))
                return content
            elif len(delim) == 1 and self.peek() == "\n":
                break
            else:
                self.advance()
        return self.text[start:self.pos]

    def key(self) -> list[str]:
        parts: list[str] = []
        while True:
            self.skip_blank(newlines=False)
            if self.peek() in ('"', "'"):
                parts.append(self.string())
            else:
                start = self.pos
                while not self.at_end() and self.peek() in _BARE:
                    self.pos += 1
                if self.pos == start:
                    return parts
                parts.append(self.text[start:self.pos])
            self.skip_blank(newlines=False)
            if self.peek() != ".":
                return parts
            self.advance()

    def header(self) -> str:
        array = self.text.startswith("[[", self.pos)
        self.advance(2 if array else 1)
        line = self.line
        name = ".".join(self.key())
        if array:
            self.counts[name] = self.counts.get(name, 0) + 1
            name = f"{name}[{self.counts[name]}]"
        self.lines.setdefault(name, line)
        self.skip_to_line_end()
        return name

    def value(self, path: str) -> None:
        self.skip_blank(newlines=False)
        c = self.peek()
        if c in ('"', "'"):
            self.string()
        elif c == "{":
            self.container(path, "}", self.key_value)
        elif c == "[":
            index = [0]

            def element(prefix: str) -> None:
                index[0] += 1
                self.lines.setdefault(f"{prefix}[{index[0]}]", self.line)
                self.value(f"{prefix}[{index[0]}]")
            self.container(path, "]", element)
        else:
            while not self.at_end() and self.peek() not in ",]}\n#":
                self.pos += 1

    def container(self, path: str, close: str, item: Callable[[str], None]) -> None:
        self.advance()
        while not self.at_end():
            self.skip_blank(newlines=True)
            if self.peek() == close:
                self.advance()
                return
            start = self.pos
            if self.peek() == ",":
                self.advance()
                continue
            item(path)
            if self.pos == start:   # malformed: make progress, tomllib reports it
                self.advance()

    def key_value(self, prefix: str) -> None:
        line = self.line
        parts = self.key()
        if not parts:
            self.skip_to_line_end()
            return
        path = ".".join(([prefix] if prefix else []) + parts)
        self.lines.setdefault(path, line)
        self.skip_blank(newlines=False)
        if self.peek() == "=":
            self.advance()
            self.value(path)

    def scan(self) -> dict[str, int]:
        table = ""
        while True:
            self.skip_blank(newlines=True)
            if self.at_end():
                return self.lines
            start = self.pos
            if self.peek() == "[":
                table = self.header()
            else:
                self.key_value(table)
            if self.pos == start:
                self.advance()


def key_lines(text: str) -> dict[str, int]:
    """Line number (from 1) of every key path written in a TOML text.

    A best effort by scanning the text, as :mod:`tomllib` reports no positions. Paths are
    dotted; arrays of tables and array elements are indexed from 1, e.g.
    ``{"surface": 3, "surface.shape": 4, "load[2].force": 17, "output.probes[1]": 30}``.
    """
    return _KeyScanner(text).scan()


# =====================================================================================
# Validation: every problem becomes one line of a ScenarioError
# =====================================================================================
class _Invalid(Exception):
    """A value is not allowed; the message says what was given and what is allowed.

    ``sub`` locates the offending element inside the value (``"[2]"``).
    """

    def __init__(self, message: str, sub: str = "") -> None:
        super().__init__(message)
        self.sub = sub


class _Problems:
    """Collects the problems of one scenario text, each with its key path and line."""

    def __init__(self, source: str, lines: Mapping[str, int],
                 origins: Mapping[str, str] | None = None) -> None:
        self.source = source
        self.lines = lines
        self.origins = dict(origins or {})
        self.items: list[tuple[int, str]] = []

    def line_of(self, path: str) -> int | None:
        """Line of ``path`` or of its nearest written parent (for a missing key)."""
        while path:
            if path in self.lines:
                return self.lines[path]
            cut = max(path.rfind("."), path.rfind("["))
            path = path[:cut] if cut > 0 else ""
        return None

    def where(self, path: str) -> str:
        if path in self.origins:
            return f"{self.source} ({self.origins[path]})"
        line = self.line_of(path)
        return f"{self.source}:{line}" if line is not None else self.source

    def add(self, path: str, message: str) -> None:
        line = self.line_of(path) if path not in self.origins else None
        self.items.append((line or 0, f"{self.where(path)}: {path}: {message}"))

    def message(self) -> str:
        """All problems, sorted by line, in one text."""
        items = [text for _, text in sorted(self.items, key=lambda item: item[0])]
        if len(items) == 1:
            return items[0]
        head = f"{self.source}: {len(items)} problems in the scenario"
        return "\n".join([head] + [f"  {item}" for item in items])

    def raise_if_any(self) -> None:
        if self.items:
            raise ScenarioError(self.message())


def _describe(value: Any) -> str:
    if isinstance(value, dict):
        return "a table"
    if isinstance(value, list):
        return f"an array {_short(value)}"
    if isinstance(value, bool):
        return f"the boolean {str(value).lower()}"
    if isinstance(value, str):
        return f"the string {value!r}"
    return f"{type(value).__name__} {value!r}"


def _short(value: Any) -> str:
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


# -- value checkers: return the normalised value or raise _Invalid -------------------------
def _is_number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def number(low: float | None = None, high: float | None = None, *, open_low: bool = False,
           allow_inf: bool = False) -> Callable[[Any], float]:
    """Checker of a finite real (``inf`` only if allowed) in ``[low, high]`` (``(low`` if open)."""
    parts = []
    if low is not None:
        parts.append(f"{'>' if open_low else '>='} {low:g}")
    if high is not None:
        parts.append(f"<= {high:g}")
    allowed = "a number" + (" " + " and ".join(parts) if parts else "")

    def check(value: Any) -> float:
        if not _is_number(value):
            raise _Invalid(f"expected {allowed}, got {_describe(value)}")
        x = float(value)
        if math.isnan(x) or (math.isinf(x) and not (allow_inf and x > 0)):
            raise _Invalid(f"expected {allowed}, got {x}")
        if low is not None and (x < low or (open_low and x == low)):
            raise _Invalid(f"expected {allowed}, got {value!r}")
        if high is not None and x > high:
            raise _Invalid(f"expected {allowed}, got {value!r}")
        return x
    check.allowed = allowed  # type: ignore[attr-defined]
    return check


def integer(low: int | None = None, high: int | None = None) -> Callable[[Any], int]:
    """Checker of an integer in ``[low, high]``."""
    bounds = " ".join(([f">= {low}"] if low is not None else [])
                      + ([f"<= {high}"] if high is not None else []))
    allowed = "an integer" + (" " + bounds.replace(" <=", " and <=") if bounds else "")

    def check(value: Any) -> int:
        if isinstance(value, bool) or not isinstance(value, int):
            raise _Invalid(f"expected {allowed}, got {_describe(value)}")
        if (low is not None and value < low) or (high is not None and value > high):
            raise _Invalid(f"expected {allowed}, got {value}")
        return int(value)
    check.allowed = allowed  # type: ignore[attr-defined]
    return check


def choice(*options: str) -> Callable[[Any], str]:
    """Checker of one string among ``options``."""
    allowed = "one of " + ", ".join(f'"{o}"' for o in options)

    def check(value: Any) -> str:
        if not isinstance(value, str) or value not in options:
            raise _Invalid(f"expected {allowed}, got {_describe(value)}")
        return value
    check.allowed = allowed  # type: ignore[attr-defined]
    return check


def text(value: Any) -> str:
    """Checker of a string."""
    if not isinstance(value, str):
        raise _Invalid(f"expected a string, got {_describe(value)}")
    return value


text.allowed = "a string"  # type: ignore[attr-defined]


def vector(length: int, item: Callable[[Any], Any], name: str) -> Callable[[Any], tuple]:
    """Checker of an array of exactly ``length`` items, each checked by ``item``."""
    allowed = f"an array of {length} {getattr(item, 'allowed', 'values')[2:]}s {name}"
    allowed = allowed.replace("a numbers", "numbers").replace("an integers", "integers")

    def check(value: Any) -> tuple:
        if not isinstance(value, list) or len(value) != length:
            raise _Invalid(f"expected {allowed}, got {_describe(value)}")
        try:
            return tuple(item(v) for v in value)
        except _Invalid as exc:
            raise _Invalid(f"expected {allowed}; {exc}") from None
    check.allowed = allowed  # type: ignore[attr-defined]
    return check


def scalar_or_pair(item: Callable[[Any], Any], name: str) -> Callable[[Any], tuple]:
    """Checker of one value for both directions or a pair ``[u, v]``."""
    pair = vector(2, item, name)
    pair_allowed = getattr(pair, "allowed", "a pair")
    allowed = f"{getattr(item, 'allowed', 'a value')} or {pair_allowed}"

    def check(value: Any) -> tuple:
        if isinstance(value, list):
            return pair(value)
        try:
            v = item(value)
        except _Invalid:
            raise _Invalid(f"expected {allowed}, got {_describe(value)}") from None
        return (v, v)
    check.allowed = allowed  # type: ignore[attr-defined]
    return check


def one_or_pair(item: Callable[[Any], Any], name: str) -> Callable[[Any], Any]:
    """Like :func:`scalar_or_pair` but a single value is kept as given (not doubled)."""
    both = scalar_or_pair(item, name)

    def check(value: Any) -> Any:
        pair = both(value)
        return pair if isinstance(value, list) else pair[0]
    check.allowed = both.allowed  # type: ignore[attr-defined]
    return check


def array_of(item: Callable[[Any], Any], name: str, min_length: int = 0) -> Callable[[Any], tuple]:
    """Checker of an array (at least ``min_length`` long) of items."""
    allowed = f"an array of {name}" + (f" (at least {min_length})" if min_length else "")

    def check(value: Any) -> tuple:
        if not isinstance(value, list) or len(value) < min_length:
            raise _Invalid(f"expected {allowed}, got {_describe(value)}")
        out = []
        for i, v in enumerate(value, start=1):
            try:
                out.append(item(v))
            except _Invalid as exc:
                raise _Invalid(str(exc), sub=f"[{i}]{exc.sub}") from None
        return tuple(out)
    check.allowed = allowed  # type: ignore[attr-defined]
    return check


_REQUIRED = object()


@dataclass(frozen=True)
class Key:
    """One documented key: its checker, default (or required) and meaning."""

    check: Callable[[Any], Any]
    default: Any = _REQUIRED
    doc: str = ""

    @property
    def required(self) -> bool:
        return self.default is _REQUIRED

    @property
    def allowed(self) -> str:
        return getattr(self.check, "allowed", "")


_POSITIVE = number(0.0, open_low=True)
_NONNEG = number(0.0)
_REAL = number()
_PAIR = vector(2, _POSITIVE, "[u, v]")
_RANGE = vector(2, _REAL, "[low, high]")

#: parameters of each built-in shape (passed to the function of ``splinedeform.shapes``)
_SIZE = Key(scalar_or_pair(_POSITIVE, "[L_u, L_v]"), (1.0, 1.0),
            "side lengths; the domain is [0, L_u] × [0, L_v]")
SHAPE_PARAMETERS: dict[str, dict[str, Key]] = {
    "plane": {"size": _SIZE},
    "tile": {"radius": Key(_POSITIVE, 1.0, "radius of the arc"),
             "angle": Key(number(0.0, 2 * math.pi, open_low=True), math.pi / 2,
                          "opening angle of the arc (radians, < 2π)"),
             "length": Key(_POSITIVE, 2.0, "length along the axis")},
    "half_sphere": {"radius": Key(_POSITIVE, 1.0, "sphere radius")},
    "cylinder": {"radius": Key(_POSITIVE, 1.0, "radius"),
                 "height": Key(_POSITIVE, 2.0, "height (along z)")},
    "torus": {"R": Key(_POSITIVE, 1.0, "radius of the centre line"),
              "r": Key(_POSITIVE, 0.4, "tube radius (r < R)")},
    "saddle": {"size": _SIZE,
               "height": Key(_REAL, 0.25, "z = height (ξ² - η²), ξ, η in [-1, 1]")},
    "file": {},
}

SURFACE_KEYS: dict[str, Key] = {
    "shape": Key(choice(*SHAPES), doc="built-in shape, or a net / point grid from a file"),
    "cells": Key(scalar_or_pair(integer(1, 512), "[m_u, m_v]"), None,
                 "knot spans per direction (default: the shape's own)"),
    "degree": Key(integer(1, 7), 3, "polynomial degree of the B-splines"),
    "knots": Key(one_or_pair(choice(*KNOTS), "[u, v]"), None,
                 "knot layout per direction (default: the shape's own)"),
    "method": Key(choice(*FIT_METHODS), "interpolate",
                  "how control points are fitted to the shape"),
    "path": Key(text, None, "control net (.json/.npz) or point grid (.npy/.npz) file"),
    "frame": Key(integer(), -1, "frame of a control net file (negative from the end)"),
}

MATERIAL_KEYS: dict[str, Key] = {
    "mass": Key(_POSITIVE, 1.0, "mass density μ"),
    "damping": Key(_NONNEG, 0.0, "viscous damping γ"),
    "rayleigh": Key(_NONNEG, 0.0, "stiffness-proportional damping β"),
    "w10": Key(_NONNEG, 0.0, "tension in u"),
    "w01": Key(_NONNEG, 0.0, "tension in v"),
    "w20": Key(_NONNEG, 0.0, "bending in u"),
    "w11": Key(_NONNEG, 0.0, "twist (bending, mixed)"),
    "w02": Key(_NONNEG, 0.0, "bending in v"),
    "mass_matrix": Key(choice(*MASS_MATRICES), "consistent", "consistent or lumped mass"),
}

FREE_REGION_KEYS: dict[str, Key] = {
    "u": Key(_RANGE, None, "parameter range in u of the moving control points"),
    "v": Key(_RANGE, None, "parameter range in v of the moving control points"),
}

BOUNDARY_KEYS: dict[str, Key] = {
    **{e: Key(choice(*PRESETS), "free", f"edge {e[0]} = {'0' if e[1] == '0' else 'L'}")
       for e in EDGES},
    "free_region": Key(lambda v: v, None, "only control points with Greville abscissae "
                                          "in this box move"),
}

LOAD_KEYS: dict[str, Key] = {
    "kind": Key(choice(*LOAD_KINDS), doc="point force, uniform force per area, or pressure"),
    "at": Key(vector(2, _REAL, "[u, v]"), None, "parameters of a point force"),
    "force": Key(vector(3, _REAL, "[fx, fy, fz]"), None, "force (point) or force per area"),
    "q": Key(_REAL, None, "pressure along the initial normal x_u × x_v"),
    "profile": Key(choice(*PROFILES), "constant", "time profile s(t) scaling the load"),
    "t_on": Key(_NONNEG, 0.0, "step: switch-on time"),
    "t_off": Key(number(0.0, allow_inf=True), math.inf, "step: switch-off time"),
    "points": Key(array_of(vector(2, _REAL, "[t, s]"), "[t, s] pairs", 1), None,
                  "piecewise: scale s from time t on"),
    "omega": Key(_POSITIVE, None, "harmonic: angular frequency ω in sin(ωt + φ)"),
    "phase": Key(_REAL, 0.0, "harmonic: phase φ"),
}

#: load keys allowed for each kind and each profile
LOAD_KIND_KEYS = {"point": ("at", "force"), "uniform": ("force",), "pressure": ("q",)}
PROFILE_KEYS = {"constant": (), "step": ("t_on", "t_off"), "piecewise": ("points",),
                "harmonic": ("omega", "phase")}

SOLVE_KEYS: dict[str, Key] = {
    "kind": Key(choice(*SOLVE_KINDS), doc="static equilibrium, free vibration modes, or motion"),
    "method": Key(choice(*METHODS), "analytic", "time integration (dynamic)"),
    "t_end": Key(_POSITIVE, None, "end time (dynamic)"),
    "frames": Key(integer(2, 100000), 50, "number of equally spaced frames in [0, t_end]"),
    "times": Key(array_of(_NONNEG, "times >= 0", 1), None, "explicit frame times"),
    "modes": Key(integer(0, 1000), 6, "number of vibration modes to report"),
    "rtol": Key(number(0.0, 1.0, open_low=True), 1e-8, "relative tolerance (rk45..bdf)"),
    "atol": Key(_POSITIVE, 1e-10, "absolute tolerance (rk45..bdf)"),
    "dt": Key(_POSITIVE, None, "time step (newmark); default t_end / (20 (frames - 1))"),
}

#: keys of [solve] used by each kind / method
SOLVE_KIND_KEYS = {"static": ("frames",), "modes": ("modes", "frames"),
                   "dynamic": ("method", "t_end", "frames", "times", "modes", "rtol", "atol",
                               "dt")}

OUTPUT_KEYS: dict[str, Key] = {
    "formats": Key(array_of(choice(*FORMATS, *FORMAT_ALIASES), "format names"), ("report",),
                   "what to write"),
    "resolution": Key(integer(2, 1024), 32, "tessellation samples per direction"),
    "probes": Key(array_of(vector(2, _REAL, "[u, v]"), "[u, v] pairs"), (),
                  "points whose displacement is reported and plotted"),
    "time": Key(_NONNEG, None, "state written as a mesh (default: the last frame)"),
}

TOP_KEYS: dict[str, Key] = {
    "title": Key(text, "", "a one-line title, shown in reports"),
    "description": Key(text, "", "free text, copied to the report"),
}

TABLES: dict[str, dict[str, Key]] = {
    "surface": SURFACE_KEYS, "material": MATERIAL_KEYS, "boundary": BOUNDARY_KEYS,
    "load": LOAD_KEYS, "solve": SOLVE_KEYS, "output": OUTPUT_KEYS,
}


def documented_keys() -> list[str]:
    """Every key path a scenario may contain, as listed in ``docs/scenario.md``.

    Array tables are written without index (``load.force``); shape parameters as
    ``surface.<name>``; the free region as ``boundary.free_region.u``.
    """
    keys = list(TOP_KEYS)
    for table, schema in TABLES.items():
        keys += [f"{table}.{k}" for k in schema]
    keys += [f"boundary.free_region.{k}" for k in FREE_REGION_KEYS]
    for params in SHAPE_PARAMETERS.values():
        keys += [f"surface.{k}" for k in params if f"surface.{k}" not in keys]
    return keys


# =====================================================================================
# The validated scenario
# =====================================================================================
@dataclass(frozen=True)
class SurfaceSpec:
    """``[surface]``: a built-in shape with its parameters, or a file."""

    shape: str
    cells: tuple[int, int] | None = None
    degree: int = 3
    knots: str | tuple[str, str] | None = None
    method: str = "interpolate"
    path: Path | None = None
    frame: int = -1
    parameters: dict[str, Any] = field(default_factory=dict)


@dataclass(frozen=True)
class MaterialSpec:
    """``[material]``: the :class:`~splinedeform.material.Material` arguments and the mass matrix."""

    mass: float = 1.0
    damping: float = 0.0
    rayleigh: float = 0.0
    w10: float = 0.0
    w01: float = 0.0
    w20: float = 0.0
    w11: float = 0.0
    w02: float = 0.0
    mass_matrix: str = "consistent"

    def weights(self) -> dict[str, float]:
        return {k: getattr(self, k) for k in MATERIAL_KEYS if k != "mass_matrix"}


@dataclass(frozen=True)
class BoundarySpec:
    """``[boundary]``: edge presets and an optional box of moving control points."""

    u0: str = "free"
    u1: str = "free"
    v0: str = "free"
    v1: str = "free"
    free_u: tuple[float, float] | None = None
    free_v: tuple[float, float] | None = None

    def edges(self) -> dict[str, str]:
        return {e: getattr(self, e) for e in EDGES}

    @property
    def has_free_region(self) -> bool:
        return self.free_u is not None or self.free_v is not None


@dataclass(frozen=True)
class LoadSpec:
    """One ``[[load]]`` table."""

    kind: str
    at: tuple[float, float] | None = None
    force: tuple[float, float, float] | None = None
    q: float | None = None
    profile: str = "constant"
    t_on: float = 0.0
    t_off: float = math.inf
    points: tuple[tuple[float, float], ...] | None = None
    omega: float | None = None
    phase: float = 0.0


@dataclass(frozen=True)
class SolveSpec:
    """``[solve]``: what to compute and at which times."""

    kind: str
    method: str = "analytic"
    t_end: float | None = None
    frames: int = 50
    times: tuple[float, ...] | None = None
    modes: int = 6
    rtol: float = 1e-8
    atol: float = 1e-10
    dt: float | None = None

    def frame_times(self) -> tuple[float, ...]:
        """Frame times: ``times`` if given, else ``frames`` equally spaced in ``[0, t_end]``."""
        if self.times is not None:
            return self.times
        t_end = self.t_end or 0.0
        return tuple(t_end * i / (self.frames - 1) for i in range(self.frames))


@dataclass(frozen=True)
class OutputSpec:
    """``[output]``: which files to write."""

    formats: tuple[str, ...] = ("report",)
    resolution: int = 32
    probes: tuple[tuple[float, float], ...] = ()
    time: float | None = None


@dataclass(frozen=True)
class Scenario:
    """A validated scenario; build it with :func:`build`, run it with :func:`run`."""

    surface: SurfaceSpec
    material: MaterialSpec
    boundary: BoundarySpec
    loads: tuple[LoadSpec, ...]
    solve: SolveSpec
    output: OutputSpec
    title: str = ""
    description: str = ""
    source: str = "<scenario>"
    directory: Path = field(default_factory=Path.cwd)
    raw: dict[str, Any] = field(default_factory=dict, repr=False, compare=False)
    lines: dict[str, int] = field(default_factory=dict, repr=False, compare=False)
    origins: dict[str, str] = field(default_factory=dict, repr=False, compare=False)

    @property
    def name(self) -> str:
        """File stem (or ``scenario``), used to name outputs."""
        stem = Path(self.source).stem
        return stem if stem and not stem.startswith("<") else "scenario"

    def error(self, path: str, message: str) -> ScenarioError:
        """A :class:`ScenarioError` located at ``path`` (``file:line: path: message``)."""
        problems = _Problems(self.source, self.lines, self.origins)
        problems.add(path, message)
        return ScenarioError(problems.message())


# -- reading ---------------------------------------------------------------------------
def load_scenario(path: str | Path, overrides: Mapping[str, Any] | None = None,
                  origin: str = "override") -> Scenario:
    """Read and validate a scenario file.

    Parameters
    ----------
    path : str or Path
        The TOML file. Relative file names inside it (``surface.path``) are resolved
        against its folder.
    overrides : mapping, optional
        ``{"solve.frames": 5, "surface.cells": 4}``: values replacing (or, for ``None``,
        removing) keys of the file before validation; problems with them are reported as
        coming from ``origin``.

    Raises
    ------
    ScenarioError
        With every problem found, each as ``file:line: key.path: message``.
    """
    path = Path(path)
    try:
        content = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise ScenarioError(f"{path}: scenario file not found") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise ScenarioError(f"{path}: cannot read the scenario file ({exc})") from None
    return parse_scenario(content, source=str(path), directory=path.parent.resolve(),
                          overrides=overrides, origin=origin)


def parse_scenario(content: str, source: str = "<scenario>", directory: Path | None = None,
                   overrides: Mapping[str, Any] | None = None,
                   origin: str = "override") -> Scenario:
    """Validate the TOML text of a scenario (see :func:`load_scenario`)."""
    try:
        raw = tomllib.loads(content)
    except tomllib.TOMLDecodeError as exc:
        match = re.search(r"\(at line (\d+), column (\d+)\)", str(exc))
        reason = re.sub(r"\s*\(at line \d+, column \d+\)", "", str(exc))
        where = f"{source}:{match.group(1)}" if match else source
        column = f" (column {match.group(2)})" if match else ""
        raise ScenarioError(f"{where}: TOML syntax error{column}: {reason}") from None
    lines = key_lines(content)
    origins: dict[str, str] = {}
    if overrides:
        raw = _apply_overrides(raw, overrides)
        origins = {key: origin for key in overrides}
    return _validate(raw, source, lines, origins, directory or Path.cwd())


def with_overrides(scenario: Scenario, overrides: Mapping[str, Any],
                   origin: str = "override") -> Scenario:
    """A copy of ``scenario`` with keys replaced (``None`` removes a key), validated again.

    Keys are ``"table.key"`` (``"solve.frames"``) or top-level names; a key of
    ``load`` applies to every ``[[load]]`` table.
    """
    raw = _apply_overrides(scenario.raw, overrides)
    origins = {**scenario.origins, **{key: origin for key in overrides}}
    return _validate(raw, scenario.source, scenario.lines, origins, scenario.directory)


def _apply_overrides(raw: Mapping[str, Any], overrides: Mapping[str, Any]) -> dict[str, Any]:
    out = copy.deepcopy(dict(raw))
    for key, value in overrides.items():
        table, _, name = key.rpartition(".")
        targets: list[dict[str, Any]]
        if not table:
            targets = [out]
        elif table == "load":
            targets = [t for t in out.get("load", []) if isinstance(t, dict)]
        else:
            if not isinstance(out.get(table, {}), dict):
                raise InputError(f"cannot override {key}: [{table}] is not a table")
            targets = [out.setdefault(table, {})]
        for target in targets:
            if value is None:
                target.pop(name, None)
            else:
                target[name] = copy.deepcopy(value)
    return out


# -- validation ------------------------------------------------------------------------
def _check_table(raw: Any, schema: Mapping[str, Key], path: str, problems: _Problems,
                 table_name: str, allowed_extra: Mapping[str, Key] | None = None
                 ) -> dict[str, Any]:
    """Check each key of a table against its schema; return the valid values given."""
    if not isinstance(raw, dict):
        problems.add(path, f"expected a table [{table_name}], got {_describe(raw)}")
        return {}
    known = {**schema, **(allowed_extra or {})}
    values: dict[str, Any] = {}
    for key, value in raw.items():
        where = f"{path}.{key}"
        if key not in known:
            problems.add(where, f"unknown key in [{table_name}]; allowed keys: "
                                f"{', '.join(known)}")
            continue
        try:
            values[key] = known[key].check(value)
        except _Invalid as exc:
            problems.add(where + exc.sub, str(exc))
    return values


def _require(values: Mapping[str, Any], raw: Any, keys: Iterable[str], schema: Mapping[str, Key],
             path: str, problems: _Problems, reason: str = "") -> None:
    """Report each key of ``keys`` missing from the table ``raw``."""
    if not isinstance(raw, dict):
        return
    for key in keys:
        if key not in raw:
            problems.add(f"{path}.{key}", f"missing{reason}; expected {schema[key].allowed}")


def _not_applicable(raw: Any, keys: Iterable[str], allowed: Iterable[str], path: str,
                    problems: _Problems, context: str) -> None:
    """Report keys given although they do not apply (``context`` says why)."""
    if not isinstance(raw, dict):
        return
    allowed = set(allowed)
    for key in keys:
        if key in raw and key not in allowed:
            problems.add(f"{path}.{key}", f"does not apply {context}")


def _with_defaults(schema: Mapping[str, Key], values: Mapping[str, Any],
                   keys: Iterable[str]) -> dict[str, Any]:
    out = {}
    for key in keys:
        if key in values:
            out[key] = values[key]
        elif not schema[key].required:
            out[key] = schema[key].default
    return out


def _validate(raw: dict[str, Any], source: str, lines: Mapping[str, int],
              origins: Mapping[str, str], directory: Path) -> Scenario:
    problems = _Problems(source, lines, origins)
    for key in raw:
        if key not in TABLES and key not in TOP_KEYS:
            problems.add(key, "unknown key or table; allowed: "
                              f"{', '.join(list(TOP_KEYS) + [f'[{t}]' for t in TABLES])}")
    top = {}
    for key in TOP_KEYS:
        if key in raw:
            try:
                top[key] = TOP_KEYS[key].check(raw[key])
            except _Invalid as exc:
                problems.add(key, str(exc))
    surface = _validate_surface(raw, problems, directory)
    material = _validate_material(raw, problems, surface)
    boundary = _validate_boundary(raw, problems)
    solve = _validate_solve(raw, problems)
    loads = _validate_loads(raw, problems, solve)
    output = _validate_output(raw, problems, solve)
    problems.raise_if_any()
    assert surface and material and boundary and solve and output is not None
    return Scenario(surface=surface, material=material, boundary=boundary, loads=loads,
                    solve=solve, output=output, title=top.get("title", ""),
                    description=top.get("description", ""), source=source,
                    directory=directory, raw=raw, lines=dict(lines), origins=dict(origins))


def _validate_surface(raw: Mapping[str, Any], problems: _Problems,
                      directory: Path) -> SurfaceSpec | None:
    if "surface" not in raw:
        problems.add("surface", "missing table [surface]; it needs at least shape = "
                                f"{SURFACE_KEYS['shape'].allowed}")
        return None
    table = raw["surface"]
    parameters = {k: v for params in SHAPE_PARAMETERS.values() for k, v in params.items()}
    values = _check_table(table, SURFACE_KEYS, "surface", problems, "surface", parameters)
    _require(values, table, ["shape"], SURFACE_KEYS, "surface", problems)
    shape = values.get("shape")
    if shape is None:
        return None
    own = SHAPE_PARAMETERS[shape]
    for key in parameters:
        if isinstance(table, dict) and key in table and key not in own:
            problems.add(f"surface.{key}", f"is not a parameter of shape {shape!r}; its "
                                           f"parameters are: {', '.join(own) or 'none'}")
    if shape == "file":
        _require(values, table, ["path"], SURFACE_KEYS, "surface", problems,
                 " (shape = \"file\" reads the net or grid from this file)")
    else:
        _not_applicable(table, ["path", "frame"], [], "surface", problems,
                        f"to shape {shape!r}, only to shape = \"file\"")
    spec = _with_defaults(SURFACE_KEYS, values, [k for k in SURFACE_KEYS if k != "shape"])
    if spec.get("path") is not None:
        spec["path"] = (directory / spec["path"]).resolve()
    params = {k: values.get(k, key.default) for k, key in own.items()}
    return SurfaceSpec(shape=shape, parameters=params, **spec)


def _validate_material(raw: Mapping[str, Any], problems: _Problems,
                       surface: SurfaceSpec | None) -> MaterialSpec | None:
    table = raw.get("material", {})
    values = _check_table(table, MATERIAL_KEYS, "material", problems, "material")
    spec = MaterialSpec(**values)
    weights = ("w10", "w01", "w20", "w11", "w02")
    if isinstance(table, dict) and all(getattr(spec, w) == 0 for w in weights) and not any(
            w in table and w not in values for w in weights):
        problems.add("material", "all stiffness weights are zero (or missing): the surface "
                                 "would have no elastic energy; set a tension weight (w10, "
                                 "w01) or a bending weight (w20, w11, w02) > 0")
    bending = spec.w20 > 0 or spec.w11 > 0 or spec.w02 > 0
    if bending and surface is not None and surface.shape != "file" and surface.degree < 2:
        problems.add("surface.degree", "bending weights (w20, w11, w02) need second "
                                       "derivatives: degree must be >= 2")
    return spec


def _validate_boundary(raw: Mapping[str, Any], problems: _Problems) -> BoundarySpec | None:
    table = raw.get("boundary", {})
    values = _check_table(table, BOUNDARY_KEYS, "boundary", problems, "boundary")
    region = values.pop("free_region", None)
    box: dict[str, tuple[float, float] | None] = {"free_u": None, "free_v": None}
    if region is not None:
        ranges = _check_table(region, FREE_REGION_KEYS, "boundary.free_region", problems,
                              "boundary.free_region")
        if isinstance(region, dict) and not region:
            problems.add("boundary.free_region", "is empty; give u = [low, high] and/or "
                                                 "v = [low, high]")
        for key, (low, high) in ranges.items():
            if not low < high:
                problems.add(f"boundary.free_region.{key}",
                             f"expected [low, high] with low < high, got [{low:g}, {high:g}]")
            box[f"free_{key}"] = (low, high)
    return BoundarySpec(**values, **box)


def _validate_loads(raw: Mapping[str, Any], problems: _Problems,
                    solve: SolveSpec | None) -> tuple[LoadSpec, ...]:
    tables = raw.get("load", [])
    if isinstance(tables, dict):
        problems.add("load", "write loads as an array of tables: [[load]] (double brackets)")
        return ()
    if not isinstance(tables, list):
        problems.add("load", f"expected [[load]] tables, got {_describe(tables)}")
        return ()
    if not tables and solve is not None and solve.kind != "modes":
        problems.add("load", f"a {solve.kind} solve needs at least one [[load]] table")
    return tuple(spec for i, table in enumerate(tables, start=1)
                 if (spec := _validate_load(table, f"load[{i}]", problems)) is not None)


def _validate_load(table: Any, path: str, problems: _Problems) -> LoadSpec | None:
    values = _check_table(table, LOAD_KEYS, path, problems, "[load]")
    _require(values, table, ["kind"], LOAD_KEYS, path, problems)
    kind, profile = values.get("kind"), values.get("profile", "constant")
    if kind is None:
        return None
    _require(values, table, LOAD_KIND_KEYS[kind], LOAD_KEYS, path, problems,
             f" (a {kind} load needs it)")
    _not_applicable(table, ("at", "force", "q"), LOAD_KIND_KEYS[kind], path, problems,
                    f"to a {kind} load (it uses {', '.join(LOAD_KIND_KEYS[kind])})")
    used = PROFILE_KEYS[profile]
    _not_applicable(table, ("t_on", "t_off", "points", "omega", "phase"), used, path, problems,
                    f"to profile {profile!r}" + (f" (it uses {', '.join(used)})" if used else ""))
    needed = {"piecewise": ["points"], "harmonic": ["omega"]}.get(profile, [])
    _require(values, table, needed, LOAD_KEYS, path, problems, f" (profile {profile!r} needs it)")
    if profile == "step" and values.get("t_off", math.inf) <= values.get("t_on", 0.0):
        problems.add(f"{path}.t_off", f"must be > t_on = {values.get('t_on', 0.0):g}, got "
                                      f"{values['t_off']:g}")
    if "points" in values:
        times = [t for t, _ in values["points"]]
        bad = _first_not_increasing(times)
        if bad is not None:
            problems.add(f"{path}.points[{bad}]", f"times must be >= 0 and increasing, got "
                                                  f"{times}")
    if "at" in values:
        if any(x < 0 for x in values["at"]):
            problems.add(f"{path}.at", f"parameters must be >= 0, got {list(values['at'])}")
    if values.get("q") == 0 or ("force" in values and not any(values["force"])):
        problems.add(f"{path}.{'q' if kind == 'pressure' else 'force'}",
                     "is zero: this load does nothing; remove the [[load]] table or give a "
                     "non-zero value")
    given = [k for k in LOAD_KEYS if k != "kind"]
    return LoadSpec(kind=kind, **_with_defaults(LOAD_KEYS, values, given))


def _first_not_increasing(times: Iterable[float]) -> int | None:
    """Index (from 1) of the first time that is negative or not above the one before."""
    previous = -math.inf
    for i, t in enumerate(times, start=1):
        if t < 0 or t <= previous:
            return i
        previous = t
    return None


def _validate_solve(raw: Mapping[str, Any], problems: _Problems) -> SolveSpec | None:
    if "solve" not in raw:
        problems.add("solve", f"missing table [solve]; it needs kind = "
                              f"{SOLVE_KEYS['kind'].allowed}")
        return None
    table = raw["solve"]
    values = _check_table(table, SOLVE_KEYS, "solve", problems, "solve")
    _require(values, table, ["kind"], SOLVE_KEYS, "solve", problems)
    kind = values.get("kind")
    if kind is None:
        return None
    used = SOLVE_KIND_KEYS[kind]
    _not_applicable(table, SOLVE_KEYS, ("kind",) + used, "solve", problems,
                    f"to kind {kind!r}" + (f" (it uses {', '.join(used)})" if used else ""))
    if kind == "dynamic":
        _check_dynamic(table, values, problems)
    if kind == "modes" and values.get("modes", 1) < 1:
        problems.add("solve.modes", f"a modes solve needs modes >= 1, got {values['modes']}")
    return SolveSpec(kind=kind, **_with_defaults(SOLVE_KEYS, values,
                                                 [k for k in SOLVE_KEYS if k != "kind"]))


def _check_dynamic(table: Mapping[str, Any], values: dict[str, Any], problems: _Problems) -> None:
    method = values.get("method", "analytic")
    if "frames" in table and "times" in table:
        problems.add("solve.times", "give either frames or times, not both")
    if "t_end" not in table and "times" not in table:
        problems.add("solve.t_end", f"missing (a dynamic solve needs an end time); expected "
                                    f"{SOLVE_KEYS['t_end'].allowed}")
    times = values.get("times")
    if times is not None:
        bad = _first_not_increasing(times)
        if bad is not None:
            problems.add(f"solve.times[{bad}]", f"times must be increasing, got {list(times)}")
        if "t_end" in values and times[-1] > values["t_end"]:
            problems.add("solve.times", f"times must be <= t_end = {values['t_end']:g}, "
                                        f"got {times[-1]:g}")
        values.setdefault("t_end", times[-1] if times[-1] > 0 else None)
        if values["t_end"] is None:
            problems.add("solve.times", "needs a time > 0")
    _not_applicable(table, ("rtol", "atol"), ("rtol", "atol") if method in IVP_METHODS else (),
                    "solve", problems, f"to method {method!r} (only to {', '.join(IVP_METHODS)})")
    _not_applicable(table, ("dt",), ("dt",) if method == "newmark" else (), "solve", problems,
                    f"to method {method!r} (only to newmark)")


def _validate_output(raw: Mapping[str, Any], problems: _Problems,
                     solve: SolveSpec | None) -> OutputSpec | None:
    table = raw.get("output", {})
    values = _check_table(table, OUTPUT_KEYS, "output", problems, "output")
    if "formats" in values:
        expanded: list[str] = []
        for name in values["formats"]:
            for f in FORMAT_ALIASES.get(name, (name,)):
                if f not in expanded:
                    expanded.append(f)
        values["formats"] = tuple(expanded)
    if "time" in values and solve is not None:
        if solve.kind != "dynamic":
            problems.add("output.time", f"does not apply to a {solve.kind} solve (only dynamic)")
        elif solve.t_end is not None and values["time"] > solve.t_end:
            problems.add("output.time", f"must be <= t_end = {solve.t_end:g}, got "
                                        f"{values['time']:g}")
    for i, (u, v) in enumerate(values.get("probes", ()), start=1):
        if u < 0 or v < 0:
            problems.add(f"output.probes[{i}]", f"parameters must be >= 0, got [{u:g}, {v:g}]")
    return OutputSpec(**values)


# =====================================================================================
# Printing: the effective scenario (defaults filled in) as TOML
# =====================================================================================
def _toml_value(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if math.isinf(value):
            return "inf" if value > 0 else "-inf"
        return repr(value)
    if isinstance(value, (str, Path)):   # JSON escapes are TOML escapes; TOML also bans DEL
        return json.dumps(str(value), ensure_ascii=False).replace("\x7f", "\\u007f")
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_toml_value(v) for v in value) + "]"
    if isinstance(value, dict):
        return "{ " + ", ".join(f"{k} = {_toml_value(v)}" for k, v in value.items()) + " }"
    raise TypeError(f"cannot write {type(value).__name__} as TOML")


def _toml_table(header: str, items: Iterable[tuple[str, Any]]) -> list[str]:
    return [header] + [f"{k} = {_toml_value(v)}" for k, v in items if v is not None] + [""]


def _solve_items(solve: SolveSpec) -> list[tuple[str, Any]]:
    items: list[tuple[str, Any]] = [("kind", solve.kind)]
    if solve.kind == "static":
        items += [("frames", solve.frames)]
    if solve.kind == "dynamic":
        items += [("method", solve.method), ("t_end", solve.t_end)]
        items += [("times", solve.times)] if solve.times is not None else [("frames", solve.frames)]
        items += [("modes", solve.modes)]
        if solve.method in IVP_METHODS:
            items += [("rtol", solve.rtol), ("atol", solve.atol)]
        if solve.method == "newmark":
            items += [("dt", solve.dt)]
    elif solve.kind == "modes":
        items += [("modes", solve.modes), ("frames", solve.frames)]
    return items


def _load_items(load: LoadSpec) -> list[tuple[str, Any]]:
    keys = ("kind",) + LOAD_KIND_KEYS[load.kind] + ("profile",) + PROFILE_KEYS[load.profile]
    return [(k, getattr(load, k)) for k in keys]


def scenario_to_toml(scenario: Scenario) -> str:
    """The scenario as TOML with every default filled in: exactly what would run.

    Reading the text back with :func:`parse_scenario` gives an equal scenario.
    """
    s = scenario
    out = [f"{k} = {_toml_value(getattr(s, k))}" for k in TOP_KEYS if getattr(s, k)]
    out += [""] if out else []
    surface = s.surface
    items: list[tuple[str, Any]] = [("shape", surface.shape), *surface.parameters.items()]
    fitted = [("cells", surface.cells), ("degree", surface.degree), ("knots", surface.knots),
              ("method", surface.method)]
    if surface.shape == "file":
        given = s.raw.get("surface", {})
        grid = surface.path is not None and surface.path.suffix.lower() == ".npy"
        items += [("path", surface.path)]
        items += [item for item in fitted if grid or item[0] in given]
        items += [("frame", surface.frame)] if "frame" in given else []
    else:
        items += fitted
    out += _toml_table("[surface]", items)
    out += _toml_table("[material]", [(k, getattr(s.material, k)) for k in MATERIAL_KEYS])
    boundary: list[tuple[str, Any]] = [(e, getattr(s.boundary, e)) for e in EDGES]
    region = {k: getattr(s.boundary, f"free_{k}") for k in "uv"
              if getattr(s.boundary, f"free_{k}") is not None}
    out += _toml_table("[boundary]", boundary + ([("free_region", region)] if region else []))
    for load in s.loads:
        out += _toml_table("[[load]]", _load_items(load))
    out += _toml_table("[solve]", _solve_items(s.solve))
    out += _toml_table("[output]", [(k, getattr(s.output, k)) for k in OUTPUT_KEYS])
    return "\n".join(out).rstrip() + "\n"


# =====================================================================================
# Building: scenario -> surface, model, load
# =====================================================================================
@dataclass
class Built:
    """The library objects of a scenario (see :func:`build`)."""

    surface: Any            # splinedeform.Surface
    model: Any              # splinedeform.Model
    load: Any               # splinedeform.loads.Load or None
    fixed: Any = None       # bool mask (n_u, n_v) of the free region, or None


@contextmanager
def _located(scenario: Scenario, path: str) -> Iterator[None]:
    """Re-raise library input errors as scenario errors located at ``path``."""
    try:
        yield
    except ScenarioError:
        raise
    except InputError as exc:
        raise scenario.error(path, str(exc)) from None


def build_surface(scenario: Scenario) -> Any:
    """The initial surface: a built-in shape, a stored control net or a fitted point grid."""
    spec = scenario.surface
    if spec.shape == "file":
        return _surface_from_file(scenario)
    from . import shapes

    with _located(scenario, "surface"):
        return getattr(shapes, spec.shape)(**spec.parameters, **_fit_options(spec))


def _fit_options(spec: SurfaceSpec) -> dict[str, Any]:
    """``cells``, ``degree``, ``knots``, ``method`` for a shape function (None: its default)."""
    options: dict[str, Any] = {"degree": spec.degree, "method": spec.method}
    if spec.cells is not None:
        options["cells"] = spec.cells
    if spec.knots is not None:
        options["knots"] = spec.knots
    return options


def _surface_from_file(scenario: Scenario) -> Any:
    from . import shapes
    from .export import read_control_net

    spec = scenario.surface
    path = spec.path
    assert path is not None
    suffix = path.suffix.lower()
    if not path.is_file():
        raise scenario.error("surface.path", f"file not found: {path}")
    if suffix not in (".json", ".npz", ".npy"):
        raise scenario.error("surface.path", f"expected a control net (.json, .npz) or a point "
                                             f"grid (.npy, .npz), got {path.name!r}")
    grid = _point_grid(scenario, path) if suffix in (".npy", ".npz") else None
    if grid is None:
        fitted = [k for k in ("cells", "degree", "knots", "method")
                  if k in scenario.raw.get("surface", {})]
        if fitted:
            raise scenario.error(f"surface.{fitted[0]}", f"does not apply to a control net "
                                                         f"file ({path.name} holds its own bases)")
        with _located(scenario, "surface.path"):
            return read_control_net(path, frame=spec.frame)
    if "frame" in scenario.raw.get("surface", {}):
        raise scenario.error("surface.frame", "applies to control net files only, "
                                              f"{path.name} is a point grid")
    if spec.method == "quasi":
        raise scenario.error("surface.method", "a point grid is fitted by \"interpolate\" "
                                               "or \"l2\" (\"quasi\" needs a function)")
    with _located(scenario, "surface.path"):
        return shapes.from_points(grid, **_fit_options(spec))


def _point_grid(scenario: Scenario, path: Path) -> Any:
    """The ``(N_u, N_v, 3)`` grid in a ``.npy`` / ``.npz`` file, or None for a control net."""
    import numpy as np

    try:
        with open(path, "rb") as fh:
            data = np.load(fh, allow_pickle=False)
            if isinstance(data, np.lib.npyio.NpzFile):
                if "control_points" in data.files and "kind_u" in data.files:
                    return None
                names = data.files
                if "points" not in names and len(names) != 1:
                    raise scenario.error("surface.path", f"{path.name} holds {names}; a point "
                                                         "grid .npz needs one array or 'points'")
                data = data["points" if "points" in names else names[0]]
    except (OSError, ValueError) as exc:
        raise scenario.error("surface.path", f"cannot read {path.name}: {exc}") from None
    if data.ndim != 3 or data.shape[2] != 3:
        raise scenario.error("surface.path", f"a point grid must have shape (N_u, N_v, 3), "
                                             f"got {data.shape}")
    return data


def build_load(scenario: Scenario) -> Any:
    """The sum of the ``[[load]]`` tables as a :mod:`splinedeform.loads` object (or None)."""
    from . import loads as L

    total = None
    for i, spec in enumerate(scenario.loads, start=1):
        with _located(scenario, f"load[{i}]"):
            profile = {"constant": lambda: L.Constant(),
                       "step": lambda: L.Step(spec.t_on, spec.t_off),
                       "piecewise": lambda: L.Piecewise(spec.points),
                       "harmonic": lambda: L.Harmonic(spec.omega, spec.phase)}[spec.profile]()
            load = {"point": lambda: L.Point(spec.at[0], spec.at[1], spec.force, profile),
                    "uniform": lambda: L.Uniform(spec.force, profile),
                    "pressure": lambda: L.Pressure(spec.q, profile)}[spec.kind]()
        total = load if total is None else total + load
    return total


def free_region_mask(scenario: Scenario, surface: Any) -> Any:
    """``fixed`` mask (True = fixed): control points whose Greville point lies outside the box."""
    boundary = scenario.boundary
    if not boundary.has_free_region:
        return None
    inside = []
    for name, basis in (("u", surface.basis_u), ("v", surface.basis_v)):
        g = basis.greville()
        box = getattr(boundary, f"free_{name}") or (-math.inf, math.inf)
        tol = 1e-12 * basis.length
        inside.append((g >= box[0] - tol) & (g <= box[1] + tol))
    moving = inside[0][:, None] & inside[1][None, :]
    if not moving.any():
        raise scenario.error("boundary.free_region", "no control point has its Greville "
                                                     "abscissae inside this box; widen it")
    return ~moving


def _check_parameters(scenario: Scenario, surface: Any) -> None:
    """Point loads and probes must lie on the parameter domain (any value when periodic)."""
    bases = (surface.basis_u, surface.basis_v)
    checks = [(f"load[{i}].at", spec.at) for i, spec in enumerate(scenario.loads, start=1)
              if spec.at is not None]
    checks += [(f"output.probes[{i}]", p) for i, p in enumerate(scenario.output.probes, start=1)]
    for path, (u, v) in checks:
        for x, basis, name in ((u, bases[0], "u"), (v, bases[1], "v")):
            if not basis.periodic and not -1e-12 <= x <= basis.length * (1 + 1e-12):
                raise scenario.error(path, f"{name} = {x:g} is outside the parameter domain "
                                           f"[0, {basis.length:g}] of this surface")


def build(scenario: Scenario) -> Built:
    """Surface, model and load of a scenario; library input errors name the scenario key."""
    from .material import Material
    from .model import Model

    surface = build_surface(scenario)
    _check_parameters(scenario, surface)
    fixed = free_region_mask(scenario, surface)
    with _located(scenario, "material"):
        material = Material(**scenario.material.weights())
    with _located(scenario, "boundary"):
        model = Model(surface, material, boundary=scenario.boundary.edges(), fixed=fixed,
                      mass_matrix=scenario.material.mass_matrix)
    return Built(surface=surface, model=model, load=build_load(scenario), fixed=fixed)


def describe(scenario: Scenario, built: Built | None = None) -> list[tuple[str, str]]:
    """(label, value) rows saying what :func:`run` would do (for ``splinedeform validate``)."""
    s = scenario
    rows = [("scenario", s.title or s.name), ("surface", s.surface.shape)]
    if built is not None:
        n_u, n_v = built.surface.shape
        rows += [("control net", f"{n_u} x {n_v} ({n_u * n_v} points)"),
                 ("free control points", str(built.model.n_free))]
    rows += [("loads", ", ".join(f"{ld.kind} ({ld.profile})" for ld in s.loads) or "none"),
             ("solve", s.solve.kind + (f" with {s.solve.method} to t = {s.solve.t_end:g}"
                                       if s.solve.kind == "dynamic" else "")),
             ("frames", str(len(s.solve.frame_times()) if s.solve.kind == "dynamic"
                            else s.solve.frames)),
             ("outputs", ", ".join(s.output.formats) or "none")]
    return rows
