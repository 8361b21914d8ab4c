"""A refused re-solve is worded in the page's terms: its field, never a line of the file
the session started from (the change was made on the page, not in the file)."""

from __future__ import annotations

import pytest

from splinedeform.errors import InputError
from splinedeform.scenario import load_scenario
from splinedeform.sculpt.messages import ResolveMessage
from splinedeform.sculpt.session import Session, in_page_words, page_field

SHEET = """title = "sheet"
[surface]
shape = "plane"
cells = 3
[material]
damping = 0.8
w10 = 1.0
w01 = 1.0
[boundary]
u0 = "clamped"
[solve]
kind = "modes"
"""


@pytest.fixture()
def session(tmp_path):
    (tmp_path / "sheet.toml").write_text(SHEET)
    return Session(load_scenario(tmp_path / "sheet.toml"), resolution=4, modes=None)


@pytest.mark.parametrize("change, words", [
    ({"material": {"mass": 1.0, "w10": 0.0, "w01": 0.0}, "boundary": {"u0": "clamped"}},
     "Material: all stiffness weights are zero"),
    ({"material": {"mass": 1.0, "w10": 1.0, "w01": 1.0}, "boundary": {"u0": "pole"}},
     "Boundary u0: "),
    ({"material": {"mass": 1.0, "w10": 1.0, "w01": 1.0}, "boundary": {"u0": "clamped"},
      "free_region": {"u": [5.0, 6.0]}}, "Free set: the free region box: "),
])
def test_a_refusal_names_the_page_field_and_no_line_of_the_file(session, change, words):
    with pytest.raises(InputError) as info:
        session.resolve(ResolveMessage.model_validate(change))
    message = str(info.value)
    assert message.startswith(words), message
    assert "sheet.toml" not in message
    assert session.progress["error"] == message and session.version == 1


def test_several_problems_are_each_worded_for_the_page():
    source = "/data/a (1).toml"
    text = (f"{source}: 2 problems in the scenario\n  {source}:5: material.w10: too big\n"
            f"  {source} (sculpt page): boundary.free_points[2]: off the net")
    assert in_page_words(text, source).splitlines() == [
        "2 problems with the page's settings:", "  Material w10: too big",
        "  Free set: the painted control points [2]: off the net"]
    assert page_field("boundary.v1") == "Boundary v1" and page_field("solve.t_end") == "solve.t_end"
