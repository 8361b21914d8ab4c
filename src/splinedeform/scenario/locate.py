"""Where keys are written in a TOML text, and problems reported at their lines."""

from __future__ import annotations

import tomllib
from typing import Any, Callable, Mapping

from ..errors import ScenarioError
from ..terminal import printable


# =====================================================================================
# Where keys are written: tomllib gives values, not positions
# =====================================================================================
_BARE = frozenset("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789_-")


def _decoded(quote: str, raw: str) -> str:
    """The key a quoted TOML key names: a basic ``"..."`` key's escapes decoded by tomllib.

    A literal ``'...'`` key has no escapes. An undecodable raw text is returned as it is
    (tomllib has already refused such a file before any key is located).
    """
    if quote == "'" or "\\" not in raw:
        return raw
    try:
        return tomllib.loads(f'k = "{raw}"')["k"]
    except tomllib.TOMLDecodeError:
        return raw


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
                parts.append(_decoded(self.peek(), self.string()))
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


#: deepest nesting of arrays and inline tables a scenario may use (it needs 3)
MAX_NESTING = 64


def nesting_too_deep(text: str, limit: int = MAX_NESTING) -> int | None:
    """Line where arrays / inline tables nest deeper than ``limit``, or None.

    Checked before parsing: :mod:`tomllib` and the key scanner recurse once per level, so a
    file nested thousands deep would otherwise end in a ``RecursionError``.
    """
    scanner = _KeyScanner(text)
    depth = 0
    while not scanner.at_end():
        c = scanner.peek()
        if c in ('"', "'"):
            scanner.string()
            continue
        if c == "#":
            scanner.skip_to_line_end()
            continue
        if c in "[{":
            depth += 1
            if depth > limit:
                return scanner.line
        elif c in "]}":
            depth = max(depth - 1, 0)
        scanner.advance()
    return None


def key_lines(text: str) -> dict[str, int]:
    """Line number (from 1) of every key path written in a TOML text.

    A best effort by scanning the text, as :mod:`tomllib` reports no positions. Paths are
    dotted; arrays of tables and array elements are indexed from 1, e.g.
    ``{"surface": 3, "surface.shape": 4, "load[2].force": 17, "output.probes[1]": 30}``.
    """
    return _KeyScanner(text).scan()


# =====================================================================================


# =====================================================================================
# Problems: each becomes one line of a ScenarioError
# =====================================================================================
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
        items = [printable(text) for _, text in sorted(self.items, key=lambda item: item[0])]
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


