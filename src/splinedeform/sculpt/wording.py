"""A scenario error about the page's settings, in the page's words (its fields, not the
lines of a file the page never showed)."""

from __future__ import annotations

import re

PAGE_FIELDS = {"material": "Material", "boundary": "Boundary",
               "boundary.free_region": "Free set: the free region box",
               "boundary.free_points": "Free set: the painted control points",
               "boundary.faces_free_points": "Free set: the painted control points of face"}
"""What the page calls a key of the scenario (material weights and edges: ``Material
w10``, ``Boundary u0``)."""


def page_field(key: str) -> str:
    """The page's name of a scenario key path (``material.w10`` → ``Material w10``)."""
    for prefix in sorted(PAGE_FIELDS, key=len, reverse=True):
        if key == prefix or key.startswith(prefix + ".") or key.startswith(prefix + "["):
            rest = key[len(prefix):].lstrip(".")
            return PAGE_FIELDS[prefix] + (f" {rest}" if rest else "")
    return key


def in_page_words(message: str, source: str) -> str:
    """A scenario error about the page's settings, worded for the page: each
    ``file:line: key: text`` (or ``file (sculpt page): key: text``) becomes
    ``<page field>: text``; the file and its lines are not the page's."""
    where = re.compile(rf"^(\s*){re.escape(source)}(?::\d+| \([^)]*\))?: ([\w.\[\]]+): ")
    head = re.compile(rf"^{re.escape(source)}: (\d+) problems in the scenario$")
    lines = []
    for line in message.splitlines():
        line = head.sub(r"\1 problems with the page's settings:", line)
        lines.append(where.sub(lambda m: m.group(1) + page_field(m.group(2)) + ": ", line))
    return "\n".join(lines)
