"""Value checkers of scenario keys: each returns the normalised value or raises :class:`_Invalid`."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Callable

from .locate import _describe


class _Invalid(Exception):
    """A value is not allowed; the message says what was given and what is allowed.

    ``sub`` locates the offending element inside the value (``"[2]"``).
    """

    def __init__(self, message: str, sub: str = "") -> None:
        super().__init__(message)
        self.sub = sub


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


