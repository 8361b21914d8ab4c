"""Text that is safe to print on a terminal.

Scenario files are shared between people, and their titles, key names and paths reach the
terminal in tables and error messages. Control characters there are instructions to the
terminal, not text: ``ESC [2J`` clears the screen, ``ESC ] 0 ; … BEL`` sets the window
title, ``ESC ] 8 ;;`` makes hyperlinks, and the Unicode bidirectional overrides reorder what
is shown. :func:`printable` replaces each of them with a visible escape such as ``\\x1b``.
"""

from __future__ import annotations

import re

#: C0 controls except tab and newline, DEL, C1 controls, and the bidirectional formatting
#: characters (embeddings, overrides, isolates) and line/paragraph separators
_CONTROL = re.compile("[\x00-\x08\x0b-\x1f\x7f-\x9f\u061c\u200e\u200f\u2028\u2029"
                      "\u202a-\u202e\u2066-\u2069]")


def _visible(match: re.Match[str]) -> str:
    code = ord(match.group())
    return f"\\x{code:02x}" if code < 0x100 else f"\\u{code:04x}"


def printable(text: str) -> str:
    """``text`` with every terminal control character replaced by its escape (``\\x1b``).

    Tabs and newlines are kept; everything else is printed as it is.

    >>> printable("title\\x1b]0;owned\\x07")
    'title\\\\x1b]0;owned\\\\x07'
    """
    return _CONTROL.sub(_visible, text)
