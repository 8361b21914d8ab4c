"""Nothing a scenario file says reaches the terminal as a control sequence."""
from __future__ import annotations

import re

import pytest
from typer.testing import CliRunner

from splinedeform import cli
from splinedeform.terminal import printable

HOSTILE = "\x1b]0;owned\x07\x1b[2J\x1b]8;;http://x/\x1b\\link\x9b31m \u202eevil\u2066 \r\b"
#: every character a terminal may act on: C0 but tab/newline, DEL, C1, bidi, separators
CONTROL = re.compile("[\x00-\x08\x0b-\x1f\x7f-\x9f\u061c\u200e\u200f\u2028\u2029"
                     "\u202a-\u202e\u2066-\u2069]")

SCENARIO = """\
title = {title}
[surface]
shape = "plane"
cells = 3
{key}
[material]
w10 = 1.0
w01 = 1.0
[boundary]
u0 = "clamped"
[solve]
kind = "modes"
modes = 2
[output]
formats = ["report"]
"""


def toml_string(text: str) -> str:
    import json
    return json.dumps(text)        # a JSON string with \\uXXXX escapes is a TOML basic string


def test_printable_makes_every_control_character_visible_and_keeps_the_rest():
    shown = printable(HOSTILE + "\tok\nnext é ✓")
    assert not CONTROL.search(shown)
    assert shown.startswith(r"\x1b]0;owned\x07\x1b[2J") and r"\u202eevil\u2066" in shown
    assert shown.endswith("\tok\nnext é ✓")
    assert printable("plain text [bold]") == "plain text [bold]"


@pytest.mark.parametrize("command", ["run", "validate"])
def test_a_hostile_title_is_printed_as_visible_text(tmp_path, command):
    path = tmp_path / "case.toml"
    path.write_text(SCENARIO.format(title=toml_string(HOSTILE + " [bold red]markup[/]"), key=""))
    args = [command, str(path)] + (["-o", str(tmp_path / "out")] if command == "run" else [])
    result = CliRunner().invoke(cli.app, args)
    assert result.exit_code == 0, result.output
    assert not CONTROL.search(result.output)
    assert r"\x1b]0;owned\x07" in result.output and "[bold red]markup[/]" in result.output


def test_a_hostile_key_name_in_an_error_is_printed_as_visible_text(tmp_path):
    path = tmp_path / "case.toml"
    path.write_text(SCENARIO.format(title='"t"', key=f"{toml_string(HOSTILE)} = 1"))
    result = CliRunner().invoke(cli.app, ["validate", str(path)])
    assert result.exit_code != 0 and "unknown key in [surface]" in result.output
    assert not CONTROL.search(result.output) and r"\x1b[2J" in result.output
